#pragma once

// The interface between libfacet and its two image modules: libfacet_image, which holds every
// use of OpenImageIO and OpenColorIO (image/), and libfacet_exr, the EXR writer on OpenEXR
// alone (exr.cpp). OpenImageIO, OpenColorIO and their dependencies are some 260 shared objects
// and 120 MiB of memory; libfacet loads libfacet_image with dlopen() the first time an image is
// read or a non-EXR image written or a display transform is resolved, so that a process pays
// for them only when it touches such a file, not before the scene is loaded or the first ray is
// traced, and a render to .exr (the default output) not at all.
//
//   libfacet.so  --dlopen on first use-->  libfacet_image.so  --links-->  OpenImageIO, OpenColorIO
//                --dlopen to write .exr->  libfacet_exr.so    --links-->  OpenEXR
//   image_api.cpp: the functions of            image/*.cpp, exr.cpp: the implementations (their
//   facet/image.h, forwarding to the tables    symbols are local to the module but for the table)
//
// Both sides are built from the same tree: a table is checked by its layout version only.

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
    ImageHeader (*read_image_header)(const std::string &);
    ByteImage (*read_image_bytes)(const std::string &);
};

/// libfacet_exr's table.
struct ExrLibrary {
    int version; ///< FACET_EXR_LIBRARY_VERSION of the library that filled the table
    /// write_image() of an .exr: the image is valid and the folder exists (checked by the caller).
    void (*write_exr)(const std::string &, const Image &, const ImageWriteOptions &);
    const char *(*versions)();
};

} // namespace facet::detail

/// Bump when ImageLibrary changes.
#define FACET_IMAGE_LIBRARY_VERSION 2
/// The one symbol libfacet_image exports.
#define FACET_IMAGE_LIBRARY_ENTRY "facet_image_library"
/// Bump when ExrLibrary changes.
#define FACET_EXR_LIBRARY_VERSION 1
/// The one symbol libfacet_exr exports.
#define FACET_EXR_LIBRARY_ENTRY "facet_exr_library"
