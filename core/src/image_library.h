#pragma once

// The interface between libfacet and libfacet_image, the library that holds every use of
// OpenImageIO and OpenColorIO (image.cpp). Those two libraries and their dependencies are
// some 260 shared objects; libfacet loads libfacet_image with dlopen() the first time an image
// is read or written or a display transform is resolved, so that a process pays for them only
// when it touches an image file, not before the scene is loaded or the first ray is traced.
//
//   libfacet.so  --dlopen on first use-->  libfacet_image.so  --links-->  OpenImageIO, OpenColorIO
//   image_api.cpp: the functions of            image.cpp: the implementation (its symbols are
//   facet/image.h, forwarding to the table     local to the library but for the table)
//
// Both sides are built from the same tree: the table is checked by its layout version only.

#include <facet/image.h>

namespace facet::detail {

struct ImageLibrary {
    int version; ///< FACET_IMAGE_LIBRARY_VERSION of the library that filled the table
    void (*write_image)(const std::string &, const Image &, const ImageWriteOptions &);
    void (*check_image_path)(const std::string &);
    void (*check_image_output)(const std::string &, const ImageWriteOptions &);
    OcioDisplays (*ocio_displays)(const std::string &);
    DisplayView (*resolve_display_view)(const ImageWriteOptions &);
    Image (*read_image)(const std::string &);
    ImageFile (*read_image_file)(const std::string &);
    std::string (*ocio_config_path)(const std::string &);
    const char *(*versions)();
};

} // namespace facet::detail

/// Bump when ImageLibrary changes.
#define FACET_IMAGE_LIBRARY_VERSION 1
/// The one symbol libfacet_image exports.
#define FACET_IMAGE_LIBRARY_ENTRY "facet_image_library"
