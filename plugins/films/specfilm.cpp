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
spacing of their wavelengths and at least every nanometre, so every band gets samples and
wavelengths outside all bands are traced only in short stretches next to a band's edge. Parts
of an SRF outside 360-830 nm are not rendered (facet's spectral range). Light tracers (`ptracer`)
cannot render into bands; the `aov` integrator's albedo, `moment` and `stokes` develop their own
RGB and are refused with it, and so is a sensor's own `srf`.

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
| compensate | boolean | false | Accepted for compatibility, no effect: a pixel's sums are float, each pass's added in a fixed order, and the passes of a split render are added in double |
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
        props.get_bool("sample_border", false);
        props.get_bool("compensate", false);
        m_bands = read_bands(props);
    }

    std::string default_extension() const override { return ".exr"; }

    void write(const Image &image, const std::string &path,
               const ImageWriteOptions &opts) const override {
        std::string ext = lower(std::filesystem::path(path).extension().string());
        if (ext != ".exr")
            FACET_THROW(
                "{}: specfilm writes OpenEXR only (its channels are the spectral bands {}): "
                "name the output .exr",
                path, fmt::join(m_bands->names(), ", "));
        // The bands in the component format; the AOVs after them stay float32 (as hdrfilm's).
        ImageWriteOptions o = opts;
        o.half = m_half;
        if (m_half) o.half_channels = m_bands->names();
        o.rec709 = false;
        write_image(path, image, o);
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

    /// The nested spectra, sorted by name, on the grid of their sum (SpectralBands::fit).
    static std::shared_ptr<const SpectralBands> read_bands(const Properties &props) {
        std::vector<SpectralBands::Band> bands;
        for (const auto &[name, obj] : props.objects())
            if (obj && obj->type() != ObjectType::ReconstructionFilter &&
                !std::dynamic_pointer_cast<SpectrumTexture>(obj))
                FACET_THROW_AT(props.location(name),
                               "specfilm: \"{}\" is a {}, not a spectrum: the film takes spectra "
                               "(sensor response functions) and a reconstruction filter",
                               name, object_type_name(obj->type()));
        for (auto &[name, srf] : props.spectra(SpectrumKind::Measured)) {
            if (name.rfind(RawChannelPrefix, 0) == 0)
                FACET_THROW_AT(props.location(name),
                               "specfilm: the band \"{}\" has the prefix of facet's raw channels "
                               "(\"{}\"): rename it",
                               name, RawChannelPrefix);
            bands.push_back({name, std::move(srf)});
        }
        if (bands.empty())
            FACET_THROW_AT(props.location(),
                           "specfilm needs at least one spectrum (a sensor response function), "
                           "e.g. <spectrum name=\"band\" value=\"400:0, 550:1, 700:0\"/>");
        std::sort(bands.begin(), bands.end(),
                  [](const auto &a, const auto &b) { return a.name < b.name; });
        try {
            return SpectralBands::fit(std::move(bands));
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
