#include <facet/logger.h>
#include <facet/spectral_upsampling.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <dlfcn.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

namespace facet {

namespace fs = std::filesystem;

namespace {

constexpr const char *TableName = "rgb2spec_srgb.bin";
constexpr char Magic[8] = {'F', 'C', 'T', 'R', '2', 'S', '\0', '\0'};
constexpr uint32_t Version = 2;

/// The table written by core/scripts/rgb2spec_opt.cpp (its header comment gives the layout):
/// three tables, by largest channel, of n (scale) x n (y) x n (x) cells of 3 coefficients for
/// λ in nm; the scale of the largest channel and the ratios of the other two to it (x, y) at
/// the cells.
struct Table {
    int n = 0;
    std::vector<float> scale, ratio;
    std::vector<float> coeffs;
};

uint32_t read_u32(const unsigned char *p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

float read_f32(const unsigned char *p) {
    uint32_t v = read_u32(p);
    float f;
    std::memcpy(&f, &v, 4);
    return f;
}

Table load_table() {
    const std::string path = spectral_upsampling_table_path();
    std::ifstream in(path, std::ios::binary);
    if (!in) FACET_THROW("could not open the spectral upsampling table \"{}\"", path);
    std::vector<unsigned char> data((std::istreambuf_iterator<char>(in)),
                                    std::istreambuf_iterator<char>());
    if (data.size() < 16 || std::memcmp(data.data(), Magic, 8) != 0)
        FACET_THROW("\"{}\" is not a spectral upsampling table (written by rgb2spec_opt)", path);
    if (read_u32(data.data() + 8) != Version)
        FACET_THROW("\"{}\": table version {}, expected {}", path, read_u32(data.data() + 8),
                    Version);
    Table t;
    uint32_t n = read_u32(data.data() + 12);
    size_t expected = 16 + 4 * (2 * size_t(n) + 9 * size_t(n) * n * n);
    if (n < 3 || n > 256 || data.size() != expected)
        FACET_THROW("\"{}\": {} bytes for a table of resolution {}, expected {}", path, data.size(),
                    n, expected);
    t.n = int(n);
    const unsigned char *p = data.data() + 16;
    for (uint32_t k = 0; k < n; ++k, p += 4) t.scale.push_back(read_f32(p));
    for (uint32_t k = 0; k < n; ++k, p += 4) t.ratio.push_back(read_f32(p));
    t.coeffs.resize(9 * size_t(n) * n * n);
    for (float &c : t.coeffs) {
        c = read_f32(p);
        p += 4;
        if (!std::isfinite(c)) FACET_THROW("\"{}\": a coefficient is not finite", path);
    }
    for (uint32_t k = 1; k < n; ++k)
        if (!(t.scale[k] > t.scale[k - 1]) || !(t.ratio[k] > t.ratio[k - 1]))
            FACET_THROW("\"{}\": an axis of the table is not increasing", path);
    if (t.ratio.front() != 0.f || t.ratio.back() != 1.f)
        FACET_THROW("\"{}\": the ratio axis does not span [0, 1]", path);
    return t;
}

/// The cell of `axis` holding `v` and the position in it, in [0, 1] (clamped to the axis).
int locate(const std::vector<float> &axis, float v, float &f) {
    int i = int(std::upper_bound(axis.begin(), axis.end(), v) - axis.begin()) - 1;
    i = clamp(i, 0, int(axis.size()) - 2);
    f = (v - axis[size_t(i)]) / (axis[size_t(i) + 1] - axis[size_t(i)]);
    return i;
}

const Table &table() {
    static const Table t = load_table();
    return t;
}

} // namespace

std::string SigmoidPolynomial::to_string() const {
    return fmt::format("SigmoidPolynomial[c0={}, c1={}, c2={}]", c0, c1, c2);
}

std::string spectral_upsampling_table_path() {
    // As the other data facet installs (the OpenColorIO config): next to libfacet
    // (<prefix>/lib/libfacet.so -> <prefix>/share/facet; a multiarch libdir is one level
    // deeper), then the configured prefix, then the build tree.
    std::vector<fs::path> candidates;
    Dl_info info{};
    if (dladdr(reinterpret_cast<void *>(&spectral_upsampling_table_path), &info) &&
        info.dli_fname) {
        fs::path libdir = fs::absolute(fs::path(info.dli_fname)).parent_path();
        candidates.push_back(libdir / ".." / "share" / "facet" / TableName);
        candidates.push_back(libdir / ".." / ".." / "share" / "facet" / TableName);
    }
#ifdef FACET_INSTALL_DATA_DIR
    candidates.push_back(fs::path(FACET_INSTALL_DATA_DIR) / TableName);
#endif
#ifdef FACET_BUILD_DATA_DIR
    candidates.push_back(fs::path(FACET_BUILD_DATA_DIR) / TableName);
#endif
    std::string tried;
    for (const fs::path &c : candidates) {
        std::error_code ec;
        if (fs::is_regular_file(c, ec)) return c.lexically_normal().string();
        tried += "\n  " + c.string();
    }
    FACET_THROW("the spectral upsampling table {} was not found (looked in:{})", TableName, tried);
}

SigmoidPolynomial rgb_to_sigmoid(const Color3f &rgb_in) {
    const Color3f rgb = map(rgb_in, [](float v) {
        return v > 0.f ? (v < 1.f ? v : 1.f) : 0.f; // NaN -> 0
    });
    if (rgb.r == rgb.g && rgb.g == rgb.b && (rgb.r == 0.f || rgb.r == 1.f))
        return {0.f, 0.f, rgb.r == 0.f ? -Infinity : Infinity};

    const Table &t = table();
    const int n = t.n;
    // The table of the largest channel; the other two relative to it, as rgb2spec_opt's grid.
    int l = 0;
    if (rgb[1] > rgb[l]) l = 1;
    if (rgb[2] > rgb[l]) l = 2;
    float z = rgb[l], fx, fy, fz;
    int xi = locate(t.ratio, rgb[(l + 1) % 3] / z, fx);
    int yi = locate(t.ratio, rgb[(l + 2) % 3] / z, fy);
    int zi = locate(t.scale, z, fz);

    float c[3] = {0.f, 0.f, 0.f};
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
                float w = (dz ? fz : 1.f - fz) * (dy ? fy : 1.f - fy) * (dx ? fx : 1.f - fx);
                size_t cell = ((size_t(l) * n + zi + dz) * n + yi + dy) * n + xi + dx;
                for (int i = 0; i < 3; ++i) c[i] += w * t.coeffs[3 * cell + i];
            }
    return {c[0], c[1], c[2]};
}

RGBSpectrum RGBSpectrum::from_rgb(const Color3f &rgb, SpectrumKind kind) {
    RGBSpectrum result;
    if (kind == SpectrumKind::Reflectance || kind == SpectrumKind::Unbounded) {
        // Mitsuba 3's spectral modes clamp an unbounded rgb (an eta or k) too: its peer
        // references show it.
        result.poly = rgb_to_sigmoid(rgb);
        return result;
    }
    result = scaled(rgb);
    result.illuminant = kind == SpectrumKind::Emission;
    return result;
}

RGBSpectrum RGBSpectrum::scaled(const Color3f &rgb) {
    RGBSpectrum result;
    const float scale = 2.f * rgb.max();
    if (!(scale > 0.f) || !std::isfinite(scale)) {
        result.poly = rgb_to_sigmoid(Color3f(0.f));
        result.scale = 0.f;
        return result;
    }
    result.poly = rgb_to_sigmoid(rgb / scale);
    result.scale = scale;
    return result;
}

Color3f RGBSpectrum::eval(const Wavelengths &lambda) const {
    Color3f v = poly(lambda) * scale;
    if (illuminant) v *= cie_d65(lambda);
    return v;
}

} // namespace facet
