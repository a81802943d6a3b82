#pragma once

// Checks shared by the BSDF unit tests (dielectric, conductor, rough*, ...): creation from
// parameters, error messages, eval/pdf/sample consistency and energy (white furnace). Chi-square
// tests are lines of tests/chi2/configs.txt, not GoogleTest cases.

#include "draws.h"

#include <facet/bsdf.h>
#include <facet/chi2.h> // direction_from_angles
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/random.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace bsdf_checks {

using namespace facet;

/// Parameters as (name, value) pairs; use std::string for strings (not const char*).
using Params = std::vector<std::pair<std::string, Properties::Value>>;

inline Properties make_props(const std::string &plugin, const Params &params = {}) {
    Properties props(plugin);
    for (const auto &[name, value] : params) props.set(name, value);
    return props;
}

inline std::shared_ptr<BSDF> make_bsdf(const std::string &plugin, const Params &params = {}) {
    return PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, make_props(plugin, params));
}

/// Expects creating the BSDF to throw a facet::Error whose message contains `fragment`.
inline void expect_error(const std::string &plugin, const Params &params,
                         const std::string &fragment) {
    try {
        make_bsdf(plugin, params);
        ADD_FAILURE() << plugin << ": expected an error containing \"" << fragment << "\"";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
            << plugin << ": message \"" << e.what() << "\" lacks \"" << fragment << "\"";
    }
}

/// A BSDF built around nested BSDFs (twosided, mask, blendbsdf), passed as `_arg_N` children.
inline std::shared_ptr<BSDF> make_nested(const std::string &plugin,
                                         const std::vector<std::shared_ptr<BSDF>> &nested,
                                         const Params &params = {}) {
    Properties props = make_props(plugin, params);
    for (size_t i = 0; i < nested.size(); ++i)
        props.set_object("_arg_" + std::to_string(i), nested[i]);
    return PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, props);
}

/// expect_error() for a BSDF with nested BSDFs.
inline void expect_nested_error(const std::string &plugin,
                                const std::vector<std::shared_ptr<BSDF>> &nested,
                                const Params &params, const std::string &fragment) {
    try {
        make_nested(plugin, nested, params);
        ADD_FAILURE() << plugin << ": expected an error containing \"" << fragment << "\"";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

/// A context that enables only component `component`.
inline BSDFContext component_ctx(uint32_t component, TransportMode mode = TransportMode::Radiance) {
    BSDFContext ctx(mode);
    ctx.component = component;
    return ctx;
}

/// A texture that varies over the surface: its value is u.
class RampTexture final : public Texture {
public:
    Color3f eval(const SurfaceInteraction &si) const override { return Color3f(si.uv.x); }
    Color3f mean() const override { return Color3f(0.5f); }
    std::string to_string() const override { return "RampTexture"; }
};

inline SurfaceInteraction make_si(const Vector3f &wi) {
    SurfaceInteraction si;
    si.p = Point3f(0.f);
    si.n = Normal3f(0.f, 0.f, 1.f);
    si.t = 1.f;
    si.uv = Point2f(0.5f, 0.5f);
    si.dp_du = Vector3f(1.f, 0.f, 0.f);
    si.dp_dv = Vector3f(0.f, 1.f, 0.f);
    si.wi = wi;
    return si;
}

/// Uniform direction on the sphere, or on the upper hemisphere; kept away from the horizon
/// (|cos θ| >= 1e-2), where float results are legitimately fragile.
inline Vector3f random_direction(PCG32 &rng, bool upper_only) {
    for (;;) {
        Vector3f v = warp::square_to_uniform_sphere(next_point2f(rng));
        if (upper_only) v.z = std::abs(v.z);
        if (std::abs(v.z) >= 1e-2f) return v;
    }
}

/// The promise of BSDFFlags::WiSideOnly, which `bsdf` must have: for `count` random incident
/// directions (both sides) and outgoing ones on the other side of the shading plane, eval(),
/// eval_pdf() and eval_pdf_polarized() give no light. Returns how many of the mirrored outgoing
/// directions (on wi's side) have light, so callers can make sure the check was not vacuous.
inline int check_wi_side_only(const BSDF &bsdf, int count = 2000, uint64_t seed = 11) {
    EXPECT_TRUE(has_flag(bsdf.flags(), BSDFFlags::WiSideOnly)) << bsdf.to_string();
    PCG32 rng(seed);
    const BSDFContext ctx;
    int lit = 0;
    for (int n = 0; n < count; ++n) {
        const Vector3f wi = random_direction(rng, false);
        const SurfaceInteraction si = make_si(wi);
        Vector3f other = random_direction(rng, false);
        if (Frame::cos_theta(other) * Frame::cos_theta(wi) > 0.f) other.z = -other.z;
        EXPECT_TRUE(bsdf.eval(ctx, si, other).is_black())
            << bsdf.to_string() << " wi " << wi << " wo " << other;
        EXPECT_TRUE(bsdf.eval_pdf(ctx, si, other).first.is_black()) << bsdf.to_string();
        if (has_flag(bsdf.flags(), BSDFFlags::Polarizing)) {
            EXPECT_TRUE(bsdf.eval_pdf_polarized(ctx, si, other).first.unpolarized().is_black())
                << bsdf.to_string();
        }
        const Vector3f same(other.x, other.y, -other.z);
        if (!bsdf.eval(ctx, si, same).is_black()) ++lit;
    }
    return lit;
}

/// Each channel of a within `rel` (relative to b, at least 1e-6 absolute) of b.
inline void expect_color_near(const Color3f &a, const Color3f &b, float rel) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(a[c], b[c], rel * std::max(1e-6f, std::abs(b[c]))) << "channel " << c;
}

inline bool near_rel(float a, float b, float rel) {
    return std::abs(a - b) <= rel * std::max(std::abs(a), std::abs(b)) + 1e-12f;
}

/**
 * For `count` random incident directions (upper hemisphere unless `both_sides`): every sample
 * with a density has weight == eval/pdf and bs.pdf == pdf() (relative `tol`), and eval_pdf()
 * equals (eval(), pdf()) at the sampled direction and at a random one. Returns the number of
 * smooth samples checked, so callers can make sure the check was not vacuous.
 */
inline int check_sample_eval_pdf(const BSDF &bsdf, const BSDFContext &ctx, bool both_sides,
                                 int count = 2000, uint64_t seed = 1, float tol = 1e-3f) {
    PCG32 rng(seed);
    int checked = 0, failures = 0;
    for (int i = 0; i < count && failures < 5; ++i) {
        SurfaceInteraction si = make_si(random_direction(rng, !both_sides));
        float s1 = rng.next_float();
        Point2f s2 = next_point2f(rng);
        auto [bs, weight] = bsdf.sample(ctx, si, s1, s2);

        Vector3f other = random_direction(rng, false);
        auto [v_other, p_other] = bsdf.eval_pdf(ctx, si, other);
        Color3f e_other = bsdf.eval(ctx, si, other);
        float pdf_other = bsdf.pdf(ctx, si, other);
        bool ok = near_rel(p_other, pdf_other, 1e-5f);
        for (int c = 0; c < 3; ++c) ok &= near_rel(v_other[c], e_other[c], 1e-5f);
        if (!ok) {
            ++failures;
            ADD_FAILURE() << "eval_pdf != (eval, pdf) at wi = " << si.wi << ", wo = " << other;
        }

        if (weight.is_black() || has_flag(bs.sampled_type, BSDFFlags::Delta)) continue;
        EXPECT_TRUE(weight.is_finite());
        EXPECT_NEAR(norm(bs.wo), 1.f, 1e-4f);
        auto [value, pdf] = bsdf.eval_pdf(ctx, si, bs.wo);
        Color3f expected = value / pdf;
        ok = pdf > 0.f && near_rel(bs.pdf, pdf, tol);
        for (int c = 0; c < 3; ++c) ok &= near_rel(weight[c], expected[c], tol);
        if (!ok) {
            ++failures;
            ADD_FAILURE() << "wi = " << si.wi << ", wo = " << bs.wo << ": weight " << weight
                          << " vs eval/pdf " << expected << ", sampled pdf " << bs.pdf
                          << " vs pdf() " << pdf;
        }
        ++checked;
    }
    return checked;
}

/// Monte Carlo mean of the sample weights for incident direction wi (the albedo; failed samples
/// count as zero). Radiance-mode refraction is compensated by η² so the result is energy.
inline Color3f furnace(const BSDF &bsdf, const BSDFContext &ctx, const Vector3f &wi, int count,
                       uint64_t seed = 7) {
    PCG32 rng(seed);
    SurfaceInteraction si = make_si(wi);
    double sum[3] = {0, 0, 0};
    for (int i = 0; i < count; ++i) {
        float s1 = rng.next_float();
        Point2f s2 = next_point2f(rng);
        auto [bs, weight] = bsdf.sample(ctx, si, s1, s2);
        float scale = ctx.mode == TransportMode::Radiance ? bs.eta * bs.eta : 1.f;
        for (int c = 0; c < 3; ++c) sum[c] += double(weight[c]) * scale;
    }
    return Color3f(float(sum[0] / count), float(sum[1] / count), float(sum[2] / count));
}

/// Integral of pdf() over the sphere for incident direction si.wi: a jittered res x res grid
/// of the square mapped to the uniform sphere. Stratification keeps the error of a peaked lobe
/// (rough glass: a density of ~40 /sr) far below that of independent uniform samples, whose
/// estimate scatters by ~0.02 at 200000 samples.
inline double pdf_sphere_integral(const BSDF &bsdf, const BSDFContext &ctx,
                                  const SurfaceInteraction &si, int res = 448, uint64_t seed = 5) {
    PCG32 rng(seed);
    double sum = 0.0;
    for (int i = 0; i < res; ++i)
        for (int j = 0; j < res; ++j) {
            Point2f u = next_point2f(rng);
            Point2f cell((float(i) + u.x) / float(res), (float(j) + u.y) / float(res));
            sum += double(bsdf.pdf(ctx, si, warp::square_to_uniform_sphere(cell)));
        }
    return sum * 4.0 * double(Pi) / (double(res) * double(res));
}

/// What the BSDF's own samples bring through delta component `k` from si.wi, on average: the
/// mean over `count` samples (sample1 stratified) of the weight of those that follow it. A
/// SeparableDelta component sampled alone must return this as its weight.
inline Color3f delta_share(const BSDF &bsdf, const SurfaceInteraction &si, uint32_t k,
                           int count = 65536, uint64_t seed = 8) {
    PCG32 rng(seed);
    const BSDFContext ctx;
    double sum[3] = {0, 0, 0};
    for (int i = 0; i < count; ++i) {
        const float s1 = (float(i) + rng.next_float()) / float(count);
        auto [bs, weight] = bsdf.sample(ctx, si, s1, next_point2f(rng));
        if (bs.sampled_component != k || weight.is_black()) continue;
        for (int c = 0; c < 3; ++c) sum[c] += double(weight[c]);
    }
    return Color3f(float(sum[0] / count), float(sum[1] / count), float(sum[2] / count));
}

/// Every component flagged SeparableDelta keeps its promise for `count` random incident
/// directions (upper hemisphere unless `both_sides`): sampled alone, its weight is
/// delta_share() (relative `tol`), and its direction the one the BSDF's samples take. Returns
/// the number of (direction, component) pairs checked with light through the lobe.
inline int check_separable_delta(const BSDF &bsdf, bool both_sides, int count = 24,
                                 uint64_t seed = 3, float tol = 1e-2f) {
    PCG32 rng(seed);
    int checked = 0;
    for (int n = 0; n < count; ++n) {
        const SurfaceInteraction si = make_si(random_direction(rng, !both_sides));
        for (uint32_t k = 0; k < uint32_t(bsdf.component_count()); ++k) {
            if (!has_flag(bsdf.flags(k), BSDFFlags::SeparableDelta)) continue;
            EXPECT_TRUE(
                has_flag(bsdf.flags(k), BSDFFlags::DeltaReflection | BSDFFlags::DeltaTransmission))
                << "component " << k << " is flagged SeparableDelta but is not a delta lobe";
            auto [lobe, weight] = bsdf.sample(component_ctx(k), si, 0.5f, Point2f(0.5f));
            const Color3f share = delta_share(bsdf, si, k);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(weight[c], share[c], tol * std::max(share[c], 1e-4f))
                    << "component " << k << ", cos θi = " << si.wi.z << ", channel " << c;
            if (weight.is_black()) continue;
            ++checked;
            auto [bs, full] = bsdf.sample(BSDFContext(), si, 0.f, Point2f(0.5f));
            for (float s1 = 0.f; bs.sampled_component != k && s1 < 1.f; s1 += 1.f / 4096.f)
                std::tie(bs, full) = bsdf.sample(BSDFContext(), si, s1, Point2f(0.5f));
            EXPECT_EQ(bs.sampled_component, k);
            EXPECT_TRUE(bs.wo == lobe.wo) << "component " << k << ", cos θi = " << si.wi.z;
        }
    }
    return checked;
}

/// Fraction of `count` samples from si.wi with a non-zero weight.
inline double sampled_fraction(const BSDF &bsdf, const BSDFContext &ctx,
                               const SurfaceInteraction &si, int count = 50000, uint64_t seed = 6) {
    PCG32 rng(seed);
    int ok = 0;
    for (int i = 0; i < count; ++i) {
        float s1 = rng.next_float();
        Point2f s2 = next_point2f(rng);
        ok += !bsdf.sample(ctx, si, s1, s2).second.is_black();
    }
    return double(ok) / double(count);
}

} // namespace bsdf_checks

namespace bsdf_checks {

/// Every parameter the plugin asked for (present or not) appears as a row of its doc table.
inline void expect_documented(const std::string &plugin, const Params &params = {}) {
    Properties props = make_props(plugin, params);
    PluginRegistry::instance().create(ObjectType::BSDF, props);
    std::string doc = PluginRegistry::instance().descriptor(plugin, ObjectType::BSDF).doc;
    EXPECT_FALSE(props.requested_names().empty());
    for (const std::string &name : props.requested_names())
        EXPECT_NE(doc.find("| " + name + " |"), std::string::npos)
            << plugin << ": parameter \"" << name << "\" is missing from the doc table";
}

} // namespace bsdf_checks
