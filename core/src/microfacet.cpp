#include <facet/logger.h>
#include <facet/microfacet.h>
#include <facet/properties.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace facet {

namespace {

const float InvSqrtPi = 0.56418958354775628f;

/// Where the Newton steps of Beckmann's visible-slope sampling start: X = erf(x̃) of the exact
/// inverse of the CDF (sample_visible_11()) on a grid over w = sin θ / (sin θ + cos θ), which is
/// about linear in θ at both ends, and u, read bilinearly. From there one Newton step reaches a
/// float's precision for u in [1/32, 31/32] (unit.microfacet checks the result against the CDF
/// in double); the tails keep the exact inverse for θ = π/2 as their start, and three steps.
/// This halves the sampler's work (an erf, a log and two steps of an erfinv and an exp fewer).
/// The grid: 34 KB, solved in double at first use (3 ms).
class BeckmannStart {
public:
    static constexpr int NW = 65, NU = 129;
    static constexpr float ULow = 1.f / 32.f, UHigh = 31.f / 32.f;

    BeckmannStart() {
        for (int i = 0; i < NW; ++i) {
            const double w = double(i) / (NW - 1), len = std::hypot(w, 1.0 - w);
            const double sin_theta = w / len, cos_theta = (1.0 - w) / len;
            float *row = m_x + i * NU;
            if (i == 0) { // normal incidence: x̃ is a plain Gaussian
                for (int j = 0; j < NU; ++j) row[j] = float(2.0 * j / (NU - 1) - 1.0);
                continue;
            }
            if (i == NW - 1) { // grazing: C ∝ exp(−x̃²) for x̃ < 0
                row[0] = -1.f;
                for (int j = 1; j < NU; ++j)
                    row[j] = float(-std::erf(std::sqrt(-std::log(double(j) / (NU - 1)))));
                continue;
            }
            // C(x̃) = 1 + erf(x̃) + k·exp(−x̃²) on (−∞, cot θ], C' = (2/√π)·exp(−x̃²)·(1 − x̃·tan θ):
            // Newton's steps kept inside a bracket (halving it where a step leaves it), from the
            // previous u's root.
            const double tan_theta = sin_theta / cos_theta, cot_theta = cos_theta / sin_theta;
            const double k = tan_theta / std::sqrt(Pi_d);
            const double total = 1.0 + std::erf(cot_theta) + k * std::exp(-cot_theta * cot_theta);
            row[0] = -1.f;
            row[NU - 1] = float(std::erf(cot_theta));
            double x = -6.0;
            for (int j = 1; j < NU - 1; ++j) {
                const double target = total * double(j) / (NU - 1);
                double lo = x, hi = cot_theta;
                for (int it = 0; it < 100; ++it) {
                    const double e = std::exp(-x * x);
                    const double value = 1.0 + std::erf(x) + k * e - target;
                    if (value < 0.0)
                        lo = x;
                    else
                        hi = x;
                    const double slope = 2.0 / std::sqrt(Pi_d) * e * (1.0 - x * tan_theta);
                    double next = slope > 0.0 ? x - value / slope : 0.5 * (lo + hi);
                    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
                    if (std::abs(next - x) <= 1e-13 * (1.0 + std::abs(x)) || hi - lo < 1e-13) {
                        x = next;
                        break;
                    }
                    x = next;
                }
                row[j] = float(std::erf(x));
            }
        }
    }

    /// X at (w, u) for u in [ULow, UHigh].
    float operator()(float w, float u) const {
        float fw = w * float(NW - 1), fu = u * float(NU - 1);
        const int iw = std::min(int(fw), NW - 2), iu = std::min(int(fu), NU - 2);
        fw -= float(iw);
        fu -= float(iu);
        const float *x = m_x + iw * NU + iu;
        return (x[0] + (x[1] - x[0]) * fu) * (1.f - fw) + (x[NU] + (x[NU + 1] - x[NU]) * fu) * fw;
    }

private:
    static constexpr double Pi_d = 3.14159265358979323846;
    float m_x[NW * NU];
};

} // namespace

const char *microfacet_type_name(MicrofacetType type) {
    return type == MicrofacetType::Beckmann ? "beckmann" : "ggx";
}

std::pair<Vector3f, float> MicrofacetDistribution::sample(const Vector3f &wi,
                                                          const Point2f &u) const {
    return m_sample_visible ? sample_visible_normals(wi, u) : sample_all(u);
}

std::pair<Vector3f, float> MicrofacetDistribution::sample_all(const Point2f &u) const {
    // Azimuth: uniform when isotropic; otherwise inverted from the marginal of D·cos θ, which
    // gives tan φ = (αv/αu)·tan(2π u.y), with the quadrant taken from u.y.
    float phi, alpha_2;
    if (m_alpha_u == m_alpha_v) {
        phi = 2.f * Pi * u.y;
        alpha_2 = m_alpha_u * m_alpha_u;
    } else {
        phi = std::atan(m_alpha_v / m_alpha_u * std::tan(2.f * Pi * u.y));
        if (std::abs(u.y - 0.5f) < 0.25f) phi += Pi;
        float c = std::cos(phi), s = std::sin(phi);
        alpha_2 = 1.f / (sqr(c / m_alpha_u) + sqr(s / m_alpha_v));
    }
    float cos_phi = std::cos(phi), sin_phi = std::sin(phi);

    // Elevation: inverse of the radial CDF of D·cos θ for the effective α of this azimuth.
    float tan_theta_2 = m_type == MicrofacetType::Beckmann ? -alpha_2 * std::log1p(-u.x)
                                                           : alpha_2 * u.x / (1.f - u.x);
    float cos_theta_2 = 1.f / (1.f + tan_theta_2);
    float cos_theta = std::sqrt(cos_theta_2);
    float sin_theta = std::sqrt(tan_theta_2 * cos_theta_2); // not √(1 − cos²θ): no cancellation

    Vector3f m(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
    // D(m)·cos θm from tan²θ itself: evaluating D at m rebuilt in float would amplify the
    // rounding of cos θm (relative 1.7e-4 at α = 0.05).
    //   Beckmann: exp(−tan²θ/α²) / (π αu αv cos³θ);  GGX: 1 / (π αu αv cos³θ (1 + tan²θ/α²)²).
    float cos_theta_3 = cos_theta_2 * cos_theta;
    float t = tan_theta_2 / alpha_2;
    float pdf = m_type == MicrofacetType::Beckmann
                    ? std::exp(-t) / (Pi * m_alpha_u * m_alpha_v * cos_theta_3)
                    : 1.f / (Pi * m_alpha_u * m_alpha_v * cos_theta_3 * sqr(1.f + t));
    // The same cut-off as eval(), so sample() and pdf() agree on which normals have a density.
    if (!std::isfinite(pdf) || !(pdf > 1e-20f)) pdf = 0.f;
    return {m, pdf};
}

std::pair<Vector3f, float> MicrofacetDistribution::sample_visible_normals(const Vector3f &wi,
                                                                          const Point2f &u) const {
    if (Frame::cos_theta(wi) <= 0.f) return {Vector3f(0.f, 0.f, 1.f), 0.f};
    // 1. Stretch wi into the configuration of an α = 1 distribution.
    Vector3f wi_s = normalize(Vector3f(m_alpha_u * wi.x, m_alpha_v * wi.y, wi.z));
    // 2. Sample a visible slope of the α = 1 distribution for the azimuth φ = 0.
    Point2f slope = sample_visible_11(Frame::cos_theta(wi_s), u);
    // 3. Rotate to the azimuth of wi and unstretch.
    float cos_phi = Frame::cos_phi(wi_s), sin_phi = Frame::sin_phi(wi_s);
    slope = Point2f(cos_phi * slope.x - sin_phi * slope.y, sin_phi * slope.x + cos_phi * slope.y);
    // (x̃/αu)² + (ỹ/αv)² of the unstretched slope is the squared length of the stretched one.
    float e = sqr(slope.x) + sqr(slope.y);
    slope.x *= m_alpha_u;
    slope.y *= m_alpha_v;
    // 4. The normal of the slope.
    float tan_theta_2 = sqr(slope.x) + sqr(slope.y);
    Vector3f m = normalize(Vector3f(-slope.x, -slope.y, 1.f));
    if (!is_finite(m) || !std::isfinite(tan_theta_2)) return {Vector3f(0.f, 0.f, 1.f), 0.f};

    // 5. pdf = D(m)·G1(wi)·(wi·m)/cos θi, with D and wi·m from the slope rather than from m
    // rebuilt in float: 1/cos²θm = 1 + tan²θm, and (wi·m)·√(1 + tan²θm) = wi.z − slope·wi.xy.
    //   Beckmann: D = exp(−e)·(1 + tan²θ)² / (π αu αv);  GGX: D = (1 + tan²θ)² / (π αu αv (1 +
    //   e)²).
    float sec_2 = 1.f + tan_theta_2;
    float D = m_type == MicrofacetType::Beckmann
                  ? std::exp(-e) * sqr(sec_2) / (Pi * m_alpha_u * m_alpha_v)
                  : sqr(sec_2 / (1.f + e)) / (Pi * m_alpha_u * m_alpha_v);
    float wi_dot_m = (wi.z - slope.x * wi.x - slope.y * wi.y) / std::sqrt(sec_2);
    // eval()'s cut-off (D·cos θm), so sample() and pdf() agree on which normals have a density.
    if (!std::isfinite(D) || !(D / std::sqrt(sec_2) > 1e-20f) || !(wi_dot_m > 0.f)) return {m, 0.f};
    return {m, D * visible_normalization(wi) * wi_dot_m / Frame::cos_theta(wi)};
}

Point2f MicrofacetDistribution::sample_visible_11(float cos_theta_i, const Point2f &u_in) const {
    if (m_type == MicrofacetType::GGX) {
        // Heitz 2018: a uniform point on the projected hemisphere of visible normals, which is a
        // half disk plus a half ellipse; warp y to the ellipse's half.
        Point2f p = warp::square_to_uniform_disk_concentric(u_in);
        float s = 0.5f * (1.f + cos_theta_i);
        p.y = lerp(s, safe_sqrt(1.f - p.x * p.x), p.y);
        float x = p.x, y = p.y, z = safe_sqrt(1.f - x * x - y * y);
        float sin_theta_i = safe_sqrt(1.f - cos_theta_i * cos_theta_i);
        // The normal (s·z − c·y, x, s·y + c·z) in the frame of wi, as a slope.
        float inv_nz = 1.f / (sin_theta_i * y + cos_theta_i * z);
        return Point2f((cos_theta_i * y - sin_theta_i * z) * inv_nz, x * inv_nz);
    }

    // Beckmann (Heitz & d'Eon 2014, Jakob 2014). The visible slopes of the α = 1 distribution
    // seen at elevation θ have density ∝ exp(−x̃² − ỹ²)·(cos θ − x̃ sin θ) for x̃ < cot θ: ỹ is a
    // plain Gaussian, x̃ is found by inverting its CDF numerically. In the variable X = erf(x̃) the
    // CDF is, up to normalisation, C(X) = 1 + X + tanθ/√π·exp(−x̃²), with C'(X) = 1 − x̃·tanθ.
    Point2f u(clamp(u_in.x, 1e-6f, 1.f - 1e-6f), clamp(u_in.y, 1e-6f, 1.f - 1e-6f));
    float sin_theta_i = safe_sqrt(1.f - cos_theta_i * cos_theta_i);
    float tan_theta_i = sin_theta_i / cos_theta_i;
    if (!(tan_theta_i > 1e-4f)) // near normal incidence every normal is visible alike
        return Point2f(erfinv(2.f * u.x - 1.f), erfinv(2.f * u.y - 1.f));

    float cot_theta_i = cos_theta_i / sin_theta_i;
    // C is defined on [−1, x_max]. From cot θ = 4 on (3.84 would do) erf(cot θ) exceeds the
    // bound and the exp term is below half a float's step of 1 + x_max: the same values to the
    // last bit without erf and exp, as a test checks.
    float x_max = 1.f - 1e-6f, target = u.x * (1.f + x_max);
    if (cot_theta_i < 4.f) {
        x_max = std::min(std::erf(cot_theta_i), x_max);
        target = u.x * (1.f + x_max + InvSqrtPi * tan_theta_i * std::exp(-sqr(cot_theta_i)));
    }

    float X;
    int steps;
    if (u.x >= BeckmannStart::ULow && u.x <= BeckmannStart::UHigh) {
        static const BeckmannStart start;
        X = clamp(start(sin_theta_i / (sin_theta_i + cos_theta_i), u.x), -1.f + 1e-6f, x_max);
        // One Newton step, taken in the slope: the step ΔX = C/C' of X = erf(x̃) moves x̃ by
        // ΔX / erf'(x̃) = ΔX·√π/2·exp(x̃²) to first order, an error of the order of the step's
        // own, and one erfinv fewer than inverting the new X. A step that leaves X's range is
        // clamped in X as below.
        const float slope = erfinv(X), e = std::exp(-slope * slope);
        const float value = 1.f + X + InvSqrtPi * tan_theta_i * e - target;
        const float step = value / (1.f - slope * tan_theta_i);
        const float next = X - step;
        if (next >= -1.f + 1e-6f && next <= x_max && e > 0.f)
            return Point2f(slope - step * (0.5f / InvSqrtPi) / e, erfinv(2.f * u.y - 1.f));
        X = clamp(next, -1.f + 1e-6f, x_max);
        steps = 0;
    } else {
        // The tails: the exact inverse for θ = π/2 (C ∝ exp(−x̃²)), mapped onto [−1, x_max].
        X = x_max - (1.f + x_max) * std::erf(std::sqrt(-std::log(u.x)));
        steps = 3;
    }
    for (int i = 0; i < steps; ++i) { // Newton steps
        float slope = erfinv(X);
        float value = 1.f + X + InvSqrtPi * tan_theta_i * std::exp(-slope * slope) - target;
        float derivative = 1.f - slope * tan_theta_i;
        X = clamp(X - value / derivative, -1.f + 1e-6f, x_max);
    }
    return Point2f(erfinv(X), erfinv(2.f * u.y - 1.f));
}

std::string MicrofacetDistribution::to_string() const {
    return fmt::format("MicrofacetDistribution[type = {}, alpha_u = {}, alpha_v = {}, "
                       "sample_visible = {}]",
                       microfacet_type_name(m_type), m_alpha_u, m_alpha_v, m_sample_visible);
}

MicrofacetParameters::MicrofacetParameters(MicrofacetType type, std::shared_ptr<Texture> alpha_u,
                                           std::shared_ptr<Texture> alpha_v, bool sample_visible)
    : m_type(type), m_alpha_u(std::move(alpha_u)), m_alpha_v(std::move(alpha_v)),
      m_sample_visible(sample_visible) {
    m_constant = !m_alpha_u->is_spatially_varying() && !m_alpha_v->is_spatially_varying();
    if (m_constant) {
        m_const_u = m_alpha_u->mean().mean();
        m_const_v = m_alpha_v->mean().mean();
    }
    m_anisotropic = m_alpha_u != m_alpha_v && !(m_constant && m_const_u == m_const_v);
}

std::string MicrofacetParameters::to_string() const {
    return fmt::format("distribution = {}, alpha_u = {}, alpha_v = {}, sample_visible = {}",
                       microfacet_type_name(m_type), m_alpha_u->to_string(), m_alpha_v->to_string(),
                       m_sample_visible);
}

MicrofacetParameters read_microfacet(const Properties &props, float default_alpha,
                                     bool allow_textures) {
    std::string name = props.get_string("distribution", "beckmann");
    MicrofacetType type;
    if (name == "beckmann")
        type = MicrofacetType::Beckmann;
    else if (name == "ggx")
        type = MicrofacetType::GGX;
    else
        FACET_THROW_AT(props.has("distribution") ? props.location("distribution")
                                                 : props.location(),
                       "distribution must be beckmann or ggx, found \"{}\"", name);

    bool has_alpha = props.has("alpha"), has_u = props.has("alpha_u"), has_v = props.has("alpha_v");
    if (has_alpha && (has_u || has_v))
        FACET_THROW_AT(props.location(), "give either alpha or both alpha_u and alpha_v, not both");
    if (has_u != has_v)
        FACET_THROW_AT(props.location(),
                       "alpha_u and alpha_v must be given together (found only {})",
                       has_u ? "alpha_u" : "alpha_v");

    auto read = [&](const char *param) {
        if (!allow_textures && props.has(param) && props.type(param) == Properties::Type::Object)
            FACET_THROW_AT(props.location(param), "{} must be a number here, not a texture", param);
        std::shared_ptr<Texture> tex = props.texture(param, default_alpha, SpectrumKind::Unbounded);
        if (!tex->is_spatially_varying()) {
            float value = tex->mean().mean();
            const Location &loc = props.has(param) ? props.location(param) : props.location();
            if (!(value >= 0.f) || !std::isfinite(value))
                FACET_THROW_AT(loc, "{} must be a roughness >= 0, found {}", param, value);
            if (value == 0.f)
                FACET_LOG(Warn,
                          "{}{} = 0 is clamped to {}; a smooth plugin (conductor, dielectric) "
                          "renders this case exactly",
                          loc.valid() ? loc.to_string() + ": " : "", param,
                          MicrofacetDistribution::MinAlpha);
        }
        return tex;
    };
    std::shared_ptr<Texture> alpha_u, alpha_v;
    if (has_u) {
        alpha_u = read("alpha_u");
        alpha_v = read("alpha_v");
    } else {
        alpha_u = alpha_v = read("alpha");
    }
    bool sample_visible = props.get_bool("sample_visible", true);
    return MicrofacetParameters(type, alpha_u, alpha_v, sample_visible);
}

} // namespace facet
