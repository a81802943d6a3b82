static const char *DOC = R"DOC(
# srgb: a colour given in linear sRGB

A constant colour (linear Rec.709 RGB, as `<rgb>`), used as stored. Where it describes a
reflectance it must lie in [0, 1] (as Mitsuba requires); emitted and other unbounded
quantities take the colour as it is.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| color | rgb | — | The colour |

```xml
<bsdf type="diffuse">
    <spectrum type="srgb" name="reflectance">
        <rgb name="color" value="0.8, 0.3, 0.1"/>
    </spectrum>
</bsdf>
```
)DOC";

#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class SRGBSpectrum final : public SpectrumTexture {
public:
    explicit SRGBSpectrum(const Properties &props) {
        if (!props.has("color"))
            FACET_THROW_AT(props.location(), "srgb: the parameter \"color\" is required");
        m_color = props.get_color("color", SpectrumKind::Unbounded);
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(m_color[c]))
                FACET_THROW_AT(props.location("color"), "srgb: the colour must be finite");
    }
    Color3f value(SpectrumKind kind) const override {
        if (kind == SpectrumKind::Reflectance)
            for (int c = 0; c < 3; ++c)
                if (!(m_color[c] >= 0.f && m_color[c] <= 1.f))
                    FACET_THROW("srgb: invalid RGB reflectance value [{}, {}, {}], must be in "
                                "the range [0, 1]",
                                m_color.r, m_color.g, m_color.b);
        return m_color;
    }
    std::string to_string() const override {
        return fmt::format("SRGBSpectrum[color = [{}, {}, {}]]", m_color.r, m_color.g, m_color.b);
    }

private:
    Color3f m_color;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::SRGBSpectrum, Texture, "srgb", "Constant linear sRGB colour", DOC,
                          ::facet::AllModes)
