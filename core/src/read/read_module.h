#pragma once

// What the files of libfacet_read (the lean image readers, see image_library.h) share:
//   module.cpp  the table libfacet calls the module through, and which reader a file goes to
//               (by its first bytes, as libfacet_image falls back to a file's contents)
//   exr.cpp     OpenEXR files, on OpenEXR
//   png.cpp     PNG files, on libpng
//   jpeg.cpp    JPEG files, on libjpeg
// Each reader reads the files it can read exactly as libfacet_image reads them: the same sizes,
// windows, channel names and order, and the same float for every value, bit for bit
// (tests/unit/core/lean_read.cpp compares the two modules file by file). It returns false for
// any other file (a feature it leaves to OpenImageIO, a header that fails a check, a decoding
// error), which libfacet_image then reads or reports. No reader throws or prints.

#include "image_library.h"

#include <cstdint>
#include <string>

namespace facet::detail {

bool read_exr(const std::string &path, LeanRead &read);
bool read_png(const std::string &path, LeanRead &read);
bool read_jpeg(const std::string &path, LeanRead &read);

/// The float libfacet_image (OpenImageIO) gives an 8-bit value: v / 255, as it rounds it.
float unorm8_to_float(uint8_t v);
/// The float libfacet_image gives a 16-bit value: v / 65535, as it rounds it.
float unorm16_to_float(uint16_t v);

} // namespace facet::detail
