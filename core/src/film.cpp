#include "tabulated_filter.h"

#include <facet/film.h>
#include <facet/plugin.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <xmmintrin.h>

namespace facet {

// ---------------------------------------------------------------------------------------------
// ImageBlock

int ImageBlock::border_for(const ReconstructionFilter &filter) {
    return int(std::floor(filter.radius() + 0.5f));
}

void ImageBlock::reset(const Point2i &offset, const Point2i &size, int border, int aov_count,
                       int colour_count) {
    if (size.x < 0 || size.y < 0 || border < 0 || aov_count < 0 || colour_count < 0)
        FACET_THROW("ImageBlock::reset: invalid size {}x{}, border {}, AOV count {} or colour "
                    "count {}",
                    size.x, size.y, border, aov_count, colour_count);
    m_offset = offset;
    m_size = size;
    m_border = border;
    m_aov_count = aov_count;
    m_colour_count = colour_count;
    Point2i s = storage_size();
    // assign() keeps the capacity, so a block reused for equally sized tiles allocates nothing.
    m_data.assign(size_t(s.x) * size_t(s.y) * size_t(channel_count()), 0.f);
}

namespace {

/// floor(x) for |x| < 2^31 without the library call: the truncation, less one below zero where
/// x was not an integer.
inline int floor_int(float x) {
    const int t = int(x);
    return t - int(x < float(t));
}

} // namespace

inline bool ImageBlock::footprint_range(const Point2f &pos, float radius, Footprint &fp) const {
    // Non-finite positions, and positions far beyond any film (whose pixel indices would not
    // fit an int), reach no pixel.
    if (!(std::abs(pos.x) < 1e9f) || !(std::abs(pos.y) < 1e9f)) return false;
    const Point2i s = storage_size();
    // Continuous position in film pixels, with pixel centres at integers, and the film pixel of
    // storage pixel (0, 0): the filter weights do not depend on where the block lies, so the
    // blocks of a crop window (or a light tracer's block of it) weigh a sample exactly as those
    // of the whole film do.
    const float px = pos.x - 0.5f, py = pos.y - 0.5f;
    fp.ox = m_offset.x - m_border;
    fp.oy = m_offset.y - m_border;
    fp.px = px;
    fp.py = py;
    fp.ux0 = -floor_int(radius - px) - fp.ox; // ceil(px - radius)
    fp.uy0 = -floor_int(radius - py) - fp.oy;
    fp.ux1 = floor_int(px + radius) - fp.ox;
    fp.uy1 = floor_int(py + radius) - fp.oy;
    fp.x0 = std::max(0, fp.ux0);
    fp.y0 = std::max(0, fp.uy0);
    const int x1 = std::min(s.x - 1, fp.ux1);
    const int y1 = std::min(s.y - 1, fp.uy1);
    if (fp.x0 > x1 || fp.y0 > y1) return false;
    fp.nx = size_t(x1 - fp.x0 + 1);
    fp.ny = size_t(y1 - fp.y0 + 1);
    return true;
}

inline void ImageBlock::footprint_weights(const TabulatedFilter &w, Footprint &fp, float *wx,
                                          float *wy) {
    // The argument is the sample's offset from the pixel centre.
    fp.sum_x = fp.sum_y = 0.f;
    for (size_t i = 0; i < fp.nx; ++i)
        fp.sum_x += (wx[i] = w(fp.px - float(fp.ox + fp.x0 + int(i))));
    for (size_t j = 0; j < fp.ny; ++j)
        fp.sum_y += (wy[j] = w(fp.py - float(fp.oy + fp.y0 + int(j))));
}

inline void ImageBlock::scratch_weights(const TabulatedFilter &w, Footprint &fp) {
    // Grows only the first time a block sees a filter of this size.
    if (m_wx.size() < fp.nx) m_wx.resize(fp.nx);
    if (m_wy.size() < fp.ny) m_wy.resize(fp.ny);
    footprint_weights(w, fp, m_wx.data(), m_wy.data());
}

bool ImageBlock::footprint(const Point2f &pos, const ReconstructionFilter &filter, Footprint &fp) {
    if (!footprint_range(pos, filter.radius(), fp)) return false;
    scratch_weights(filter.table(), fp);
    return true;
}

namespace {

/// Adds a sample of weight w to pixel p: r, g, b, the AOVs (when given), then the weight.
inline void add_sample(float *p, float w, const Color3f &L, const float *aovs, int aov_count) {
    p[0] += w * L.r;
    p[1] += w * L.g;
    p[2] += w * L.b;
    if (aovs)
        for (int k = 0; k < aov_count; ++k) p[3 + k] += w * aovs[k];
    p[3 + aov_count] += w;
}

/// Adds a sample of weight w and `n` values to pixel p, then the weight.
inline void add_values(float *p, float w, const float *values, int n) {
    for (int k = 0; k < n; ++k) p[k] += w * values[k];
    p[n] += w;
}

} // namespace

inline bool ImageBlock::single_pixel(const Point2f &pos, float c, float *&pixel) {
    // A filter whose weight is a constant c on [-1/2, 1/2) and 0 elsewhere (the box), at film
    // positions in [0, 2^22) (every sample of a film, short of absurd sizes): there pos - 0.5
    // and its offset from any pixel are exact in float, so the one pixel of the footprint with
    // a non-zero weight is floor(pos), the pixel the sample lies in, with the weight c·c.
    if (!(c != 0.f && pos.x >= 0.f && pos.x < 4194304.f && pos.y >= 0.f && pos.y < 4194304.f))
        return false;
    const Point2i s = storage_size();
    const int x = int(pos.x) - (m_offset.x - m_border), y = int(pos.y) - (m_offset.y - m_border);
    pixel = x >= 0 && x < s.x && y >= 0 && y < s.y
                ? m_data.data() + (size_t(y) * size_t(s.x) + size_t(x)) * size_t(channel_count())
                : nullptr;
    return true;
}

template <typename Add> inline void
ImageBlock::for_each_footprint_pixel(Footprint &fp, const TabulatedFilter &table, Add add) {
    const Point2i s = storage_size();
    const int nc = channel_count();
    scratch_weights(table, fp);
    for (size_t j = 0; j < fp.ny; ++j) {
        const float wy = m_wy[j];
        if (wy == 0.f) continue;
        float *row = m_data.data() + (size_t(fp.y0) + j) * size_t(s.x) * nc;
        for (size_t i = 0; i < fp.nx; ++i) {
            const float w = m_wx[i] * wy;
            if (w != 0.f) add(row + (size_t(fp.x0) + i) * nc, w);
        }
    }
}

void ImageBlock::put(const Point2f &pos, const Color3f &L, const float *aovs,
                     const ReconstructionFilter &filter) {
    FACET_ASSERT(m_colour_count == 3);
    // The box's one pixel here; put_footprint() takes the rest, with the same weights.
    const TabulatedFilter &table = filter.table();
    const float c = table.single_pixel_weight();
    if (float *p; single_pixel(pos, c, p)) {
        if (p) add_sample(p, c * c, L, aovs, m_aov_count);
        return;
    }
    put_footprint(pos, L, aovs, filter, table);
}

__attribute__((noinline)) void ImageBlock::put_footprint(const Point2f &pos, const Color3f &L,
                                                         const float *aovs,
                                                         const ReconstructionFilter &filter,
                                                         const TabulatedFilter &table) {
    Footprint fp;
    if (!footprint_range(pos, filter.radius(), fp)) return;
    if (m_aov_count > 0 || fp.nx > SmallFootprint || fp.ny > SmallFootprint) {
        for_each_footprint_pixel(
            fp, table, [&](float *p, float w) { add_sample(p, w, L, aovs, m_aov_count); });
        return;
    }
    // A pixel of r, g, b and the weight, a footprint of at most SmallFootprint² pixels (every
    // filter up to a radius of 3.5: the tent 2 x 2 or 3 x 3, the gaussian up to 5 x 5): the
    // weights stay on the stack and a pixel takes one 4-wide product and sum, the same
    // arithmetic as add_sample() (the weight channel gains w · 1 = w). The film's share of the
    // Veach scene's CPU (perf): 4.8% with the general loop and the library's ceil and floor,
    // 2.9% this way.
    float wx[SmallFootprint], wy[SmallFootprint];
    footprint_weights(table, fp, wx, wy);
    const __m128 value = _mm_setr_ps(L.r, L.g, L.b, 1.f);
    const size_t row_floats = size_t(storage_size().x) * 4;
    float *first = m_data.data() + size_t(fp.y0) * row_floats + size_t(fp.x0) * 4;
    for (size_t j = 0; j < fp.ny; ++j) {
        const float wyj = wy[j];
        if (wyj == 0.f) continue;
        float *row = first + j * row_floats;
        for (size_t i = 0; i < fp.nx; ++i) {
            const float w = wx[i] * wyj;
            if (w == 0.f) continue;
            float *p = row + i * 4;
            _mm_storeu_ps(p, _mm_add_ps(_mm_loadu_ps(p), _mm_mul_ps(_mm_set1_ps(w), value)));
        }
    }
}

void ImageBlock::put_values(const Point2f &pos, const float *values,
                            const ReconstructionFilter &filter) {
    const int n = m_colour_count + m_aov_count;
    const TabulatedFilter &table = filter.table();
    const float c = table.single_pixel_weight();
    if (float *p; single_pixel(pos, c, p)) {
        if (p) add_values(p, c * c, values, n);
        return;
    }
    Footprint fp;
    if (!footprint_range(pos, filter.radius(), fp)) return;
    for_each_footprint_pixel(fp, table, [&](float *p, float w) { add_values(p, w, values, n); });
}

void ImageBlock::splat(const Point2f &pos, const Color3f &L, const ReconstructionFilter &filter) {
    FACET_ASSERT(m_colour_count == 3);
    Footprint fp;
    if (!footprint(pos, filter, fp)) return;
    const Point2i s = storage_size();
    const size_t nx = fp.nx, ny = fp.ny;
    const int x0 = fp.x0, y0 = fp.y0;
    // A footprint cut by the block edge keeps its share of the whole footprint's weights (the
    // pixels beyond the edge belong to another block, or to none): the sums run over the whole
    // footprint, in the same order as when nothing is cut, so a crop window's pixels receive
    // the same splats as in a render of the whole film.
    const TabulatedFilter &weight = filter.table();
    auto whole_sum = [&weight](float p, int o, int u0, int u1, int c0, size_t n, float clipped,
                               const std::vector<float> &w) {
        if (u0 == c0 && u1 == c0 + int(n) - 1) return clipped;
        float sum = 0.f;
        for (int i = u0; i <= u1; ++i)
            sum += i >= c0 && i < c0 + int(n) ? w[size_t(i - c0)] : weight(p - float(o + i));
        return sum;
    };
    const float sx = whole_sum(fp.px, fp.ox, fp.ux0, fp.ux1, x0, nx, fp.sum_x, m_wx);
    const float sy = whole_sum(fp.py, fp.oy, fp.uy0, fp.uy1, y0, ny, fp.sum_y, m_wy);
    const float norm = sx * sy;
    if (!(norm != 0.f) || !std::isfinite(norm)) return;
    const float inv = 1.f / norm;
    const int nc = channel_count();
    for (size_t j = 0; j < ny; ++j) {
        const float wy = m_wy[j] * inv;
        if (wy == 0.f) continue;
        float *row = m_data.data() + (size_t(y0) + j) * size_t(s.x) * nc;
        for (size_t i = 0; i < nx; ++i) {
            const float w = m_wx[i] * wy;
            if (w == 0.f) continue;
            float *p = row + (size_t(x0) + i) * nc;
            p[0] += w * L.r;
            p[1] += w * L.g;
            p[2] += w * L.b;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Film

namespace {

int read_positive(const Properties &props, const char *name, int64_t def) {
    int64_t v = props.get_int(name, def);
    if (v <= 0 || v > (1 << 20))
        FACET_THROW_AT(props.location(name),
                       "{} must be a positive number of pixels (at most {}), got {}", name, 1 << 20,
                       v);
    return int(v);
}

} // namespace

Film::Film(const Properties &props) {
    m_size = {read_positive(props, "width", 768), read_positive(props, "height", 576)};

    int64_t ox = props.get_int("crop_offset_x", 0), oy = props.get_int("crop_offset_y", 0);
    if (ox < 0 || oy < 0 || ox >= m_size.x || oy >= m_size.y)
        FACET_THROW_AT(props.location(), "the crop offset ({}, {}) must lie inside the {}x{} film",
                       ox, oy, m_size.x, m_size.y);
    m_crop_offset = {int(ox), int(oy)};
    int64_t cw = props.get_int("crop_width", m_size.x - ox);
    int64_t ch = props.get_int("crop_height", m_size.y - oy);
    if (cw <= 0 || ch <= 0 || ox + cw > m_size.x || oy + ch > m_size.y)
        FACET_THROW_AT(
            props.location(),
            "the crop window (offset ({}, {}), size {}x{}) must be non-empty and lie inside the "
            "{}x{} film",
            ox, oy, cw, ch, m_size.x, m_size.y);
    m_crop_size = {int(cw), int(ch)};

    // Far above real renders (16384x8192); a hostile size fails here, not in the allocator.
    constexpr int64_t MaxPixels = int64_t(1) << 27;
    if (int64_t(m_size.x) * int64_t(m_size.y) > MaxPixels)
        FACET_THROW_AT(props.location(),
                       "the film is {}x{} pixels, more than the {} pixels (2^27, e.g. 16384x8192) "
                       "{} supports",
                       m_size.x, m_size.y, MaxPixels, props.plugin_name());
    std::string format = props.get_string("component_format", "float16");
    std::transform(format.begin(), format.end(), format.begin(),
                   [](unsigned char ch) { return char(std::tolower(ch)); });
    if (format == "float16" || format == "float32")
        m_half = format == "float16";
    else
        FACET_THROW_AT(props.location("component_format"),
                       "component_format must be float16 or float32, got \"{}\"{}", format,
                       format == "uint32" ? " (uint32 is not supported)" : "");

    for (const auto &[name, obj] : props.objects()) {
        if (!obj || obj->type() != ObjectType::ReconstructionFilter) continue;
        if (m_filter)
            FACET_THROW_AT(props.location(name), "a film takes only one reconstruction filter");
        m_filter = std::static_pointer_cast<ReconstructionFilter>(obj);
        props.mark_queried(name);
    }
    if (!m_filter)
        m_filter = PluginRegistry::instance().create_as<ReconstructionFilter>(
            ObjectType::ReconstructionFilter, Properties("gaussian"));
}

void Film::check_crop_window(const Point2i &offset, const Point2i &size) const {
    if (offset.x < 0 || offset.y < 0 || size.x <= 0 || size.y <= 0 ||
        int64_t(offset.x) + size.x > m_size.x || int64_t(offset.y) + size.y > m_size.y)
        FACET_THROW("the crop window [{}, {}) x [{}, {}) must be non-empty and lie inside the "
                    "{}x{} film (pixels 0..{} x 0..{})",
                    offset.x, int64_t(offset.x) + size.x, offset.y, int64_t(offset.y) + size.y,
                    m_size.x, m_size.y, m_size.x - 1, m_size.y - 1);
}

// ---------------------------------------------------------------------------------------------
// FilmBuffer

FilmBuffer::FilmBuffer(const Point2i &offset, const Point2i &size,
                       std::vector<std::string> aov_names, bool splats)
    : FilmBuffer(offset, size, {"R", "G", "B"}, std::move(aov_names), splats) {}

FilmBuffer::FilmBuffer(const Point2i &offset, const Point2i &size,
                       std::vector<std::string> colour_names, std::vector<std::string> aov_names,
                       bool splats)
    : m_offset(offset), m_size(size), m_colour_names(std::move(colour_names)),
      m_aov_names(std::move(aov_names)) {
    if (splats && m_colour_names != std::vector<std::string>{"R", "G", "B"})
        FACET_THROW("a light tracer splats R, G, B: it cannot fill the colour channels {}",
                    fmt::join(m_colour_names, ", "));
    // The accumulation buffer and the developed image (floats) of every channel.
    constexpr uint64_t BudgetBytes = uint64_t(8) << 30;
    const uint64_t pixels = uint64_t(std::max(size.x, 0)) * uint64_t(std::max(size.y, 0));
    const uint64_t channels = channel_count() + (splats ? 3 : 0);
    uint64_t bytes = 0;
    if (__builtin_mul_overflow(pixels, channels * 8, &bytes) || bytes > BudgetBytes)
        FACET_THROW("a {}x{} film with {} AOV channels needs {:.1f} GiB for its buffers, more "
                    "than the {} GiB budget: lower the resolution, crop it or use fewer AOVs",
                    size.x, size.y, m_aov_names.size(),
                    double(pixels) * double(channels) * 8.0 / double(1 << 30), BudgetBytes >> 30);
    m_sums.assign(size_t(pixels) * channel_count(), 0.f);
    if (splats) m_splats.assign(size_t(pixels) * 3, 0.f);
}

void FilmBuffer::put_splats(const ImageBlock &block) {
    if (m_splats.empty()) FACET_THROW("FilmBuffer::put_splats: the buffer has no splat buffer");
    const int nc = block.channel_count();
    const Point2i s = block.storage_size();
    const float *data = block.data().data();
    const int bx = block.offset().x - block.border() - m_offset.x;
    const int by = block.offset().y - block.border() - m_offset.y;
    for (int y = 0; y < s.y; ++y) {
        int cy = by + y;
        if (cy < 0 || cy >= m_size.y) continue;
        for (int x = 0; x < s.x; ++x) {
            int cx = bx + x;
            if (cx < 0 || cx >= m_size.x) continue;
            const float *src = data + (size_t(y) * s.x + x) * nc;
            float *dst = m_splats.data() + (size_t(cy) * m_size.x + cx) * 3;
            for (int c = 0; c < 3; ++c) dst[c] += src[c];
        }
    }
}

void FilmBuffer::put_block(const ImageBlock &block) {
    const int nc = block.channel_count();
    if (size_t(nc) != channel_count())
        FACET_THROW("FilmBuffer::put_block: the block has {} colour and {} AOV channels, the "
                    "buffer expects {} and {}",
                    block.colour_count(), block.aov_count(), m_colour_names.size(),
                    m_aov_names.size());
    const Point2i s = block.storage_size();
    const float *data = block.data().data();
    // Block storage pixel (0, 0) is film pixel offset - border; map it to the window.
    const int bx = block.offset().x - block.border() - m_offset.x;
    const int by = block.offset().y - block.border() - m_offset.y;
    for (int y = 0; y < s.y; ++y) {
        int cy = by + y;
        if (cy < 0 || cy >= m_size.y) continue;
        for (int x = 0; x < s.x; ++x) {
            int cx = bx + x;
            if (cx < 0 || cx >= m_size.x) continue;
            const float *src = data + (size_t(y) * s.x + x) * nc;
            float *dst = m_sums.data() + (size_t(cy) * m_size.x + cx) * nc;
            for (int c = 0; c < nc; ++c) dst[c] += src[c];
        }
    }
}

std::vector<std::string> FilmBuffer::raw_channel_names() const {
    std::vector<std::string> names;
    const std::string p = RawChannelPrefix;
    for (const auto &n : m_colour_names) names.push_back(p + "sum." + n);
    for (const auto &n : m_aov_names) names.push_back(p + "sum." + n);
    names.push_back(p + "weight");
    if (!m_splats.empty())
        for (const char *c : {"R", "G", "B"}) names.push_back(p + "splat." + c);
    return names;
}

std::vector<float> FilmBuffer::raw_sums() const {
    if (!m_raw.empty()) return std::vector<float>(m_raw.begin(), m_raw.end());
    const size_t pixels = size_t(m_size.x) * size_t(m_size.y);
    const size_t nc = channel_count(), ns = m_splats.empty() ? 0 : 3, n = nc + ns;
    std::vector<float> out(pixels * n);
    for (size_t i = 0; i < pixels; ++i) {
        for (size_t c = 0; c < nc; ++c) out[i * n + c] = m_sums[i * nc + c];
        for (size_t c = 0; c < ns; ++c) out[i * n + nc + c] = m_splats[i * 3 + c];
    }
    return out;
}

void FilmBuffer::set_raw_sums(const std::vector<double> &raw) {
    const size_t pixels = size_t(m_size.x) * size_t(m_size.y);
    const size_t n = channel_count() + (m_splats.empty() ? 0 : 3);
    if (raw.size() != pixels * n)
        FACET_THROW("FilmBuffer::set_raw_sums: {} values for {} pixels of {} raw channels",
                    raw.size(), pixels, n);
    m_raw = raw;
}

// ---------------------------------------------------------------------------------------------
// Development

namespace {

template <typename T> void develop_sums(const T *storage, int values, const T *splat,
                                        double splat_scale, int alpha_at, float *dst) {
    const bool splatted = splat && (splat[0] != 0 || splat[1] != 0 || splat[2] != 0);
    const double w = storage ? double(storage[values]) : 0.0;
    // Filters with negative lobes can give a negative sum: divide by it all the same (as
    // Mitsuba does); only a pixel without any weight stays 0.
    const double inv = w != 0.0 ? 1.0 / w : 0.0;
    int o = 0;
    for (int c = 0; c < values; ++c) {
        if (c == alpha_at) dst[o++] = w > 0.0 || splatted ? 1.f : 0.f;
        const double s = c < 3 && splat ? double(splat[c]) * splat_scale : 0.0;
        dst[o++] = float((storage ? double(storage[c]) * inv : 0.0) + s);
    }
    if (alpha_at >= values) dst[o] = w > 0.0 || splatted ? 1.f : 0.f;
}

} // namespace

void develop_pixel(const double *storage, int values, const double *splat, double splat_scale,
                   int alpha_at, float *dst) {
    develop_sums(storage, values, splat, splat_scale, alpha_at, dst);
}

void develop_pixel(const float *storage, int values, const float *splat, double splat_scale,
                   int alpha_at, float *dst) {
    develop_sums(storage, values, splat, splat_scale, alpha_at, dst);
}

std::vector<std::string> Film::colour_channels() const {
    return m_bands ? m_bands->names() : std::vector<std::string>{"R", "G", "B"};
}

Image Film::develop(const FilmBuffer &buffer) const {
    const std::vector<std::string> &colours = buffer.colour_names(), &aovs = buffer.aov_names();
    const int values = int(colours.size() + aovs.size());
    const size_t nc = buffer.channel_count();
    Image img(buffer.size().x, buffer.size().y, values + (m_alpha ? 1 : 0));
    img.x = buffer.offset().x;
    img.y = buffer.offset().y;
    img.full_width = m_size.x;
    img.full_height = m_size.y;
    img.channel_names = colours;
    if (m_alpha) img.channel_names.push_back("A");
    img.channel_names.insert(img.channel_names.end(), aovs.begin(), aovs.end());
    const std::vector<float> &sums = buffer.sums(), &splats = buffer.splats();
    const std::vector<double> &raw = buffer.raw();
    const int alpha_at = m_alpha ? int(colours.size()) : -1;
    const size_t nraw = nc + (splats.empty() ? 0 : 3);
    for (size_t i = 0, n = size_t(buffer.size().x) * size_t(buffer.size().y); i < n; ++i) {
        float *dst = img.data.data() + i * size_t(img.channels);
        if (!raw.empty())
            develop_pixel(raw.data() + i * nraw, values,
                          splats.empty() ? nullptr : raw.data() + i * nraw + nc,
                          buffer.splat_scale(), alpha_at, dst);
        else
            develop_pixel(sums.data() + i * nc, values,
                          splats.empty() ? nullptr : splats.data() + i * 3, buffer.splat_scale(),
                          alpha_at, dst);
    }
    return img;
}

void Film::write(const Image &image, const std::string &path, const ImageWriteOptions &opts) const {
    ImageWriteOptions o = opts;
    o.half = m_half;
    write_image(path, image, o);
}

std::string Film::to_string() const {
    return fmt::format(
        "Film[size={}x{}, crop_offset=({}, {}), crop_size={}x{}, component_format={}, "
        "alpha={}, rfilter={}]",
        m_size.x, m_size.y, m_crop_offset.x, m_crop_offset.y, m_crop_size.x, m_crop_size.y,
        m_half ? "float16" : "float32", m_alpha, m_filter ? m_filter->to_string() : "none");
}

} // namespace facet
