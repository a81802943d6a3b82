#pragma once

#include <facet/assert.h>

#include <map>
#include <string>
#include <vector>

namespace facet {

/// Interleaved float image.
struct Image {
    int width = 0, height = 0, channels = 0;
    /// Where the pixels lie in a larger image (OpenEXR's data and display windows): this image
    /// is the window at (x, y) of a full_width x full_height one (0: the image itself). A film's
    /// crop window is developed so; EXR files keep both windows.
    int x = 0, y = 0, full_width = 0, full_height = 0;
    std::vector<std::string> channel_names;
    std::vector<float> data;

    Image() = default;
    Image(int w, int h, int c) : width(w), height(h), channels(c), data(size_t(w) * h * c, 0.f) {}
    float &at(int x, int y, int c) {
        FACET_ASSERT(x >= 0 && x < width && y >= 0 && y < height && c >= 0 && c < channels);
        return data[(size_t(y) * width + x) * channels + c];
    }
    float at(int x, int y, int c) const {
        FACET_ASSERT(x >= 0 && x < width && y >= 0 && y < height && c >= 0 && c < channels);
        return data[(size_t(y) * width + x) * channels + c];
    }
};

struct ImageWriteOptions {
    bool half = false;       ///< float16 for EXR
    std::string ocio_config; ///< "" = $OCIO, else the installed config
    std::string display = "sRGB";
    std::string view = "Standard";
    std::map<std::string, std::string> metadata;
};

/// Writes with OpenImageIO to a temporary file next to `path`, then renames it over `path`.
/// .exr/.hdr/.pfm stay scene-linear; 8-bit formats (.png, .jpg, ...) go through the OpenColorIO
/// display/view transform of the chosen config.
void write_image(const std::string &path, const Image &image, const ImageWriteOptions &opts = {});
/// Reads any format OpenImageIO knows; 8-bit images are returned as stored (no decoding).
Image read_image(const std::string &path);
/// Path of the OCIO config facet uses: `explicit_path`, else $OCIO, else the installed one.
std::string ocio_config_path(const std::string &explicit_path = "");

} // namespace facet
