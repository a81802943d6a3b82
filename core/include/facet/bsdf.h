#pragma once

#include <facet/color.h>
#include <facet/interaction.h>
#include <facet/logger.h>
#include <facet/mueller.h>
#include <facet/object.h>

#include <type_traits>
#include <utility>
#include <vector>

/**
 * BSDF conventions, followed by every BSDF plugin:
 * - Directions are in the local shading frame: the normal is +Z and Frame::cos_theta(v) == v.z.
 * - `si.wi` points away from the surface (towards where the light goes in radiance mode).
 * - `eval` returns f(wi, wo)·|cos θo|.
 * - `sample` returns the sampled record and the weight f·|cos θo| / pdf; for delta lobes the
 *   lobe's value divided by its discrete probability. A zero weight means the sample failed.
 * - `pdf` is the solid-angle density of exactly what `sample` does, lobe selection included;
 *   delta lobes have pdf 0 in `pdf` and their discrete probability in BSDFSample::pdf.
 * - Each method first checks that a lobe is enabled in the context and that wi is on a supported
 *   side. Two-sidedness belongs to the `twosided` adapter.
 * - In the polarized mode the path integrator asks a BSDF flagged `Polarizing` for Mueller
 *   matrices (sample_polarized(), eval_pdf_polarized()): the same quantities with every colour
 *   value replaced by the matrix that maps the Stokes vector of the light arriving along −wo_hat
 *   to that of the light leaving along wi_hat, in the implicit frames (mueller::stokes_basis()) of
 *   those local directions. Light travels from wo to wi in radiance mode (wo_hat = wo,
 *   wi_hat = si.wi) and from wi to wo in importance mode (wo_hat = si.wi, wi_hat = wo). Entry
 *   (0, 0) of the matrix is the colour value the unpolarised methods return.
 */
namespace facet {

enum class TransportMode : uint32_t { Radiance = 0, Importance = 1 };

enum class BSDFFlags : uint32_t {
    Empty = 0,
    Null = 0x1,
    DiffuseReflection = 0x2,
    DiffuseTransmission = 0x4,
    GlossyReflection = 0x8,
    GlossyTransmission = 0x10,
    DeltaReflection = 0x20,
    DeltaTransmission = 0x40,
    Delta1DReflection = 0x80,
    Delta1DTransmission = 0x100,
    Anisotropic = 0x1000,
    SpatiallyVarying = 0x2000,
    NonSymmetric = 0x4000,
    FrontSide = 0x8000,
    BackSide = 0x10000,
    NeedsDifferentials = 0x20000,
    /// The BSDF's value depends on the polarisation of light, or changes it: the polarized mode
    /// asks it for Mueller matrices. Others depolarise (mueller::depolarizer()).
    Polarizing = 0x40000,
    /// On a delta component: sampled alone (BSDFContext::component), it returns the lobe's whole
    /// weight, the light the BSDF's own samples bring through it on average (they pick it with
    /// the probability they divide by). An integrator may then count what the lobe sees in every
    /// sample, whichever lobe the sample follows (the path tracer does, for a BSDF with smooth
    /// lobes too, when every delta component says so). Adapters pass it on from the BSDFs they
    /// nest; blendbsdf clears it (its delta samples are weighted with the other BSDF's value).
    SeparableDelta = 0x80000,
    /// The BSDF's value is zero wherever wo lies on the other side of the shading frame's plane
    /// from wi (Frame::cos_theta(wi) * Frame::cos_theta(wo) <= 0): it reflects, and only to the
    /// side light comes from. An integrator may then tell light samples that no light counts
    /// from the other side (Emitter::sample_direction_mis()'s `side`). Reflecting BSDFs that
    /// test both cosines in the frame they are given say so; adapters that evaluate a nested BSDF
    /// in another frame (normalmap, bumpmap) do not pass it on.
    WiSideOnly = 0x100000,

    Reflection = DiffuseReflection | DeltaReflection | Delta1DReflection | GlossyReflection,
    Transmission =
        DiffuseTransmission | DeltaTransmission | Delta1DTransmission | GlossyTransmission | Null,
    Diffuse = DiffuseReflection | DiffuseTransmission,
    Glossy = GlossyReflection | GlossyTransmission,
    Smooth = Diffuse | Glossy,
    Delta = Null | DeltaReflection | DeltaTransmission,
    Delta1D = Delta1DReflection | Delta1DTransmission,
    All = Diffuse | Glossy | Delta | Delta1D,
};

constexpr BSDFFlags operator|(BSDFFlags a, BSDFFlags b) {
    return BSDFFlags(uint32_t(a) | uint32_t(b));
}
constexpr BSDFFlags operator&(BSDFFlags a, BSDFFlags b) {
    return BSDFFlags(uint32_t(a) & uint32_t(b));
}
constexpr BSDFFlags operator~(BSDFFlags a) { return BSDFFlags(~uint32_t(a)); }
inline BSDFFlags &operator|=(BSDFFlags &a, BSDFFlags b) { return a = a | b; }
inline BSDFFlags &operator&=(BSDFFlags &a, BSDFFlags b) { return a = a & b; }
/// True when any bit of `b` is set in `a`.
constexpr bool has_flag(BSDFFlags a, BSDFFlags b) { return (uint32_t(a) & uint32_t(b)) != 0; }

/// What the caller wants from a BSDF query: transport mode, enabled lobe types, one component.
struct BSDFContext {
    TransportMode mode = TransportMode::Radiance;
    uint32_t type_mask = uint32_t(BSDFFlags::All);
    uint32_t component = uint32_t(-1);

    BSDFContext() = default;
    explicit BSDFContext(TransportMode m) : mode(m) {}
    /// True when lobe type `type` of component `comp` takes part in this query.
    bool is_enabled(BSDFFlags type, uint32_t comp = 0) const {
        return (type_mask & uint32_t(type)) == uint32_t(type) &&
               (component == uint32_t(-1) || component == comp);
    }
};

struct BSDFSample {
    Vector3f wo;
    float pdf = 0.f;
    float eta = 1.f; ///< relative IOR along the sampled direction (1 for reflection)
    BSDFFlags sampled_type = BSDFFlags::Empty;
    uint32_t sampled_component = uint32_t(-1);
};

/// Most components a BSDF may have. Adapters list their nested BSDFs' components (twosided
/// twice for a single nested one), so nesting them doubles the count per level: 26 nested
/// twosided took gigabytes. Real materials have a handful.
constexpr size_t MaxBSDFComponents = 1024;

class BSDF : public Object {
public:
    ObjectType type() const override { return ObjectType::BSDF; }

    /// Samples wo given si.wi. `sample1` picks the lobe, `sample2` the direction.
    /// Returns the record and the weight f·|cos θo|/pdf (zero on failure).
    virtual std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx,
                                                  const SurfaceInteraction &si, float sample1,
                                                  const Point2f &sample2) const = 0;
    /// f(wi, wo)·|cos θo|; zero for delta lobes.
    virtual Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                         const Vector3f &wo) const = 0;
    /// Solid-angle density of sample(); zero for delta lobes.
    virtual float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                      const Vector3f &wo) const = 0;
    virtual std::pair<Color3f, float> eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                                               const Vector3f &wo) const {
        return {eval(ctx, si, wo), pdf(ctx, si, wo)};
    }
    /**
     * sample() in the polarized mode: the weight is a Mueller matrix (see the conventions above).
     * The default, for BSDFs that do not polarise: light passed by a Null lobe keeps its
     * polarisation (the identity times the weight), any other is depolarised.
     */
    virtual std::pair<BSDFSample, Mueller> sample_polarized(const BSDFContext &ctx,
                                                            const SurfaceInteraction &si,
                                                            float sample1,
                                                            const Point2f &sample2) const {
        auto [bs, weight] = sample(ctx, si, sample1, sample2);
        return {bs, has_flag(bs.sampled_type, BSDFFlags::Null) ? Mueller::identity(weight)
                                                               : mueller::depolarizer(weight)};
    }
    /// eval_pdf() in the polarized mode; the default depolarises.
    virtual std::pair<Mueller, float> eval_pdf_polarized(const BSDFContext &ctx,
                                                         const SurfaceInteraction &si,
                                                         const Vector3f &wo) const {
        auto [value, pdf] = eval_pdf(ctx, si, wo);
        return {mueller::depolarizer(value), pdf};
    }
    /// Fraction of light passed straight through (wo = -wi) by Null lobes.
    virtual Color3f eval_null_transmission(const SurfaceInteraction &si) const {
        return Color3f(0.f);
    }
    /// Albedo for AOVs and denoisers.
    virtual Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const {
        return Color3f(0.f);
    }
    /// A hint that the BSDF is about to be queried at `si`: one that reads memory the cache may
    /// not hold (an image texture's texels) may start loading it here and return true, so that
    /// the caller gives the load time (the path tracer takes its light sample before the BSDF's
    /// when the BSDF is BSDFFlags::SpatiallyVarying and this returns true). It must not change
    /// any result; the default loads nothing and returns false. Adapters pass it on to their
    /// nested BSDFs and textures (Texture::prefetch()), true when any of them started a load.
    virtual bool prefetch(const SurfaceInteraction &) const { return false; }

    BSDFFlags flags() const { return m_flags; }
    BSDFFlags flags(size_t component) const { return m_components.at(component); }
    size_t component_count() const { return m_components.size(); }
    bool needs_differentials() const { return has_flag(m_flags, BSDFFlags::NeedsDifferentials); }

protected:
    /// Sets the per-component flags and their union, but for WiSideOnly, which the BSDF has
    /// only when every component has it.
    void set_components(std::vector<BSDFFlags> components) {
        if (components.size() > MaxBSDFComponents)
            FACET_THROW("the BSDF would have {} components, more than the {} facet supports "
                        "(nested twosided or blendbsdf adapters multiply their nested BSDFs' "
                        "components)",
                        components.size(), MaxBSDFComponents);
        m_components = std::move(components);
        m_flags = BSDFFlags::Empty;
        bool wi_side_only = !m_components.empty();
        for (BSDFFlags f : m_components) {
            m_flags |= f;
            wi_side_only = wi_side_only && has_flag(f, BSDFFlags::WiSideOnly);
        }
        if (!wi_side_only) m_flags = m_flags & ~BSDFFlags::WiSideOnly;
    }
    BSDFFlags m_flags = BSDFFlags::Empty;
    std::vector<BSDFFlags> m_components;
};

/// The side of the light samples at si (Scene::sample_emitter_direction()): the shading normal
/// towards wi for a BSDF that reflects only to wi's side (BSDFFlags::WiSideOnly), else none
/// (zero: light may count from every direction).
inline Vector3f light_side(const BSDF &bsdf, const SurfaceInteraction &si) {
    if (!has_flag(bsdf.flags(), BSDFFlags::WiSideOnly)) return Vector3f(0.f);
    const float cos_i = Frame::cos_theta(si.wi);
    if (cos_i > 0.f) return si.sh_frame.n;
    if (cos_i < 0.f) return -si.sh_frame.n;
    return Vector3f(0.f);
}

/**
 * For BSDFs written once for both value types (adapters that combine nested BSDFs): `V` =
 * Color3f calls sample()/eval_pdf(), `V` = Mueller the polarized mode's sample_polarized()/
 * eval_pdf_polarized().
 */
template <typename V> std::pair<BSDFSample, V> sample_as(const BSDF &bsdf, const BSDFContext &ctx,
                                                         const SurfaceInteraction &si,
                                                         float sample1, const Point2f &sample2) {
    if constexpr (std::is_same_v<V, Mueller>)
        return bsdf.sample_polarized(ctx, si, sample1, sample2);
    else
        return bsdf.sample(ctx, si, sample1, sample2);
}
template <typename V> std::pair<V, float> eval_pdf_as(const BSDF &bsdf, const BSDFContext &ctx,
                                                      const SurfaceInteraction &si,
                                                      const Vector3f &wo) {
    if constexpr (std::is_same_v<V, Mueller>)
        return bsdf.eval_pdf_polarized(ctx, si, wo);
    else
        return bsdf.eval_pdf(ctx, si, wo);
}
/// A Null lobe's weight `w` as a V: the colour, or the matrix that passes the light unchanged.
template <typename V> V null_weight(const Color3f &w) {
    if constexpr (std::is_same_v<V, Mueller>)
        return Mueller::identity(w);
    else
        return w;
}

} // namespace facet
