static const char *DOC = R"DOC(
# bitmap: image texture

An image file (OpenEXR, PNG, JPEG, Radiance RGBE, PFM and PNM, Targa, BMP or TIFF, read through
OpenImageIO by the reader the extension names, or else the one that recognises the contents)
looked up by the texture coordinates of the surface point. The pixel at the top-left corner of
the image is at uv = (0, 0) and u grows to the right, v downwards, as in Mitsuba; mesh loaders
that flip v (OBJ, by default) therefore show the image's top row at the file's v = 1. Outside
[0, 1]² the image repeats, mirrors or clamps as `wrap_mode` says.

8-bit and 16-bit formats (PNG, JPEG, ...) store sRGB-encoded values and are decoded to linear
RGB on load, unless `raw` is set (for data such as roughness, opacity or normal maps); EXR, HDR
and PFM images are linear already and are used as stored. Grey images give grey colours (an
alpha channel is ignored). `eval_1` (scalar parameters such as a roughness) returns the grey
value, or the luminance of a colour image. In the mono mode a colour image's `eval` is its
luminance too, unless `raw` is set (a normal map keeps its three channels).

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| filename | string | — | Image file, found through the scene's file resolver |
| filter_type | string | bilinear | Lookup filter: bilinear (interpolates the four nearest pixel centres) or nearest |
| wrap_mode | string | repeat | Behaviour outside [0, 1]²: repeat, mirror or clamp |
| raw | boolean | false | Use 8-bit values as stored (no sRGB decoding), for non-colour data |
| to_uv | transform | identity | Transform applied to the texture coordinates (its x, y affine part) |
| format | string | auto | Storage precision: auto (half precision for 8- and 16-bit images such as PNG or JPEG; EXR, HDR and PFM as stored), variant (32-bit float) or fp16 (half precision) |
| accel | boolean | true | Accepted for compatibility; lookups always run on the CPU |

```xml
<bsdf type="diffuse">
    <texture type="bitmap" name="reflectance">
        <string name="filename" value="textures/wood.jpg"/>
        <string name="wrap_mode" value="mirror"/>
        <transform name="to_uv">
            <scale x="4" y="4"/>
        </transform>
    </texture>
</bsdf>
```
)DOC";

#include <facet/distribution.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/resolver.h>
#include <facet/spectral_upsampling.h>
#include <facet/texture.h>
#include <facet/texture_image.h>
#include <facet/transform.h>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

namespace facet {

namespace {

enum class FilterType { Nearest, Bilinear };
enum class WrapMode { Repeat, Mirror, Clamp };

/// Formats whose pixels are scene-linear floating-point values.
bool is_linear_format(const std::string &path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".exr" || ext == ".hdr" || ext == ".rgbe" || ext == ".pfm";
}

} // namespace

class Bitmap final : public Texture {
public:
    explicit Bitmap(const Properties &props) {
        m_filename = props.get_string("filename");
        std::string filter = props.get_string("filter_type", "bilinear");
        if (filter == "bilinear")
            m_filter = FilterType::Bilinear;
        else if (filter == "nearest")
            m_filter = FilterType::Nearest;
        else
            FACET_THROW_AT(props.location("filter_type"),
                           "bitmap: filter_type must be bilinear or nearest, found \"{}\"", filter);
        std::string wrap = props.get_string("wrap_mode", "repeat");
        if (wrap == "repeat")
            m_wrap = WrapMode::Repeat;
        else if (wrap == "mirror")
            m_wrap = WrapMode::Mirror;
        else if (wrap == "clamp")
            m_wrap = WrapMode::Clamp;
        else
            FACET_THROW_AT(props.location("wrap_mode"),
                           "bitmap: wrap_mode must be repeat, mirror or clamp, found \"{}\"", wrap);
        m_raw = props.get_bool("raw", false);
        std::string format = props.get_string("format", "auto");
        if (format != "auto" && format != "variant" && format != "fp16")
            FACET_THROW_AT(props.location("format"),
                           "bitmap: format must be auto, variant or fp16, found \"{}\"", format);
        props.get_bool("accel", true);

        Transform to_uv = props.get_transform("to_uv", Transform());
        const auto &m = to_uv.matrix.m;
        m_uv_matrix[0] = m[0][0], m_uv_matrix[1] = m[0][1], m_uv_matrix[2] = m[0][3];
        m_uv_matrix[3] = m[1][0], m_uv_matrix[4] = m[1][1], m_uv_matrix[5] = m[1][3];

        m_path = file_resolver().resolve(m_filename);
        // As in Mitsuba, `auto` stores images of 16 bits per channel or fewer in half precision
        // (after decoding). Integer formats are; a half EXR already holds half values, and
        // float HDR/PFM/EXR files keep 32 bits. Every bitmap of the same file and decoding
        // shares one copy of the texels (8-bit files keep a byte per value).
        const bool linear = is_linear_format(m_path);
        TexelDecoding how;
        how.srgb = !m_raw && !linear;
        how.half = format == "fp16" || (format == "auto" && !linear);
        try {
            m_texels = load_texels(m_path, how);
        } catch (const Error &e) {
            FACET_THROW_AT(props.location("filename"), "bitmap: {}", e.message());
        }
        const TexelImage &t = *m_texels;
        if (t.width <= 0 || t.height <= 0 || t.channels <= 0)
            FACET_THROW_AT(props.location("filename"), "bitmap: \"{}\" holds no pixels", m_path);
        m_width = t.width;
        m_height = t.height;
        m_channels = t.channels;
        m_floats = t.bytes.empty() ? t.floats.data() : nullptr;
        m_bytes = t.bytes.empty() ? nullptr : t.bytes.data();
        m_table = t.table.data();
        // The mono mode renders a colour image's luminance (interpolating luminances is taking
        // the luminance of the interpolated colour: both are linear).
        m_luminance = props.mode() == ColourMode::Mono && !m_raw && m_channels == 3;
        m_mean = m_luminance ? in_mode(t.mean, ColourMode::Mono) : t.mean;
        m_max = t.max; // in mono a bound: no luminance exceeds the largest channel
        // The spectral mode upsamples each pixel of a colour image once, as a reflectance
        // (clamped to [0, 1], as Mitsuba's spectral bitmaps are); lookups blend the pixels'
        // spectra. Raw and grey images keep their values.
        if (is_spectral(props.mode()) && !m_raw && m_channels == 3) {
            m_curves.resize(size_t(m_width) * size_t(m_height));
            for (int y = 0; y < m_height; ++y)
                for (int x = 0; x < m_width; ++x)
                    m_curves[size_t(y) * size_t(m_width) + size_t(x)] =
                        rgb_to_sigmoid(m_bytes ? pixel<3, true>(x, y) : pixel<3, false>(x, y));
        }
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        if (m_luminance) return Color3f(eval_1(si));
        Point2f uv = to_uv(si.uv);
        if (!m_curves.empty()) return lookup_spectral(uv, si.wavelengths);
        if (m_bytes) return m_channels == 1 ? Color3f(lookup<1, true>(uv).r) : lookup<3, true>(uv);
        return m_channels == 1 ? Color3f(lookup<1, false>(uv).r) : lookup<3, false>(uv);
    }

    float eval_1(const SurfaceInteraction &si) const override {
        Point2f uv = to_uv(si.uv);
        if (m_bytes)
            return m_channels == 1 ? lookup<1, true>(uv).r : lookup<3, true>(uv).luminance();
        return m_channels == 1 ? lookup<1, false>(uv).r : lookup<3, false>(uv).luminance();
    }

    /// Gradient of eval_1 in (u, v): the slope of the bilinear interpolation (zero for the
    /// nearest filter, which is piecewise constant), carried through to_uv by its transpose.
    Vector2f eval_1_grad(const SurfaceInteraction &si) const override {
        const Point2f uv = to_uv(si.uv);
        Vector2f g =
            m_bytes ? (m_channels == 1 ? lookup_grad<1, true>(uv) : lookup_grad<3, true>(uv))
                    : (m_channels == 1 ? lookup_grad<1, false>(uv) : lookup_grad<3, false>(uv));
        return {m_uv_matrix[0] * g.x + m_uv_matrix[3] * g.y,
                m_uv_matrix[1] * g.x + m_uv_matrix[4] * g.y};
    }

    /// Starts loading the pixels eval() will read at si.
    bool prefetch(const SurfaceInteraction &si) const override {
        const Point2f uv = to_uv(si.uv);
        if (m_filter == FilterType::Nearest) {
            auto [x, y] = nearest_pixel(uv);
            prefetch_pixels(x, x, y);
            return true;
        }
        const Footprint f = bilinear_footprint(uv);
        prefetch_pixels(f.xa, f.xb, f.ya);
        prefetch_pixels(f.xa, f.xb, f.yb);
        return true;
    }

    Color3f mean() const override { return m_mean; }
    float max() const override { return m_max; }

    /// An area light's texture sampling: a texel (a cell of the nearest filter; of the bilinear
    /// filter's texel grid) in proportion to its luminance, then a uniform point in it. With the
    /// bilinear filter a cell's weight is the largest over the texel and its eight neighbours,
    /// whose values reach into the cell, so the density is positive wherever the lookup is. Only
    /// for the identity to_uv (the sampled uv is then the shape's).
    bool prepare_position_sampling() override {
        static const float identity[6] = {1, 0, 0, 0, 1, 0};
        if (!std::equal(std::begin(m_uv_matrix), std::end(m_uv_matrix), identity)) return false;
        if (m_position_sampling) return true;
        const size_t w = size_t(m_width), h = size_t(m_height);
        std::vector<float> texel(w * h);
        for (size_t y = 0; y < h; ++y)
            for (size_t x = 0; x < w; ++x) {
                const int xi = int(x), yi = int(y);
                const float v =
                    m_channels == 1
                        ? (m_bytes ? pixel<1, true>(xi, yi) : pixel<1, false>(xi, yi)).r
                        : (m_bytes ? pixel<3, true>(xi, yi) : pixel<3, false>(xi, yi)).luminance();
                texel[y * w + x] = v > 0.f && std::isfinite(v) ? v : 0.f;
            }
        std::vector<float> weight = texel;
        if (m_filter == FilterType::Bilinear)
            for (int y = 0; y < m_height; ++y)
                for (int x = 0; x < m_width; ++x) {
                    float m = 0.f;
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx)
                            m = std::max(m, texel[size_t(wrap(y + dy, m_height)) * w +
                                                  size_t(wrap(x + dx, m_width))]);
                    weight[size_t(y) * w + size_t(x)] = m;
                }
        m_position_distribution.build(weight.data(), weight.size());
        m_position_sampling = m_position_distribution.sum() > 0.0;
        return m_position_sampling;
    }

    std::pair<Point2f, float> sample_position(const Point2f &u) const override {
        float ux = u.x;
        const size_t i = m_position_distribution.sample_reuse(ux);
        const size_t x = i % size_t(m_width), y = i / size_t(m_width);
        const Point2f uv(std::min((float(x) + ux) / float(m_width), OneMinusEpsilon),
                         std::min((float(y) + u.y) / float(m_height), OneMinusEpsilon));
        return {uv, pdf_position(uv)};
    }

    float pdf_position(const Point2f &uv) const override {
        if (!(uv.x >= 0.f && uv.x <= 1.f && uv.y >= 0.f && uv.y <= 1.f)) return 0.f;
        const size_t x = std::min(size_t(uv.x * float(m_width)), size_t(m_width) - 1);
        const size_t y = std::min(size_t(uv.y * float(m_height)), size_t(m_height) - 1);
        return m_position_distribution.pmf(y * size_t(m_width) + x) * float(m_width) *
               float(m_height);
    }

    int width() const { return m_width; }
    int height() const { return m_height; }
    Point2i resolution() const override { return {m_width, m_height}; }

    std::string to_string() const override {
        static const char *filters[] = {"nearest", "bilinear"};
        static const char *wraps[] = {"repeat", "mirror", "clamp"};
        return fmt::format("Bitmap[\"{}\", {}x{}, {} channel{}, filter_type = {}, wrap_mode = {}, "
                           "raw = {}, mean = [{}, {}, {}]]",
                           m_filename, m_width, m_height, m_channels, m_channels == 1 ? "" : "s",
                           filters[int(m_filter)], wraps[int(m_wrap)], m_raw, m_mean.r, m_mean.g,
                           m_mean.b);
    }

private:
    Point2f to_uv(const Point2f &uv) const {
        return {m_uv_matrix[0] * uv.x + m_uv_matrix[1] * uv.y + m_uv_matrix[2],
                m_uv_matrix[3] * uv.x + m_uv_matrix[4] * uv.y + m_uv_matrix[5]};
    }

    /// Pixel index i wrapped into [0, n).
    int wrap(int i, int n) const {
        switch (m_wrap) {
        case WrapMode::Repeat: {
            int r = i % n;
            return r < 0 ? r + n : r;
        }
        case WrapMode::Mirror: {
            int period = 2 * n, r = i % period;
            if (r < 0) r += period;
            return r < n ? r : period - 1 - r;
        }
        case WrapMode::Clamp:
        default:
            return clamp(i, 0, n - 1);
        }
    }

    /// Integer part of x, kept in a range where int arithmetic cannot overflow.
    static int floor_to_int(float x) {
        if (!(x == x)) return 0; // NaN
        return int(std::floor(clamp(x, -1e8f, 1e8f)));
    }

    /// The texel at (x, y): C floats, or C bytes through their table.
    template <int C, bool Bytes> Color3f pixel(int x, int y) const {
        const size_t i = (size_t(y) * size_t(m_width) + size_t(x)) * C;
        if constexpr (Bytes) {
            const uint8_t *p = m_bytes + i;
            if constexpr (C == 1)
                return Color3f(m_table[p[0]]);
            else
                return Color3f(m_table[p[0]], m_table[p[1]], m_table[p[2]]);
        } else {
            const float *p = m_floats + i;
            if constexpr (C == 1)
                return Color3f(p[0]);
            else
                return Color3f(p[0], p[1], p[2]);
        }
    }

    template <int C, bool Bytes> Color3f lookup(const Point2f &uv) const {
        return filtered(uv, [&](int px, int py) { return pixel<C, Bytes>(px, py); });
    }

    /// The spectral mode's lookup: the pixels' spectra at `lambda`, blended as lookup() blends
    /// their colours.
    Color3f lookup_spectral(const Point2f &uv, const Wavelengths &lambda) const {
        return filtered(uv, [&](int px, int py) {
            const SigmoidPolynomial &c = m_curves[size_t(py) * size_t(m_width) + size_t(px)];
            return c(lambda);
        });
    }

    /// The bilinear filter's four pixels around uv (transformed): columns xa and xb, rows ya
    /// and yb (wrapped), and the weights fx and fy of xb and yb.
    struct Footprint {
        int xa, xb, ya, yb;
        float fx, fy;
    };
    Footprint bilinear_footprint(const Point2f &uv) const {
        // Pixel centres sit at half-integers.
        float x = uv.x * float(m_width) - 0.5f, y = uv.y * float(m_height) - 0.5f;
        int x0 = floor_to_int(x), y0 = floor_to_int(y);
        float fx = clamp(x - float(x0), 0.f, 1.f), fy = clamp(y - float(y0), 0.f, 1.f);
        if (!std::isfinite(fx)) fx = 0.f;
        if (!std::isfinite(fy)) fy = 0.f;
        return {wrap(x0, m_width),
                wrap(x0 + 1, m_width),
                wrap(y0, m_height),
                wrap(y0 + 1, m_height),
                fx,
                fy};
    }
    /// The nearest filter's pixel at uv (transformed).
    std::pair<int, int> nearest_pixel(const Point2f &uv) const {
        return {wrap(floor_to_int(uv.x * float(m_width)), m_width),
                wrap(floor_to_int(uv.y * float(m_height)), m_height)};
    }

    /// The filter's blend of the values value(x, y) of the pixels around uv (transformed).
    template <typename Value> Color3f filtered(const Point2f &uv, Value value) const {
        if (m_filter == FilterType::Nearest) {
            auto [x, y] = nearest_pixel(uv);
            return value(x, y);
        }
        const auto [xa, xb, ya, yb, fx, fy] = bilinear_footprint(uv);
        return (value(xa, ya) * (1.f - fx) + value(xb, ya) * fx) * (1.f - fy) +
               (value(xa, yb) * (1.f - fx) + value(xb, yb) * fx) * fy;
    }

    /// Starts loading pixels xa and xb of row y as eval() reads them: the spectral mode's curves,
    /// else the bytes or floats.
    void prefetch_pixels(int xa, int xb, int y) const {
        const char *base;
        size_t size;
        if (!m_curves.empty()) {
            base = reinterpret_cast<const char *>(m_curves.data());
            size = sizeof(SigmoidPolynomial);
        } else if (m_bytes) {
            base = reinterpret_cast<const char *>(m_bytes);
            size = size_t(m_channels);
        } else {
            base = reinterpret_cast<const char *>(m_floats);
            size = size_t(m_channels) * sizeof(float);
        }
        const size_t row = size_t(y) * size_t(m_width);
        // The lines from the first byte to the last of a pixel, or of two neighbours.
        auto span = [&](size_t first_pixel, size_t last_pixel) {
            const size_t last = (row + last_pixel + 1) * size - 1;
            for (size_t at = ((row + first_pixel) * size) & ~size_t(63); at <= last; at += 64)
                prefetch_line(base + at);
        };
        if (xb == xa + 1 || xb == xa) {
            span(size_t(xa), size_t(xb));
        } else { // xb wrapped to the row's other end
            span(size_t(xa), size_t(xa));
            span(size_t(xb), size_t(xb));
        }
    }

    /// Gradient of the scalar (grey or luminance) bilinear lookup with respect to the transformed
    /// uv: the four pixels of lookup(), differentiated in x and y, times the resolution.
    template <int C, bool Bytes> Vector2f lookup_grad(const Point2f &uv) const {
        if (m_filter == FilterType::Nearest) return Vector2f(0.f);
        const auto [xa, xb, ya, yb, fx, fy] = bilinear_footprint(uv);
        auto value = [&](int px, int py) {
            Color3f c = pixel<C, Bytes>(px, py);
            return C == 1 ? c.r : c.luminance();
        };
        float f00 = value(xa, ya), f10 = value(xb, ya), f01 = value(xa, yb), f11 = value(xb, yb);
        float dfdx = (1.f - fy) * (f10 - f00) + fy * (f11 - f01);
        float dfdy = (1.f - fx) * (f01 - f00) + fx * (f11 - f10);
        return {dfdx * float(m_width), dfdy * float(m_height)};
    }

    std::string m_filename, m_path;
    FilterType m_filter = FilterType::Bilinear;
    WrapMode m_wrap = WrapMode::Repeat;
    bool m_luminance = false; ///< eval() gives the luminance (the mono mode, colour images)
    bool m_raw = false;
    float m_uv_matrix[6] = {1, 0, 0, 0, 1, 0};
    int m_width = 0, m_height = 0, m_channels = 3;
    std::shared_ptr<const TexelImage> m_texels; ///< shared by every bitmap of the file
    const float *m_floats = nullptr;            ///< m_texels' floats, or
    const uint8_t *m_bytes = nullptr;           ///< its bytes, looked up in
    const float *m_table = nullptr;             ///< its table
    /// The spectral mode's pixel spectra (a colour image that is not raw; else empty).
    std::vector<SigmoidPolynomial> m_curves;
    Color3f m_mean;
    float m_max = 0.f;
    /// The texel table of sample_position(), built by prepare_position_sampling() for emitters.
    DiscreteDistribution m_position_distribution;
    bool m_position_sampling = false;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Bitmap, Texture, "bitmap", "Image texture read with OpenImageIO",
                          DOC, ::facet::AllModes)
