static const char *DOC = R"DOC(
# regular: a spectrum sampled at evenly spaced wavelengths

Values at `n` evenly spaced wavelengths from `wavelength_min` to `wavelength_max` (both ends
included), interpolated linearly and zero outside the range. facet converts the spectrum to RGB
when the scene is loaded, as its use calls for (Mitsuba's RGB variants cannot evaluate it): it is
integrated against the CIE 1931 curves, a reflectance weighted by D65 and clamped to [0, 1], an
emission unweighted and clamped at 0 (the same conversion as a `<spectrum value="λ:v, ...">` list).

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| wavelength_min | float | — | Wavelength of the first value (nm) |
| wavelength_max | float | — | Wavelength of the last value (nm) |
| values | string | — | The values, separated by commas or spaces (at least two) |

```xml
<spectrum type="regular" name="reflectance">
    <float name="wavelength_min" value="400"/>
    <float name="wavelength_max" value="700"/>
    <string name="values" value="0.1, 0.5, 0.9"/>
</spectrum>
```
)DOC";

#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class RegularSpectrum final : public SpectrumTexture {
public:
    explicit RegularSpectrum(const Properties &props) {
        for (const char *name : {"wavelength_min", "wavelength_max", "values"})
            if (!props.has(name))
                FACET_THROW_AT(props.location(), "regular: the parameter \"{}\" is required", name);
        double lo = props.get_float("wavelength_min"), hi = props.get_float("wavelength_max");
        if (!(lo < hi) || !std::isfinite(hi))
            FACET_THROW_AT(props.location(),
                           "regular: wavelength_min ({}) must be below wavelength_max ({})", lo,
                           hi);
        try {
            m_data.values = parse_number_list(props.get_string("values"), "regular: values");
        } catch (const Error &e) {
            FACET_THROW_AT(props.location("values"), "{}", e.message());
        }
        size_t n = m_data.values.size();
        if (n < 2)
            FACET_THROW_AT(props.location("values"),
                           "regular: values needs at least two entries, found {}", n);
        m_data.uniform = false;
        for (size_t i = 0; i < n; ++i)
            m_data.wavelengths.push_back(lo + (hi - lo) * double(i) / double(n - 1));
    }
    Color3f value(SpectrumKind kind) const override { return spectrum_to_rgb(m_data, kind); }
    std::shared_ptr<Texture> spectral(SpectrumKind kind) const override {
        return data_spectrum_texture(m_data, kind);
    }
    std::string to_string() const override {
        return fmt::format("RegularSpectrum[{}]", m_data.to_string());
    }

private:
    SpectrumData m_data;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::RegularSpectrum, Texture, "regular",
                          "Spectrum sampled at evenly spaced wavelengths", DOC, ::facet::AllModes)
