#pragma once

// What the files of libfacet_image (the image and colour module, see image_library.h) share:
//   display.cpp        OpenColorIO: configs, the working space, display/view transforms
//   write.cpp          write_image() of every format but EXR, and the checks of an output path
//   read.cpp           read_image() and its variants: opening a file and reading its pixels
//   header_checks.cpp  the hostile-header checks made before OpenImageIO opens or reads a file
//                      (EXR's are in libfacet, ../exr_headers.cpp: libfacet_read needs them too)
//   png_messages.cpp   keeps libpng from printing its own error messages
//   module.cpp         the table libfacet calls the module through (its one exported symbol)

#include <facet/image.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace facet::detail {

/// The extension of `path`, lower case, with its dot ("" when it has none).
inline std::string lower_extension(const std::string &path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

// display.cpp

/// Display-referred 8-bit pixels for `image`: the channels `ch` (grey, grey+alpha, RGB or RGBA)
/// through the display transform of `opts`.
std::vector<uint8_t> to_display_8bit(const Image &image, const std::vector<int> &ch,
                                     const ImageWriteOptions &opts);

// header_checks.cpp: each throws the error read_image() gives for a hostile header.

/// A BMP's header, read before OpenImageIO decodes it (nothing for another format).
void check_bmp_header(const std::string &path);
/// A TIFF's strips as OpenImageIO will buffer them (`spec`: the file's, as opened).
void check_tiff_strips(const std::string &path, const OIIO::ImageSpec &spec);

} // namespace facet::detail
