static const char *DOC = R"DOC(
# checkerboard: two-colour checkerboard

A procedural checkerboard of 2 × 2 checks over the unit square of texture coordinates, repeated
outside it. Colour queries (a reflectance, a radiance) see `color0` where the fractional parts of
u and v fall in the same half (both ≤ 0.5 or both > 0.5) and `color1` elsewhere. **Scalar
queries (a roughness, a blend weight, a mask opacity) see the opposite squares**: `color0`
where the halves differ. This is Mitsuba 3's convention (its scalar evaluation swaps the two
colours) and scenes written for it depend on it. `to_uv` scales, rotates or shifts the pattern
(a scale of 4 gives 8 × 8 checks); it acts on (u, v, 1), its z row and column are ignored.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| color0 | spectrum or texture | 0.4 | Colour of the checks whose u and v halves agree (for scalar queries: of the others) |
| color1 | spectrum or texture | 0.2 | Colour of the other checks (for scalar queries: of those whose halves agree) |
| to_uv | transform | identity | Transform applied to the texture coordinates (its x, y affine part) |

```xml
<bsdf type="diffuse">
    <texture type="checkerboard" name="reflectance">
        <rgb name="color0" value="0.8, 0.8, 0.8"/>
        <rgb name="color1" value="0.1, 0.1, 0.1"/>
        <transform name="to_uv">
            <scale x="4" y="4"/>
        </transform>
    </texture>
</bsdf>
```
)DOC";

#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/transform.h>

#include <fmt/format.h>

#include <cmath>

namespace facet {

class Checkerboard final : public Texture {
public:
    explicit Checkerboard(const Properties &props) {
        m_color0 = props.texture("color0", 0.4f);
        m_color1 = props.texture("color1", 0.2f);
        m_to_uv = props.get_transform("to_uv", Transform());
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        return in_color0(si) ? m_color0->eval(si) : m_color1->eval(si);
    }

    /// Mitsuba 3 swaps the squares for scalar queries: color0 where the u and v halves differ.
    float eval_1(const SurfaceInteraction &si) const override {
        return in_color0(si) ? m_color1->eval_1(si) : m_color0->eval_1(si);
    }

    /// Piecewise: the gradient of the square's own texture (zero for plain colours); the steps
    /// at the square edges have no gradient.
    Vector2f eval_1_grad(const SurfaceInteraction &si) const override {
        return in_color0(si) ? m_color0->eval_1_grad(si) : m_color1->eval_1_grad(si);
    }

    /// Half of each colour over any whole number of periods.
    Color3f mean() const override { return (m_color0->mean() + m_color1->mean()) * 0.5f; }
    float max() const override { return std::max(m_color0->max(), m_color1->max()); }

    std::string to_string() const override {
        return fmt::format("Checkerboard[color0 = {}, color1 = {}, to_uv = {}]",
                           m_color0->to_string(), m_color1->to_string(), m_to_uv.to_string());
    }

private:
    bool in_color0(const SurfaceInteraction &si) const {
        Point3f p = m_to_uv.apply_point(Point3f(si.uv.x, si.uv.y, 0.f));
        bool upper_u = p.x - std::floor(p.x) > 0.5f, upper_v = p.y - std::floor(p.y) > 0.5f;
        return upper_u == upper_v;
    }

    std::shared_ptr<Texture> m_color0, m_color1;
    Transform m_to_uv;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Checkerboard, Texture, "checkerboard",
                          "Procedural two-colour checkerboard in texture space", DOC,
                          ::facet::AllModes)
