static const char *DOC = R"DOC(
# roughplastic: rough plastic (diffuse base under a rough dielectric coating)

A diffuse material under a rough dielectric coating whose microfacets follow a Beckmann or GGX
distribution: the rough counterpart of `plastic`. The coating reflects a glossy lobe
F·D·G/(4·cos θi·cos θo) (Walter et al. 2007); the light it lets through scatters in the diffuse
base and leaves through the coating again:

f_diffuse·cos θo = ρ/(1 − fdr) · (1/η²) · T(cos θi) · T(cos θo) · cos θo/π

where T(μ) is the energy a rough dielectric interface transmits at incidence cos θ = μ (the
integral of its transmission lobe, precomputed for 64 values of μ by Gauss–Legendre quadrature
over the visible microfacet normals and interpolated linearly) and fdr is the rough interface's
hemispherical reflectance from inside (with `nonlinear`, ρ·fdr replaces fdr). Sampling picks the
glossy lobe with probability (1 − T(cos θi))·w against T(cos θi)·(1 − w), w being the specular
sampling weight s/(s + d) of the mean reflectances; the weight is eval/pdf of the mixture.
The roughness is isotropic and a plain number (the tables depend on it). Only the front side
reflects (wrap the BSDF in `twosided` for two-sided surfaces).

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| distribution | string | beckmann | Microfacet distribution of the coating: beckmann or ggx |
| alpha | float | 0.1 | Roughness of the coating (RMS slope; isotropic, a number) |
| alpha_u | float | — | Not supported unless equal to alpha_v (the model is isotropic); use alpha |
| alpha_v | float | — | Not supported unless equal to alpha_u (the model is isotropic); use alpha |
| sample_visible | boolean | true | Sample only the normals visible from wi (Heitz & d'Eon 2014) |
| int_ior | float or string | polypropylene (1.49) | Interior index of refraction, a number or a material name |
| ext_ior | float or string | air (1.000277) | Exterior index of refraction, a number or a material name |
| diffuse_reflectance | spectrum or texture | 0.5 | Albedo ρ of the diffuse base |
| specular_reflectance | spectrum or texture | 1.0 | Tint of the glossy reflection (for artistic control only) |
| nonlinear | boolean | false | Account for the colour shift of internal scattering: ρ/(1 − ρ·fdr) instead of ρ/(1 − fdr) |

Components: 0 = the glossy reflection of the coating (GlossyReflection), 1 = the diffuse base
(DiffuseReflection). Equal interior and exterior IORs are an error (there would be no coating).

```xml
<bsdf type="roughplastic">
    <string name="distribution" value="ggx"/>
    <float name="alpha" value="0.2"/>
    <rgb name="diffuse_reflectance" value="0.7, 0.1, 0.1"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/fresnel.h>
#include <facet/ior.h>
#include <facet/microfacet.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <tuple>
#include <vector>

namespace facet {

namespace {

constexpr int TransmittanceRes = 64;

/// Gauss–Legendre nodes and weights of order n on [−1, 1] (Newton iteration on P_n).
void gauss_legendre(int n, std::vector<double> &nodes, std::vector<double> &weights) {
    nodes.assign(size_t(n), 0.0);
    weights.assign(size_t(n), 0.0);
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < n; ++i) {
        double x = std::cos(pi * (i + 0.75) / (n + 0.5)), dp = 0.0;
        for (int it = 0; it < 100; ++it) {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            double p0 = 1.0, p1 = x;
            for (int k = 2; k <= n; ++k) {
                double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            if (n == 1) p0 = 1.0;
            dp = n * (x * p1 - p0) / (x * x - 1.0);
            double dx = p1 / dp;
            x -= dx;
            if (std::abs(dx) < 1e-15) break;
        }
        nodes[size_t(i)] = x;
        weights[size_t(i)] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
}

/**
 * Energy that a rough dielectric interface (relative IOR `eta`) reflects (`reflect` = true) or
 * transmits for light arriving from wi = (sin θ, 0, cos θ): the integral over the normals visible
 * from wi of F·G1(wo, m) or (1 − F)·G1(wo, m), i.e. the mean sample weight of the rough
 * dielectric's lobe. An n × n Gauss–Legendre rule on the unit square of the visible-normal
 * sampler (Heitz & d'Eon 2014) does the integral; the normal of each node is the one
 * MicrofacetDistribution::sample() returns for wi (whose azimuth is 0), without its density.
 */
double rough_interface_energy(const MicrofacetDistribution &distr, const Vector3f &wi, float eta,
                              bool reflect, const std::vector<double> &nodes,
                              const std::vector<double> &weights) {
    const size_t n = nodes.size();
    const float alpha = distr.alpha();
    // Slopes of the α = 1 configuration seen from the stretched wi.
    float cos_s = normalize(Vector3f(alpha * wi.x, alpha * wi.y, wi.z)).z;
    auto node = [&](size_t i) { return float(0.5 * nodes[i] + 0.5); };
    // Beckmann's visible slopes are separable (x̃ from the first number, ỹ a Gaussian of the
    // second), so each axis is solved once per node instead of once per node pair.
    std::vector<float> slope_x, slope_y;
    bool separable = distr.type() == MicrofacetType::Beckmann;
    if (separable) {
        slope_x.resize(n);
        slope_y.resize(n);
        for (size_t i = 0; i < n; ++i) {
            slope_x[i] = distr.sample_visible_11(cos_s, Point2f(node(i), 0.5f)).x;
            slope_y[i] = distr.sample_visible_11(cos_s, Point2f(0.5f, node(i))).y;
        }
    }

    // wi lies in the xz plane and the distribution is isotropic: the normal whose y slope is
    // negated gives the same value (wo mirrored in y), and the rule's nodes and weights are
    // symmetric about the middle. Half of the nodes of the variate that sets the y slope (the
    // second for Beckmann, the first, the disk's x, for GGX) are evaluated and counted twice:
    // the tables cost half as much (they were 125 ms of the staircase's load) for the same rule
    // up to rounding. n is even.
    FACET_ASSERT(n % 2 == 0);
    const size_t a_end = separable ? n : n / 2, b_end = separable ? n / 2 : n;
    double sum = 0.0;
    for (size_t a = 0; a < a_end; ++a) {
        for (size_t b = 0; b < b_end; ++b) {
            Point2f slope = separable ? Point2f(slope_x[a], slope_y[b])
                                      : distr.sample_visible_11(cos_s, Point2f(node(a), node(b)));
            Vector3f m = normalize(Vector3f(-alpha * slope.x, -alpha * slope.y, 1.f));
            if (!is_finite(m)) continue;
            auto [F, cos_t, eta_it, eta_ti] = fresnel_dielectric(dot(wi, m), eta);
            float f;
            if (reflect) {
                Vector3f wo = facet::reflect(wi, m);
                if (Frame::cos_theta(wo) <= 0.f) continue;
                f = F * distr.smith_g1(wo, m);
            } else {
                Vector3f wo = refract(wi, m, cos_t, eta_ti);
                if (Frame::cos_theta(wo) >= 0.f) continue;
                f = (1.f - F) * distr.smith_g1(wo, m);
            }
            sum += 0.5 * weights[a] * weights[b] * double(f); // 2 x the quarter of the Jacobian
        }
    }
    return sum;
}

/// The precomputed tables of one (distribution, α, η).
struct CoatingTables {
    std::array<float, TransmittanceRes> external_transmittance{};
    float internal_reflectance = 0.f;
};

/**
 * T(μ) for μ = 0, 1/63, ..., 1 and the internal reflectance 2·mean(R(μ, 1/η)·μ) (Gauss–Legendre
 * with 32² nodes for a relative IOR above one, 128² for the TIR-prone one below).
 */
CoatingTables compute_tables(MicrofacetType type, float alpha, float eta) {
    MicrofacetDistribution distr(type, alpha, true);
    std::vector<double> nodes_ext, weights_ext, nodes_int, weights_int;
    gauss_legendre(eta > 1.f ? 32 : 128, nodes_ext, weights_ext);
    gauss_legendre(1.f / eta > 1.f ? 32 : 128, nodes_int, weights_int);
    CoatingTables tables;
    double internal = 0.0;
    for (int j = 0; j < TransmittanceRes; ++j) {
        float mu = std::max(1e-6f, float(j) / float(TransmittanceRes - 1));
        Vector3f wi(std::sqrt(std::max(0.f, 1.f - mu * mu)), 0.f, mu);
        double t = rough_interface_energy(distr, wi, eta, false, nodes_ext, weights_ext);
        tables.external_transmittance[size_t(j)] = float(clamp(t, 0.0, 1.0));
        internal +=
            rough_interface_energy(distr, wi, 1.f / eta, true, nodes_int, weights_int) * double(mu);
    }
    tables.internal_reflectance = float(2.0 * internal / TransmittanceRes);
    return tables;
}

/// Tables are shared by all instances with the same coating (scenes reuse materials a lot).
const CoatingTables &coating_tables(MicrofacetType type, float alpha, float eta) {
    static std::mutex mutex;
    static std::map<std::tuple<int, float, float>, CoatingTables> cache;
    std::lock_guard<std::mutex> lock(mutex);
    auto key = std::make_tuple(int(type), alpha, eta);
    auto it = cache.find(key);
    if (it == cache.end()) it = cache.emplace(key, compute_tables(type, alpha, eta)).first;
    return it->second;
}

} // namespace

class RoughPlastic final : public BSDF {
public:
    explicit RoughPlastic(const Properties &props) {
        m_microfacet = read_microfacet(props, 0.1f, /*allow_textures=*/false);
        if (m_microfacet.is_anisotropic())
            FACET_THROW_AT(props.location(), "roughplastic is isotropic only: give one alpha, not "
                                             "different alpha_u and alpha_v");
        m_alpha = m_microfacet.alpha_u()->mean().mean();

        float int_ior = read_ior(props, "int_ior", "polypropylene");
        float ext_ior = read_ior(props, "ext_ior", "air");
        if (int_ior == ext_ior)
            FACET_THROW_AT(props.location(),
                           "roughplastic: int_ior and ext_ior must differ (both "
                           "are {}), otherwise there is no coating; use diffuse instead",
                           int_ior);
        m_eta = int_ior / ext_ior;
        m_inv_eta_2 = 1.f / (m_eta * m_eta);

        m_diffuse_reflectance = props.texture("diffuse_reflectance", 0.5f);
        if (props.has("specular_reflectance"))
            m_specular_reflectance = props.texture("specular_reflectance", 1.f);
        m_nonlinear = props.get_bool("nonlinear", false);

        float d_mean = m_diffuse_reflectance->mean().mean();
        float s_mean = m_specular_reflectance ? m_specular_reflectance->mean().mean() : 1.f;
        m_specular_sampling_weight = d_mean + s_mean > 0.f ? s_mean / (d_mean + s_mean) : 0.5f;

        const CoatingTables &tables = coating_tables(m_microfacet.type(), m_alpha, m_eta);
        m_external_transmittance = tables.external_transmittance;
        m_internal_reflectance = tables.internal_reflectance;

        BSDFFlags spec = BSDFFlags::GlossyReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly;
        BSDFFlags diff =
            BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly;
        if (m_specular_reflectance && m_specular_reflectance->is_spatially_varying())
            spec |= BSDFFlags::SpatiallyVarying;
        if (m_diffuse_reflectance->is_spatially_varying()) diff |= BSDFFlags::SpatiallyVarying;
        set_components({spec, diff});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1, const Point2f &sample2) const override {
        bool has_specular = ctx.is_enabled(BSDFFlags::GlossyReflection, 0);
        bool has_diffuse = ctx.is_enabled(BSDFFlags::DiffuseReflection, 1);
        float cos_i = Frame::cos_theta(si.wi);
        BSDFSample bs;
        if ((!has_specular && !has_diffuse) || cos_i <= 0.f) return {bs, Color3f(0.f)};

        float p_spec = specular_probability(cos_i, has_specular, has_diffuse);
        bs.eta = 1.f;
        if (sample1 < p_spec) {
            MicrofacetDistribution distr = m_microfacet.at(si);
            auto [m, pdf_m] = distr.sample(si.wi, sample2);
            if (!(pdf_m > 0.f)) return {bs, Color3f(0.f)};
            bs.wo = facet::reflect(si.wi, m);
            bs.sampled_type = BSDFFlags::GlossyReflection;
            bs.sampled_component = 0;
        } else {
            bs.wo = warp::square_to_cosine_hemisphere(sample2);
            bs.sampled_type = BSDFFlags::DiffuseReflection;
            bs.sampled_component = 1;
        }
        if (Frame::cos_theta(bs.wo) <= 0.f) return {bs, Color3f(0.f)};
        // The weight of a mixture is its value over its density, whichever lobe drew wo.
        auto [value, pdf] = eval_pdf(ctx, si, bs.wo);
        if (!(pdf > 0.f) || value.is_black()) return {bs, Color3f(0.f)};
        bs.pdf = pdf;
        return {bs, value / pdf};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        return eval_pdf(ctx, si, wo).first;
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        return eval_pdf(ctx, si, wo).second;
    }

    std::pair<Color3f, float> eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                                       const Vector3f &wo) const override {
        bool has_specular = ctx.is_enabled(BSDFFlags::GlossyReflection, 0);
        bool has_diffuse = ctx.is_enabled(BSDFFlags::DiffuseReflection, 1);
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if ((!has_specular && !has_diffuse) || cos_i <= 0.f || cos_o <= 0.f)
            return {Color3f(0.f), 0.f};

        float p_spec = specular_probability(cos_i, has_specular, has_diffuse);
        Color3f value(0.f);
        float pdf = 0.f;
        if (has_specular) {
            MicrofacetDistribution distr = m_microfacet.at(si);
            Vector3f h = normalize(si.wi + wo);
            float D = distr.eval(h);
            if (D > 0.f) {
                // f·cos θo = F·D·G / (4 cos θi); the density of wo = reflect(wi, m) is
                // pdf(m)/(4 wo·m) (Walter et al. 2007, eq. 14).
                float F = fresnel_dielectric(dot(si.wi, h), m_eta).F;
                Color3f spec(F * D * distr.G(si.wi, wo, h) / (4.f * cos_i));
                if (m_specular_reflectance) spec *= m_specular_reflectance->eval(si);
                value += spec;
                pdf += p_spec * distr.pdf(si.wi, h) / (4.f * dot(wo, h));
            }
        }
        if (has_diffuse) {
            Color3f rho = m_diffuse_reflectance->eval(si);
            Color3f albedo = m_nonlinear ? rho / (Color3f(1.f) - rho * m_internal_reflectance)
                                         : rho / (1.f - m_internal_reflectance);
            value += albedo *
                     (m_inv_eta_2 * transmittance(cos_i) * transmittance(cos_o) * InvPi * cos_o);
            pdf += (1.f - p_spec) * warp::square_to_cosine_hemisphere_pdf(wo);
        }
        return {value, pdf};
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_diffuse_reflectance->eval(si);
    }

    /// Energy the coating transmits at incidence cos θ = mu (the precomputed table).
    float transmittance(float mu) const {
        float x = clamp(mu, 0.f, 1.f) * float(TransmittanceRes - 1);
        int i = std::min(int(x), TransmittanceRes - 2);
        float t = x - float(i);
        return (1.f - t) * m_external_transmittance[size_t(i)] +
               t * m_external_transmittance[size_t(i) + 1];
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_diffuse_reflectance, si);
        started |= facet::prefetch(m_specular_reflectance, si);
        started |= m_microfacet.prefetch(si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("RoughPlastic[{}, eta = {}, diffuse_reflectance = {}, "
                           "specular_reflectance = {}, nonlinear = {}, internal_reflectance = {}, "
                           "specular_sampling_weight = {}]",
                           m_microfacet.to_string(), m_eta, m_diffuse_reflectance->to_string(),
                           m_specular_reflectance ? m_specular_reflectance->to_string() : "1",
                           m_nonlinear, m_internal_reflectance, m_specular_sampling_weight);
    }

private:
    /// Probability of the glossy lobe: (1 − T_i)·w against T_i·(1 − w), or all-or-nothing when
    /// only one lobe is enabled.
    float specular_probability(float cos_i, bool has_specular, bool has_diffuse) const {
        if (has_specular != has_diffuse) return has_specular ? 1.f : 0.f;
        float t_i = transmittance(cos_i);
        float p_spec = (1.f - t_i) * m_specular_sampling_weight;
        float p_diff = t_i * (1.f - m_specular_sampling_weight);
        return p_spec + p_diff > 0.f ? p_spec / (p_spec + p_diff) : 0.f;
    }

    MicrofacetParameters m_microfacet;
    float m_alpha;
    float m_eta, m_inv_eta_2;
    float m_specular_sampling_weight;
    bool m_nonlinear;
    std::shared_ptr<Texture> m_diffuse_reflectance, m_specular_reflectance;
    std::array<float, TransmittanceRes> m_external_transmittance{};
    float m_internal_reflectance = 0.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::RoughPlastic, BSDF, "roughplastic",
                          "Rough plastic: a diffuse base under a rough dielectric coating", DOC,
                          ::facet::AllModes)
