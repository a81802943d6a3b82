static const char *DOC = R"DOC(
# rawconstant: a constant used as stored

A constant texture whose value reaches the plugin unchanged: no colour conversion and no range
check, in any mode (for data such as an identity normal map, (0.5, 0.5, 1)). A single float is
repeated in the three channels. The scalar value (eval_1) of a vector is the mean of its
components.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| value | float or vector | — | The value: one float, or a 3D vector |

```xml
<texture type="rawconstant" name="normalmap">
    <vector name="value" value="0.5, 0.5, 1"/>
</texture>
```
)DOC";

#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class RawConstant final : public Texture {
public:
    explicit RawConstant(const Properties &props) {
        if (!props.has("value"))
            FACET_THROW_AT(props.location(),
                           "rawconstant: the parameter \"value\" is required (a float or a 3D "
                           "vector)");
        switch (props.type("value")) {
        case Properties::Type::Vector: {
            Vector3f v = props.get_vector("value");
            m_value = Color3f(v.x, v.y, v.z);
            break;
        }
        case Properties::Type::Float:
        case Properties::Type::Integer:
            m_value = Color3f(float(props.get_float("value")));
            break;
        default:
            FACET_THROW_AT(props.location("value"),
                           "rawconstant: \"value\" must be a float or a 3D vector, found {}",
                           props.entry_to_string("value"));
        }
    }
    Color3f eval(const SurfaceInteraction &) const override { return m_value; }
    float eval_1(const SurfaceInteraction &) const override { return m_value.mean(); }
    Vector2f eval_1_grad(const SurfaceInteraction &) const override { return Vector2f(0.f); }
    Color3f mean() const override { return m_value; }
    float max() const override { return m_value.max(); }
    bool is_spatially_varying() const override { return false; }
    std::string to_string() const override {
        return fmt::format("RawConstant[value = [{}, {}, {}]]", m_value.r, m_value.g, m_value.b);
    }

private:
    Color3f m_value;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::RawConstant, Texture, "rawconstant",
                          "Constant used as stored (no colour conversion)", DOC, ::facet::AllModes)
