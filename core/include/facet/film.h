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

class SpectralTexture;

/// Accumulates filtered samples for a rectangle of pixels (a render block plus the filter border).
/// Each pixel stores Σ w·value for each colour channel (r, g, b, or a film's spectral bands),
/// Σ w·aov for every extra channel, and Σ w.
class ImageBlock {
public:
    ImageBlock() = default;
    /// `offset`/`size` are the block's pixels in film coordinates; `border` extra pixels each side;
    /// `aov_count` extra channels after the `colour_count` colour channels (r, g, b by default).
    /// Reuses the existing memory when it is big enough.
    void reset(const Point2i &offset, const Point2i &size, int border, int aov_count = 0,
               int colour_count = 3);
    /// Adds radiance L at continuous film position `pos` (pixel centres at .5) with the filter.
    /// Extra channels receive zero. (A block of r, g, b.)
    void put(const Point2f &pos, const Color3f &L, const ReconstructionFilter &filter) {
        put(pos, L, nullptr, filter);
    }
    /// The same with `aov_count()` extra values (`aovs` may be null when there are none).
    void put(const Point2f &pos, const Color3f &L, const float *aovs,
             const ReconstructionFilter &filter);
    /// Adds a sample of any block: `values` holds its colour_count() colour values, then its
    /// aov_count() extra ones.
    void put_values(const Point2f &pos, const float *values, const ReconstructionFilter &filter);
    /// Splats L at `pos` for a light tracer: the filter weights over the footprint are normalised
    /// to sum to one and only r, g, b receive them (the weight channel stays untouched), so the
    /// energy of a splat lands on the film whatever the filter. FilmBuffer::put_splats() takes
    /// the result.
    void splat(const Point2f &pos, const Color3f &L, const ReconstructionFilter &filter);
    const Point2i &offset() const { return m_offset; }
    const Point2i &size() const { return m_size; }
    int border() const { return m_border; }
    int aov_count() const { return m_aov_count; }
    int colour_count() const { return m_colour_count; }
    /// Floats per pixel: the colours, the AOVs, weight (4 for r, g, b without AOVs).
    int channel_count() const { return m_colour_count + m_aov_count + 1; }
    /// Pixels per row/column of data(): size + 2·border.
    Point2i storage_size() const { return {m_size.x + 2 * m_border, m_size.y + 2 * m_border}; }
    /// channel_count() floats per pixel, rows of size.x + 2·border; pixel (0, 0) of the data is
    /// film pixel offset - border.
    const std::vector<float> &data() const { return m_data; }

    /// Border (in pixels) that a block needs around it for `filter`: floor(radius + 0.5).
    static int border_for(const ReconstructionFilter &filter);

private:
    Point2i m_offset, m_size;
    int m_border = 0, m_aov_count = 0, m_colour_count = 3;
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
    /// footprint()'s pixels, without the weights.
    bool footprint_range(const Point2f &pos, float radius, Footprint &fp) const;
    /// footprint()'s weights, into wx[0, nx) and wy[0, ny).
    static void footprint_weights(const TabulatedFilter &w, Footprint &fp, float *wx, float *wy);
    /// footprint()'s weights into m_wx and m_wy.
    void scratch_weights(const TabulatedFilter &w, Footprint &fp);
    /// put() of a sample that reaches more than one pixel, or outside put()'s one-pixel
    /// shortcut: out of line, so that put()'s shortcut saves no registers. `table` is the
    /// filter's.
    void put_footprint(const Point2f &pos, const Color3f &L, const float *aovs,
                       const ReconstructionFilter &filter, const TabulatedFilter &table);
    /// The widest footprint (pixels along an axis) put_footprint() takes without the general
    /// loop.
    static constexpr size_t SmallFootprint = 8;
    /// For a box filter of constant weight `c` (single_pixel_weight(), 0 for other filters) at
    /// an ordinary film position: true, with the one pixel the sample reaches (null: outside
    /// the block). False: the footprint decides.
    bool single_pixel(const Point2f &pos, float c, float *&pixel);
    /// add(pixel, weight) for each pixel of footprint `fp` (its range found by
    /// footprint_range()) with a non-zero weight of the filter `table`.
    template <typename Add>
    void for_each_footprint_pixel(Footprint &fp, const TabulatedFilter &table, Add add);

    std::vector<float> m_wx, m_wy; ///< scratch filter weights, reused
};

/// The accumulation buffers of one render: for a window of film pixels, Σ w·value per colour
/// channel (r, g, b, or a film's spectral bands), Σ w·aov per AOV channel and Σ w per pixel, and
/// for a light tracer a splat buffer of r, g, b. A render owns its buffer; the Film only
/// describes how to develop and store it, so one Film (and one Scene) may serve any number of
/// renders at once.
class FilmBuffer {
public:
    /// The window `offset` + [0, size) of the film, with the colour channels R, G, B, the extra
    /// channels `aov_names`, and a splat buffer when `splats`. Refuses (FACET_THROW) buffers
    /// beyond an 8 GiB budget instead of failing in the allocator (or the kernel's OOM killer).
    FilmBuffer(const Point2i &offset, const Point2i &size, std::vector<std::string> aov_names,
               bool splats = false);
    /// The same with the colour channels `colour_names` (Film::colour_channels()); a splat
    /// buffer needs R, G, B.
    FilmBuffer(const Point2i &offset, const Point2i &size, std::vector<std::string> colour_names,
               std::vector<std::string> aov_names, bool splats);

    const Point2i &offset() const { return m_offset; }
    const Point2i &size() const { return m_size; }
    const std::vector<std::string> &colour_names() const { return m_colour_names; }
    const std::vector<std::string> &aov_names() const { return m_aov_names; }
    bool has_splats() const { return !m_splats.empty(); }
    /// Floats per pixel of sums(): the colours, the AOVs, weight.
    size_t channel_count() const { return m_colour_names.size() + m_aov_names.size() + 1; }

    /// Adds a finished block (the render loop calls this in a fixed order). Pixels outside the
    /// window (parts of the filter border) are dropped.
    void put_block(const ImageBlock &block);
    /// Adds the r, g, b channels of `block` (filled with ImageBlock::splat) to the splat buffer;
    /// development adds that buffer, times splat_scale(), to the normalised image, so splats are
    /// not divided by sample weights.
    void put_splats(const ImageBlock &block);
    /// Factor applied to the splat buffer when developing (1 / light paths per pixel).
    void set_splat_scale(double scale) { m_splat_scale = scale; }
    double splat_scale() const { return m_splat_scale; }

    /// channel_count() sums per window pixel, in scanline order (float, as the blocks: half
    /// the memory of doubles; a pass adds each pixel's blocks in a fixed order).
    const std::vector<float> &sums() const { return m_sums; }
    /// 3 splat sums per window pixel (empty without a splat buffer).
    const std::vector<float> &splats() const { return m_splats; }

    /// Raw channels: the sums the window is developed from, named "facet.sum.<colour>" (R, G, B
    /// or the film's bands), "facet.sum.<aov>" (Σ w·value over the samples that reach the pixel
    /// through the filter), "facet.weight" (Σ w), then "facet.splat.R/G/B" with a splat buffer.
    /// A part of a render split into passes carries them (rounded to float) after its developed
    /// channels, so that passes merge exactly: their sums are added in pass order and developed
    /// once (develop_pixel), whatever the filter.
    std::vector<std::string> raw_channel_names() const;
    /// The raw channels of every window pixel, rounded to float (raw_channel_names() per pixel).
    std::vector<float> raw_sums() const;
    /// Replaces the sums (and splats) by `raw`, raw_channel_names() doubles per pixel: the sums
    /// of several passes added up, developed once. They are kept in double (raw()).
    void set_raw_sums(const std::vector<double> &raw);
    /// The sums set_raw_sums() gave (empty: none), which development takes instead of sums().
    const std::vector<double> &raw() const { return m_raw; }

private:
    Point2i m_offset, m_size;
    std::vector<std::string> m_colour_names, m_aov_names;
    std::vector<float> m_sums;   ///< channel_count() per window pixel
    std::vector<float> m_splats; ///< 3 per window pixel (empty: none)
    std::vector<double> m_raw;   ///< set_raw_sums()
    double m_splat_scale = 1.0;
};

/// The spectral bands a film records instead of R, G, B (the `specfilm` plugin): one channel per
/// sensor response function (SRF) s_j, the radiance weighted by it, ∫ s_j(λ) L(λ) dλ. A path's
/// wavelengths are drawn (stratified, as sample_wavelengths()) from the sum S of the SRFs,
/// tabulated on a regular grid and interpolated linearly, so every band's wavelengths get
/// samples; a path's band j is the mean over its wavelengths of s_j(λ)·L(λ) / pdf(λ).
class SpectralBands {
public:
    struct Band {
        std::string name;
        /// Evaluated at the path's wavelengths (a spectral texture of the spectral modes, or a
        /// constant).
        std::shared_ptr<Texture> srf;
    };
    /// The bands (their channels in this order) and the grid of S: `points` values from
    /// `lambda_min` to `lambda_max` nm (both included, within 360-830 nm). Throws facet::Error
    /// when S has no positive value on the grid.
    SpectralBands(std::vector<Band> bands, float lambda_min, float lambda_max, size_t points);
    /// The bands on the grid their responses call for: from the smallest to the largest
    /// wavelength a tabulated response is given at (360-830 nm for one that is not, such as a
    /// constant), at their finest spacing and at least every nanometre, cut to 360-830 nm (with
    /// a warning for a response given partly outside). Throws facet::Error, without a
    /// location, for a response given only outside that range or responses zero everywhere.
    static std::shared_ptr<const SpectralBands> fit(std::vector<Band> bands);

    size_t size() const { return m_bands.size(); }
    const std::vector<std::string> &names() const { return m_names; }
    /// The four wavelengths of a path from one uniform number `u` (u + i/4 modulo 1), each
    /// drawn from S by inversion, with their weights 1 / pdf.
    std::pair<Wavelengths, Color3f> sample_wavelengths(float u) const;
    /// The density sample_wavelengths() draws each lane from (per nm; 0 outside the grid).
    float pdf(float lambda) const;
    /// Band j's response at `lambda`.
    Color3f eval(size_t j, const Wavelengths &lambda) const;
    /// The bands of a path's radiance `L` at `lambda` (drawn with weights `weight`): size()
    /// values written to `out`.
    void develop(const Color3f &L, const Wavelengths &lambda, const Color3f &weight,
                 float *out) const;
    float lambda_min() const { return m_min; }
    float lambda_max() const { return m_max; }

private:
    std::vector<Band> m_bands;
    std::vector<const SpectralTexture *> m_spectral; ///< per band: its srf as one, or null
    std::vector<std::string> m_names;
    float m_min = 0.f, m_max = 0.f, m_step = 0.f;
    std::vector<float> m_values; ///< S at the grid points (negative parts cut to 0)
    std::vector<double> m_cdf;   ///< of the grid's segments, normalised; points values
    double m_integral = 0.0;     ///< ∫ S over the grid
};

/// Film: image size, crop window, reconstruction filter and output format: a read-only
/// description during a render. The `hdrfilm` plugin derives from it.
class Film : public Object {
public:
    /// Reads width (768), height (576; at most 2^27 pixels), crop_offset_x/y, crop_width/height,
    /// component_format (float16 or float32) and the nested rfilter (default gaussian).
    explicit Film(const Properties &props);
    ObjectType type() const override { return ObjectType::Film; }

    Point2i size() const { return m_size; }
    /// The crop window of the scene file (crop_offset_x/y, crop_width/height).
    Point2i crop_offset() const { return m_crop_offset; }
    Point2i crop_size() const { return m_crop_size; }
    /// Throws (naming what is wrong) unless the window `offset` + [0, size) is non-empty and lies
    /// inside the film: a render's own crop window (RenderOptions::crop).
    void check_crop_window(const Point2i &offset, const Point2i &size) const;
    const ReconstructionFilter &rfilter() const { return *m_filter; }
    /// The bands the film records in the spectral modes instead of R, G, B (null: R, G, B, the
    /// path's XYZ as linear Rec.709). A film with bands also draws the path's wavelengths.
    const SpectralBands *bands() const { return m_bands.get(); }
    /// The names of the colour channels the film accumulates: R, G, B, or its bands'.
    std::vector<std::string> colour_channels() const;

    /// The normalised colour channels (linear RGB or the bands; alpha after them when the pixel
    /// format asks) of the buffer's window, followed by the AOV channels. Pixels without any sample
    /// weight are 0 (and alpha 0). The image's window (Image::x, y, full_width, full_height) is the
    /// buffer's window inside the film, so an EXR of a crop has the crop as data window and the
    /// whole film as display window.
    virtual Image develop(const FilmBuffer &buffer) const;
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
    std::shared_ptr<ReconstructionFilter> m_filter;
    bool m_half = true;   ///< component_format float16
    bool m_alpha = false; ///< pixel_format rgba
    std::shared_ptr<const SpectralBands> m_bands;
};

/// Prefix of the raw channels (Film::raw_channel_names).
inline constexpr const char *RawChannelPrefix = "facet.";

/// One developed pixel, as Film::develop computes it: `storage` holds the `values` sums Σ w·v
/// (the colours, then the AOVs) and Σ w (null: no weighted samples), `splat` the splatted r, g,
/// b (null: none), added times `splat_scale` to the first three values. Writes the values
/// divided by Σ w to `dst`, with the alpha (1 where the pixel has a weight or a splat) inserted
/// before value `alpha_at` (none: -1).
void develop_pixel(const double *storage, int values, const double *splat, double splat_scale,
                   int alpha_at, float *dst);
/// The same from float sums (a FilmBuffer's), in double arithmetic.
void develop_pixel(const float *storage, int values, const float *splat, double splat_scale,
                   int alpha_at, float *dst);

} // namespace facet
