#pragma once

// The hostile-header check of OpenEXR files, in libfacet for both modules that read them
// (libfacet_read and libfacet_image, see image_library.h).

#include <string>

namespace facet::detail {

/// An EXR's headers, scanned before OpenEXR reads them (nothing for another format): throws the
/// error read_image() gives for a header OpenEXR would allocate or loop from.
void check_exr_headers(const std::string &path);

} // namespace facet::detail
