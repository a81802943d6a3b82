#pragma once

#include <facet/bsdf.h>
#include <facet/mueller.h>

/// The shared shape of the thin optical elements (polarizer, retarder, circular): a sheet that
/// light crosses without changing direction (one Null lobe, wo = −wi, on both sides), changing
/// only its polarisation and intensity.
namespace facet {

class OpticalElement : public BSDF {
public:
    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float /*sample1*/,
                                          const Point2f & /*sample2*/) const override {
        BSDFSample bs;
        if (!pass(ctx, bs, si)) return {bs, Color3f(0.f)};
        return {bs, unpolarized(si)};
    }

    std::pair<BSDFSample, Mueller> sample_polarized(const BSDFContext &ctx,
                                                    const SurfaceInteraction &si, float /*sample1*/,
                                                    const Point2f & /*sample2*/) const override {
        BSDFSample bs;
        if (!pass(ctx, bs, si)) return {bs, Mueller{}};
        // Light crosses the sheet along si.wi in radiance mode, along −si.wi in importance mode.
        const Vector3f forward = ctx.mode == TransportMode::Radiance ? si.wi : -si.wi;
        return {bs, polarized(si, forward)};
    }

    Color3f eval(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return Color3f(0.f);
    }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return 0.f;
    }
    std::pair<Color3f, float> eval_pdf(const BSDFContext &, const SurfaceInteraction &,
                                       const Vector3f &) const override {
        return {Color3f(0.f), 0.f};
    }
    Color3f eval_null_transmission(const SurfaceInteraction &si) const override {
        return unpolarized(si);
    }

protected:
    OpticalElement() {
        set_components(
            {BSDFFlags::Null | BSDFFlags::FrontSide | BSDFFlags::BackSide | BSDFFlags::Polarizing});
    }
    /// What the element passes of unpolarised light (the modes without polarisation).
    virtual Color3f unpolarized(const SurfaceInteraction &si) const = 0;
    /// Its Mueller matrix for light crossing it along the local direction `forward`, between
    /// the implicit frames of `forward` (mueller::stokes_basis()).
    virtual Mueller polarized(const SurfaceInteraction &si, const Vector3f &forward) const = 0;

private:
    static bool pass(const BSDFContext &ctx, BSDFSample &bs, const SurfaceInteraction &si) {
        if (!ctx.is_enabled(BSDFFlags::Null, 0)) return false;
        bs.wo = -si.wi;
        bs.pdf = 1.f;
        bs.eta = 1.f;
        bs.sampled_type = BSDFFlags::Null;
        bs.sampled_component = 0;
        return true;
    }
};

} // namespace facet
