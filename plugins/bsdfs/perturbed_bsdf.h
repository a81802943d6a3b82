#pragma once

// What `normalmap` and `bumpmap` share: a nested BSDF evaluated in a perturbed shading frame, with
// Mitsuba 3's two robustness options (flip_invalid_normals, use_shadowing_function). The two
// plugins differ only in how they compute the perturbed normal.

#include <facet/bsdf.h>
#include <facet/properties.h>

#include <cmath>
#include <memory>
#include <string>

namespace facet {

/**
 * Terminator softening of Conty Estevez, Lecocq and Stein ("A Microfacet-Based Shadowing Function
 * to Solve the Bump Terminator Problem", Ray Tracing Gems, 2019): a Smith-like shadowing term
 * whose roughness grows with the tilt of the perturbed normal `n_p` (relative to the unperturbed
 * shading frame); `wo` is in the unperturbed frame.
 */
inline float shadow_terminator(const Vector3f &n_p, const Vector3f &wo) {
    float alpha2 = std::min(0.125f * Frame::tan_theta_2(n_p), 1.f);
    float g = 2.f / (1.f + std::sqrt(1.f + alpha2 * Frame::tan_theta_2(wo)));
    return std::isfinite(g) ? g : 0.f;
}

class PerturbedBSDF : public BSDF {
public:
    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1, const Point2f &sample2) const override {
        Frame local;
        SurfaceInteraction psi = perturb(si, local);
        auto [bs, weight] = m_nested->sample(ctx, psi, sample1, sample2);
        if (weight.is_black()) return {bs, Color3f(0.f)};
        // Back to the unperturbed frame; a direction that changes sides there is rejected.
        Vector3f wo = local.to_world(bs.wo);
        if (!(Frame::cos_theta(bs.wo) * Frame::cos_theta(wo) > 0.f)) {
            bs.pdf = 0.f;
            return {bs, Color3f(0.f)};
        }
        bs.wo = wo;
        if (m_use_shadowing) weight *= shadow_terminator(local.n, wo);
        return {bs, weight};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        Frame local;
        SurfaceInteraction psi = perturb(si, local);
        Vector3f pwo = local.to_local(wo);
        if (!(Frame::cos_theta(wo) * Frame::cos_theta(pwo) > 0.f)) return Color3f(0.f);
        Color3f value = m_nested->eval(ctx, psi, pwo);
        if (m_use_shadowing) value *= shadow_terminator(local.n, wo);
        return value;
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        Frame local;
        SurfaceInteraction psi = perturb(si, local);
        Vector3f pwo = local.to_local(wo);
        if (!(Frame::cos_theta(wo) * Frame::cos_theta(pwo) > 0.f)) return 0.f;
        return m_nested->pdf(ctx, psi, pwo);
    }

    std::pair<Color3f, float> eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                                       const Vector3f &wo) const override {
        Frame local;
        SurfaceInteraction psi = perturb(si, local);
        Vector3f pwo = local.to_local(wo);
        if (!(Frame::cos_theta(wo) * Frame::cos_theta(pwo) > 0.f)) return {Color3f(0.f), 0.f};
        auto [value, pdf] = m_nested->eval_pdf(ctx, psi, pwo);
        if (m_use_shadowing) value *= shadow_terminator(local.n, wo);
        return {value, pdf};
    }

    /// The polarized mode: the nested BSDF's matrix, turned from the implicit frames of the
    /// perturbed frame's directions into those of the unperturbed frame's.
    std::pair<BSDFSample, Mueller> sample_polarized(const BSDFContext &ctx,
                                                    const SurfaceInteraction &si, float sample1,
                                                    const Point2f &sample2) const override {
        Frame local;
        SurfaceInteraction psi = perturb(si, local);
        auto [bs, weight] = m_nested->sample_polarized(ctx, psi, sample1, sample2);
        if (weight.is_black()) return {bs, Mueller{}};
        Vector3f wo = local.to_world(bs.wo);
        if (!(Frame::cos_theta(bs.wo) * Frame::cos_theta(wo) > 0.f)) {
            bs.pdf = 0.f;
            return {bs, Mueller{}};
        }
        weight = to_unperturbed(ctx, local, weight, psi.wi, bs.wo);
        bs.wo = wo;
        if (m_use_shadowing) weight = weight * shadow_terminator(local.n, wo);
        return {bs, weight};
    }
    std::pair<Mueller, float> eval_pdf_polarized(const BSDFContext &ctx,
                                                 const SurfaceInteraction &si,
                                                 const Vector3f &wo) const override {
        Frame local;
        SurfaceInteraction psi = perturb(si, local);
        Vector3f pwo = local.to_local(wo);
        if (!(Frame::cos_theta(wo) * Frame::cos_theta(pwo) > 0.f)) return {Mueller{}, 0.f};
        auto [value, pdf] = m_nested->eval_pdf_polarized(ctx, psi, pwo);
        value = to_unperturbed(ctx, local, value, psi.wi, pwo);
        if (m_use_shadowing) value = value * shadow_terminator(local.n, wo);
        return {value, pdf};
    }

    /// The pass-through of a nested Null lobe does not depend on the normal.
    Color3f eval_null_transmission(const SurfaceInteraction &si) const override {
        return m_nested->eval_null_transmission(si);
    }
    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_nested->eval_diffuse_reflectance(si);
    }

    /// A nested matrix between the implicit frames of the perturbed directions wi, wo (light
    /// from wo to wi in radiance mode, BSDF's conventions), between those of the unperturbed.
    static Mueller to_unperturbed(const BSDFContext &ctx, const Frame &local, const Mueller &M,
                                  const Vector3f &wi, const Vector3f &wo) {
        const bool radiance = ctx.mode == TransportMode::Radiance;
        return mueller::to_world(local, M, radiance ? -wo : -wi, radiance ? wi : wo);
    }

    /// The perturbed frame relative to si.sh_frame (normal = the perturbed normal, flipped to
    /// the side of wi when flip_invalid_normals asks for it).
    Frame local_frame(const SurfaceInteraction &si) const {
        Vector3f n = perturbation(si);
        // Keep the shading normal on the side of the incident direction (Schüssler et al. 2017).
        if (m_flip_invalid && Frame::cos_theta(si.wi) * dot(si.wi, n) <= 0.f)
            n = Vector3f(-n.x, -n.y, n.z);
        float len2 = dot(n, n);
        n = len2 > 0.f && std::isfinite(len2) ? n / std::sqrt(len2) : Vector3f(0.f, 0.f, 1.f);
        // The tangent follows the unperturbed one (Gram-Schmidt of the local x axis).
        Vector3f s = Vector3f(1.f, 0.f, 0.f) - n * n.x;
        float s2 = dot(s, s);
        s = s2 > 0.f && std::isfinite(s2) ? s / std::sqrt(s2) : Vector3f(0.f, 1.f, 0.f);
        return Frame(s, cross(n, s), n);
    }

protected:
    /// Reads the nested BSDF (exactly one) and the two flags; `name` is used in messages.
    PerturbedBSDF(const Properties &props, const char *name) {
        for (const auto &[child, obj] : props.objects()) {
            auto bsdf = std::dynamic_pointer_cast<BSDF>(obj);
            if (!bsdf) continue;
            if (m_nested)
                FACET_THROW_AT(props.location(),
                               "{} takes exactly one nested BSDF, found a second (\"{}\")", name,
                               child);
            m_nested = bsdf;
            props.mark_queried(child);
        }
        if (!m_nested) FACET_THROW_AT(props.location(), "{} needs a nested BSDF", name);
        m_flip_invalid = props.get_bool("flip_invalid_normals", true);
        m_use_shadowing = props.get_bool("use_shadowing_function", true);
    }

    /// The nested BSDF's components, marked spatially varying when the normal varies.
    void set_nested_components(bool varying) {
        BSDFFlags extra = varying ? BSDFFlags::SpatiallyVarying : BSDFFlags::Empty;
        std::vector<BSDFFlags> components;
        for (size_t i = 0; i < m_nested->component_count(); ++i)
            // Not WiSideOnly: the nested BSDF's sides are those of the perturbed frame.
            components.push_back((m_nested->flags(i) & ~BSDFFlags::WiSideOnly) | extra);
        set_components(std::move(components));
    }

    /// The perturbed normal in the coordinates of si.sh_frame, not necessarily normalised.
    virtual Vector3f perturbation(const SurfaceInteraction &si) const = 0;

    std::shared_ptr<BSDF> m_nested;
    bool m_flip_invalid = true, m_use_shadowing = true;

private:
    /// si with the perturbed shading frame (in world space) and wi expressed in it.
    SurfaceInteraction perturb(const SurfaceInteraction &si, Frame &local) const {
        local = local_frame(si);
        SurfaceInteraction psi = si;
        psi.sh_frame = Frame(si.sh_frame.to_world(local.s), si.sh_frame.to_world(local.t),
                             si.sh_frame.to_world(local.n));
        psi.wi = local.to_local(si.wi);
        return psi;
    }
};

} // namespace facet
