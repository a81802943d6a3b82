static const char *DOC = R"DOC(
# specfilm

Spectral film of the spectral modes (`scalar_spectral`, `scalar_spectral_polarized`): instead of
R, G, B it records one channel per nested spectrum, a sensor response function (SRF) s: the
radiance weighted by it, ∫ s(λ) L(λ) dλ over 360-830 nm (an SRF is not normalised: divide it by
its integral for a mean). The channels are named after the spectra's parameter names, in
alphabetical order, followed by the integrator's AOVs; there is no alpha. The film writes
OpenEXR only.

The paths' wavelengths are drawn from the sum of the SRFs (four per path, stratified), tabulated
on a regular grid from the smallest to the largest wavelength the spectra are given at (the whole
range for a spectrum not given at wavelengths, such as a constant or `blackbody`), at the finest
spacing of their wavelengths and at least every nanometre, so every band gets samples and no
wavelength outside all bands is traced. Parts of
an SRF outside 360-830 nm are not rendered (facet's spectral range). Light tracers (`ptracer`)
cannot render into bands; the `aov` integrator's albedo, `moment` and `stokes` develop their own
RGB and are refused with it.

| Parameter | Type | Default | Description |
|---|---|---|---|
| width | integer | 768 | Image width in pixels (width·height at most 2²⁷) |
| height | integer | 576 | Image height in pixels |
| crop_offset_x | integer | 0 | Left column of the crop window (as hdrfilm's) |
| crop_offset_y | integer | 0 | Top row of the crop window |
| crop_width | integer | width - crop_offset_x | Width of the crop window |
| crop_height | integer | height - crop_offset_y | Height of the crop window |
| component_format | string | float16 | float16 or float32 (EXR sample type) |
| sample_border | boolean | false | Accepted for compatibility (as hdrfilm's) |
| compensate | boolean | false | Accepted for compatibility; the film always accumulates in double precision |
| (spectra) | spectrum | — | One or more SRFs: `<spectrum name="..." value="λ:v, ..."/>`, `filename="x.spd"`, or a spectrum plugin (`regular`, `irregular`, `uniform`, ...) |
| (rfilter) | rfilter | gaussian | Nested reconstruction filter |

```xml
<film type="specfilm">
    <integer name="width" value="640"/>
    <integer name="height" value="480"/>
    <spectrum name="band1_red" filename="data_red.spd"/>
    <spectrum name="band2_green" value="500:0, 550:1, 600:0"/>
    <spectrum name="band3_blue" type="regular">
        <float name="wavelength_min" value="400"/>
        <float name="wavelength_max" value="500"/>
        <string name="values" value="0, 1, 0"/>
    </spectrum>
</film>
```
)DOC";

#include <facet/film.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/spectrum.h>
#include <facet/texture.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

namespace facet {

class SpecFilm final : public Film {
public:
    explicit SpecFilm(const Properties &props) : Film(props) {
        constexpr int64_t MaxPixels = int64_t(1) << 27;
        int64_t pixels = 0;
        if (__builtin_mul_overflow(int64_t(m_size.x), int64_t(m_size.y), &pixels) ||
            pixels > MaxPixels)
            FACET_THROW_AT(props.location(),
                           "the film is {}x{} pixels, more than the {} pixels (2^27, e.g. "
                           "16384x8192) specfilm supports",
                           m_size.x, m_size.y, MaxPixels);
        const std::string component_format = lower(props.get_string("component_format", "float16"));
        if (component_format == "float16")
            m_half = true;
        else if (component_format == "float32")
            m_half = false;
        else
            FACET_THROW_AT(props.location("component_format"),
                           "component_format must be float16 or float32, got \"{}\"{}",
                           component_format,
                           component_format == "uint32" ? " (uint32 is not supported)" : "");
        props.get_bool("sample_border", false);
        props.get_bool("compensate", false);
        m_bands = read_bands(props);
    }

    std::string default_extension() const override { return ".exr"; }

    void write(const Image &image, const std::string &path,
               const ImageWriteOptions &opts) const override {
        std::string ext = lower(std::filesystem::path(path).extension().string());
        if (ext != ".exr")
            FACET_THROW("{}: specfilm writes OpenEXR only (its channels are the spectral bands {}): "
                        "name the output .exr",
                        path, fmt::join(m_bands->names(), ", "));
        Film::write(image, path, opts);
    }

    std::string to_string() const override {
        return fmt::format("SpecFilm[bands=({}), grid=[{}, {}] nm, {}]",
                           fmt::join(m_bands->names(), ", "), m_bands->lambda_min(),
                           m_bands->lambda_max(), Film::to_string());
    }

private:
    static std::string lower(std::string s) {
        std::transform(s.begin(), s.end(), s.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
        return s;
    }

    /// The nested spectra, sorted by name, and the grid of their sum: from the smallest to the
    /// largest tabulated wavelength, at the finest spacing (the whole range at 1 nm for a
    /// spectrum without wavelengths).
    static std::shared_ptr<const SpectralBands> read_bands(const Properties &props) {
        std::vector<SpectralBands::Band> bands;
        double lo = INFINITY, hi = -INFINITY, resolution = 1.0;
        for (const auto &[name, obj] : props.objects())
            if (obj && obj->type() != ObjectType::ReconstructionFilter &&
                !std::dynamic_pointer_cast<SpectrumTexture>(obj))
                FACET_THROW_AT(props.location(name),
                               "specfilm: \"{}\" is a {}, not a spectrum: the film takes spectra "
                               "(sensor response functions) and a reconstruction filter",
                               name, object_type_name(obj->type()));
        for (auto &[name, srf] : props.spectra(SpectrumKind::Measured)) {
            if (const std::optional<TabulatedRange> r = tabulated_range(*srf)) {
                if (r->max <= SpectralMinNm || r->min >= SpectralMaxNm)
                    FACET_THROW_AT(props.location(name),
                                   "specfilm: the spectrum \"{}\" is given over [{}, {}] nm, "
                                   "outside the {}-{} nm facet renders",
                                   name, r->min, r->max, SpectralMinNm, SpectralMaxNm);
                if (r->min < SpectralMinNm || r->max > SpectralMaxNm)
                    FACET_LOG(Warn,
                              "{}: specfilm: the spectrum \"{}\" is given over [{}, {}] nm: its "
                              "parts outside {}-{} nm are not rendered",
                              props.location(name).to_string(), name, r->min, r->max,
                              SpectralMinNm, SpectralMaxNm);
                lo = std::min(lo, r->min);
                hi = std::max(hi, r->max);
                resolution = std::min(resolution, r->resolution);
            } else {
                lo = SpectralMinNm;
                hi = SpectralMaxNm;
            }
            bands.push_back({name, std::move(srf)});
        }
        if (bands.empty())
            FACET_THROW_AT(props.location(),
                           "specfilm needs at least one spectrum (a sensor response function), "
                           "e.g. <spectrum name=\"band\" value=\"400:0, 550:1, 700:0\"/>");
        std::sort(bands.begin(), bands.end(),
                  [](const auto &a, const auto &b) { return a.name < b.name; });
        lo = std::max(lo, double(SpectralMinNm));
        hi = std::min(hi, double(SpectralMaxNm));
        // At least the finest spacing's resolution (bounded: 2^20 points at most).
        const double span = hi - lo;
        const double steps = std::ceil(span / std::max(resolution, span / double(1 << 20)) - 1e-6);
        const size_t points = size_t(std::clamp(steps, 1.0, double(1 << 20) - 1.0)) + 1;
        try {
            return std::make_shared<SpectralBands>(std::move(bands), float(lo), float(hi), points);
        } catch (const Error &e) {
            if (e.location().valid()) throw;
            FACET_THROW_AT(props.location(), "specfilm: {}", e.message());
        }
    }
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::SpecFilm, Film, "specfilm",
                          "Spectral film: one channel per sensor response function", DOC,
                          ::facet::mode_bit(::facet::ColourMode::Spectral) |
                              ::facet::mode_bit(::facet::ColourMode::SpectralPolarized))
