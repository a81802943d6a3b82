static const char *DOC = R"DOC(
# d65: the CIE D65 illuminant

The daylight spectrum Mitsuba uses as the default emission spectrum, optionally tinted by a
colour. facet renders in RGB, as Mitsuba's RGB variants do, where D65 is the white point: the
spectrum becomes `scale` (a plain uniform value, not the slightly purple conversion of a
uniform `<spectrum value>`), and with a `color` it becomes `color` · `scale`.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| color | rgb | (1, 1, 1) | Colour multiplying the illuminant |
| scale | float | 1 | Multiplier |

```xml
<emitter type="area">
    <spectrum type="d65" name="radiance">
        <rgb name="color" value="0.9, 0.5, 0.2"/>
        <float name="scale" value="2"/>
    </spectrum>
</emitter>
```
)DOC";

#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class D65Spectrum final : public SpectrumTexture {
public:
    explicit D65Spectrum(const Properties &props) {
        Color3f color = props.get_color("color", Color3f(1.f), SpectrumKind::Unbounded);
        float scale = float(props.get_float("scale", 1.0));
        if (!std::isfinite(scale))
            FACET_THROW_AT(props.location("scale"), "d65: scale must be finite, found {}", scale);
        m_value = color * scale;
    }
    Color3f value(SpectrumKind) const override { return m_value; }
    /// D65 itself times the upsampled colour (an emitter's rgb as the spectral mode reads it),
    /// whatever the parameter's kind.
    std::shared_ptr<Texture> spectral(SpectrumKind) const override {
        return rgb_spectrum_texture(m_value, SpectrumKind::Emission);
    }
    std::string to_string() const override {
        return fmt::format("D65Spectrum[value = [{}, {}, {}]]", m_value.r, m_value.g, m_value.b);
    }

private:
    Color3f m_value;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::D65Spectrum, Texture, "d65",
                          "CIE D65 illuminant (RGB: a plain value)", DOC, ::facet::AllModes)
