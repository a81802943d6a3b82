// The headers read_image() checks itself before OpenImageIO opens or reads a file, where a
// library would allocate from a header before facet could check it (README, "Fuzzing").
//
// The libraries' own limits do not replace these checks in the versions facet builds with
// (measured on OpenImageIO 2.4.7, each corpus entry replayed without facet's
// check and with the library's limit set low):
// - OpenImageIO's `limits:imagesize_MB` and `limits:channels` are honoured by its TIFF reader
//   only (EXR, PNG, JPEG, RGBE, PNM/PFM, Targa and BMP files of any size open), and count the
//   image, not a TIFF strip: the RLE BMP entry still took 1.9 GB with the limit at 64 MB, the
//   TIFF strip entry still ended in std::bad_alloc.
// EXR headers are checked by check_exr_headers() (exr_headers.cpp, in libfacet: libfacet_read
// reads EXR files too).
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
#include <memory>
#include <string>
#include <vector>

namespace facet::detail {

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
