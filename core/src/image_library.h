#pragma once

// The interface between libfacet and its three image modules: libfacet_image, which holds every
// use of OpenImageIO and OpenColorIO (image/), libfacet_exr, the EXR writer on OpenEXR alone
// (exr.cpp), and libfacet_read, the readers of the formats scenes use most (EXR on OpenEXR, PNG
// on libpng, JPEG on libjpeg: read/), together a few MiB. OpenImageIO, OpenColorIO and their
// dependencies are some 260 shared objects and 120 MiB of memory; libfacet loads libfacet_image
// with dlopen() the first time an image is read or a non-EXR image written or a display transform
// is resolved, so that a process pays for them only when it touches such a file, not before the
// scene is loaded or the first ray is traced, and a render to .exr (the default output) not at all.
// An image is read by libfacet_read when it is one of the files it reads (read/read_module.h says
// which), else by libfacet_image: a scene whose textures and environment maps are such files (most
// scenes) never loads OpenImageIO.
//
//   libfacet.so  --dlopen on first use-->  libfacet_image.so  --links-->  OpenImageIO, OpenColorIO
//                --dlopen to write .exr->  libfacet_exr.so    --links-->  OpenEXR
//                --dlopen to read------->  libfacet_read.so   --links-->  OpenEXR, libpng, libjpeg
//   image_api.cpp: the functions of            image/*.cpp, exr.cpp: the implementations (their
//   facet/image.h, forwarding to the tables    symbols are local to the module but for the table)
//
// Both sides are built from the same tree: a table is checked by its layout version only.

#include <facet/image.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

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

/// A read by libfacet_read: what read_image(), read_image_header() and read_image_bytes() return.
struct LeanRead {
    bool header_only = false;        ///< in: sizes, windows and channel names, no pixels
    bool want_bytes = false;         ///< in: 8-bit values kept as stored (read_image_bytes())
    Image image;                     ///< out: pixels as floats, unless `bytes` holds them
    bool keeps_bytes = false;        ///< out: the values are bytes, read (or readable) as stored
    std::vector<uint8_t> bytes;      ///< out: the interleaved bytes (want_bytes and keeps_bytes)
    std::array<float, 256> values{}; ///< out: the float each byte value converts to
};

/// libfacet_read's table.
struct ReadLibrary {
    int version; ///< FACET_READ_LIBRARY_VERSION of the library that filled the table
    /// Reads `path` into `read` when it is a file the module reads, by its contents. False,
    /// with `read.image` empty, for any other file, and for one it cannot read (libfacet_image
    /// then reads it, or gives the error). Never throws.
    bool (*read)(const std::string &path, LeanRead &read);
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
/// Bump when ReadLibrary or LeanRead changes.
#define FACET_READ_LIBRARY_VERSION 1
/// The one symbol libfacet_read exports.
#define FACET_READ_LIBRARY_ENTRY "facet_read_library"
