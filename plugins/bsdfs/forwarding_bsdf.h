#pragma once

#include <facet/bsdf.h>
#include <facet/mueller.h>

/// The BSDFs that combine nested BSDFs (twosided, mask, blendbsdf) are written once for colours
/// and for the polarized mode's Mueller matrices: `Derived` defines
///   template <typename V> std::pair<BSDFSample, V> sample_impl(ctx, si, sample1, sample2) const
///   template <typename V> std::pair<V, float> eval_pdf_impl(ctx, si, wo) const
/// (V = Color3f or Mueller, calling the nested BSDFs through sample_as<V>/eval_pdf_as<V>), and
/// this base overrides sample(), eval_pdf() and their polarized forms with them.
namespace facet {

template <class Derived> class ForwardingBSDF : public BSDF {
public:
    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1, const Point2f &sample2) const override {
        return self().template sample_impl<Color3f>(ctx, si, sample1, sample2);
    }
    std::pair<BSDFSample, Mueller> sample_polarized(const BSDFContext &ctx,
                                                    const SurfaceInteraction &si, float sample1,
                                                    const Point2f &sample2) const override {
        return self().template sample_impl<Mueller>(ctx, si, sample1, sample2);
    }
    std::pair<Color3f, float> eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                                       const Vector3f &wo) const override {
        return self().template eval_pdf_impl<Color3f>(ctx, si, wo);
    }
    std::pair<Mueller, float> eval_pdf_polarized(const BSDFContext &ctx,
                                                 const SurfaceInteraction &si,
                                                 const Vector3f &wo) const override {
        return self().template eval_pdf_impl<Mueller>(ctx, si, wo);
    }

private:
    const Derived &self() const { return static_cast<const Derived &>(*this); }
};

} // namespace facet
