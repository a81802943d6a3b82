#include <facet/film.h>
#include <facet/logger.h>
#include <facet/spectrum.h>
#include <facet/texture.h>

#include <algorithm>
#include <cmath>

namespace facet {

namespace {

/// A band's response at four wavelengths: per wavelength for a spectral texture, else the
/// texture's constant.
Color3f eval_srf(const Texture &srf, const SpectralTexture *spectral, const Wavelengths &lambda) {
    if (spectral) return spectral->eval_wavelengths(lambda);
    const Color3f c = srf.mean();
    return Color3f(c.r, c.r, c.r, c.r);
}

} // namespace

SpectralBands::SpectralBands(std::vector<Band> bands, float lambda_min, float lambda_max,
                             size_t points)
    : m_bands(std::move(bands)), m_min(lambda_min), m_max(lambda_max) {
    if (m_bands.empty()) FACET_THROW("spectral bands need at least one sensor response function");
    if (!(lambda_min >= SpectralMinNm && lambda_max <= SpectralMaxNm && lambda_min < lambda_max) ||
        points < 2 || points > (size_t(1) << 20))
        FACET_THROW("spectral bands: the grid [{}, {}] nm of {} points must lie within {}-{} nm "
                    "with 2 to 2^20 points",
                    lambda_min, lambda_max, points, SpectralMinNm, SpectralMaxNm);
    for (const Band &b : m_bands) {
        if (!b.srf) FACET_THROW("spectral band \"{}\" has no response function", b.name);
        const auto *spectral = dynamic_cast<const SpectralTexture *>(b.srf.get());
        if (!spectral && b.srf->is_spatially_varying())
            FACET_THROW("spectral band \"{}\": a sensor response function is a spectrum, not the "
                        "texture {}",
                        b.name, b.srf->to_string());
        m_spectral.push_back(spectral);
        m_names.push_back(b.name);
    }
    m_step = (lambda_max - lambda_min) / float(points - 1);
    m_values.assign(points, 0.f);
    float negative = 0.f; // the first wavelength where S < 0
    // S at the grid points, four at a time.
    for (size_t k = 0; k < points; k += 4) {
        float l[4];
        for (size_t i = 0; i < 4; ++i)
            l[i] = std::min(lambda_max, lambda_min + float(std::min(k + i, points - 1)) * m_step);
        const Wavelengths lambda(l[0], l[1], l[2], l[3]);
        Color3f sum(0.f);
        for (size_t j = 0; j < m_bands.size(); ++j)
            sum += eval_srf(*m_bands[j].srf, m_spectral[j], lambda);
        const float v[4] = {sum.r, sum.g, sum.b, sum.w};
        for (size_t i = 0; i < 4 && k + i < points; ++i) {
            if (v[i] < 0.f && !negative) negative = l[i];
            m_values[k + i] = std::isfinite(v[i]) ? std::max(v[i], 0.f) : 0.f;
        }
    }
    if (negative)
        FACET_LOG(Warn,
                  "the responses of the bands {} sum to a negative value at {} nm: no wavelength "
                  "is drawn where the sum is not positive, so a band loses its response there",
                  fmt::join(m_names, ", "), negative);
    // The CDF of the piecewise linear S over the grid's segments.
    m_cdf.assign(points, 0.0);
    for (size_t k = 1; k < points; ++k)
        m_cdf[k] = m_cdf[k - 1] + 0.5 * (double(m_values[k - 1]) + double(m_values[k])) * m_step;
    m_integral = m_cdf.back();
    if (!(m_integral > 0.0) || !std::isfinite(m_integral))
        FACET_THROW("the sensor response functions of the bands {} are zero everywhere in "
                    "[{}, {}] nm: no wavelength can be sampled",
                    fmt::join(m_names, ", "), lambda_min, lambda_max);
    for (double &c : m_cdf) c /= m_integral;
    m_cdf.back() = 1.0;
}

std::pair<Wavelengths, Color3f> SpectralBands::sample_wavelengths(float u) const {
    float lambda[4], weight[4];
    const size_t segments = m_values.size() - 1;
    for (int i = 0; i < 4; ++i) {
        double ui = double(u) + 0.25 * i;
        if (ui >= 1.0) ui -= 1.0;
        // The segment k with cdf[k] <= ui < cdf[k + 1] (segments without mass never).
        size_t k = size_t(std::upper_bound(m_cdf.begin(), m_cdf.end(), ui) - m_cdf.begin());
        k = std::min(k == 0 ? 0 : k - 1, segments - 1);
        // Invert the linear density a + (b - a)·t over the segment: the mass m (in units of
        // the step) is a·t + (b - a)·t²/2.
        const double a = m_values[k], b = m_values[k + 1];
        const double m = (ui - m_cdf[k]) * m_integral / double(m_step);
        const double disc = std::max(a * a + 2.0 * (b - a) * m, 0.0);
        const double den = a + std::sqrt(disc);
        const double t = den > 0.0 ? std::clamp(2.0 * m / den, 0.0, 1.0) : 0.0;
        lambda[i] =
            std::clamp(float(double(m_min) + (double(k) + t) * double(m_step)), m_min, m_max);
        const float p = pdf(lambda[i]);
        weight[i] = p > 0.f ? 1.f / p : 0.f;
    }
    return {Wavelengths(lambda[0], lambda[1], lambda[2], lambda[3]),
            Color3f(weight[0], weight[1], weight[2], weight[3])};
}

std::shared_ptr<const SpectralBands> SpectralBands::fit(std::vector<Band> bands) {
    double lo = INFINITY, hi = -INFINITY, resolution = 1.0;
    for (const Band &b : bands) {
        if (!b.srf) FACET_THROW("spectral band \"{}\" has no response function", b.name);
        const std::optional<TabulatedRange> r = tabulated_range(*b.srf);
        if (!r) {
            lo = SpectralMinNm;
            hi = SpectralMaxNm;
            continue;
        }
        if (r->max <= SpectralMinNm || r->min >= SpectralMaxNm)
            FACET_THROW("the spectrum \"{}\" is given over [{}, {}] nm, outside the {}-{} nm "
                        "facet renders",
                        b.name, r->min, r->max, SpectralMinNm, SpectralMaxNm);
        if (r->min < SpectralMinNm || r->max > SpectralMaxNm)
            FACET_LOG(Warn,
                      "the spectrum \"{}\" is given over [{}, {}] nm: its parts outside {}-{} nm "
                      "are not rendered",
                      b.name, r->min, r->max, SpectralMinNm, SpectralMaxNm);
        lo = std::min(lo, r->min);
        hi = std::max(hi, r->max);
        resolution = std::min(resolution, r->resolution);
    }
    lo = std::max(lo, double(SpectralMinNm));
    hi = std::min(hi, double(SpectralMaxNm));
    if (!(lo < hi)) FACET_THROW("spectral bands need at least one response function");
    // Steps of at most `resolution` (2^20 points at most).
    const double span = hi - lo;
    const double steps = std::ceil(span / std::max(resolution, span / double(1 << 20)) - 1e-6);
    const size_t points = size_t(std::clamp(steps, 1.0, double(1 << 20) - 1.0)) + 1;
    return std::make_shared<SpectralBands>(std::move(bands), float(lo), float(hi), points);
}

Color3f SpectralBands::eval(size_t j, const Wavelengths &lambda) const {
    return eval_srf(*m_bands[j].srf, m_spectral[j], lambda);
}

float SpectralBands::pdf(float lambda) const {
    if (!(lambda >= m_min && lambda <= m_max)) return 0.f;
    const size_t segments = m_values.size() - 1;
    const float x = (lambda - m_min) / m_step;
    const size_t k = std::min(size_t(x), segments - 1);
    const float t = std::clamp(x - float(k), 0.f, 1.f);
    const float s = m_values[k] + (m_values[k + 1] - m_values[k]) * t;
    return float(double(s) / m_integral);
}

void SpectralBands::develop(const Color3f &L, const Wavelengths &lambda, const Color3f &weight,
                            float *out) const {
    const Color3f lw = L * weight;
    for (size_t j = 0; j < m_bands.size(); ++j) {
        const Color3f v = eval_srf(*m_bands[j].srf, m_spectral[j], lambda) * lw;
        out[j] = 0.25f * (v.r + v.g + v.b + v.w);
    }
}

} // namespace facet
