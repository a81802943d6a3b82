// The headers of an OpenEXR file, checked before OpenEXR reads them, where the library would
// allocate from a header before facet could check it (README, "Fuzzing"). Both readers of EXR
// files call it: libfacet_read (read/exr.cpp) and libfacet_image (image/read.cpp).
//
// OpenEXR's own limits do not replace this check in the version facet builds with (measured on
// OpenEXR 3.1.5, each corpus entry replayed without facet's check and with the library's limit
// set low): Header::setMaxImageSize/setMaxTileSize bound each dimension alone, are checked
// after every attribute has been read (the attribute-size entry still ran past 10 s with both
// limits at 4096/256), and are process-wide (they would also bound the EXR writer and a Python
// user's own OpenEXR reads). OpenImageIO's experimental `openexr:core` reader (OpenEXR's C core)
// refused the two attribute entries at once in the same trial: once it is OpenImageIO's
// default, the attribute part of check_exr_headers() may go.
// Each check names the fuzz regression (tests/data/fuzz/image/regressions/) and the test
// (tests/unit/core/hostile_files.cpp) that need it.
#include "exr_headers.h"

#include <facet/checked.h>
#include <facet/logger.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace facet::detail {

namespace {

/// Bytes OpenEXR (3.1) reads for a value of each fixed-size attribute type, whatever size the
/// file gives it.
int exr_fixed_size(const std::string &type) {
    static const std::map<std::string, int> sizes = {
        {"box2i", 16},      {"box2f", 16},   {"chromaticities", 32},
        {"compression", 1}, {"double", 8},   {"envmap", 1},
        {"float", 4},       {"int", 4},      {"keycode", 28},
        {"lineOrder", 1},   {"m33f", 36},    {"m44f", 64},
        {"m33d", 72},       {"m44d", 128},   {"rational", 8},
        {"tiledesc", 9},    {"timecode", 8}, {"v2i", 8},
        {"v2f", 8},         {"v2d", 16},     {"v3i", 12},
        {"v3f", 12},        {"v3d", 24},     {"deepImageState", 1}};
    auto it = sizes.find(type);
    return it == sizes.end() ? -1 : it->second;
}

/// The most raw pixel bytes an EXR compression can store per byte of file, with a factor of two
/// to spare, or 0 where there is no useful bound: none 1, RLE 64 (a run of 128 bytes in 2),
/// ZIP and ZIPS 1032 (deflate's limit), PIZ 409.6 (its Huffman coder sends a run of 256 equal
/// 16-bit values as a code, a run code and an 8-bit count: 10 bits at best), PXR24 4/3 of
/// deflate's (24 of 32 bits kept), B44 32/14 and B44A 32/3 (a flat 4x4 block of halves in 3
/// bytes), DWAA and DWAB 64 x 1032 (channels that are not colour are run-length coded, then
/// deflated; a colour channel's 8x8 block, 128 bytes, leaves 2 bytes of DC and 2 of AC to
/// deflate, 33,024 at best). Measured on constant images of 4096x512 halves: PIZ 397, DWAA
/// 3,791, DWAB 9,511.
double exr_max_ratio(int compression) {
    switch (compression) {
    case 0:
        return 2.0;
    case 1:
        return 128.0;
    case 2:
    case 3:
        return 2 * 1032.0;
    case 4:
        return 2 * 409.6;
    case 5:
        return 2 * 1032.0 * 4.0 / 3.0;
    case 6:
        return 2 * 32.0 / 14.0;
    case 7:
        return 2 * 32.0 / 3.0;
    case 8:
    case 9:
        return 2 * 64.0 * 1032.0;
    default:
        return 0.0;
    }
}

} // namespace

/**
 * OpenEXR (3.1) allocates header attributes at sizes the file gives before reading them, so a
 * 1 KB file whose attribute claims 1.7 GB costs that much memory and a minute. The headers are
 * scanned here first, the way OpenEXR reads them:
 * - every attribute must fit in the rest of the file;
 * - a value OpenEXR reads by its contents (fixed-size types, a channel list, a string vector, a
 *   preview image) must take exactly the bytes its size says: OpenEXR does not skip to the
 *   declared end, so a value read past it or short of it makes OpenEXR read the next attribute
 *   from the middle of a value (a channel list that ran on gave a 1.6 GB "attribute" from a
 *   223-byte file);
 * - the pixels the data window and the channel list declare must pass allocation_bytes(), and
 *   fit in the file at the best ratio the compression can reach (exr_max_ratio());
 * - a tile (allocated whole) must pass allocation_bytes() and be at most 256x256 pixels or 4
 *   times the data window (a 20x12 image in tiles of 8 x 16777224 took 2.2 GB and 4 s).
 * Values checked by their size alone are skipped unread; the rest of the file is not read.
 */
void check_exr_headers(const std::string &path) {
    std::unique_ptr<std::FILE, int (*)(std::FILE *)> file(std::fopen(path.c_str(), "rb"),
                                                          &std::fclose);
    if (!file) return; // OpenImageIO reports it
    std::FILE *f = file.get();
    std::fseek(f, 0, SEEK_END);
    const long size_or_error = std::ftell(f);
    if (size_or_error < 8) return;
    const size_t file_size = size_t(size_or_error);
    std::rewind(f);
    // The file's bytes [0, n), read as far as the scan needs them: values checked by their size
    // alone are skipped unread.
    std::vector<unsigned char> buf;
    size_t n = 0;
    auto have = [&](size_t upto) {
        if (upto <= n) return true;
        if (upto > file_size) return false;
        buf.resize(std::min(file_size, std::max({upto, 2 * n, size_t(1) << 16})));
        n += std::fread(buf.data() + n, 1, buf.size() - n, f);
        buf.resize(n);
        return upto <= n;
    };
    if (!have(8) || buf[0] != 0x76 || buf[1] != 0x2f || buf[2] != 0x31 || buf[3] != 0x01) return;
    const bool multipart = (buf[5] & 0x10) != 0; // version field bit 12
    const bool deep_file = (buf[5] & 0x08) != 0; // bit 11: deep data ("non-image")
    size_t pos = 8;
    auto cstring = [&](size_t &at, size_t limit, std::string &out) {
        out.clear();
        while (at < limit && have(at + 1) && buf[at] != 0 && out.size() < 256)
            out += char(buf[at++]);
        if (at >= limit || !have(at + 1) || buf[at] != 0) return false;
        ++at;
        return true;
    };
    auto int32_at = [&](size_t at) {
        int32_t v;
        std::memcpy(&v, buf.data() + at, 4);
        return v;
    };
    auto fail = [&](const std::string &name, const std::string &type, const std::string &why) {
        FACET_THROW("cannot read image \"{}\": the EXR attribute \"{}\" ({}) {}", path, name, type,
                    why);
    };
    std::string name, type, channel;
    for (int header = 0; have(pos + 1); ++header) {
        if (buf[pos] == 0) break; // an empty header ends the list of a multi-part file
        // OpenEXR reads a header over its default one: a 64x64 data window, ZIP, no channels.
        int64_t width = 64, height = 64, pixel_bytes = -1;
        double sampled_bytes = 0.0; // per pixel, for channels stored at 1/(xs ys) of the pixels
        int compression = 3;        // ZIP
        bool deep = deep_file && !multipart;
        uint64_t tile_pixels = 0; // up to (2^32 - 1)^2
        for (;;) {
            if (!have(pos + 1)) return;
            if (buf[pos] == 0) {
                ++pos;
                break;
            }
            if (!cstring(pos, file_size, name) || !cstring(pos, file_size, type) || !have(pos + 4))
                return;
            const int32_t size = int32_at(pos);
            pos += 4;
            // Needed by timeout-exr-attribute-size, HostileImages.ExrAttributesLargerThanTheFile.
            if (size < 0 || int64_t(size) > int64_t(file_size) - int64_t(pos))
                fail(name, type, fmt::format("claims {} bytes, more than the file holds", size));
            const size_t end = pos + size_t(size);
            const int fixed = exr_fixed_size(type);
            const bool read_value = fixed >= 0 || type == "chlist" || type == "stringvector" ||
                                    type == "preview" || (type == "string" && name == "type");
            if (read_value && !have(end)) return; // a read error: OpenImageIO reports it
            // Exact sizes: needed by exr-chlist-past-its-size-1.6GB-attribute,
            // HostileImages.ExrAttributesReadPastOrShortOfTheirSize.
            if (fixed >= 0 && size != fixed) {
                fail(name, type, fmt::format("has {} bytes instead of {}", size, fixed));
            } else if (type == "chlist") {
                // Channels (a name, then type, pLinear, 3 reserved bytes, x and y sampling),
                // then an empty name. Only the list named "channels" describes the pixels.
                const bool pixels_list = name == "channels";
                if (pixels_list) {
                    pixel_bytes = 0;
                    sampled_bytes = 0.0;
                }
                size_t at = pos;
                for (;;) {
                    if (at < end && buf[at] == 0) {
                        ++at;
                        break;
                    }
                    if (!cstring(at, end, channel) || at + 16 > end)
                        fail(name, type, "runs past its size");
                    const int32_t pixel_type = int32_at(at);
                    const int bytes = pixel_type == 1 ? 2 : 4; // HALF, or UINT and FLOAT
                    const int32_t xs = int32_at(at + 8), ys = int32_at(at + 12);
                    if (pixels_list) {
                        pixel_bytes += bytes;
                        if (xs > 0 && ys > 0) sampled_bytes += bytes / (double(xs) * double(ys));
                    }
                    at += 16;
                }
                if (at != end) fail(name, type, "ends before its size");
            } else if (type == "stringvector") {
                size_t at = pos;
                while (at < end) {
                    const int32_t length = at + 4 <= end ? int32_at(at) : -1;
                    if (length < 0 || int64_t(length) > int64_t(end - at - 4))
                        fail(name, type, "has a string that runs past its size");
                    at += 4 + size_t(length);
                }
            } else if (type == "floatvector") {
                if (size % 4 != 0) fail(name, type, "is not a whole number of floats");
            } else if (type == "preview") {
                const uint32_t w = size >= 8 ? uint32_t(int32_at(pos)) : 0;
                const uint32_t h = size >= 8 ? uint32_t(int32_at(pos + 4)) : 0;
                if (size < 8 || uint64_t(w) * h * 4 != uint64_t(size) - 8)
                    fail(name, type, "declares a size its pixels do not have");
            } else if (type == "idmanifest") {
                if (size < 4) fail(name, type, "is shorter than its 4-byte length");
            }
            if (type == "compression" && name == "compression") compression = buf[pos];
            if (type == "string" && name == "type" && multipart) {
                const std::string value(buf.begin() + long(pos), buf.begin() + long(end));
                deep = value == "deepscanline" || value == "deeptile";
            }
            if (type == "tiledesc" && name == "tiles")
                tile_pixels = uint64_t(uint32_t(int32_at(pos))) * uint32_t(int32_at(pos + 4));
            if (type == "box2i" && name == "dataWindow") {
                width = int64_t(int32_at(pos + 8)) - int32_at(pos) + 1;
                height = int64_t(int32_at(pos + 12)) - int32_at(pos + 4) + 1;
            }
            pos = end;
        }
        // The pixels of this part at full resolution, before OpenEXR sizes its buffers by them.
        size_t pixels = 0;
        if (width > 0 && height > 0 && pixel_bytes > 0) {
            if (!checked_mul(size_t(width), size_t(height), pixels))
                pixels = std::numeric_limits<size_t>::max();
            // Needed by HostileImages.ExrDataWindowWithinTheAllocationLimit.
            allocation_bytes(pixels, size_t(pixel_bytes), path, "EXR data window");
            // OpenEXR and OpenImageIO allocate whole tiles; beyond the image they hold padding.
            // Needed by oom-exr-tiles-8x16777224, timeout-exr-tiles-under-the-default-data-window,
            // HostileImages.TilesArePaddingOnlyWithinReason (a per-dimension tile limit cannot
            // relate a tile to the data window).
            if (tile_pixels > 0) {
                allocation_bytes(size_t(tile_pixels), size_t(pixel_bytes), path, "EXR tile");
                if (tile_pixels > std::max<uint64_t>(4 * uint64_t(pixels), 65536))
                    FACET_THROW("cannot read image \"{}\": its tiles of {} pixels are larger "
                                "than 256x256 and 4 times its {}x{}-pixel data window",
                                path, tile_pixels, width, height);
            }
            // Pixels that cannot be in the file: more than its compression can pack into its
            // bytes (OpenEXR pads a short chunk without an error). Needed by
            // timeout-exr-data-window-beyond-zip-ratio,
            // HostileImages.ExrPixelsMustFitTheFilesCompression.
            const double bound = exr_max_ratio(compression) * double(file_size);
            if (!deep && bound > 0.0 && double(pixels) * sampled_bytes > bound)
                FACET_THROW("cannot read image \"{}\": its data window declares {}x{} pixels "
                            "({:.0f} bytes), more than its compression can hold in {} bytes",
                            path, width, height, double(pixels) * sampled_bytes, file_size);
        }
        if (!multipart) break;
    }
}

} // namespace facet::detail
