static const char *DOC = R"DOC(
# plaindiffuse: a Lambertian BSDF through the BSDF interface alone

The same reflection as facet's `diffuse`, f = ρ/π on the front side, written only against the
BSDF interface: it does not implement prefetch(), so a render never has it load its texture's
texels ahead, and the path tracer samples it before the light sample (facet's `diffuse`, whose
bitmap starts loading, after). Built twice out of tree by facet's SDK test: `plaindiffuse` flags
itself SpatiallyVarying when its reflectance varies (the path tracer then asks it to prefetch),
`plaindiffuse_unflagged` never does.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| reflectance | spectrum or texture | 0.5 | Diffuse albedo ρ |
)DOC";

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

#ifdef PLAIN_UNFLAGGED
#define PLAIN_NAME "plaindiffuse_unflagged"
#else
#define PLAIN_NAME "plaindiffuse"
#endif

namespace facet {

class PlainDiffuse final : public BSDF {
public:
    explicit PlainDiffuse(const Properties &props) {
        m_reflectance = props.texture("reflectance", 0.5f);
        BSDFFlags flags =
            BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly;
#ifndef PLAIN_UNFLAGGED
        if (m_reflectance->is_spatially_varying()) flags |= BSDFFlags::SpatiallyVarying;
#endif
        set_components({flags});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float, const Point2f &sample2) const override {
        BSDFSample bs;
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || Frame::cos_theta(si.wi) <= 0.f)
            return {bs, Color3f(0.f)};
        bs.wo = warp::square_to_cosine_hemisphere(sample2);
        bs.pdf = warp::square_to_cosine_hemisphere_pdf(bs.wo);
        bs.sampled_type = BSDFFlags::DiffuseReflection;
        bs.sampled_component = 0;
        if (!(bs.pdf > 0.f) || Frame::cos_theta(bs.wo) <= 0.f) return {bs, Color3f(0.f)};
        return {bs, m_reflectance->eval(si)};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || cos_i <= 0.f || cos_o <= 0.f)
            return Color3f(0.f);
        return m_reflectance->eval(si) * (InvPi * cos_o);
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || cos_i <= 0.f || cos_o <= 0.f)
            return 0.f;
        return warp::square_to_cosine_hemisphere_pdf(wo);
    }

    std::string to_string() const override {
        return fmt::format("PlainDiffuse[reflectance = {}]", m_reflectance->to_string());
    }

private:
    std::shared_ptr<Texture> m_reflectance;
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::PlainDiffuse, BSDF, PLAIN_NAME,
                    "Lambertian reflection through the BSDF interface alone", DOC)
