static const char *DOC = R"DOC(
# irregular: a spectrum sampled at given wavelengths

Values at the listed (strictly ascending) wavelengths, interpolated linearly and zero outside
their range. facet converts the spectrum to RGB when the scene is loaded, as its use calls for
(Mitsuba's RGB variants cannot evaluate it): it is integrated against the CIE 1931 curves, a
reflectance weighted by D65 and clamped to [0, 1], an emission unweighted and clamped at 0 (the
same conversion as a `<spectrum value="λ:v, ...">` list).

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| wavelengths | string | — | Wavelengths in nm, separated by commas or spaces, strictly ascending |
| values | string | — | One value per wavelength |

```xml
<spectrum type="irregular" name="radiance">
    <string name="wavelengths" value="400, 500, 650"/>
    <string name="values" value="1, 3, 0.5"/>
</spectrum>
```
)DOC";

#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class IrregularSpectrum final : public SpectrumTexture {
public:
    explicit IrregularSpectrum(const Properties &props) {
        for (const char *name : {"wavelengths", "values"})
            if (!props.has(name))
                FACET_THROW_AT(props.location(), "irregular: the parameter \"{}\" is required",
                               name);
        try {
            m_data.wavelengths =
                parse_number_list(props.get_string("wavelengths"), "irregular: wavelengths");
            m_data.values = parse_number_list(props.get_string("values"), "irregular: values");
        } catch (const Error &e) {
            FACET_THROW_AT(props.location(), "{}", e.message());
        }
        if (m_data.wavelengths.size() != m_data.values.size())
            FACET_THROW_AT(props.location(),
                           "irregular: wavelengths and values must have the same size ({} vs {})",
                           m_data.wavelengths.size(), m_data.values.size());
        for (size_t i = 1; i < m_data.wavelengths.size(); ++i)
            if (!(m_data.wavelengths[i] > m_data.wavelengths[i - 1]))
                FACET_THROW_AT(props.location("wavelengths"),
                               "irregular: wavelengths must be strictly ascending ({} nm follows "
                               "{} nm)",
                               m_data.wavelengths[i], m_data.wavelengths[i - 1]);
        m_data.uniform = false;
    }
    Color3f value(SpectrumKind kind) const override { return spectrum_to_rgb(m_data, kind); }
    std::shared_ptr<Texture> spectral(SpectrumKind kind) const override {
        return data_spectrum_texture(m_data, kind);
    }
    std::string to_string() const override {
        return fmt::format("IrregularSpectrum[{}]", m_data.to_string());
    }

private:
    SpectrumData m_data;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::IrregularSpectrum, Texture, "irregular",
                          "Spectrum sampled at given wavelengths", DOC, ::facet::AllModes)
