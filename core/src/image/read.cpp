// read_image() and its variants: the readers facet allows, the checks of a header's sizes, and
// the pixels read in bands of rows.
#include "exr_headers.h"
#include "image_module.h"

#include <facet/checked.h>
#include <facet/image.h>
#include <facet/logger.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace facet {

using detail::check_bmp_header;
using detail::check_exr_headers;
using detail::check_tiff_strips;
using detail::lower_extension;

namespace {

/// The image formats facet reads: Mitsuba 3's (OpenEXR, PNG, JPEG, Radiance RGBE, PFM and the
/// other PNM formats, Targa, BMP) and TIFF, by OpenImageIO's names for its readers.
constexpr const char *ReadableFormats[] = {"openexr", "png",   "jpeg", "hdr",
                                           "pnm",     "targa", "bmp",  "tiff"};

bool is_readable_format(const std::string &name) {
    return std::any_of(std::begin(ReadableFormats), std::end(ReadableFormats),
                       [&](const char *f) { return name == f; });
}

/// Opens `path` with the reader its extension names, or, when that reader cannot open it, with
/// the first other reader of ReadableFormats that recognises the contents. OpenImageIO's own
/// fallback (try_all_readers, turned off when this library loads: facet_image_library()) would hand
/// a file that is not what its name says to each of its thirty readers, camera raw, DICOM, GDAL,
/// OpenVDB and video among them: more parsers exposed to a downloaded asset, and slow (a malformed
/// .png: 0.8 ms of CPU against 0.01 ms with the one reader; under the address sanitizer, most of
/// the image fuzzer's time).
std::unique_ptr<OIIO::ImageInput> open_image(const std::string &path) {
    // Created from the bare extension, the reader is only made; from a file name OpenImageIO
    // would open the file with it too.
    const std::string ext = lower_extension(path);
    auto in = ext.size() > 1 ? OIIO::ImageInput::create(ext.substr(1), /*do_open=*/false) : nullptr;
    std::string error;
    OIIO::ImageSpec spec;
    // Colour is kept as stored next to an alpha channel (Mitsuba drops alpha, it never
    // multiplies colour by it); left to itself OpenImageIO premultiplies PNG, TIFF and Targa.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    if (in && is_readable_format(in->format_name())) {
        if (in->open(path, spec, config)) return in;
        error = in->geterror();
    } else {
        (void)OIIO::geterror(); // "could not find a format reader", said better below
        error = in ? fmt::format("{} files are not read", in->format_name())
                   : "the extension names no image format";
        error += " (facet reads OpenEXR, PNG, JPEG, RGBE, PFM and PNM, Targa, BMP and TIFF)";
    }
    for (const char *format : ReadableFormats) {
        if (in && in->format_name() == std::string(format)) continue;
        auto other = OIIO::ImageInput::create(format, /*do_open=*/false);
        if (!other || !other->valid_file(path)) continue;
        if (other->open(path, spec, config)) return other;
        // The contents are this format's: its reader's error says what is wrong.
        error = fmt::format("read as {} (by its contents): {}", format, other->geterror());
        break;
    }
    if (error.empty()) error = "read error";
    FACET_THROW("cannot read image \"{}\": {}", path, error);
}

/// How read_pixels() reads: the checked header only, or the pixels; where the values are
/// bytes (8-bit, one type for every channel, scanlines), into `bytes` as stored when given.
struct PixelRead {
    bool header_only = false;
    std::vector<uint8_t> *bytes = nullptr;
    bool keeps_bytes = false; ///< out: the values are (or would be) read into `bytes`
};

Image read_pixels(const std::string &path, PixelRead &how) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        FACET_THROW("cannot read image \"{}\": {}", path,
                    fs::exists(path, ec) ? "not a regular file" : "no such file");
    check_exr_headers(path);
    check_bmp_header(path);
    auto in = open_image(path);
    const OIIO::ImageSpec spec = in->spec();
    // The header's sizes are checked before anything is allocated: positive, a 2D flat image,
    // and a product that neither wraps nor exceeds the allocation limit.
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
        FACET_THROW("cannot read image \"{}\": it declares {}x{} pixels of {} channels", path,
                    spec.width, spec.height, spec.nchannels);
    if (spec.depth != 1 || spec.deep)
        FACET_THROW("cannot read image \"{}\": {} images are not supported", path,
                    spec.deep ? "deep" : "volume");
    size_t row = 0, values = 0;
    if (!checked_mul(size_t(spec.width), size_t(spec.nchannels), row) ||
        !checked_mul(row, size_t(spec.height), values))
        values = std::numeric_limits<size_t>::max();
    // OpenImageIO's limits:imagesize_MB would say so for a TIFF only (header_checks.cpp); needed
    // by HostileImages.HeaderDimensionsAreCheckedBeforeAllocating (a PFM).
    allocation_bytes(values, sizeof(float), path, "image pixels");
    // OpenImageIO's TIFF reader buffers whole strips (check_tiff_strips(), and the row-by-row
    // reading of MinIsWhite files below).
    const bool tiff_strips = spec.tile_width <= 0 && in->format_name() == std::string("tiff");
    if (tiff_strips) check_tiff_strips(path, spec);
    // A band of whole tiles, converted to float by OpenImageIO in a buffer of its own.
    if (spec.tile_width > 0) {
        size_t tiles_x = 0, tile_values = 0;
        const size_t tw = size_t(spec.tile_width), th = size_t(std::max(spec.tile_height, 1));
        const size_t td = size_t(std::max(spec.tile_depth, 1));
        if (!checked_mul((size_t(spec.width) + tw - 1) / tw, tw, tiles_x) ||
            !checked_mul(tiles_x, th, tile_values) || !checked_mul(tile_values, td, tile_values) ||
            !checked_mul(tile_values, size_t(spec.nchannels), tile_values))
            tile_values = std::numeric_limits<size_t>::max();
        // Needed by HostileImages.TilesArePaddingOnlyWithinReason (a tiled TIFF).
        allocation_bytes(tile_values, sizeof(float), path, "a row of image tiles");
    }

    Image img;
    img.width = spec.width;
    img.height = spec.height;
    img.channels = spec.nchannels;
    img.channel_names.assign(spec.channelnames.begin(), spec.channelnames.end());
    // The data window (the pixels read) inside the display window (origin 0 in facet's files).
    img.x = spec.x - spec.full_x;
    img.y = spec.y - spec.full_y;
    img.full_width = spec.full_width;
    img.full_height = spec.full_height;
    img.channel_names.resize(size_t(spec.nchannels));
    // Read in bands of rows (whole tile rows for tiled files), growing the buffer as rows
    // arrive: a header that claims gigabytes of pixels in a small, truncated file fails at its
    // first missing row instead of after the whole buffer has been zeroed.
    // OpenImageIO 2.4 inverts a MinIsWhite TIFF strip it decompresses itself (deflate, 8 or 16
    // bits, contiguous channels) over channels x its values, writing past the buffer when there
    // is more than one channel (a valid 16x64 grey + alpha file aborted the process). It reads
    // a single row through libtiff and inverts that row's values only: such files are read row
    // by row.
    const bool miniswhite_strips =
        tiff_strips && spec.nchannels > 1 &&
        spec.get_int_attribute("tiff:PhotometricInterpretation", -1) == 0;
    const int band = spec.tile_width > 0 ? std::max(spec.tile_height, 1)
                     : miniswhite_strips
                         ? 1
                         : int(std::clamp<size_t>((size_t(1) << 22) / row, 1, 4096));
    // Scanlines of one type are read in the file's own layout (all channels of spec.format) and
    // converted here, band by band: asked for any other layout, OpenImageIO converts through a
    // 64 MB buffer it allocates for every read, however small the image.
    const bool native_layout = spec.tile_width <= 0 && spec.channelformats.empty();
    const bool convert_here = native_layout && spec.format != OIIO::TypeDesc::FLOAT;
    // Bytes as stored: the values convert_here would convert, unconverted.
    how.keeps_bytes = convert_here && spec.format == OIIO::TypeDesc::UINT8;
    if (how.header_only) return img;
    std::vector<uint8_t> *bytes = how.keeps_bytes ? how.bytes : nullptr;
    std::vector<unsigned char> native;
    bool ok = true;
    for (int y0 = 0; ok && y0 < spec.height; y0 += band) {
        const int y1 = std::min(spec.height, y0 + std::max(band, 1));
        const size_t values = size_t(y1 - y0) * row;
        if (bytes) {
            bytes->resize(size_t(y1) * row);
            ok = in->read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, spec.nchannels,
                                    OIIO::TypeDesc::UNKNOWN, bytes->data() + size_t(y0) * row);
            continue;
        }
        img.data.resize(size_t(y1) * row);
        float *dst = img.data.data() + size_t(y0) * row;
        if (spec.tile_width > 0) {
            ok = in->read_tiles(0, 0, spec.x, spec.x + spec.width, spec.y + y0, spec.y + y1, spec.z,
                                spec.z + 1, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, dst);
        } else if (convert_here) {
            native.resize(values * spec.format.size());
            ok = in->read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, spec.nchannels,
                                    OIIO::TypeDesc::UNKNOWN, native.data()) &&
                 OIIO::convert_pixel_values(spec.format, native.data(), OIIO::TypeDesc::FLOAT, dst,
                                            int(values));
        } else {
            ok = in->read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, spec.nchannels,
                                    native_layout ? OIIO::TypeDesc::UNKNOWN : OIIO::TypeDesc::FLOAT,
                                    dst);
        }
    }
    std::string err = ok ? "" : in->geterror();
    in->close();
    if (!ok) FACET_THROW("cannot read image \"{}\": {}", path, err.empty() ? "read error" : err);
    return img;
}

Image read_pixels_or_throw(const std::string &path, PixelRead &how) {
    // A size that passed every check can still be more than the machine has (a TIFF strip of
    // many more rows than the image, say, which OpenImageIO buffers whole).
    try {
        return read_pixels(path, how);
    } catch (const std::bad_alloc &) {
        FACET_THROW("cannot read image \"{}\": out of memory (a size the file gives is more "
                    "than this machine can allocate)",
                    path);
    }
}

} // namespace

Image read_image(const std::string &path) {
    PixelRead how;
    return read_pixels_or_throw(path, how);
}

ImageHeader read_image_header(const std::string &path) {
    PixelRead how;
    how.header_only = true;
    ImageHeader header;
    header.image = read_pixels_or_throw(path, how);
    header.bytes = how.keeps_bytes;
    return header;
}

ByteImage read_image_bytes(const std::string &path) {
    ByteImage out;
    PixelRead how;
    how.bytes = &out.bytes;
    out.image = read_pixels_or_throw(path, how);
    // Each byte value as the float path converts it (the same conversion, value by value).
    uint8_t all[256];
    for (int i = 0; i < 256; ++i) all[i] = uint8_t(i);
    if (!OIIO::convert_pixel_values(OIIO::TypeDesc::UINT8, all, OIIO::TypeDesc::FLOAT,
                                    out.values.data(), 256))
        FACET_THROW("cannot read image \"{}\": OpenImageIO cannot convert bytes to floats", path);
    return out;
}

ImageFile read_image_file(const std::string &path) {
    ImageFile file;
    file.image = read_image(path);
    auto in = open_image(path);
    const OIIO::ImageSpec &spec = in->spec();
    // The film's colour comes first; AOVs and raw sums after it may be float32.
    file.half = (spec.channelformats.empty() ? spec.format : spec.channelformats[0]) ==
                OIIO::TypeDesc::HALF;
    for (int c = 0; c < spec.nchannels; ++c)
        if ((spec.channelformats.empty() ? spec.format : spec.channelformats[size_t(c)]) ==
            OIIO::TypeDesc::HALF)
            file.half_channels.push_back(spec.channel_name(c));
    for (const OIIO::ParamValue &p : spec.extra_attribs)
        file.attributes[p.name().string()] = p.get_string();
    in->close();
    return file;
}

} // namespace facet
