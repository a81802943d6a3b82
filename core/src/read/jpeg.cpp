// JPEG files, on libjpeg, decoded as libfacet_image (OpenImageIO 2.4) decodes them: libjpeg's
// default decompression (the accurate integer DCT, fancy upsampling) to grey (Y) or RGB. CMYK
// and YCCK files, which it converts its own way, are left to it, and so is any file libjpeg
// warns about (a truncated or corrupt stream that libjpeg would pad with grey).
//
// libjpeg reports errors by longjmp(): every call that can fail runs in a function of its own
// that holds no C++ object (jpeg_guarded()), so that no destructor is skipped.
#include "read_module.h"

#include <facet/checked.h>

#include <csetjmp>
#include <cstdio>
// jpeglib.h needs size_t and FILE declared before it.
#include <jpeglib.h>
#include <string>
#include <vector>

namespace facet::detail {

namespace {

struct JpegErrors {
    jpeg_error_mgr mgr;  ///< first: libjpeg's pointer to it is a pointer to this
    std::jmp_buf jump;   ///< where an error returns to
    bool warned = false; ///< libjpeg met corrupt data it decodes anyway
};

void on_error(j_common_ptr info) {
    std::longjmp(reinterpret_cast<JpegErrors *>(info->err)->jump, 1);
}

void on_message(j_common_ptr info, int level) {
    if (level < 0) reinterpret_cast<JpegErrors *>(info->err)->warned = true;
}

/// Runs `f()` with libjpeg's errors caught: false when libjpeg reported one.
template <typename F> bool jpeg_guarded(JpegErrors &errors, F &&f) {
    if (setjmp(errors.jump)) return false;
    f();
    return true;
}

struct JpegFile {
    std::FILE *file = nullptr;
    jpeg_decompress_struct info{};
    JpegErrors errors{};
    bool created = false;
    ~JpegFile() {
        if (created) jpeg_destroy_decompress(&info);
        if (file) std::fclose(file);
    }
};

} // namespace

bool read_jpeg(const std::string &path, LeanRead &read) {
    JpegFile in;
    in.file = std::fopen(path.c_str(), "rb");
    if (!in.file) return false;
    jpeg_decompress_struct &info = in.info;
    info.err = jpeg_std_error(&in.errors.mgr);
    in.errors.mgr.error_exit = &on_error;
    in.errors.mgr.emit_message = &on_message;
    if (!jpeg_guarded(in.errors, [&] { jpeg_create_decompress(&info); })) return false;
    in.created = true;
    bool supported = false;
    const bool started = jpeg_guarded(in.errors, [&] {
        jpeg_stdio_src(&info, in.file);
        jpeg_read_header(&info, TRUE);
        supported = info.jpeg_color_space == JCS_GRAYSCALE || info.jpeg_color_space == JCS_YCbCr ||
                    info.jpeg_color_space == JCS_RGB;
        if (!supported) return;
        info.out_color_space = info.jpeg_color_space == JCS_GRAYSCALE ? JCS_GRAYSCALE : JCS_RGB;
        jpeg_calc_output_dimensions(&info);
    });
    if (!started || !supported || in.errors.warned) return false;
    const int channels = info.output_components;
    if ((channels != 1 && channels != 3) || info.output_width == 0 || info.output_height == 0)
        return false;
    Image &img = read.image;
    img.width = int(info.output_width);
    img.height = int(info.output_height);
    img.channels = channels;
    img.channel_names =
        channels == 1 ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B"};
    img.full_width = img.width;
    img.full_height = img.height;
    const size_t row = size_t(img.width) * size_t(channels);
    size_t values = 0;
    if (!checked_mul(row, size_t(img.height), values)) return false;
    allocation_bytes(values, sizeof(float), path, "image pixels"); // throws past the limit
    read.keeps_bytes = true;
    if (read.header_only) return true;

    if (!jpeg_guarded(in.errors, [&] { jpeg_start_decompress(&info); })) return false;
    // Row by row, growing the buffer as rows arrive: a truncated file stops at its first
    // missing row, not after the whole buffer has been allocated.
    std::vector<JSAMPLE> stored;
    for (size_t y = 0; y < size_t(img.height); ++y) {
        stored.resize(row * (y + 1));
        JSAMPROW at = stored.data() + row * y;
        JDIMENSION got = 0;
        if (!jpeg_guarded(in.errors, [&] { got = jpeg_read_scanlines(&info, &at, 1); }) ||
            got != 1 || in.errors.warned)
            return false;
    }
    if (!jpeg_guarded(in.errors, [&] { jpeg_finish_decompress(&info); }) || in.errors.warned)
        return false;
    if (read.want_bytes) {
        read.bytes = std::move(stored);
        return true;
    }
    img.data.resize(values);
    for (size_t i = 0; i < values; ++i) img.data[i] = read.values[stored[i]];
    return true;
}

} // namespace facet::detail
