// OpenEXR files, on OpenEXR: single-part flat images, in scanlines or tiles (the full-resolution
// level of a tiled file, as libfacet_image reads it), whose channels are R, G, B (and A) or Y
// (and A) of half or float values, each sampled at every pixel. Layers, other channel names,
// 32-bit integer channels, subsampled (luminance-chroma) channels, deep and multi-part files are
// left to libfacet_image, which orders and converts them its own way.
#include "exr_headers.h"
#include "read_module.h"

#include <facet/checked.h>

#include <Imath/ImathBox.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfVersion.h>

#include <algorithm>
#include <string>
#include <vector>

namespace facet::detail {

namespace {

/// The channels in the order libfacet_image gives them (colour, then alpha), or none when the
/// file's channels are not one of the sets this reader takes.
std::vector<std::string> ordered_channels(const Imf::ChannelList &channels) {
    std::vector<std::string> names;
    for (auto it = channels.begin(); it != channels.end(); ++it) {
        const Imf::Channel &c = it.channel();
        if (c.xSampling != 1 || c.ySampling != 1 || (c.type != Imf::HALF && c.type != Imf::FLOAT))
            return {};
        names.emplace_back(it.name());
    }
    std::sort(names.begin(), names.end());
    for (std::vector<std::string> order :
         {std::vector<std::string>{"R", "G", "B"}, {"R", "G", "B", "A"}, {"Y"}, {"Y", "A"}}) {
        std::vector<std::string> sorted = order;
        std::sort(sorted.begin(), sorted.end());
        if (sorted == names) return order;
    }
    return {};
}

} // namespace

bool read_exr(const std::string &path, LeanRead &read) {
    check_exr_headers(path); // throws on a hostile header: libfacet_image gives the error
    Imf::InputFile file(path.c_str());
    if (Imf::isMultiPart(file.version()) || Imf::isNonImage(file.version())) return false;
    const Imf::Header &header = file.header();
    const std::vector<std::string> names = ordered_channels(header.channels());
    if (names.empty()) return false;
    const Imath::Box2i data = header.dataWindow(), display = header.displayWindow();
    Image &img = read.image;
    img.width = data.max.x - data.min.x + 1;
    img.height = data.max.y - data.min.y + 1;
    img.channels = int(names.size());
    img.channel_names = names;
    img.x = data.min.x - display.min.x;
    img.y = data.min.y - display.min.y;
    img.full_width = display.max.x - display.min.x + 1;
    img.full_height = display.max.y - display.min.y + 1;
    if (img.width <= 0 || img.height <= 0 || img.full_width <= 0 || img.full_height <= 0)
        return false;
    const size_t row = size_t(img.width) * size_t(img.channels);
    size_t values = 0;
    if (!checked_mul(row, size_t(img.height), values)) return false;
    allocation_bytes(values, sizeof(float), path, "image pixels"); // throws past the limit
    if (read.header_only) return true;
    // Read in bands of rows, growing the buffer as rows arrive: a header that claims more pixels
    // than a truncated file holds fails at its first missing row, not after the whole buffer.
    const int band = int(std::clamp<size_t>((size_t(1) << 22) / row, 1, 4096));
    for (int y0 = 0; y0 < img.height; y0 += band) {
        const int y1 = std::min(img.height, y0 + band);
        img.data.resize(size_t(y1) * row);
        Imf::FrameBuffer frame;
        for (int c = 0; c < img.channels; ++c) {
            // Slice::Make places the data window's origin at the buffer's first value.
            frame.insert(names[size_t(c)], Imf::Slice::Make(Imf::FLOAT, img.data.data() + c, data,
                                                            sizeof(float) * size_t(img.channels),
                                                            sizeof(float) * row));
        }
        file.setFrameBuffer(frame);
        file.readPixels(data.min.y + y0, data.min.y + y1 - 1);
    }
    return true;
}

} // namespace facet::detail
