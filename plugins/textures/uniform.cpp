static const char *DOC = R"DOC(
# uniform: a constant spectrum

The same value at every wavelength. As in Mitsuba's RGB variants the explicit plugin gives the
plain value (1 → white (1, 1, 1)) for reflectances and emission alike; the shorthand
`<spectrum name="radiance" value="v"/>` on an emitter instead goes through the CIE conversion
(v · xyz_to_srgb(1, 1, 1)). The wavelength range only matters to spectral renderers; it is checked
and otherwise unused.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| value | float | — | The value |
| wavelength_min | float | 360 | Lower end of the range (nm) |
| wavelength_max | float | 830 | Upper end of the range (nm) |

```xml
<bsdf type="diffuse">
    <spectrum type="uniform" name="reflectance">
        <float name="value" value="0.5"/>
    </spectrum>
</bsdf>
```
)DOC";

#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class UniformSpectrum final : public SpectrumTexture {
public:
    explicit UniformSpectrum(const Properties &props) {
        if (!props.has("value"))
            FACET_THROW_AT(props.location(), "uniform: the parameter \"value\" is required");
        m_value = float(props.get_float("value"));
        if (!std::isfinite(m_value))
            FACET_THROW_AT(props.location("value"), "uniform: value must be finite, found {}",
                           m_value);
        double lo = props.get_float("wavelength_min", 360.0);
        double hi = props.get_float("wavelength_max", 830.0);
        if (!(lo < hi))
            FACET_THROW_AT(props.location(),
                           "uniform: wavelength_min ({}) must be below wavelength_max ({})", lo,
                           hi);
    }
    Color3f value(SpectrumKind) const override { return Color3f(m_value); }
    std::shared_ptr<Texture> spectral(SpectrumKind) const override {
        return std::make_shared<ConstantTexture>(Color3f(m_value));
    }
    std::string to_string() const override {
        return fmt::format("UniformSpectrum[value = {}]", m_value);
    }

private:
    float m_value = 0.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::UniformSpectrum, Texture, "uniform", "Constant spectrum", DOC,
                          ::facet::AllModes)
