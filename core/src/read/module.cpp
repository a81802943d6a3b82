// libfacet_read: libfacet loads this module to read an image (image_api.cpp) and calls it
// through this table, the one symbol the module exports (image_library.h). A file goes to the
// reader its first bytes name, whatever its extension, as libfacet_image reads a file whose
// extension names another format by its contents.
#include "read_module.h"

#include <OpenEXR/OpenEXRConfig.h>
#include <fmt/format.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <jpeglib.h>
#include <memory>
#include <png.h>

namespace facet::detail {

float unorm8_to_float(uint8_t v) { return float(v) * (1.0f / 255.0f); }

float unorm16_to_float(uint16_t v) { return float(v) * (1.0f / 65535.0f); }

namespace {

bool lean_read(const std::string &path, LeanRead &read) {
    unsigned char magic[8] = {};
    {
        std::unique_ptr<std::FILE, int (*)(std::FILE *)> f(std::fopen(path.c_str(), "rb"),
                                                           &std::fclose);
        if (!f || std::fread(magic, 1, sizeof magic, f.get()) != sizeof magic) return false;
    }
    for (int i = 0; i < 256; ++i) read.values[size_t(i)] = unorm8_to_float(uint8_t(i));
    const unsigned char exr[4] = {0x76, 0x2f, 0x31, 0x01};
    const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    bool ok = false;
    try {
        if (std::memcmp(magic, exr, 4) == 0)
            ok = read_exr(path, read);
        else if (std::memcmp(magic, png, 8) == 0)
            ok = read_png(path, read);
        else if (magic[0] == 0xff && magic[1] == 0xd8 && magic[2] == 0xff)
            ok = read_jpeg(path, read);
    } catch (const std::exception &) {
        ok = false; // std::bad_alloc, or a library's exception: libfacet_image reports it
    }
    if (!ok) {
        read.image = Image();
        read.bytes = {};
        read.keeps_bytes = false;
    }
    return ok;
}

} // namespace

} // namespace facet::detail

extern "C" __attribute__((visibility("default"))) const facet::detail::ReadLibrary *
facet_read_library() {
    static const std::string versions =
        fmt::format("OpenEXR {}, libpng {}, libjpeg {}", OPENEXR_VERSION_STRING,
                    PNG_LIBPNG_VER_STRING, JPEG_LIB_VERSION);
    static const facet::detail::ReadLibrary table = {
        FACET_READ_LIBRARY_VERSION, &facet::detail::lean_read, [] { return versions.c_str(); }};
    return &table;
}
