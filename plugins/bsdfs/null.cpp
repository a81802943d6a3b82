static const char *DOC = R"DOC(
# null: invisible surface

A surface that does not interact with light: every ray passes straight through (wo = −wi) with
weight 1, on both sides. The pass-through is a Null lobe with discrete probability 1 and no
density (eval and pdf are zero). It is useful for shapes that only carry an emitter or mark a
boundary. As in Mitsuba 3's `path` and `direct`, the surface still counts as a bounce towards
`max_depth`, is not sampled for emitters, and blocks shadow rays (it casts a shadow).

It has no parameters.

Components: one Null lobe (both sides).

```xml
<shape type="sphere">
    <bsdf type="null"/>
</shape>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>

namespace facet {

class NullBSDF final : public BSDF {
public:
    explicit NullBSDF(const Properties &) {
        set_components({BSDFFlags::Null | BSDFFlags::FrontSide | BSDFFlags::BackSide});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float, const Point2f &) const override {
        BSDFSample bs;
        if (!ctx.is_enabled(BSDFFlags::Null, 0)) return {bs, Color3f(0.f)};
        bs.wo = -si.wi;
        bs.pdf = 1.f;
        bs.eta = 1.f;
        bs.sampled_type = BSDFFlags::Null;
        bs.sampled_component = 0;
        return {bs, Color3f(1.f)};
    }

    Color3f eval(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return Color3f(0.f);
    }

    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return 0.f;
    }

    Color3f eval_null_transmission(const SurfaceInteraction &) const override {
        return Color3f(1.f);
    }

    std::string to_string() const override { return "NullBSDF[]"; }
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::NullBSDF, BSDF, "null",
                          "Invisible surface: light passes straight through", DOC,
                          ::facet::AllModes)
