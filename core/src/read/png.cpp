// PNG files, on libpng, transformed as libfacet_image (OpenImageIO 2.4) reads them: a palette
// expanded to RGB, grey of 1, 2 or 4 bits expanded to 8, a tRNS chunk expanded to an alpha
// channel, 16-bit values kept (and converted as it converts them); colour stays as stored (no
// gamma, no premultiplied alpha). Channels: Y, Y A, R G B or R G B A.
//
// libpng reports errors by longjmp(): every call that can fail runs in a function of its own
// that holds no C++ object (png_guarded()), so that no destructor is skipped.
#include "read_module.h"

#include <facet/checked.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <memory>
#include <png.h>
#include <string>
#include <vector>

namespace facet::detail {

namespace {

/// The most bytes of pixel rows a PNG can store per byte of file: deflate's 1032:1, with a
/// factor of two to spare. A header that declares more is not read here (libfacet_image reads
/// or refuses it): the lean reader allocates only what a file can hold.
constexpr double MaxPngRatio = 2 * 1032.0;

void on_error(png_structp png, png_const_charp) { png_longjmp(png, 1); }
void on_warning(png_structp, png_const_charp) {} // ancillary chunks: nothing changes a pixel

/// Runs `f()` with libpng's errors caught: false when libpng reported one.
template <typename F> bool png_guarded(png_structp png, F &&f) {
    if (setjmp(png_jmpbuf(png))) return false;
    f();
    return true;
}

struct PngFile {
    std::FILE *file = nullptr;
    png_structp png = nullptr;
    png_infop info = nullptr;
    ~PngFile() {
        if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
        if (file) std::fclose(file);
    }
};

} // namespace

bool read_png(const std::string &path, LeanRead &read) {
    PngFile in;
    in.file = std::fopen(path.c_str(), "rb");
    if (!in.file) return false;
    std::fseek(in.file, 0, SEEK_END);
    const long file_size = std::ftell(in.file);
    std::rewind(in.file);
    in.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, &on_error, &on_warning);
    if (!in.png) return false;
    in.info = png_create_info_struct(in.png);
    if (!in.info) return false;
    png_structp png = in.png;
    png_infop info = in.info;
    png_uint_32 width = 0, height = 0;
    int depth = 0, colour = 0, interlace = 0;
    const bool configured = png_guarded(png, [&] {
        png_init_io(png, in.file);
        png_read_info(png, info);
        png_get_IHDR(png, info, &width, &height, &depth, &colour, &interlace, nullptr, nullptr);
        if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
        if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
        if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
        if (interlace != PNG_INTERLACE_NONE) png_set_interlace_handling(png);
        png_read_update_info(png, info);
    });
    if (!configured || width == 0 || height == 0) return false;
    const int channels = png_get_channels(png, info);
    const int bits = png_get_bit_depth(png, info);
    if (channels < 1 || channels > 4 || (bits != 8 && bits != 16)) return false;
    const size_t row_bytes = png_get_rowbytes(png, info);
    const size_t row = size_t(width) * size_t(channels);
    if (row_bytes != row * size_t(bits / 8)) return false;

    Image &img = read.image;
    img.width = int(width);
    img.height = int(height);
    img.channels = channels;
    static const char *const names[4][4] = {
        {"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
    img.channel_names.assign(names[channels - 1], names[channels - 1] + channels);
    img.full_width = img.width;
    img.full_height = img.height;
    size_t values = 0;
    if (!checked_mul(row, size_t(height), values)) return false;
    allocation_bytes(values, sizeof(float), path, "image pixels"); // throws past the limit
    if (double(values) * (bits / 8) > MaxPngRatio * double(std::max(file_size, 1L))) return false;
    read.keeps_bytes = bits == 8;
    if (read.header_only) return true;

    const bool bytes = read.want_bytes && read.keeps_bytes;
    std::vector<png_byte> stored;
    if (interlace != PNG_INTERLACE_NONE) {
        // Interlaced rows come in seven passes over the whole image.
        stored.resize(row_bytes * height);
        std::vector<png_bytep> rows(height);
        for (png_uint_32 y = 0; y < height; ++y) rows[y] = stored.data() + row_bytes * y;
        if (!png_guarded(png, [&] { png_read_image(png, rows.data()); })) return false;
    } else {
        // Row by row, growing the buffer as rows arrive: a truncated file fails at its first
        // missing row, not after the whole buffer has been allocated.
        png_bytep at = nullptr;
        for (png_uint_32 y = 0; y < height; ++y) {
            stored.resize(row_bytes * (size_t(y) + 1));
            at = stored.data() + row_bytes * y;
            if (!png_guarded(png, [&] { png_read_row(png, at, nullptr); })) return false;
        }
    }
    if (bytes) {
        read.bytes = std::move(stored);
        return true;
    }
    img.data.resize(values);
    if (bits == 8) {
        for (size_t i = 0; i < values; ++i) img.data[i] = read.values[stored[i]];
    } else {
        for (size_t i = 0; i < values; ++i)
            img.data[i] = unorm16_to_float(uint16_t(stored[2 * i] << 8 | stored[2 * i + 1]));
    }
    return true;
}

} // namespace facet::detail
