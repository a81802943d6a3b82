// rgb2spec_opt: computes the coefficient table of facet's RGB -> spectrum upsampling, the
// sigmoid-polynomial model of Jakob and Hanika 2019 ("A Low-Dimensional Function Space for
// Efficient Spectral Upsampling"), read by core/src/spectral_upsampling.cpp.
//
//     rgb2spec_opt <resolution> <output file> [threads]
//
// A reflectance s(λ) = S(c0 λ² + c1 λ + c2), S(x) = 1/2 + x / (2 sqrt(1 + x²)), is fitted to each
// linear Rec.709 colour of a grid so that facet's rgb mode, spectrum_to_rgb(s, Reflectance) (CIE
// 1931 under D65 over its 1000-step quadrature), gives the colour back, relative to the white of
// that quadrature: the target of `rgb` is rgb ⊙ W, W = spectrum_to_rgb(1) = (0.99899, 0.99887,
// 0.99880). So 0 is s = 0, a grey g is the constant g and 1 is the constant 1, as in a spectral
// render, where a white reflectance reflects everything (without the scale, no reflectance
// bounded by 1 could reach the colours within 1.2e-3 of white).
//
// The fit is Gauss-Newton on the difference in CIELAB (the paper's residual, perceptually
// uniform, so dark colours are fitted as closely as bright ones relative to what can be seen),
// each cell starting from the solution of its neighbour along a path through the table (below).
//
// Table layout (the paper's): three tables, one per channel that is largest (l = 0, 1, 2 for
// r, g, b). In table l, cell (k, j, i) holds the colour with rgb[l] = z = scale[k],
// rgb[(l + 1) % 3] = x z, rgb[(l + 2) % 3] = y z, x = ratio[i], y = ratio[j], where
// scale[k] = smoothstep(smoothstep(k / (N - 1))) is dense near black and near the brightest
// colours, where the coefficients change fastest. Unlike the paper, the two ratios are not
// evenly spaced either: ratio[i] = smoothstep(i / (N - 1)). Near white and for saturated
// colours (ratios near 1 or 0) the coefficients change so fast between evenly spaced cells that
// interpolating them misses the colour by up to 8.6e-3 for N = 64 (205 of 10^5 uniform colours
// by more than 1e-3; a finer table hardly helps: 2.0e-3 for N = 128). With cells 1 / (N - 1)^2
// apart at both ends, and 1.5 times wider in the middle, where the coefficients change slowly,
// 4 of 10^6 uniform colours are off by more than 1e-3, the worst by 1.4e-3, all with the largest
// channel above 0.99, for the same table size (near white, see the disabled test
// SpectralUpsampling.DISABLED_RoundTripNearWhite).
//
// Wavelengths are normalised for the fit, λ' = (λ - 360) / 470 in [0, 1]: with λ in nm, the
// three columns of the Jacobian (λ², λ, 1) differ by ~10^5 and the linear solves lose digits.
// The table holds the coefficients for λ in nm (the polynomial in λ' expanded in double
// precision, then rounded to float32), so that evaluating a spectrum needs no conversion.
//
// File format, little-endian: the 8 bytes "FCTR2S\0\0", uint32 version (2), uint32 N, N float32
// scale values, N float32 ratio values, then 3 N^3 cells of 3 float32 coefficients (c0, c1, c2),
// cell (l, k, j, i) at index ((l N + k) N + j) N + i. The fit's colours are those of the float32
// axis values, the ones the lookup interpolates between.
#include <facet/color.h>
#include <facet/spectrum.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

namespace {

using Vec3 = std::array<double, 3>;
using Mat3 = std::array<Vec3, 3>;

template <typename T> T sqr(T x) { return x * x; }

// The quadrature of facet::spectrum_to_rgb (core/src/spectrum.cpp): 1000 equally spaced
// wavelengths over 360-830 nm, each weighted by the CIE curves, D65 (scaled as facet's cie_d65)
// and the step over the integral of y-bar. check_quadrature() compares it with the library.
constexpr int Steps = 1000;
constexpr double LambdaMin = 360.0, LambdaMax = 830.0;
constexpr double CieYIntegral = 106.7502593994140625;

struct Quadrature {
    std::array<double, Steps> lambda{};    ///< normalised wavelength of each node
    std::array<double, Steps> weight[3]{}; ///< its weight in each RGB channel
    Mat3 to_xyz{};                         ///< inverse of facet::xyz_to_srgb
    Vec3 white_xyz{};                      ///< CIELAB's reference white: to_xyz (1, 1, 1), D65
    Vec3 white_rgb{}; ///< the rgb of a constant reflectance 1 over this quadrature
};

double node_wavelength(int i) {
    return LambdaMin + (LambdaMax - LambdaMin) * double(i) / double(Steps - 1);
}

Vec3 mul(const Mat3 &m, const Vec3 &v) {
    Vec3 r{};
    for (int i = 0; i < 3; ++i) r[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
    return r;
}

/// Solves m x = b by Gaussian elimination with partial pivoting; false when m is singular.
bool solve3(Mat3 m, Vec3 b, Vec3 &x) {
    for (int c = 0; c < 3; ++c) {
        int p = c;
        for (int r = c + 1; r < 3; ++r)
            if (std::abs(m[r][c]) > std::abs(m[p][c])) p = r;
        if (!(std::abs(m[p][c]) > 1e-300)) return false;
        std::swap(m[p], m[c]);
        std::swap(b[p], b[c]);
        for (int r = c + 1; r < 3; ++r) {
            double f = m[r][c] / m[c][c];
            for (int k = c; k < 3; ++k) m[r][k] -= f * m[c][k];
            b[r] -= f * b[c];
        }
    }
    for (int r = 2; r >= 0; --r) {
        double s = b[r];
        for (int k = r + 1; k < 3; ++k) s -= m[r][k] * x[k];
        x[r] = s / m[r][r];
    }
    return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
}

Quadrature make_quadrature() {
    Quadrature q;
    Mat3 to_rgb{};
    for (int j = 0; j < 3; ++j) {
        facet::Color3f e(0.f);
        e[j] = 1.f;
        facet::Color3f c = facet::xyz_to_srgb(e);
        for (int i = 0; i < 3; ++i) to_rgb[i][j] = c[i];
    }
    for (int j = 0; j < 3; ++j) {
        Vec3 e{}, col{};
        e[j] = 1.0;
        solve3(to_rgb, e, col);
        for (int i = 0; i < 3; ++i) q.to_xyz[i][j] = col[i];
    }
    q.white_xyz = mul(q.to_xyz, Vec3{1.0, 1.0, 1.0});
    const double step = (LambdaMax - LambdaMin) / (CieYIntegral * Steps);
    for (int i = 0; i < Steps; ++i) {
        double l = node_wavelength(i);
        facet::Color3f cmf = facet::cie1931_xyz(l);
        double w = facet::cie_d65(l) * step;
        Vec3 rgb = mul(to_rgb, Vec3{cmf.r * w, cmf.g * w, cmf.b * w});
        q.lambda[size_t(i)] = (l - LambdaMin) / (LambdaMax - LambdaMin);
        for (int c = 0; c < 3; ++c) {
            q.weight[c][size_t(i)] = rgb[c];
            q.white_rgb[c] += rgb[c];
        }
    }
    return q;
}

/// The quadrature above must be the library's: compares both on a few smooth spectra.
bool check_quadrature(const Quadrature &q) {
    auto spectra = {
        +[](double) { return 1.0; },
        +[](double l) { return 0.2 + 0.7 * (l - LambdaMin) / (LambdaMax - LambdaMin); },
        +[](double l) { return 0.3 + 0.5 * std::exp(-sqr((l - 550.0) / 60.0)); },
    };
    for (auto f : spectra) {
        facet::SpectrumData s;
        s.uniform = false;
        Vec3 mine{};
        for (int i = 0; i < Steps; ++i) {
            double l = node_wavelength(i), v = f(l);
            s.wavelengths.push_back(l);
            s.values.push_back(v);
            for (int c = 0; c < 3; ++c) mine[c] += v * q.weight[c][size_t(i)];
        }
        facet::Color3f lib = facet::spectrum_to_rgb(s, facet::SpectrumKind::Reflectance);
        for (int c = 0; c < 3; ++c)
            if (!(std::abs(lib[c] - mine[c]) < 1e-5)) {
                std::fprintf(stderr,
                             "rgb2spec_opt: the quadrature differs from spectrum_to_rgb's "
                             "(channel %d: %.8f here, %.8f in libfacet)\n",
                             c, mine[c], double(lib[c]));
                return false;
            }
    }
    return true;
}

double lab_f(double t) {
    constexpr double d = 6.0 / 29.0;
    return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0 / 29.0;
}

double lab_df(double t) {
    constexpr double d = 6.0 / 29.0;
    if (t > d * d * d) {
        double c = std::cbrt(t);
        return 1.0 / (3 * c * c);
    }
    return 1.0 / (3 * d * d);
}

/// CIELAB of a linear Rec.709 colour and, if `jac`, its Jacobian with respect to the colour.
Vec3 rgb_to_lab(const Quadrature &q, const Vec3 &rgb, Mat3 *jac) {
    Vec3 xyz = mul(q.to_xyz, rgb);
    Vec3 t{xyz[0] / q.white_xyz[0], xyz[1] / q.white_xyz[1], xyz[2] / q.white_xyz[2]};
    Vec3 f{lab_f(t[0]), lab_f(t[1]), lab_f(t[2])};
    if (jac) {
        // d Lab / d f, times d f / d xyz (diagonal), times d xyz / d rgb.
        const Mat3 dlab{{{0.0, 116.0, 0.0}, {500.0, -500.0, 0.0}, {0.0, 200.0, -200.0}}};
        Vec3 df{};
        for (int i = 0; i < 3; ++i) df[i] = lab_df(t[i]) / q.white_xyz[i];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) {
                double s = 0;
                for (int k = 0; k < 3; ++k) s += dlab[r][k] * df[k] * q.to_xyz[k][c];
                (*jac)[r][c] = s;
            }
    }
    return {116.0 * f[1] - 16.0, 500.0 * (f[0] - f[1]), 200.0 * (f[1] - f[2])};
}

/// The rgb of the spectrum with normalised coefficients `c` and its Jacobian d rgb / d c.
Vec3 eval_rgb(const Quadrature &q, const Vec3 &c, Mat3 &jac) {
    // Two passes: S and S' per node (independent, so the compiler vectorises the square roots
    // and divisions), then the sums in node order.
    double s[Steps], ds[Steps];
    for (int i = 0; i < Steps; ++i) {
        double l = q.lambda[i];
        double x = (c[0] * l + c[1]) * l + c[2];
        double inv = 1.0 / std::sqrt(1.0 + x * x);
        s[i] = 0.5 + 0.5 * x * inv;
        ds[i] = 0.5 * inv * inv * inv; // S'(x) = 1 / (2 (1 + x²)^(3/2))
    }
    Vec3 rgb{};
    double j[3][3] = {};
    for (int i = 0; i < Steps; ++i) {
        double l = q.lambda[i];
        double d[3] = {ds[i] * l * l, ds[i] * l, ds[i]};
        for (int a = 0; a < 3; ++a) {
            double w = q.weight[a][i];
            rgb[a] += s[i] * w;
            for (int k = 0; k < 3; ++k) j[a][k] += d[k] * w;
        }
    }
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 3; ++k) jac[a][k] = j[a][k];
    return rgb;
}

struct FitResult {
    double rgb_error; ///< largest difference per channel from the target, after the fit
    int iterations;
};

/// Gauss-Newton on the CIELAB residual, from `c` (updated in place), halving a step that does
/// not reduce the residual.
FitResult fit(const Quadrature &q, const Vec3 &target_rgb, Vec3 &c) {
    constexpr int MaxIterations = 100;
    const Vec3 target = rgb_to_lab(q, target_rgb, nullptr);
    auto residual = [&](const Vec3 &coef, Vec3 &rgb, Vec3 &res, Mat3 &jac_lab) {
        Mat3 jac_rgb, jac_l;
        rgb = eval_rgb(q, coef, jac_rgb);
        Vec3 lab = rgb_to_lab(q, rgb, &jac_l);
        for (int i = 0; i < 3; ++i) res[i] = lab[i] - target[i];
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k)
                jac_lab[r][k] = jac_l[r][0] * jac_rgb[0][k] + jac_l[r][1] * jac_rgb[1][k] +
                                jac_l[r][2] * jac_rgb[2][k];
        return sqr(res[0]) + sqr(res[1]) + sqr(res[2]);
    };
    Vec3 rgb, res;
    Mat3 jac;
    double err = residual(c, rgb, res, jac);
    int it = 0;
    for (; it < MaxIterations && err > 1e-10; ++it) {
        Vec3 step;
        if (!solve3(jac, res, step)) break;
        bool better = false;
        for (double t = 1.0; t > 1e-6; t *= 0.5) {
            Vec3 c2{c[0] - t * step[0], c[1] - t * step[1], c[2] - t * step[2]};
            Vec3 rgb2, res2;
            Mat3 jac2;
            double err2 = residual(c2, rgb2, res2, jac2);
            if (err2 < err) {
                c = c2, rgb = rgb2, res = res2, jac = jac2, err = err2;
                better = true;
                break;
            }
        }
        if (!better) break;
    }
    double e = 0;
    for (int i = 0; i < 3; ++i) e = std::max(e, std::abs(rgb[i] - target_rgb[i]));
    return {e, it};
}

double smoothstep(double t) { return t * t * (3.0 - 2.0 * t); }

/// The coefficients for λ in nm of s(λ') with λ' = (λ - LambdaMin) / width.
std::array<float, 3> to_nm(const Vec3 &c) {
    const double a = LambdaMin, w = LambdaMax - LambdaMin;
    double c0 = c[0] / (w * w);
    double c1 = c[1] / w - 2.0 * a * c[0] / (w * w);
    double c2 = c[0] * a * a / (w * w) - c[1] * a / w + c[2];
    return {float(c0), float(c1), float(c2)};
}

struct Generator {
    const Quadrature &q;
    int n;
    std::vector<double> scale, ratio;
    std::vector<float> coeffs; // 3 n^3 cells of 3
    std::vector<Vec3> spine;   // per (table, j): the solution at (k0, j, i = 0)
    int k0;

    Vec3 target(int l, int k, int j, int i) const {
        Vec3 rgb{};
        double z = scale[k];
        rgb[l] = z;
        rgb[(l + 1) % 3] = z * ratio[size_t(i)];
        rgb[(l + 2) % 3] = z * ratio[size_t(j)];
        for (int c = 0; c < 3; ++c) rgb[c] *= q.white_rgb[c];
        return rgb;
    }
    void store(int l, int k, int j, int i, const Vec3 &c) {
        std::array<float, 3> f = to_nm(c);
        size_t idx = ((size_t(l) * n + k) * n + j) * n + i;
        std::copy(f.begin(), f.end(), coeffs.begin() + 3 * idx);
    }

    struct Stats {
        double worst = 0;
        int worst_cell[4] = {};
        long iterations = 0, cells = 0, over_1e4 = 0;
        void add(const FitResult &r, int l, int k, int j, int i) {
            iterations += r.iterations;
            ++cells;
            if (r.rgb_error > 1e-4) ++over_1e4;
            if (r.rgb_error > worst) {
                worst = r.rgb_error;
                int c[4] = {l, k, j, i};
                std::copy(c, c + 4, worst_cell);
            }
        }
        void merge(const Stats &o) {
            iterations += o.iterations;
            cells += o.cells;
            over_1e4 += o.over_1e4;
            if (o.worst > worst) {
                worst = o.worst;
                std::copy(o.worst_cell, o.worst_cell + 4, worst_cell);
            }
        }
    };

    /// One row (table l, y = j): along x from the spine at k0, and from each (k0, j, i) up and
    /// down the scale axis, each cell starting from the one before it.
    void row(int l, int j, Stats &st) {
        Vec3 at_k0 = spine[size_t(l) * n + j];
        for (int i = 0; i < n; ++i) {
            if (i > 0) {
                st.add(fit(q, target(l, k0, j, i), at_k0), l, k0, j, i);
            }
            store(l, k0, j, i, at_k0);
            Vec3 c = at_k0;
            for (int k = k0 + 1; k < n; ++k) {
                st.add(fit(q, target(l, k, j, i), c), l, k, j, i);
                store(l, k, j, i, c);
            }
            c = at_k0;
            // k = 0 is black, which no finite coefficients reach: it keeps the cell of k = 1
            // (scale[1] = 1.7e-6 for N = 64).
            for (int k = k0 - 1; k >= 1; --k) {
                st.add(fit(q, target(l, k, j, i), c), l, k, j, i);
                store(l, k, j, i, c);
            }
            store(l, 0, j, i, c);
        }
    }
};

void put_bytes(std::vector<unsigned char> &out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back((unsigned char)(v >> (8 * i)));
}

void put_float(std::vector<unsigned char> &out, float f) {
    uint32_t v;
    std::memcpy(&v, &f, 4);
    put_bytes(out, v);
}

} // namespace

int main(int argc, char **argv) {
    if (argc < 3 || argc > 4) {
        std::fprintf(stderr, "usage: rgb2spec_opt <resolution> <output file> [threads]\n");
        return 2;
    }
    const int n = std::atoi(argv[1]);
    const std::string out_path = argv[2];
    int threads = argc > 3 ? std::atoi(argv[3]) : int(std::thread::hardware_concurrency());
    if (n < 3 || n > 256) {
        std::fprintf(stderr, "rgb2spec_opt: the resolution must be in 3..256 (found %s)\n",
                     argv[1]);
        return 2;
    }
    threads = std::max(1, threads);
    auto start = std::chrono::steady_clock::now();

    const Quadrature q = make_quadrature();
    if (!check_quadrature(q)) return 1;

    Generator g{q, n, {}, {}, std::vector<float>(size_t(9) * n * n * n), {}, n / 5};
    for (int k = 0; k < n; ++k) {
        double t = k / double(n - 1);
        g.scale.push_back(double(float(smoothstep(smoothstep(t)))));
        g.ratio.push_back(double(float(smoothstep(t))));
    }

    // The spine: (k0, j, i = 0) for every j, one after the other from the grey at zero
    // coefficients (s = 1/2); then the rows, independent of each other (so the table is the
    // same for any number of threads).
    Generator::Stats total;
    for (int l = 0; l < 3; ++l) {
        Vec3 c{0.0, 0.0, 0.0};
        for (int j = 0; j < n; ++j) {
            total.add(fit(q, g.target(l, g.k0, j, 0), c), l, g.k0, j, 0);
            g.spine.push_back(c);
        }
    }
    std::atomic<int> next{0};
    std::vector<Generator::Stats> stats(static_cast<size_t>(threads));
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
            for (int job; (job = next++) < 3 * n;) g.row(job / n, job % n, stats[size_t(t)]);
        });
    for (std::thread &t : pool) t.join();
    for (const Generator::Stats &s : stats) total.merge(s);

    // A cell the fit did not bring to its colour fails the build rather than the renders.
    if (!(total.worst < 1e-5)) {
        std::fprintf(stderr,
                     "rgb2spec_opt: the fit missed the colour of table %d, cell (k, j, i) = "
                     "(%d, %d, %d) by %.3g\n",
                     total.worst_cell[0], total.worst_cell[1], total.worst_cell[2],
                     total.worst_cell[3], total.worst);
        return 1;
    }
    for (float v : g.coeffs)
        if (!std::isfinite(v)) {
            std::fprintf(stderr, "rgb2spec_opt: a coefficient is not finite\n");
            return 1;
        }

    std::vector<unsigned char> out;
    const char magic[8] = {'F', 'C', 'T', 'R', '2', 'S', '\0', '\0'};
    out.insert(out.end(), magic, magic + 8);
    put_bytes(out, 2);
    put_bytes(out, uint32_t(n));
    for (double s : g.scale) put_float(out, float(s));
    for (double r : g.ratio) put_float(out, float(r));
    for (float v : g.coeffs) put_float(out, v);
    // Written under a temporary name and renamed: an interrupted run leaves no table behind.
    const std::string tmp = out_path + ".tmp";
    FILE *f = std::fopen(tmp.c_str(), "wb");
    if (!f || std::fwrite(out.data(), 1, out.size(), f) != out.size() || std::fclose(f) != 0 ||
        std::rename(tmp.c_str(), out_path.c_str()) != 0) {
        std::fprintf(stderr, "rgb2spec_opt: could not write \"%s\"\n", out_path.c_str());
        return 1;
    }

    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("rgb2spec_opt: %ld cells (3 x %d^3) in %.1f s on %d threads, %.1f Gauss-Newton "
                "iterations per cell; largest rgb residual %.2e at table %d (k, j, i) = "
                "(%d, %d, %d); %ld cells above 1e-4\n",
                total.cells, n, secs, threads, double(total.iterations) / double(total.cells),
                total.worst, total.worst_cell[0], total.worst_cell[1], total.worst_cell[2],
                total.worst_cell[3], total.over_1e4);
    return 0;
}
