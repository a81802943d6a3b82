// The headers read_image() checks itself before OpenImageIO opens or reads a file, where a
// library would allocate from a header before facet could check it (README, "Fuzzing").
//
// The libraries' own limits do not replace these checks in the versions facet builds with
// (measured on OpenImageIO 2.4.7 and OpenEXR 3.1.5, each corpus entry replayed without facet's
// check and with the library's limit set low):
// - OpenImageIO's `limits:imagesize_MB` and `limits:channels` are honoured by its TIFF reader
//   only (EXR, PNG, JPEG, RGBE, PNM/PFM, Targa and BMP files of any size open), and count the
//   image, not a TIFF strip: the RLE BMP entry still took 1.9 GB with the limit at 64 MB, the
//   TIFF strip entry still ended in std::bad_alloc.
// - OpenEXR's Header::setMaxImageSize/setMaxTileSize bound each dimension alone, are checked
//   after every attribute has been read (the attribute-size entry still ran past 10 s with
//   both limits at 4096/256), and are process-wide (they would also bound the EXR writer and
//   a Python user's own OpenEXR reads). OpenImageIO's experimental `openexr:core` reader
//   (OpenEXR's C core) refused the two attribute entries at once in the same trial: once it
//   is OpenImageIO's default, the attribute part of check_exr_headers() may go.
// Each check below names the fuzz regression (tests/data/fuzz/image/regressions/) and the test
// (tests/unit/core/hostile_files.cpp) that need it.
#include "image_module.h"

#include <facet/checked.h>
#include <facet/logger.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
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

/**
 * OpenImageIO (2.4) decodes an RLE-compressed BMP whole as it opens the file, into a buffer of
 * a byte per pixel sized from the header: a 55-byte file declaring 604 million by 3 pixels took
 * 1.9 GB and 2 s before any size could be checked. So the header is read here first: the
 * pixels must pass allocation_bytes() (as floats, as read_image() will hold them), and an RLE
 * image may have at most 256 pixels per byte of the file (a run of 255 pixels takes two bytes;
 * only pixels the file leaves undefined can make an image sparser) and must have the depth of
 * its RLE kind.
 */
void check_bmp_header(const std::string &path) {
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) return; // OpenImageIO reports it
    unsigned char h[34] = {};
    const size_t n = std::fread(h, 1, sizeof h, f);
    std::fseek(f, 0, SEEK_END);
    const long file_size = std::ftell(f);
    std::fclose(f);
    // The magics OpenImageIO's reader takes: BM (Windows), BA, CI, CP, PT (OS/2).
    const std::string magic{char(h[0]), char(h[1])};
    if (n < 26 ||
        (magic != "BM" && magic != "BA" && magic != "CI" && magic != "CP" && magic != "PT"))
        return; // too short: OpenImageIO reports it
    auto u32 = [&](int at) {
        return uint32_t(h[at]) | uint32_t(h[at + 1]) << 8 | uint32_t(h[at + 2]) << 16 |
               uint32_t(h[at + 3]) << 24;
    };
    const uint32_t header_size = u32(14);
    int64_t width, height;
    uint32_t compression = 0;
    if (header_size == 12) { // OS/2 BITMAPCOREHEADER: 16-bit sizes, no compression
        width = int64_t(h[18] | h[19] << 8);
        height = int64_t(h[20] | h[21] << 8);
    } else {
        width = std::abs(int64_t(int32_t(u32(18))));
        height = std::abs(int64_t(int32_t(u32(22)))); // negative: rows stored top down
        if (n >= 34) compression = u32(30);
    }
    size_t pixels = 0;
    if (!checked_mul(size_t(width), size_t(height), pixels))
        pixels = std::numeric_limits<size_t>::max();
    // The checks from here on: needed by oom-bmp-rle-decoded-whole-on-open,
    // segv-bmp-rle8-with-24-bit-pixels, HostileImages.BmpHeadersAreCheckedBeforeOpenImageIODecodes.
    allocation_bytes(pixels, sizeof(float), path, "BMP pixels");
    const bool rle = compression == 1 || compression == 2;
    if (rle && file_size > 0 && pixels / 256 > size_t(file_size))
        FACET_THROW("cannot read image \"{}\": the RLE-compressed BMP declares {}x{} pixels, more "
                    "than 256 per byte of its {}-byte file",
                    path, width, height, file_size);
    // RLE8 codes 8-bit and RLE4 4-bit palette indices: OpenImageIO decodes any other depth with
    // them out of bounds (a 24-bit RLE8 file crashed it).
    const int bits = h[28] | h[29] << 8;
    if (rle && bits != (compression == 1 ? 8 : 4))
        FACET_THROW("cannot read image \"{}\": the BMP is RLE{}-compressed with {} bits per pixel "
                    "instead of {}",
                    path, compression == 1 ? 8 : 4, bits, compression == 1 ? 8 : 4);
}

namespace {

/**
 * The RowsPerStrip of a TIFF's first image, as libtiff reads it (one value of an integer type;
 * any other entry is ignored, and the strip is the whole image), or 0 when the file has none or
 * is not a TIFF. OpenImageIO (2.4) keeps it in an int and reads a band of whole strips through
 * buffers of width x channels x RowsPerStrip values computed in int, not clamped to the image's
 * rows: values from 2^31 on became a negative strip height and corrupted the heap (a 300x50
 * image, release build), and a 217-byte file made it ask for 5.6e15 bytes.
 */
uint64_t tiff_rows_per_strip(const std::string &path) {
    std::unique_ptr<std::FILE, int (*)(std::FILE *)> file(std::fopen(path.c_str(), "rb"),
                                                          &std::fclose);
    if (!file) return 0;
    std::FILE *f = file.get();
    auto read_at = [&](uint64_t at, unsigned char *out, size_t n) {
        return at <= uint64_t(std::numeric_limits<long>::max()) &&
               std::fseek(f, long(at), SEEK_SET) == 0 && std::fread(out, 1, n, f) == n;
    };
    unsigned char h[16];
    if (!read_at(0, h, 8)) return 0;
    const bool little = h[0] == 'I' && h[1] == 'I';
    if (!little && !(h[0] == 'M' && h[1] == 'M')) return 0;
    auto uint = [&](const unsigned char *b, int n) {
        uint64_t v = 0;
        for (int i = 0; i < n; ++i) v |= uint64_t(b[little ? i : n - 1 - i]) << (8 * i);
        return v;
    };
    const uint64_t version = uint(h + 2, 2);
    const bool big = version == 43; // BigTIFF: 8-byte counts and offsets
    if (version != 42 && !(big && read_at(0, h, 16))) return 0;
    const uint64_t ifd = big ? uint(h + 8, 8) : uint(h + 4, 4);
    const int count_bytes = big ? 8 : 2, entry_bytes = big ? 20 : 12, value_bytes = big ? 8 : 4;
    unsigned char e[20];
    if (!read_at(ifd, e, size_t(count_bytes))) return 0;
    const uint64_t entries = uint(e, count_bytes);
    for (uint64_t i = 0; i < std::min<uint64_t>(entries, 65536); ++i) {
        if (!read_at(ifd + uint64_t(count_bytes) + i * uint64_t(entry_bytes), e,
                     size_t(entry_bytes)))
            return 0;
        if (uint(e, 2) != 278) continue; // RowsPerStrip
        const uint64_t type = uint(e + 2, 2), count = uint(e + 4, big ? 8 : 4);
        const unsigned char *value = e + 4 + (big ? 8 : 4);
        // BYTE, SHORT, LONG, LONG8 and their signed kinds (negative values are ignored).
        const int size = type == 1 || type == 6     ? 1
                         : type == 3 || type == 8   ? 2
                         : type == 4 || type == 9   ? 4
                         : type == 16 || type == 17 ? 8
                                                    : 0;
        if (count != 1 || size == 0 || size > value_bytes) return 0;
        const uint64_t v = uint(value, size);
        const bool is_signed = type == 6 || type == 8 || type == 9 || type == 17;
        if (is_signed && (v >> (8 * size - 1)) != 0) return 0;
        return v <= 0xffffffffu ? v : 0; // libtiff ignores what a uint32 cannot hold
    }
    return 0;
}

} // namespace

/**
 * A TIFF's strips as OpenImageIO will buffer them (tiff_rows_per_strip()): a RowsPerStrip that
 * does not fit its int (2^32 - 1, TIFF's "the whole image", becomes -1, which it handles), a strip
 * whose values overflow its int, and a strip over the allocation limit are refused.
 */
void check_tiff_strips(const std::string &path, const OIIO::ImageSpec &spec) {
    // Needed by oom-tiff-rows-per-strip-overflowing-int, heap-corruption-tiff-rows-per-strip-2-31,
    // HostileImages.TiffStripsAreCheckedBeforeOpenImageIOBuffersThem.
    const uint64_t rows = tiff_rows_per_strip(path);
    if (rows == 0 || rows == 0xffffffffu) return;
    constexpr uint64_t int_max = uint64_t(std::numeric_limits<int>::max());
    uint64_t values = 0;
    if (rows > int_max || !checked_mul(uint64_t(spec.width), uint64_t(spec.nchannels), values) ||
        !checked_mul(values, rows, values) || values > int_max)
        FACET_THROW("cannot read image \"{}\": its RowsPerStrip of {} for rows of {} pixels of {} "
                    "channels is more than the TIFF reader can address",
                    path, rows, spec.width, spec.nchannels);
    allocation_bytes(size_t(values), spec.format.size(), path, "a TIFF strip");
}

} // namespace facet::detail
