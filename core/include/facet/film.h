#pragma once

#include <facet/color.h>
#include <facet/image.h>
#include <facet/object.h>
#include <facet/properties.h>
#include <facet/rfilter.h>
#include <facet/vector.h>

#include <memory>
#include <string>
#include <vector>

namespace facet {

/// Accumulates filtered samples for a rectangle of pixels (a render block plus the filter border).
/// Each pixel stores Σ w·L, Σ w·aov for every extra channel, and Σ w.
class ImageBlock {
public:
    ImageBlock() = default;
    /// `offset`/`size` are the block's pixels in film coordinates; `border` extra pixels each side;
    /// `aov_count` extra channels after r, g, b. Reuses the existing memory when it is big enough.
    void reset(const Point2i &offset, const Point2i &size, int border, int aov_count = 0);
    /// Adds radiance L at continuous film position `pos` (pixel centres at .5) with the filter.
    /// Extra channels receive zero.
    void put(const Point2f &pos, const Color3f &L, const ReconstructionFilter &filter) {
        put(pos, L, nullptr, filter);
    }
    /// The same with `aov_count()` extra values (`aovs` may be null when there are none).
    void put(const Point2f &pos, const Color3f &L, const float *aovs,
             const ReconstructionFilter &filter);
    /// Splats L at `pos` for a light tracer: the filter weights over the footprint are normalised
    /// to sum to one and only r, g, b receive them (the weight channel stays untouched), so the
    /// energy of a splat lands on the film whatever the filter. Film::put_splats() takes the
    /// result.
    void splat(const Point2f &pos, const Color3f &L, const ReconstructionFilter &filter);
    const Point2i &offset() const { return m_offset; }
    const Point2i &size() const { return m_size; }
    int border() const { return m_border; }
    int aov_count() const { return m_aov_count; }
    /// Floats per pixel: r, g, b, the AOVs, weight (4 without AOVs).
    int channel_count() const { return m_aov_count + 4; }
    /// Pixels per row/column of data(): size + 2·border.
    Point2i storage_size() const { return {m_size.x + 2 * m_border, m_size.y + 2 * m_border}; }
    /// channel_count() floats per pixel, rows of size.x + 2·border; pixel (0, 0) of the data is
    /// film pixel offset - border.
    const std::vector<float> &data() const { return m_data; }

    /// Border (in pixels) that a block needs around it for `filter`: floor(radius + 0.5).
    static int border_for(const ReconstructionFilter &filter);

private:
    Point2i m_offset, m_size;
    int m_border = 0, m_aov_count = 0;
    std::vector<float> m_data;
    /// The storage pixels [x0, x0 + nx) × [y0, y0 + ny) a sample reaches, its separable filter
    /// weights left in m_wx / m_wy, and their sums.
    struct Footprint {
        int x0 = 0, y0 = 0;
        size_t nx = 0, ny = 0;
        float sum_x = 0.f, sum_y = 0.f;
        /// The continuous position in film pixels, the film pixel of storage pixel (0, 0), and
        /// the whole footprint's first and last storage pixels before the clipping.
        float px = 0.f, py = 0.f;
        int ox = 0, oy = 0;
        int ux0 = 0, ux1 = 0, uy0 = 0, uy1 = 0;
    };
    /// False when the sample (non-finite, beyond 1e9 pixels, or outside the block) reaches no
    /// pixel.
    bool footprint(const Point2f &pos, const ReconstructionFilter &filter, Footprint &fp);
    /// put() of a sample that reaches more than one pixel, or outside put()'s one-pixel
    /// shortcut: out of line, so that put()'s shortcut saves no registers.
    void put_footprint(const Point2f &pos, const Color3f &L, const float *aovs,
                       const ReconstructionFilter &filter);

    std::vector<float> m_wx, m_wy; ///< scratch filter weights, reused
};

/// Film: image size, crop window, reconstruction filter and output format. The `hdrfilm` plugin
/// derives from it; the base class owns the pixel storage.
class Film : public Object {
public:
    /// Reads width (768), height (576), crop_offset_x/y, crop_width/height and the nested rfilter
    /// (default gaussian).
    explicit Film(const Properties &props);
    ObjectType type() const override { return ObjectType::Film; }

    Point2i size() const { return m_size; }
    Point2i crop_offset() const { return m_crop_offset; }
    Point2i crop_size() const { return m_crop_size; }
    /// Renders the window `offset` + [0, size) of the film instead of the crop window of the
    /// scene file (validated against the film size; a FACET_THROW names what is wrong).
    void set_crop_window(const Point2i &offset, const Point2i &size);
    /// Back to the crop window of the scene file (crop_offset_x/y, crop_width/height).
    void reset_crop_window();
    const ReconstructionFilter &rfilter() const { return *m_filter; }

    /// Clears the storage for a new render without extra channels.
    void prepare() { prepare({}); }
    /// Clears the storage for a new render with extra (AOV) channels named `aov_names`.
    void prepare(const std::vector<std::string> &aov_names);
    /// Names of the extra channels of the current render.
    const std::vector<std::string> &aov_names() const { return m_aov_names; }
    /// Adds a finished block (the render loop calls this in a fixed order). Pixels outside the
    /// crop window (parts of the filter border) are dropped.
    void put_block(const ImageBlock &block);

    /// Splatting path (light tracers). Adds the r, g, b channels of `block` (filled with
    /// ImageBlock::splat) to a separate splat buffer; develop() adds that buffer, times
    /// splat_scale, to the normalised image, so splats are not divided by sample weights.
    ///
    /// Determinism rule: a light tracer splits its light paths into a fixed number of work units
    /// that does not depend on the thread count, seeds each path's sample stream from (seed, path
    /// index), gives every unit its own block covering the crop window (plus the filter border)
    /// and hands the blocks in strictly in unit order (BlockMerger in render.h): the same seed and
    /// sample count give the same image for any number of threads.
    void put_splats(const ImageBlock &block);
    /// Gives the film a (zero) splat buffer, so a light tracer's image has one even before its
    /// first splat (its raw channels do not depend on how far it got).
    void prepare_splats();
    /// Factor applied to the splat buffer by develop() (1 / light paths per pixel).
    void set_splat_scale(double scale) { m_splat_scale = scale; }
    double splat_scale() const { return m_splat_scale; }
    /// Normalised linear RGB (plus alpha when the pixel format asks) of the crop window, followed
    /// by the AOV channels. Pixels without any sample weight are 0 (and alpha 0). The image's
    /// window (Image::x, y, full_width, full_height) is the crop window inside the film, so an
    /// EXR of a crop has the crop as data window and the whole film as display window.
    virtual Image develop() const;

    /// Raw channels: the sums the crop window is developed from, named "facet.sum.R",
    /// "facet.sum.G", "facet.sum.B", "facet.sum.<aov>" (Σ w·value over the samples that reach
    /// the pixel through the filter), "facet.weight" (Σ w), then "facet.splat.R/G/B" when the
    /// film has a splat buffer. A part of a render split into passes carries them (rounded to
    /// float) after its developed channels, so that passes merge exactly: their sums are added
    /// in pass order and developed once (develop_pixel), whatever the filter.
    std::vector<std::string> raw_channel_names() const;
    /// The raw channels of every crop pixel, rounded to float (raw_channel_names() per pixel).
    std::vector<float> raw_sums() const;
    /// Develops the crop window from `sums` (raw_channel_names() doubles per pixel) and
    /// `splat_scale` instead of the film's own: the render of several passes in one process.
    /// The channels are the base class's (R, G, B, A, AOVs): a film that develops into other
    /// colour channels (hdrfilm's xyz, luminance) is not converted.
    Image develop_sums(const std::vector<double> &sums, double splat_scale) const;
    /// Extension the film writes by default (".exr").
    virtual std::string default_extension() const { return ".exr"; }
    /// Writes `image` to `path` through image I/O (atomically), float16 or float32 as configured.
    virtual void write(const Image &image, const std::string &path,
                       const ImageWriteOptions &opts) const;

    bool half() const { return m_half; }
    bool has_alpha() const { return m_alpha; }
    std::string to_string() const override;

protected:
    Point2i m_size, m_crop_offset, m_crop_size;
    Point2i m_file_crop_offset, m_file_crop_size; ///< the crop window of the scene file
    std::shared_ptr<ReconstructionFilter> m_filter;
    std::vector<double> m_storage; ///< Σ w·L (3), Σ w·aov (per AOV) and Σ w per crop pixel
    std::vector<std::string> m_aov_names;
    std::vector<double> m_splats; ///< Σ splatted r, g, b per crop pixel (empty: none)
    double m_splat_scale = 1.0;
    bool m_half = true;   ///< component_format float16
    bool m_alpha = false; ///< pixel_format rgba
};

/// Prefix of the raw channels (Film::raw_channel_names).
inline constexpr const char *RawChannelPrefix = "facet.";

/// One developed pixel, as Film::develop computes it: `storage` holds Σ w·R, G, B, the
/// `aov_count` AOV sums and Σ w (null: no weighted samples), `splat` the splatted r, g, b (null:
/// none), added times `splat_scale`. Writes R, G, B, A (with `alpha`) and the AOVs to `dst`.
void develop_pixel(const double *storage, int aov_count, const double *splat, double splat_scale,
                   bool alpha, float *dst);

} // namespace facet
