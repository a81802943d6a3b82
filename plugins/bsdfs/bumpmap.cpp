static const char *DOC = R"DOC(
# bumpmap: bump mapping around a nested BSDF

Adds surface detail without changing the geometry: a height texture h(u, v), multiplied by
`scale`, displaces the surface along its shading normal, and the nested BSDF is evaluated in the
shading frame of the displaced surface. Only the height's gradient enters: the displaced
tangents are dp/du + n·(scale·∂h/∂u − n·dp/du) and likewise for v, and their cross product is
the new normal (turned to the geometric normal's side). The texture must provide a (u, v)
gradient (`bitmap` does: bilinear filtering gives a piecewise linear height, `nearest` a flat
one). Heights are in scene units per unit of (u, v); use `raw` bitmaps (no sRGB decoding).
Directions that lie on different sides of the unperturbed and the perturbed frame are rejected,
as in Mitsuba 3.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| (nested texture) | texture | — | The height map (exactly one) |
| scale | float | 1 | Multiplier of the height gradient |
| flip_invalid_normals | boolean | true | Mirror the perturbed normal's tangential part when it faces away from the incident direction (Schüssler et al. 2017), which avoids black patches |
| use_shadowing_function | boolean | true | Multiply the response by the microfacet-based terminator shadowing of Conty Estevez et al. 2019, which softens the shadow edge of tilted normals |
| (nested bsdf) | bsdf | — | The BSDF the bump map perturbs (exactly one) |

Components: those of the nested BSDF.

```xml
<bsdf type="bumpmap">
    <texture type="bitmap">
        <string name="filename" value="textures/height.png"/>
        <boolean name="raw" value="true"/>
    </texture>
    <float name="scale" value="0.3"/>
    <bsdf type="diffuse"/>
</bsdf>
```
)DOC";

#include "perturbed_bsdf.h"

#include <facet/plugin.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class BumpMap final : public PerturbedBSDF {
public:
    explicit BumpMap(const Properties &props) : PerturbedBSDF(props, "bumpmap") {
        for (const auto &[child, obj] : props.objects()) {
            auto tex = std::dynamic_pointer_cast<Texture>(obj);
            if (!tex) continue;
            if (m_height)
                FACET_THROW_AT(props.location(),
                               "bumpmap takes exactly one nested height texture, found a second "
                               "(\"{}\")",
                               child);
            m_height = tex;
            props.mark_queried(child);
        }
        if (!m_height) FACET_THROW_AT(props.location(), "bumpmap needs a nested height texture");
        m_scale = float(props.get_float("scale", 1.0));
        if (!std::isfinite(m_scale))
            FACET_THROW_AT(props.location("scale"), "bumpmap: scale must be finite, found {}",
                           m_scale);
        // Probe the texture now so that one without a gradient fails at load time, not mid-render.
        try {
            SurfaceInteraction probe;
            probe.uv = Point2f(0.5f, 0.5f);
            m_height->eval_1_grad(probe);
        } catch (const Error &e) {
            FACET_THROW_AT(props.location(),
                           "bumpmap: the nested texture cannot serve as a height field ({}); for "
                           "tangent-space normals stored as RGB use normalmap",
                           e.message());
        }
        set_nested_components(m_height->is_spatially_varying());
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_height, si);
        started |= m_nested->prefetch(si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("BumpMap[height = {}, scale = {}, flip_invalid_normals = {}, "
                           "use_shadowing_function = {}, nested = {}]",
                           m_height->to_string(), m_scale, m_flip_invalid, m_use_shadowing,
                           m_nested->to_string());
    }

protected:
    Vector3f perturbation(const SurfaceInteraction &si) const override {
        Vector2f grad = m_height->eval_1_grad(si) * m_scale;
        const Vector3f &n = si.sh_frame.n;
        Vector3f dp_du = si.dp_du + n * (grad.x - dot(n, si.dp_du));
        Vector3f dp_dv = si.dp_dv + n * (grad.y - dot(n, si.dp_dv));
        Vector3f c = cross(dp_du, dp_dv);
        if (dot(si.n, c) < 0.f) c = -c;
        return si.sh_frame.to_local(c);
    }

private:
    std::shared_ptr<Texture> m_height;
    float m_scale = 1.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::BumpMap, BSDF, "bumpmap",
                          "Bump map (height gradient) around a nested BSDF", DOC, ::facet::AllModes)
