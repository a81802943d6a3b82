static const char *DOC = R"DOC(
# chi2_lambert_bug: a Lambertian BSDF with a deliberate sampling bug (test only)

Used by the chi-square suite to check that `facet chi2` rejects a wrong sampler, exits with a
non-zero code and writes its heat maps. Never installed.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| bug | string | uniform | `none` (correct), `uniform` (samples the hemisphere uniformly but claims a cosine density), `scale` (pdf 5 % too large) |

```xml
<bsdf type="chi2_lambert_bug">
    <string name="bug" value="uniform"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class Chi2LambertBug final : public BSDF {
public:
    explicit Chi2LambertBug(const Properties &props) {
        m_bug = props.get_string("bug", "uniform");
        if (m_bug != "none" && m_bug != "uniform" && m_bug != "scale")
            FACET_THROW_AT(props.location(), "bug \"{}\": expected none, uniform or scale", m_bug);
        set_components({BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float, const Point2f &u) const override {
        BSDFSample bs;
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || si.wi.z <= 0.f)
            return {bs, Color3f(0.f)};
        bs.wo = m_bug == "uniform" ? warp::square_to_uniform_hemisphere(u)
                                   : warp::square_to_cosine_hemisphere(u);
        bs.pdf = pdf(ctx, si, bs.wo);
        bs.sampled_type = BSDFFlags::DiffuseReflection;
        bs.sampled_component = 0;
        if (!(bs.pdf > 0.f)) return {bs, Color3f(0.f)};
        return {bs, eval(ctx, si, bs.wo) / bs.pdf};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || si.wi.z <= 0.f || wo.z <= 0.f)
            return Color3f(0.f);
        return Color3f(0.5f * InvPi * wo.z);
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || si.wi.z <= 0.f || wo.z <= 0.f)
            return 0.f;
        return (m_bug == "scale" ? 1.05f : 1.f) * InvPi * wo.z;
    }

    std::string to_string() const override {
        return fmt::format("Chi2LambertBug[bug = {}]", m_bug);
    }

private:
    std::string m_bug;
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::Chi2LambertBug, BSDF, "chi2_lambert_bug",
                    "Lambertian BSDF with a deliberate sampling bug (chi-square test only)", DOC)
