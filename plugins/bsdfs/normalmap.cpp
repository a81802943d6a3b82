static const char *DOC = R"DOC(
# normalmap: normal mapping around a nested BSDF

Adds surface detail without changing the geometry: the nested BSDF is evaluated in a shading
frame whose normal comes from a texture. The texture's RGB value encodes the normal in the
tangent space of the unperturbed shading frame as n = 2·rgb − 1 (so (0.5, 0.5, 1) changes
nothing); the perturbed tangent is the unperturbed one made orthogonal to n. Use `raw` bitmaps
(no sRGB decoding) for normal maps. Directions that lie on different sides of the unperturbed and
the perturbed frame are rejected, as in Mitsuba 3.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| normalmap | texture | — | Tangent-space normals encoded as (n + 1) / 2 in the RGB channels |
| flip_invalid_normals | boolean | true | Mirror the perturbed normal's tangential part when it faces away from the incident direction (Schüssler et al. 2017), which avoids black patches |
| use_shadowing_function | boolean | true | Multiply the response by the microfacet-based terminator shadowing of Conty Estevez et al. 2019, which softens the shadow edge of tilted normals |
| (nested bsdf) | bsdf | — | The BSDF the normal map perturbs (exactly one) |

Components: those of the nested BSDF.

```xml
<bsdf type="normalmap">
    <texture type="bitmap" name="normalmap">
        <string name="filename" value="textures/bricks_normal.png"/>
        <boolean name="raw" value="true"/>
    </texture>
    <bsdf type="roughplastic"/>
</bsdf>
```
)DOC";

#include "perturbed_bsdf.h"

#include <facet/plugin.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class NormalMap final : public PerturbedBSDF {
public:
    explicit NormalMap(const Properties &props) : PerturbedBSDF(props, "normalmap") {
        if (!props.has("normalmap"))
            FACET_THROW_AT(props.location(), "normalmap needs a \"normalmap\" texture");
        m_normalmap = props.texture("normalmap", SpectrumKind::Unbounded);
        set_nested_components(m_normalmap->is_spatially_varying());
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_normalmap, si);
        started |= m_nested->prefetch(si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("NormalMap[normalmap = {}, flip_invalid_normals = {}, "
                           "use_shadowing_function = {}, nested = {}]",
                           m_normalmap->to_string(), m_flip_invalid, m_use_shadowing,
                           m_nested->to_string());
    }

protected:
    Vector3f perturbation(const SurfaceInteraction &si) const override {
        Color3f c = m_normalmap->eval(si);
        return Vector3f(2.f * c.r - 1.f, 2.f * c.g - 1.f, 2.f * c.b - 1.f);
    }

private:
    std::shared_ptr<Texture> m_normalmap;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::NormalMap, BSDF, "normalmap",
                          "Normal map (tangent-space RGB normals) around a nested BSDF", DOC,
                          ::facet::AllModes)
