// The chi-square test itself: sampling, histogram, pdf integration, pooling, the statistic and
// its p-value, and the pictures and tables written when a test fails. Adapters are in
// chi2_adapters.cpp.

#include <facet/assert.h>
#include <facet/chi2.h>
#include <facet/image.h>
#include <facet/logger.h>
#include <facet/random.h>

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numeric>

namespace facet {

// -- Statistics -------------------------------------------------------------------------------

namespace {

/// ln Γ(a) + the prefactor x^a e^-x / Γ(a) of both expansions, in logarithms to avoid overflow.
double gamma_prefactor(double a, double x) {
    return std::exp(a * std::log(x) - x - std::lgamma(a));
}

/// P(a, x) by its power series, good for x < a + 1.
double gamma_p_series(double a, double x) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 100000; ++n) {
        term *= x / (a + n);
        sum += term;
        if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    return sum * gamma_prefactor(a, x);
}

/// Q(a, x) by its continued fraction (modified Lentz evaluation), good for x >= a + 1.
double gamma_q_continued_fraction(double a, double x) {
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 100000; ++i) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::abs(d) < tiny) d = tiny;
        c = b + an / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        double step = d * c;
        h *= step;
        if (std::abs(step - 1.0) < 1e-16) break;
    }
    return h * gamma_prefactor(a, x);
}

} // namespace

double regularized_gamma_p(double a, double x) {
    if (!(a > 0.0) || !(x >= 0.0)) return std::numeric_limits<double>::quiet_NaN();
    if (x == 0.0) return 0.0;
    if (std::isinf(x)) return 1.0;
    if (x < a + 1.0) return gamma_p_series(a, x);
    return 1.0 - gamma_q_continued_fraction(a, x);
}

double regularized_gamma_q(double a, double x) {
    if (!(a > 0.0) || !(x >= 0.0)) return std::numeric_limits<double>::quiet_NaN();
    if (x == 0.0) return 1.0;
    if (std::isinf(x)) return 0.0;
    if (x < a + 1.0) return 1.0 - gamma_p_series(a, x);
    return gamma_q_continued_fraction(a, x);
}

double chi2_survival(double x, double dof) {
    if (x <= 0.0) return 1.0;
    return regularized_gamma_q(0.5 * dof, 0.5 * x);
}

double sidak_correction(double alpha, uint32_t test_count) {
    if (test_count <= 1) return alpha;
    // 1 - (1 - α)^(1/n), written with log1p/expm1 so that tiny levels keep their digits.
    return -std::expm1(std::log1p(-alpha) / double(test_count));
}

PearsonResult pearson_chi2(const std::vector<double> &observed, const std::vector<double> &expected,
                           double min_expected) {
    if (observed.size() != expected.size())
        FACET_THROW("pearson_chi2: {} observed but {} expected cells", observed.size(),
                    expected.size());
    std::vector<size_t> order(expected.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return expected[a] < expected[b]; });

    PearsonResult res;
    int terms = 0;
    double pool_obs = 0.0, pool_exp = 0.0;
    for (size_t idx : order) {
        double o = observed[idx], e = expected[idx];
        if (e == 0.0) {
            if (o > 0.0 && !res.zero_expected_hit) {
                res.zero_expected_hit = true;
                res.zero_expected_cell = idx;
            }
            continue;
        }
        if (e < min_expected) {
            pool_obs += o;
            pool_exp += e;
            ++res.pooled_cells;
            if (pool_exp >= min_expected) {
                res.statistic += sqr(pool_obs - pool_exp) / pool_exp;
                ++terms;
                pool_obs = pool_exp = 0.0;
            }
            continue;
        }
        // A pool left below the threshold joins the smallest cell above it.
        o += pool_obs;
        e += pool_exp;
        pool_obs = pool_exp = 0.0;
        res.statistic += sqr(o - e) / e;
        ++terms;
    }
    if (pool_exp > 0.0) {
        res.statistic += sqr(pool_obs - pool_exp) / pool_exp;
        ++terms;
    }
    res.dof = terms - 1;
    return res;
}

// -- The test ---------------------------------------------------------------------------------

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Unit direction of the domain point (φ, cos θ).
Vector3f domain_to_direction(double phi, double cos_theta) {
    double s = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    return Vector3f(float(std::cos(phi) * s), float(std::sin(phi) * s), float(cos_theta));
}

/// Problems found while sampling, with the first few examples (by sample index).
struct Findings {
    struct Example {
        uint64_t index;
        std::string text;
    };
    std::vector<Example> examples;   ///< outright failures
    std::vector<Example> mismatches; ///< weight or pdf inconsistencies
    uint64_t bad_direction = 0, nonfinite_weight = 0, bad_pdf = 0, weight_mismatch = 0,
             pdf_mismatch = 0, adapter_problem = 0;
    double max_pdf_error = 0.0, max_weight_error = 0.0;
    double sum[Color3f::Channels] = {}, sum_sq[Color3f::Channels] = {};
    uint64_t smooth = 0, delta = 0, failed = 0;

    void note(uint64_t index, std::string text) {
        if (examples.size() < 4) examples.push_back({index, std::move(text)});
    }
    void note_mismatch(uint64_t index, std::string text) {
        if (mismatches.size() < 4) mismatches.push_back({index, std::move(text)});
    }
};

std::string color_str(const Color3f &c) {
    if (c.w != c.g) return fmt::format("[{:.6g}, {:.6g}, {:.6g}, {:.6g}]", c.r, c.g, c.b, c.w);
    return fmt::format("[{:.6g}, {:.6g}, {:.6g}]", c.r, c.g, c.b);
}
std::string vec_str(const Vector3f &v) {
    return fmt::format("[{:.6g}, {:.6g}, {:.6g}]", v.x, v.y, v.z);
}

/// Relative difference of two values, 0 when both are 0.
double rel_diff(double a, double b) {
    double m = std::max(std::abs(a), std::abs(b));
    return m == 0.0 ? 0.0 : std::abs(a - b) / m;
}

void check_sample(const Chi2Sample &s, uint64_t index, const Chi2Options &opts, Findings &f) {
    if (!s.problem.empty()) {
        ++f.adapter_problem;
        f.note_mismatch(index, s.problem);
    }
    if (s.has_weight && !s.weight.is_finite()) {
        ++f.nonfinite_weight;
        f.note(index, fmt::format("non-finite weight {} (direction {})", color_str(s.weight),
                                  vec_str(s.d)));
        return;
    }
    if (s.kind != Chi2Sample::Kind::Smooth) return;
    float len = norm(s.d);
    if (!is_finite(s.d) || std::abs(len - 1.f) > 1e-3f) {
        ++f.bad_direction;
        f.note(index, fmt::format("sampled direction {} is not a unit vector", vec_str(s.d)));
        return;
    }
    if (!std::isfinite(s.pdf) || s.pdf < 0.f) {
        ++f.bad_pdf;
        f.note(index, fmt::format("pdf() = {} at sampled direction {}", s.pdf, vec_str(s.d)));
        return;
    }
    if (!std::isnan(s.sampled_pdf)) {
        double err = std::isfinite(s.sampled_pdf) ? rel_diff(s.sampled_pdf, s.pdf) : 1.0;
        f.max_pdf_error = std::max(f.max_pdf_error, err);
        if (err > opts.weight_tolerance) {
            ++f.pdf_mismatch;
            f.note_mismatch(index, fmt::format("sampled pdf {:.7g} but pdf() = {:.7g} at {}",
                                               s.sampled_pdf, s.pdf, vec_str(s.d)));
            return;
        }
    }
    if (s.has_value) {
        double err = (s.pdf == 0.f || !s.value.is_finite()) ? 1.0 : 0.0;
        for (int c = 0; c < Color3f::Channels; ++c)
            err = std::max(err, rel_diff(s.weight[c], double(s.value[c]) / s.pdf));
        f.max_weight_error = std::max(f.max_weight_error, err);
        if (err > opts.weight_tolerance) {
            ++f.weight_mismatch;
            f.note_mismatch(index, fmt::format("weight {} but eval/pdf = {} / {:.7g} at {}",
                                               color_str(s.weight), color_str(s.value), s.pdf,
                                               vec_str(s.d)));
        }
    }
}

/// Composite Simpson rule with n (odd) points on [a, b]; points are kept 1e-6 of the interval
/// inside it, so that a pdf is never evaluated exactly on a cell edge (often a discontinuity).
template <typename F> double simpson(F &&f, double a, double b, int n) {
    double h = (b - a) / (n - 1), inset = 1e-6 * (b - a), sum = 0.0;
    for (int k = 0; k < n; ++k) {
        double x = std::clamp(a + k * h, a + inset, b - inset);
        double w = (k == 0 || k == n - 1) ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0);
        sum += w * f(x);
    }
    return sum * h / 3.0;
}

/// Adaptive Simpson on [a, b] given the values at a, the midpoint and b. Subdivides at least
/// `min_depth` times and at most `depth` times.
template <typename F> double adaptive_simpson(F &f, double a, double b, double fa, double fm,
                                              double fb, double whole, double tol, int depth,
                                              int min_depth) {
    double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
    double flm = f(lm), frm = f(rm);
    double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    double delta = left + right - whole;
    if (depth <= 0 || (min_depth <= 0 && std::abs(delta) <= 15.0 * tol))
        return left + right + delta / 15.0;
    return adaptive_simpson(f, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1, min_depth - 1) +
           adaptive_simpson(f, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1, min_depth - 1);
}

template <typename F> double adaptive_integral(F &f, double a, double b, double tol, int depth) {
    double inset = 1e-6 * (b - a);
    auto g = [&](double x) { return f(std::clamp(x, a + inset, b - inset)); };
    double fa = g(a), fm = g(0.5 * (a + b)), fb = g(b);
    double whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    return adaptive_simpson(g, a, b, fa, fm, fb, whole, tol, depth, 2);
}

/// Integral of the pdf over one cell, and whether a bad (non-finite or negative) value was seen.
struct CellIntegral {
    double value = 0.0;
    bool bad = false;
    Vector3f bad_dir;
    double bad_value = 0.0;
};

CellIntegral integrate_cell(const Chi2Adapter &adapter, const Chi2Options &opts, double phi0,
                            double phi1, double c0, double c1, double abs_tol) {
    CellIntegral cell;
    auto f = [&](double phi, double c) {
        Vector3f d = domain_to_direction(phi, c);
        double v = adapter.pdf(d);
        if (!std::isfinite(v) || v < 0.0) {
            if (!cell.bad) {
                cell.bad = true;
                cell.bad_dir = d;
                cell.bad_value = v;
            }
            return 0.0;
        }
        return v;
    };
    int n = std::max(3, opts.ires | 1);
    auto row_fixed = [&](double c) {
        return simpson([&](double phi) { return f(phi, c); }, phi0, phi1, n);
    };
    double fixed = simpson(row_fixed, c0, c1, n);
    if (!opts.adaptive) {
        cell.value = fixed;
        return cell;
    }
    double tol = std::max(opts.tolerance * std::abs(fixed), abs_tol);
    double inner_tol = tol / (c1 - c0);
    auto row = [&](double c) {
        auto g = [&](double phi) { return f(phi, c); };
        return adaptive_integral(g, phi0, phi1, inner_tol, opts.max_depth);
    };
    cell.value = adaptive_integral(row, c0, c1, tol, opts.max_depth);
    return cell;
}

} // namespace

namespace {

// run_chi2() in four steps: histogram (sampling and per-sample checks), integrate (expected
// counts), pool (Pearson's statistic on pooled cells), verdict (p-value and global checks).

/// Step 1: draws the samples, bins the smooth ones into res.observed and checks each one.
/// Samples go in fixed chunks, so every sum is taken in the same order on any thread count.
Findings histogram(const Chi2Adapter &adapter, const Chi2Options &opts, Chi2Result &res) {
    const int dim = adapter.sample_dim(), phi_res = res.phi_res, cos_res = res.cos_res;
    const size_t cells = size_t(cos_res) * phi_res;
    const uint64_t n = opts.samples;
    const uint64_t chunk = 1 << 14;
    const size_t chunks = size_t((n + chunk - 1) / chunk);
    std::vector<Findings> findings(chunks);
    tbb::enumerable_thread_specific<std::vector<uint32_t>> histograms(
        [&] { return std::vector<uint32_t>(cells, 0u); });
    tbb::parallel_for(size_t(0), chunks, [&](size_t ci) {
        Findings &f = findings[ci];
        std::vector<uint32_t> &hist = histograms.local();
        float u[8];
        uint64_t end = std::min(n, (ci + 1) * chunk);
        for (uint64_t i = ci * chunk; i < end; ++i) {
            uint64_t h = tea_hash(uint32_t(i), opts.seed);
            PCG32 rng(h, i);
            for (int k = 0; k < dim; ++k) u[k] = rng.next_float();
            Chi2Sample s = adapter.sample(u);
            check_sample(s, i, opts, f);
            if (s.has_weight && s.weight.is_finite()) {
                for (int c = 0; c < Color3f::Channels; ++c) {
                    double w = double(s.weight[c]) * s.energy_scale;
                    f.sum[c] += w;
                    f.sum_sq[c] += w * w;
                }
            }
            if (s.kind == Chi2Sample::Kind::Failed) {
                ++f.failed;
                continue;
            }
            if (s.kind == Chi2Sample::Kind::Delta) {
                ++f.delta;
                continue;
            }
            ++f.smooth;
            if (!is_finite(s.d)) continue;
            double phi = std::atan2(double(s.d.y), double(s.d.x));
            double c = std::clamp(double(s.d.z), -1.0, 1.0);
            int ip = std::clamp(int((phi + kPi) / (2.0 * kPi) * phi_res), 0, phi_res - 1);
            int jc = std::clamp(int((c + 1.0) * 0.5 * cos_res), 0, cos_res - 1);
            FACET_ASSERT(size_t(jc) * phi_res + ip < cells);
            ++hist[size_t(jc) * phi_res + ip];
        }
    });
    res.observed.assign(cells, 0.0);
    for (const auto &hist : histograms)
        for (size_t k = 0; k < cells; ++k) res.observed[k] += hist[k];

    // The chunks' findings in chunk order; examples sorted by sample index.
    Findings total;
    for (const Findings &f : findings) {
        total.bad_direction += f.bad_direction;
        total.nonfinite_weight += f.nonfinite_weight;
        total.bad_pdf += f.bad_pdf;
        total.weight_mismatch += f.weight_mismatch;
        total.pdf_mismatch += f.pdf_mismatch;
        total.adapter_problem += f.adapter_problem;
        total.smooth += f.smooth;
        total.delta += f.delta;
        total.failed += f.failed;
        for (int c = 0; c < Color3f::Channels; ++c) {
            total.sum[c] += f.sum[c];
            total.sum_sq[c] += f.sum_sq[c];
        }
        total.max_pdf_error = std::max(total.max_pdf_error, f.max_pdf_error);
        total.max_weight_error = std::max(total.max_weight_error, f.max_weight_error);
        total.examples.insert(total.examples.end(), f.examples.begin(), f.examples.end());
        total.mismatches.insert(total.mismatches.end(), f.mismatches.begin(), f.mismatches.end());
    }
    auto by_index = [](const auto &a, const auto &b) { return a.index < b.index; };
    std::sort(total.examples.begin(), total.examples.end(), by_index);
    std::sort(total.mismatches.begin(), total.mismatches.end(), by_index);
    return total;
}

/// Step 1, reported: counts, weight statistics, outright failures and inconsistent samples.
void report_samples(const Findings &total, const Chi2Options &opts, Chi2Result &res) {
    const uint64_t n = opts.samples;
    res.smooth = total.smooth;
    res.delta = total.delta;
    res.failed = total.failed;
    res.weight_mismatches = total.weight_mismatch;
    res.pdf_mismatches = total.pdf_mismatch;
    for (int c = 0; c < Color3f::Channels; ++c) {
        double mean = total.sum[c] / double(n);
        double var = std::max(0.0, total.sum_sq[c] / double(n) - mean * mean);
        res.mean_weight[c] = float(mean);
        res.weight_stddev[c] = float(std::sqrt(var));
    }
    auto count_failure = [&](uint64_t count, const char *what) {
        if (count > 0) res.failures.push_back(fmt::format("{} of {} samples: {}", count, n, what));
    };
    count_failure(total.nonfinite_weight, "non-finite weight");
    count_failure(total.bad_direction, "sampled direction is not a unit vector");
    count_failure(total.bad_pdf, "non-finite or negative pdf() at the sampled direction");
    for (size_t k = 0; k < total.examples.size() && k < 4; ++k)
        res.failures.push_back(
            fmt::format("  sample {}: {}", total.examples[k].index, total.examples[k].text));

    // Inconsistent weights or pdfs: a few samples may miss by rounding near singular
    // configurations (grazing refraction next to total internal reflection, the poles of an
    // environment map); a systematic error misses on many samples or by much more.
    res.max_pdf_error = total.max_pdf_error;
    res.max_weight_error = total.max_weight_error;
    uint64_t mismatched = total.pdf_mismatch + total.weight_mismatch + total.adapter_problem;
    double worst = std::max(total.max_pdf_error, total.max_weight_error);
    bool mismatch_failure =
        mismatched > uint64_t(opts.mismatch_fraction * double(n)) || worst > opts.gross_tolerance;
    std::vector<std::string> &mismatch_out = mismatch_failure ? res.failures : res.notes;
    if (mismatched > 0) {
        mismatch_out.push_back(fmt::format(
            "{} of {} samples have an inconsistent pdf or weight ({} pdf vs pdf(), {} weight vs "
            "eval/pdf, {} eval_pdf vs eval and pdf; tolerance {}), the worst by {:.3g} (allowed: "
            "{} samples, none beyond {})",
            mismatched, n, total.pdf_mismatch, total.weight_mismatch, total.adapter_problem,
            opts.weight_tolerance, worst, uint64_t(opts.mismatch_fraction * double(n)),
            opts.gross_tolerance));
        for (size_t k = 0; k < total.mismatches.size() && k < (mismatch_failure ? 4u : 2u); ++k)
            mismatch_out.push_back(fmt::format("  sample {}: {}", total.mismatches[k].index,
                                               total.mismatches[k].text));
    }
}

/// Step 2: expected counts, the pdf integrated over every cell (res.expected, res.pdf_integral).
void integrate(const Chi2Adapter &adapter, const Chi2Options &opts, Chi2Result &res) {
    const int phi_res = res.phi_res, cos_res = res.cos_res;
    const size_t cells = size_t(cos_res) * phi_res;
    const double n = double(opts.samples);
    res.expected.assign(cells, 0.0);
    std::vector<CellIntegral> integrals(cells);
    const double dphi = 2.0 * kPi / phi_res, dcos = 2.0 / cos_res;
    // Adaptive rule: no cell needs to be known better than a thousandth of a sample.
    const double abs_tol = 1e-3 / n;
    tbb::parallel_for(size_t(0), cells, [&](size_t k) {
        int jc = int(k / phi_res), ip = int(k % phi_res);
        double phi0 = -kPi + ip * dphi, c0 = -1.0 + jc * dcos;
        integrals[k] = integrate_cell(adapter, opts, phi0, phi0 + dphi, c0, c0 + dcos, abs_tol);
    });
    size_t bad_cells = 0;
    for (size_t k = 0; k < cells; ++k) {
        if (integrals[k].bad) {
            if (bad_cells == 0)
                res.failures.push_back(fmt::format("pdf() = {} at direction {} (while integrating)",
                                                   integrals[k].bad_value,
                                                   vec_str(integrals[k].bad_dir)));
            ++bad_cells;
        }
        res.pdf_integral += integrals[k].value;
        res.expected[k] = integrals[k].value * n;
    }
    if (bad_cells > 0)
        res.failures.push_back(
            fmt::format("{} cells have non-finite or negative pdf values", bad_cells));
}

/// Step 3: Pearson's statistic over the cells, those expecting too little pooled (res.statistic,
/// res.dof); a sample in a cell expecting none is an outright failure.
void pool(const Chi2Options &opts, Chi2Result &res) {
    PearsonResult pr = pearson_chi2(res.observed, res.expected, opts.min_expected);
    res.statistic = pr.statistic;
    res.dof = pr.dof;
    if (pr.pooled_cells > 0)
        res.notes.push_back(fmt::format("{} cells expecting fewer than {} samples were pooled",
                                        pr.pooled_cells, opts.min_expected));
    if (pr.zero_expected_hit) {
        size_t k = pr.zero_expected_cell;
        int jc = int(k / res.phi_res), ip = int(k % res.phi_res);
        double phi = -kPi + (ip + 0.5) * 2.0 * kPi / res.phi_res,
               c = -1.0 + (jc + 0.5) * 2.0 / res.cos_res;
        res.failures.push_back(fmt::format("{} samples fell into cell (phi {}, cos theta {}) "
                                           "around direction {} where the pdf integrates to zero",
                                           res.observed[k], ip, jc,
                                           vec_str(domain_to_direction(phi, c))));
    }
}

/// Step 4: the pdf's integral against the smooth fraction, energy, the p-value, and the verdict.
void verdict(const Chi2Adapter &adapter, const Chi2Options &opts, bool tested, Chi2Result &res) {
    const double n = double(opts.samples);
    // The pdf integrates to the fraction of samples that got a smooth direction, at most 1.
    double fraction = double(res.smooth) / n;
    double integral_tol =
        5.0 * std::sqrt(std::max(fraction * (1.0 - fraction), 1.0 / n) / n) + 2e-3;
    if (res.pdf_integral > 1.0 + 2e-3)
        res.failures.push_back(fmt::format("the pdf integrates to {:.6f} > 1", res.pdf_integral));
    else if (std::abs(res.pdf_integral - fraction) > integral_tol)
        res.failures.push_back(
            fmt::format("the pdf integrates to {:.6f} but a fraction {:.6f} of "
                        "the samples produced a smooth direction (tolerance {:.2g})",
                        res.pdf_integral, fraction, integral_tol));

    // Energy: the mean weight of a passive BSDF does not exceed 1 (5 standard errors of noise).
    if (adapter.bounded_weights()) {
        for (int c = 0; c < Color3f::Channels; ++c) {
            double bound = 1.0 + 5.0 * res.weight_stddev[c] / std::sqrt(n) + 1e-4;
            if (res.mean_weight[c] > bound) {
                res.failures.push_back(
                    fmt::format("mean weight {} exceeds 1 (energy gain; bound {:.6f})",
                                color_str(res.mean_weight), bound));
                break;
            }
        }
    }

    res.significance = sidak_correction(opts.significance, std::max(1u, opts.test_count));
    if (!tested) {
        res.p_value = 1.0;
    } else if (res.dof < 1) {
        res.failures.push_back(fmt::format("too few cells with enough expected samples "
                                           "(dof = {}); use more samples or fewer cells",
                                           res.dof));
        res.p_value = 0.0;
    } else {
        res.p_value = chi2_survival(res.statistic, res.dof);
        if (!std::isfinite(res.p_value))
            res.failures.push_back("the p-value is not finite");
        else if (res.p_value < res.significance)
            res.failures.push_back(
                fmt::format("the histogram does not match the pdf: p-value {:.4g} < {:.4g}",
                            res.p_value, res.significance));
    }
    res.passed = res.failures.empty();
}

} // namespace

Chi2Result run_chi2(const Chi2Adapter &adapter, const Chi2Options &opts_in) {
    Chi2Options opts = opts_in;
    Chi2Result res;
    res.description = adapter.to_string();
    res.phi_center = adapter.plot_phi_center();
    if (opts.res < 2) FACET_THROW("chi2: res must be at least 2 (got {})", opts.res);
    if (opts.samples == 0 || opts.samples > uint64_t(0xffffffffu))
        FACET_THROW("chi2: the sample count must be in [1, 2^32) (got {})", opts.samples);
    if (opts.res % 2 == 1) {
        // An even count puts a cell edge on the horizon, where many pdfs jump.
        res.notes.push_back(fmt::format("res {} rounded up to {} (even)", opts.res, opts.res + 1));
        ++opts.res;
    }
    int dim = adapter.sample_dim();
    if (dim < 1 || dim > 8) FACET_THROW("chi2: sample_dim must be in [1, 8] (got {})", dim);
    res.cos_res = opts.res;
    res.phi_res = 2 * opts.res;
    res.samples = opts.samples;

    report_samples(histogram(adapter, opts, res), opts, res);
    integrate(adapter, opts, res);
    // Only delta lobes: no histogram to test.
    bool tested = !(res.smooth == 0 && res.pdf_integral == 0.0);
    if (tested)
        pool(opts, res);
    else
        res.notes.push_back(
            "no smooth samples and a zero pdf: only delta lobes, no histogram to test");
    verdict(adapter, opts, tested, res);
    return res;
}

std::string Chi2Result::summary() const {
    std::string s = fmt::format("chi2: {}\n", description);
    s += fmt::format("  samples  {} ({} smooth, {} delta, {} failed)\n", samples, smooth, delta,
                     failed);
    s += fmt::format(
        "  cells    {} (phi) x {} (cos theta), pdf integral {:.6f}, smooth fraction {:.6f}\n",
        phi_res, cos_res, pdf_integral, samples ? double(smooth) / samples : 0.0);
    s += fmt::format("  weight   mean {} stddev {}; largest relative error of weight {:.2g}, "
                     "of pdf {:.2g}\n",
                     color_str(mean_weight), color_str(weight_stddev), max_weight_error,
                     max_pdf_error);
    s += fmt::format("  statistic {:.2f}, dof {}, p-value {:.6g} (level {:.4g})\n", statistic, dof,
                     p_value, significance);
    for (const std::string &n : notes) s += "  note: " + n + "\n";
    for (const std::string &f : failures) s += "  failure: " + f + "\n";
    s += passed ? "  verdict: accepted\n" : "  verdict: REJECTED\n";
    return s;
}

// -- Tables (the pictures are in chi2_plot.cpp) ----------------------------------------------

void write_chi2_tables(const std::string &path, const Chi2Result &r) {
    std::ofstream out(path);
    if (!out) FACET_THROW("cannot write \"{}\"", path);
    out << "# " << r.description << "\n";
    out << fmt::format(
        "# {} phi cells x {} cos theta cells; statistic {:.4f}, dof {}, p-value {:.6g}\n",
        r.phi_res, r.cos_res, r.statistic, r.dof, r.p_value);
    out << "# phi_bin cos_bin phi_min phi_max cos_min cos_max observed expected\n";
    double dphi = 2.0 * kPi / r.phi_res, dcos = 2.0 / r.cos_res;
    for (int jc = 0; jc < r.cos_res; ++jc)
        for (int ip = 0; ip < r.phi_res; ++ip) {
            size_t k = size_t(jc) * r.phi_res + ip;
            out << fmt::format("{} {} {:.6f} {:.6f} {:.6f} {:.6f} {} {:.6f}\n", ip, jc,
                               -kPi + ip * dphi, -kPi + (ip + 1) * dphi, -1.0 + jc * dcos,
                               -1.0 + (jc + 1) * dcos, r.observed[k], r.expected[k]);
        }
    if (!out) FACET_THROW("error while writing \"{}\"", path);
}

} // namespace facet
