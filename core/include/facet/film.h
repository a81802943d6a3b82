#pragma once

#include <facet/color.h>
#include <facet/image.h>
#include <facet/object.h>
#include <facet/properties.h>
#include <facet/rfilter.h>
#include <facet/vector.h>

#include <memory>
#include <string>

namespace facet {

/// Accumulates filtered samples for a rectangle of pixels (a render block plus the filter border).
/// Each pixel stores Σ w·L and Σ w.
class ImageBlock {
public:
    ImageBlock() = default;
    /// `offset`/`size` are the block's pixels in film coordinates; `border` extra pixels each side.
    void reset(const Point2i &offset, const Point2i &size, int border);
    /// Adds radiance L at continuous film position `pos` (pixel centres at .5) with the filter.
    void put(const Point2f &pos, const Color3f &L, const ReconstructionFilter &filter);
    const Point2i &offset() const { return m_offset; }
    const Point2i &size() const { return m_size; }
    int border() const { return m_border; }
    /// 4 floats per pixel (r, g, b, weight), rows of size.x + 2·border.
    const std::vector<float> &data() const { return m_data; }

private:
    Point2i m_offset, m_size;
    int m_border = 0;
    std::vector<float> m_data;
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
    const ReconstructionFilter &rfilter() const { return *m_filter; }

    /// Clears the storage for a new render.
    void prepare();
    /// Adds a finished block (the render loop calls this in a fixed order).
    void put_block(const ImageBlock &block);
    /// Normalised linear RGB (plus alpha when the pixel format asks) of the crop window.
    virtual Image develop() const;
    /// Extension the film writes by default (".exr").
    virtual std::string default_extension() const { return ".exr"; }
    /// Writes `image` to `path` through image I/O (atomically), float16 or float32 as configured.
    virtual void write(const Image &image, const std::string &path, const ImageWriteOptions &opts) const;

    std::string to_string() const override;

protected:
    Point2i m_size, m_crop_offset, m_crop_size;
    std::shared_ptr<ReconstructionFilter> m_filter;
    std::vector<double> m_storage; ///< Σ w·L (3) and Σ w per crop pixel
    bool m_half = true;            ///< component_format float16
    bool m_alpha = false;          ///< pixel_format rgba
};

} // namespace facet
