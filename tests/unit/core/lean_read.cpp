// libfacet_read against libfacet_image (core/src/image_library.h): every file the lean readers
// read (EXR on OpenEXR, PNG on libpng, JPEG on libjpeg) must come out exactly as OpenImageIO's
// read_image(), read_image_header() and read_image_bytes() give it: the same sizes, windows,
// channel names, keeps-bytes flag, bytes and floats, bit for bit. Files the lean readers decline
// (false) are left to libfacet_image. Both modules are loaded directly, as libfacet loads them.
// The files: written here with OpenImageIO, OpenEXR, libpng and libjpeg; the repository's
// images; the image fuzzer's inputs (whose pixels OpenEXR may leave undefined: see
// pixels_are_undefined()).
#include "image_library.h"

#include <facet/image.h>
#include <facet/logger.h>
#include <facet/qmc.h>

#include <Imath/ImathBox.h>
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfRgbaFile.h>
#include <OpenEXR/ImfTiledOutputFile.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <jpeglib.h>
#include <limits>
#include <png.h>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

using namespace facet;
using facet::detail::ImageLibrary;
using facet::detail::ReadLibrary;
using facet::qmc::hash32;
namespace fs = std::filesystem;

namespace {

/// What the lean reader must do with a file: read it, decline it (which libfacet_image reads,
/// or refuses with its error), or either (then, if it reads it, exactly as libfacet_image does).
enum class Expect { Read, Decline, Refuse, Either };

const char *expect_name(Expect e) {
    return e == Expect::Read      ? "read"
           : e == Expect::Decline ? "declined"
           : e == Expect::Refuse  ? "declined and refused"
                                  : "either";
}

template <typename Table> const Table *load_module(const std::string &path, const char *entry) {
    void *handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL); // never closed, as libfacet
    if (!handle) {
        ADD_FAILURE() << "dlopen(" << path << "): " << dlerror();
        return nullptr;
    }
    auto fn = reinterpret_cast<const Table *(*)()>(dlsym(handle, entry));
    if (!fn) {
        ADD_FAILURE() << path << " has no " << entry;
        return nullptr;
    }
    return fn();
}

const ImageLibrary *image_module() {
    static const ImageLibrary *table =
        load_module<ImageLibrary>(image_library_path(), FACET_IMAGE_LIBRARY_ENTRY);
    return table;
}

const ReadLibrary *read_module() {
    static const ReadLibrary *table = load_module<ReadLibrary>(
        (fs::path(image_library_path()).parent_path() / "libfacet_read.so").string(),
        FACET_READ_LIBRARY_ENTRY);
    return table;
}

/// Bytes with structure (gradients, a few edges) and noise; every 8-bit code when w >= 256.
std::vector<uint8_t> byte_pixels(int w, int h, int c, uint32_t seed) {
    std::vector<uint8_t> v(size_t(w) * h * c);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < c; ++k) {
                const size_t i = (size_t(y) * w + x) * c + k;
                const uint32_t r = hash32(uint32_t(i) * 2654435761u + seed);
                int value = (x * 255 / std::max(w - 1, 1) + 37 * k + 11 * y) & 255;
                if (y % 3 == 1)
                    value = int(r & 255); // noise rows
                else if ((x / 4 + y / 4) % 5 == 0)
                    value = (r & 1) ? 255 : 0; // edges
                v[i] = uint8_t(value);
            }
    return v;
}

/// 16-bit values likewise.
std::vector<uint16_t> short_pixels(int w, int h, int c, uint32_t seed) {
    std::vector<uint16_t> v(size_t(w) * h * c);
    for (size_t i = 0; i < v.size(); ++i) {
        const uint32_t r = hash32(uint32_t(i) + seed);
        const int x = int((i / size_t(c)) % size_t(w));
        v[i] = i % 7 == 3 ? uint16_t(r) : uint16_t(x * 65535 / std::max(w - 1, 1) ^ (r & 0xff));
    }
    return v;
}

/// Floats of every kind a renderer stores: smooth values, negatives, large and tiny ones,
/// denormals, infinities and NaNs.
std::vector<float> float_pixels(int w, int h, int c, uint32_t seed) {
    std::vector<float> v(size_t(w) * h * c);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < c; ++k) {
                const size_t i = (size_t(y) * w + x) * c + k;
                const uint32_t r = hash32(uint32_t(i) + seed);
                float value = 0.013f * float(x) + 0.029f * float(y) + 0.31f * float(k) +
                              float(r & 0xffff) * (1.f / 65536.f);
                switch (r >> 28) {
                case 0:
                    value = -value;
                    break;
                case 1:
                    value *= 3.7e4f;
                    break;
                case 2:
                    value *= 1e-6f;
                    break;
                case 3: // denormal floats
                    value = float(r >> 8) * 1e-45f;
                    break;
                case 4:
                    value = (r & 256) ? std::numeric_limits<float>::infinity()
                                      : std::numeric_limits<float>::quiet_NaN();
                    break;
                default:
                    break;
                }
                v[i] = value;
            }
    return v;
}

std::vector<std::string> default_names(int channels) {
    switch (channels) {
    case 1:
        return {"Y"};
    case 2:
        return {"Y", "A"};
    case 3:
        return {"R", "G", "B"};
    default:
        return {"R", "G", "B", "A"};
    }
}

std::string file_bytes(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

void put_file(const std::string &path, const std::string &bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

/// Writes one image (and, for a MIP-mapped file, its smaller levels from the same values) with
/// OpenImageIO.
bool oiio_write(const std::string &path, const OIIO::ImageSpec &spec, OIIO::TypeDesc type,
                const void *pixels, bool mipmap = false) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return false;
    if (!out->open(path, spec, OIIO::ImageOutput::Create) || !out->write_image(type, pixels)) {
        ADD_FAILURE() << path << ": " << out->geterror();
        return false;
    }
    OIIO::ImageSpec level = spec;
    while (mipmap && (level.width > 1 || level.height > 1)) {
        level.width = level.full_width = std::max(1, level.width / 2);
        level.height = level.full_height = std::max(1, level.height / 2);
        if (!out->open(path, level, OIIO::ImageOutput::AppendMIPLevel) ||
            !out->write_image(type, pixels)) {
            ADD_FAILURE() << path << ": " << out->geterror();
            return false;
        }
    }
    return out->close();
}

/// How OpenImageIO sees a file's structure: its subimages, the MIP levels of the first, and its
/// tile width (0: scanlines).
struct Structure {
    int subimages = 0, levels = 0, tile_width = -1;
};

Structure structure(const std::string &path) {
    Structure s;
    auto in = OIIO::ImageInput::open(path);
    if (!in) return s;
    s.tile_width = in->spec().tile_width;
    while (in->seek_subimage(s.subimages, 0)) ++s.subimages;
    while (in->seek_subimage(0, s.levels)) ++s.levels;
    return s;
}

/// A PNG written with libpng, for what OpenImageIO does not write: palettes, transparency
/// chunks, bit depths under 8, interlacing. `rows` holds the packed rows (16-bit values
/// big-endian).
struct PngFile {
    int width = 0, height = 0, color_type = PNG_COLOR_TYPE_RGB, bit_depth = 8;
    bool interlace = false;
    std::vector<png_color> palette;
    std::vector<png_byte> trans_alpha; ///< tRNS of a palette
    bool has_trans_color = false;
    png_color_16 trans_color{}; ///< tRNS of grey or RGB
    double gamma = 0;           ///< gAMA when non-zero
    int significant_bits = 0;   ///< sBIT (every channel) when non-zero
    std::vector<uint8_t> data;  ///< height rows of rowbytes()
    size_t rowbytes() const {
        const int channels = color_type == PNG_COLOR_TYPE_RGB         ? 3
                             : color_type == PNG_COLOR_TYPE_RGB_ALPHA ? 4
                             : color_type == PNG_COLOR_TYPE_GA        ? 2
                                                                      : 1;
        return (size_t(width) * channels * bit_depth + 7) / 8;
    }
};

bool libpng_write(const std::string &path, const PngFile &png) {
    std::FILE *f = std::fopen(path.c_str(), "wb");
    if (!f) return false;
    png_structp p = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(p);
    if (setjmp(png_jmpbuf(p))) {
        png_destroy_write_struct(&p, &info);
        std::fclose(f);
        return false;
    }
    png_init_io(p, f);
    png_set_IHDR(p, info, png_uint_32(png.width), png_uint_32(png.height), png.bit_depth,
                 png.color_type, png.interlace ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (!png.palette.empty()) png_set_PLTE(p, info, png.palette.data(), int(png.palette.size()));
    if (!png.trans_alpha.empty())
        png_set_tRNS(p, info, png.trans_alpha.data(), int(png.trans_alpha.size()), nullptr);
    if (png.has_trans_color) png_set_tRNS(p, info, nullptr, 0, &png.trans_color);
    if (png.gamma > 0) png_set_gAMA(p, info, png.gamma);
    if (png.significant_bits > 0) {
        png_color_8 sbit;
        sbit.red = sbit.green = sbit.blue = sbit.gray = sbit.alpha = png_byte(png.significant_bits);
        png_set_sBIT(p, info, &sbit);
    }
    png_write_info(p, info);
    std::vector<png_bytep> rows(size_t(png.height));
    for (int y = 0; y < png.height; ++y)
        rows[size_t(y)] = const_cast<png_bytep>(png.data.data() + size_t(y) * png.rowbytes());
    png_write_image(p, rows.data());
    png_write_end(p, nullptr);
    png_destroy_write_struct(&p, &info);
    return std::fclose(f) == 0;
}

/// A JPEG written with libjpeg, for what OpenImageIO does not write (CMYK, arithmetic coding,
/// restart markers, RGB stored without the YCbCr transform).
struct JpegFile {
    int width = 0, height = 0, components = 3;
    J_COLOR_SPACE in_space = JCS_RGB, file_space = JCS_UNKNOWN; ///< UNKNOWN: libjpeg's default
    bool arithmetic = false;
    int restart_rows = 0;
    std::vector<uint8_t> data;
};

struct JpegError {
    jpeg_error_mgr mgr;
    std::jmp_buf jump;
};

bool libjpeg_write(const std::string &path, const JpegFile &jpg) {
    std::FILE *f = std::fopen(path.c_str(), "wb");
    if (!f) return false;
    jpeg_compress_struct c;
    JpegError err;
    c.err = jpeg_std_error(&err.mgr);
    err.mgr.error_exit = [](j_common_ptr info) {
        std::longjmp(reinterpret_cast<JpegError *>(info->err)->jump, 1);
    };
    if (setjmp(err.jump)) {
        jpeg_destroy_compress(&c);
        std::fclose(f);
        return false;
    }
    jpeg_create_compress(&c);
    jpeg_stdio_dest(&c, f);
    c.image_width = JDIMENSION(jpg.width);
    c.image_height = JDIMENSION(jpg.height);
    c.input_components = jpg.components;
    c.in_color_space = jpg.in_space;
    jpeg_set_defaults(&c);
    if (jpg.file_space != JCS_UNKNOWN) jpeg_set_colorspace(&c, jpg.file_space);
    jpeg_set_quality(&c, 90, TRUE);
    c.arith_code = jpg.arithmetic ? TRUE : FALSE;
    c.restart_in_rows = jpg.restart_rows;
    jpeg_start_compress(&c, TRUE);
    while (c.next_scanline < c.image_height) {
        JSAMPROW row = const_cast<JSAMPROW>(jpg.data.data() +
                                            size_t(c.next_scanline) * jpg.width * jpg.components);
        jpeg_write_scanlines(&c, &row, 1);
    }
    jpeg_finish_compress(&c);
    jpeg_destroy_compress(&c);
    return std::fclose(f) == 0;
}

/// An EXR written with OpenEXR itself from float values, for what OpenImageIO's writer does not
/// do: line orders, rip-maps, a multi-part file of one part, luminance-chroma channels.
enum class ExrKind { Scanlines, Tiles, OnePart, LuminanceChroma };

bool openexr_write(const std::string &path, Imf::Header header, ExrKind kind, uint32_t seed) {
    try {
        const Imath::Box2i dw = header.dataWindow();
        const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
        if (kind == ExrKind::LuminanceChroma) {
            const std::vector<float> v = float_pixels(w, h, 4, seed);
            std::vector<Imf::Rgba> px(size_t(w) * h);
            for (size_t i = 0; i < px.size(); ++i)
                px[i] = Imf::Rgba(std::abs(v[4 * i]), std::abs(v[4 * i + 1]),
                                  std::abs(v[4 * i + 2]), 0.5f);
            Imf::RgbaOutputFile out(path.c_str(), header, Imf::WRITE_YCA);
            out.setFrameBuffer(px.data() - dw.min.x - size_t(dw.min.y) * w, 1, size_t(w));
            out.writePixels(h);
            return true;
        }
        std::vector<std::string> names;
        for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
            names.emplace_back(it.name());
        const size_t c = names.size();
        // OpenEXR writes a channel from a slice of its own type.
        const std::vector<float> px = float_pixels(w, h, int(c), seed);
        const std::vector<Imath::half> halves(px.begin(), px.end());
        Imf::FrameBuffer fb;
        for (size_t k = 0; k < c; ++k) {
            const bool half = header.channels()[names[k]].type == Imf::HALF;
            fb.insert(names[k],
                      half ? Imf::Slice::Make(Imf::HALF, halves.data() + k, dw,
                                              sizeof(Imath::half) * c,
                                              sizeof(Imath::half) * c * size_t(w))
                           : Imf::Slice::Make(Imf::FLOAT, px.data() + k, dw, sizeof(float) * c,
                                              sizeof(float) * c * size_t(w)));
        }
        if (kind == ExrKind::Tiles) {
            Imf::TiledOutputFile out(path.c_str(), header);
            out.setFrameBuffer(fb);
            for (int ly = 0; ly < out.numYLevels(); ++ly)
                for (int lx = 0; lx < out.numXLevels(); ++lx) {
                    if (out.levelMode() != Imf::RIPMAP_LEVELS && lx != ly) continue;
                    out.writeTiles(0, out.numXTiles(lx) - 1, 0, out.numYTiles(ly) - 1, lx, ly);
                }
        } else if (kind == ExrKind::OnePart) {
            header.setName("only");
            header.setType(Imf::SCANLINEIMAGE);
            Imf::MultiPartOutputFile file(path.c_str(), &header, 1);
            Imf::OutputPart out(file, 0);
            out.setFrameBuffer(fb);
            out.writePixels(h);
        } else {
            Imf::OutputFile out(path.c_str(), header);
            out.setFrameBuffer(fb);
            out.writePixels(h);
        }
        return true;
    } catch (const std::exception &e) {
        ADD_FAILURE() << path << ": " << e.what();
        return false;
    }
}

Imf::Header openexr_header(int w, int h, const std::vector<std::string> &names, Imf::PixelType type,
                           Imf::Compression compression = Imf::ZIP_COMPRESSION) {
    Imf::Header header(w, h);
    header.compression() = compression;
    for (const std::string &n : names) header.channels().insert(n, Imf::Channel(type));
    return header;
}

std::string bits_of(float v) {
    uint32_t b;
    std::memcpy(&b, &v, sizeof b);
    return fmt::format("{} (0x{:08x})", v, b);
}

/// Leaves freed blocks of many sizes filled with `pattern`, the bytes the next allocations of
/// those sizes start with.
void stain_heap(unsigned char pattern) {
    std::vector<void *> blocks;
    // Every small size class (16 bytes apart), then sizes 1/8 apart.
    for (size_t size = 16; size <= (size_t(1) << 16); size += size < 4096 ? 16 : size / 8)
        for (int k = 0; k < 8; ++k) {
            void *b = std::malloc(size);
            if (!b) continue;
            std::memset(b, pattern, size);
            blocks.push_back(b);
        }
    for (auto it = blocks.rbegin(); it != blocks.rend(); ++it) std::free(*it);
}

/// Whether the pixels either module reads from `path` depend on memory the reader never wrote
/// (OpenEXR 3.1 copies a chunk that decompresses to fewer bytes than its lines need from an
/// uninitialised buffer): each module's reads of the file, after the heap is stained with
/// different bytes, differ. Such pixels cannot be compared.
bool pixels_are_undefined(const std::string &path) {
    std::vector<float> lean_first, oiio_first;
    for (unsigned char pattern : {0x00, 0xff, 0x3c, 0xc3, 0x7e}) {
        stain_heap(pattern);
        detail::LeanRead read;
        std::vector<float> lean =
            read_module()->read(path, read) ? read.image.data : std::vector<float>{};
        stain_heap(pattern);
        std::vector<float> oiio;
        try {
            oiio = image_module()->read_image(path).data;
        } catch (const std::exception &) {}
        auto same = [](const std::vector<float> &a, const std::vector<float> &b) {
            return a.size() == b.size() &&
                   (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
        };
        if (pattern == 0x00) {
            lean_first = std::move(lean), oiio_first = std::move(oiio);
        } else if (!same(lean, lean_first) || !same(oiio, oiio_first)) {
            return true;
        }
    }
    return false;
}

/// The fields of two images equal, and their values bit for bit (NaNs by their bits). A damaged
/// file (`damaged`) may have undefined pixels (pixels_are_undefined(`path`)), left uncompared.
void expect_same_image(const Image &lean, const Image &ref, const std::string &what,
                       const std::string &path, bool damaged) {
    SCOPED_TRACE(what);
    EXPECT_EQ(lean.width, ref.width);
    EXPECT_EQ(lean.height, ref.height);
    EXPECT_EQ(lean.channels, ref.channels);
    EXPECT_EQ(lean.x, ref.x);
    EXPECT_EQ(lean.y, ref.y);
    EXPECT_EQ(lean.full_width, ref.full_width);
    EXPECT_EQ(lean.full_height, ref.full_height);
    EXPECT_EQ(lean.channel_names, ref.channel_names);
    ASSERT_EQ(lean.data.size(), ref.data.size());
    if (lean.data.empty() ||
        std::memcmp(lean.data.data(), ref.data.data(), lean.data.size() * sizeof(float)) == 0)
        return;
    static std::vector<std::string> undefined;
    if (std::find(undefined.begin(), undefined.end(), path) != undefined.end()) return;
    const bool varies = pixels_are_undefined(path);
    if (varies && damaged) {
        std::printf("lean_read: %s: pixels read from uninitialised memory, not compared\n",
                    path.c_str());
        undefined.push_back(path);
        return;
    }
    size_t first = 0, count = 0;
    for (size_t i = lean.data.size(); i-- > 0;)
        if (std::memcmp(&lean.data[i], &ref.data[i], sizeof(float)) != 0) first = i, ++count;
    const size_t c = size_t(std::max(ref.channels, 1)), w = size_t(std::max(ref.width, 1));
    ADD_FAILURE() << count << " of " << lean.data.size() << " values differ; the first, value "
                  << first << " (x " << first / c % w << ", y " << first / c / w << ", channel "
                  << first % c << "): lean " << bits_of(lean.data[first]) << ", image module "
                  << bits_of(ref.data[first])
                  << (varies ? " (and the values of a module vary from read to read)" : "");
}

/// What one read of a file by the lean reader gave.
struct LeanResult {
    bool ok = false;
    detail::LeanRead read;
};

LeanResult lean(const std::string &path, bool header_only, bool want_bytes) {
    LeanResult r;
    r.read.header_only = header_only;
    r.read.want_bytes = want_bytes;
    try {
        r.ok = read_module()->read(path, r.read);
    } catch (const std::exception &e) {
        ADD_FAILURE() << "the lean reader threw: " << e.what();
    } catch (...) {
        ADD_FAILURE() << "the lean reader threw";
    }
    if (!r.ok) {
        // Declined: nothing is left in the result.
        EXPECT_EQ(r.read.image.width, 0);
        EXPECT_EQ(r.read.image.channels, 0);
        EXPECT_TRUE(r.read.image.data.empty());
        EXPECT_TRUE(r.read.image.channel_names.empty());
        EXPECT_TRUE(r.read.bytes.empty());
    }
    return r;
}

/// Reads `path` with both modules in the three ways; where the lean reader reads it, the image
/// module must read it too, identically (but for undefined pixels, when the file is `damaged`).
/// Returns which of the three reads the lean reader accepted: 1 read_image(), 2
/// read_image_header(), 4 read_image_bytes().
int compare_file(const std::string &path, Expect expect, bool damaged = false) {
    SCOPED_TRACE(fmt::format("{} (expected {})", path, expect_name(expect)));
    const ImageLibrary *oiio = image_module();
    int accepted = 0;

    // read_image()
    LeanResult full = lean(path, false, false);
    accepted |= full.ok ? 1 : 0;
    if (full.ok) {
        try {
            expect_same_image(full.read.image, oiio->read_image(path), "read_image", path, damaged);
        } catch (const std::exception &e) {
            ADD_FAILURE() << "read_image: the lean reader reads it, the image module throws: "
                          << e.what();
        }
    }

    // read_image_header()
    LeanResult head = lean(path, true, false);
    accepted |= head.ok ? 2 : 0;
    if (head.ok) {
        try {
            const ImageHeader h = oiio->read_image_header(path);
            expect_same_image(head.read.image, h.image, "read_image_header", path, damaged);
            EXPECT_EQ(head.read.keeps_bytes, h.bytes) << "read_image_header: keeps_bytes";
            EXPECT_TRUE(head.read.bytes.empty()) << "read_image_header";
        } catch (const std::exception &e) {
            ADD_FAILURE() << "read_image_header: the lean reader reads it, the image module "
                             "throws: "
                          << e.what();
        }
    }

    // read_image_bytes()
    LeanResult bytes = lean(path, false, true);
    accepted |= bytes.ok ? 4 : 0;
    if (bytes.ok) {
        try {
            const ByteImage b = oiio->read_image_bytes(path);
            expect_same_image(bytes.read.image, b.image, "read_image_bytes", path, damaged);
            EXPECT_EQ(bytes.read.keeps_bytes, !b.bytes.empty()) << "read_image_bytes: keeps_bytes";
            if (head.ok) {
                EXPECT_EQ(bytes.read.keeps_bytes, head.read.keeps_bytes)
                    << "keeps_bytes of read_image_bytes and read_image_header";
            }
            EXPECT_EQ(bytes.read.bytes.size(), b.bytes.size()) << "read_image_bytes: bytes";
            if (bytes.read.bytes.size() == b.bytes.size() && bytes.read.bytes != b.bytes) {
                const auto d = std::mismatch(bytes.read.bytes.begin(), bytes.read.bytes.end(),
                                             b.bytes.begin());
                ADD_FAILURE() << "read_image_bytes: byte " << d.first - bytes.read.bytes.begin()
                              << " differs: lean " << int(*d.first) << ", image module "
                              << int(*d.second);
            }
            for (size_t i = 0; i < 256; ++i)
                if (std::memcmp(&bytes.read.values[i], &b.values[i], sizeof(float)) != 0) {
                    ADD_FAILURE() << "read_image_bytes: values[" << i << "]: lean "
                                  << bits_of(bytes.read.values[i]) << ", image module "
                                  << bits_of(b.values[i]);
                    break;
                }
        } catch (const std::exception &e) {
            ADD_FAILURE() << "read_image_bytes: the lean reader reads it, the image module "
                             "throws: "
                          << e.what();
        }
    }

    if (expect == Expect::Read) {
        EXPECT_TRUE(full.ok) << "read_image: the lean reader declines it";
        EXPECT_TRUE(head.ok) << "read_image_header: the lean reader declines it";
        EXPECT_TRUE(bytes.ok) << "read_image_bytes: the lean reader declines it";
    } else if (expect == Expect::Decline || expect == Expect::Refuse) {
        EXPECT_EQ(accepted, 0) << "the lean reader reads a file it should leave to OpenImageIO";
        // OpenImageIO reads it (the test files are valid), so libfacet still does; or gives the
        // error libfacet gives.
        if (expect == Expect::Decline)
            EXPECT_NO_THROW(oiio->read_image(path));
        else
            EXPECT_THROW(oiio->read_image(path), std::exception);
    }
    return accepted;
}

/// A fresh folder per test, removed afterwards.
class LeanReader : public ::testing::Test {
protected:
    void SetUp() override {
        ASSERT_NE(image_module(), nullptr);
        ASSERT_NE(read_module(), nullptr);
        const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() /
                fmt::format("facet-lean-read-{}-{}", ::getpid(), info->name());
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }
    std::string path(const std::string &name) const { return (m_dir / name).string(); }

    /// Writes a file with `write` (false: the writer cannot make it, the file is skipped) and
    /// queues it for check().
    template <typename Write> void add(const std::string &name, Expect expect, Write &&write) {
        if (!write(path(name))) {
            std::printf("lean_read: %s not written, skipped\n", name.c_str());
            return;
        }
        m_files.emplace_back(name, expect);
    }
    /// compare_file() on every queued file; prints the files of Expect::Either the lean reader
    /// took and left.
    void check(bool damaged = false) {
        std::string taken, left;
        for (const auto &[name, expect] : m_files) {
            const int accepted = compare_file(path(name), expect, damaged);
            if (expect != Expect::Either) continue;
            (accepted ? taken : left) += " " + name;
            if (accepted && accepted != 7) { // the header, say, but not the pixels
                taken += "(only";
                if (accepted & 1) taken += " image";
                if (accepted & 2) taken += " header";
                if (accepted & 4) taken += " bytes";
                taken += ")";
            }
        }
        if (!taken.empty() || !left.empty())
            std::printf("lean_read: read by the lean reader:%s\nlean_read: left to "
                        "OpenImageIO:%s\n",
                        taken.empty() ? " none" : taken.c_str(),
                        left.empty() ? " none" : left.c_str());
        m_files.clear();
    }

    fs::path m_dir;
    std::vector<std::pair<std::string, Expect>> m_files;
};

/// An EXR of `channels` names in `format` (HALF, FLOAT, UINT), float pixels.
OIIO::ImageSpec exr_spec(int w, int h, const std::vector<std::string> &names, OIIO::TypeDesc format,
                         const char *compression = "zip") {
    OIIO::ImageSpec spec(w, h, int(names.size()), format);
    spec.channelnames = names;
    spec.alpha_channel = -1;
    for (size_t i = 0; i < names.size(); ++i)
        if (names[i] == "A") spec.alpha_channel = int(i);
    spec.attribute("compression", compression);
    return spec;
}

} // namespace

TEST_F(LeanReader, ModulesLoadWithTheirVersions) {
    EXPECT_EQ(image_module()->version, FACET_IMAGE_LIBRARY_VERSION);
    EXPECT_EQ(read_module()->version, FACET_READ_LIBRARY_VERSION);
    const std::string versions = read_module()->versions();
    EXPECT_NE(versions.find("OpenEXR"), std::string::npos) << versions;
    EXPECT_NE(versions.find("libpng"), std::string::npos) << versions;
    EXPECT_NE(versions.find("libjpeg"), std::string::npos) << versions;
}

TEST_F(LeanReader, MissingEmptyAndOtherFilesAreDeclined) {
    put_file(path("empty.png"), "");
    put_file(path("short.exr"), "v/1");
    put_file(path("text.jpg"), "not an image at all");
    fs::create_directories(path("folder.png"));
    std::vector<uint8_t> px = byte_pixels(5, 4, 3, 1);
    ASSERT_TRUE(oiio_write(path("a.tga"), OIIO::ImageSpec(5, 4, 3, OIIO::TypeDesc::UINT8),
                           OIIO::TypeDesc::UINT8, px.data()));
    ASSERT_TRUE(oiio_write(path("a.bmp"), OIIO::ImageSpec(5, 4, 3, OIIO::TypeDesc::UINT8),
                           OIIO::TypeDesc::UINT8, px.data()));
    for (const char *name :
         {"missing.exr", "empty.png", "short.exr", "text.jpg", "folder.png", "a.tga", "a.bmp"}) {
        SCOPED_TRACE(name);
        for (int mode = 0; mode < 3; ++mode)
            EXPECT_FALSE(lean(path(name), mode == 1, mode == 2).ok);
    }
}

TEST_F(LeanReader, ExrFilesMatchTheImageModule) {
    const auto HALF = OIIO::TypeDesc::HALF, FLOAT = OIIO::TypeDesc::FLOAT;
    const char *compressions[] = {"zip", "none", "piz", "rle", "zips", "pxr24", "b44", "dwaa"};
    int n = 0;
    for (OIIO::TypeDesc format : {HALF, FLOAT})
        for (int channels = 1; channels <= 4; ++channels)
            for (int layout = 0; layout < 3; ++layout) { // scanlines, tiles, MIP-mapped tiles
                const int w = 37 + 8 * layout, h = 23 + 5 * channels;
                const std::string name =
                    fmt::format("{}{}-{}.exr", format == HALF ? "half" : "float", channels,
                                layout == 0   ? "scanline"
                                : layout == 1 ? "tiled"
                                              : "mipmap");
                const char *compression = compressions[size_t(n++) % std::size(compressions)];
                add(name, Expect::Read, [&](const std::string &p) {
                    OIIO::ImageSpec spec =
                        exr_spec(w, h, default_names(channels), format, compression);
                    if (layout > 0) spec.tile_width = spec.tile_height = 16;
                    if (layout == 2) {
                        spec.attribute("textureformat", "Plain Texture");
                        spec.attribute("openexr:levelmode", 1); // MIPMAP_LEVELS
                    }
                    const std::vector<float> px = float_pixels(w, h, channels, uint32_t(n));
                    if (!oiio_write(p, spec, FLOAT, px.data(), layout == 2)) return false;
                    const Structure s = structure(p);
                    EXPECT_EQ(s.tile_width, layout > 0 ? 16 : 0) << p;
                    EXPECT_EQ(s.levels, layout == 2 ? 6 : 1) << p; // 45x33 down to 1x1
                    return true;
                });
            }

    // Every half value (Y, 256 x 256): NaNs, infinities, denormals.
    add("half-every-code.exr", Expect::Read, [&](const std::string &p) {
        std::vector<uint16_t> px(65536);
        for (size_t i = 0; i < px.size(); ++i) px[i] = uint16_t(i);
        return oiio_write(p, exr_spec(256, 256, {"Y"}, HALF), HALF, px.data());
    });
    add("half-every-code-tiled.exr", Expect::Read, [&](const std::string &p) {
        std::vector<uint16_t> px(65536 * 2);
        for (size_t i = 0; i < px.size(); ++i) px[i] = uint16_t(i * 40503u >> 1);
        OIIO::ImageSpec spec = exr_spec(256, 256, {"Y", "A"}, HALF, "piz");
        spec.tile_width = spec.tile_height = 16;
        return oiio_write(p, spec, HALF, px.data());
    });
    // Float NaNs with payloads, signalling NaNs, negative zero, the extremes.
    add("float-special-bits.exr", Expect::Read, [&](const std::string &p) {
        const uint32_t specials[] = {0x7f800001u, 0x7fbfffffu, 0x7fc00000u, 0xffc00001u,
                                     0x80000000u, 0x00000001u, 0x7f7fffffu, 0xff800000u,
                                     0x007fffffu, 0x3f800000u, 0xbf800000u, 0x7fffffffu};
        std::vector<uint32_t> px(size_t(12 * 5 * 3));
        for (size_t i = 0; i < px.size(); ++i)
            px[i] = i % 3 == 0 ? specials[(i / 3) % 12] : hash32(uint32_t(i));
        return oiio_write(p, exr_spec(12, 5, {"R", "G", "B"}, FLOAT, "none"), FLOAT, px.data());
    });

    // Data windows inside and across the display window.
    for (int tiled = 0; tiled < 2; ++tiled) {
        add(fmt::format("window-inside-{}.exr", tiled), Expect::Read, [&](const std::string &p) {
            OIIO::ImageSpec spec = exr_spec(37, 23, {"R", "G", "B", "A"}, HALF);
            spec.x = 5, spec.y = 3, spec.full_x = 0, spec.full_y = 0;
            spec.full_width = 64, spec.full_height = 48;
            if (tiled) spec.tile_width = spec.tile_height = 16;
            const std::vector<float> px = float_pixels(37, 23, 4, 7);
            return oiio_write(p, spec, FLOAT, px.data());
        });
        add(fmt::format("window-overscan-{}.exr", tiled), Expect::Read, [&](const std::string &p) {
            OIIO::ImageSpec spec = exr_spec(40, 30, {"Y"}, FLOAT);
            spec.x = -6, spec.y = 2, spec.full_x = -4, spec.full_y = -2;
            spec.full_width = 33, spec.full_height = 20;
            if (tiled) spec.tile_width = spec.tile_height = 16;
            const std::vector<float> px = float_pixels(40, 30, 1, 8);
            return oiio_write(p, spec, FLOAT, px.data());
        });
    }
    add("one-pixel.exr", Expect::Read, [&](const std::string &p) {
        const float px[3] = {0.25f, -1.f, 65504.f};
        return oiio_write(p, exr_spec(1, 1, {"R", "G", "B"}, HALF), FLOAT, px);
    });
    add("tall-bands.exr", Expect::Read, [&](const std::string &p) {
        const std::vector<float> px = float_pixels(3, 5000, 1, 9); // more rows than one band
        return oiio_write(p, exr_spec(3, 5000, {"Y"}, FLOAT), FLOAT, px.data());
    });

    // Half colour with a float alpha (per-channel formats).
    add("mixed-half-float.exr", Expect::Either, [&](const std::string &p) {
        OIIO::ImageSpec spec = exr_spec(21, 13, {"R", "G", "B", "A"}, HALF);
        spec.channelformats = {HALF, HALF, HALF, FLOAT};
        const std::vector<float> px = float_pixels(21, 13, 4, 10);
        return oiio_write(p, spec, FLOAT, px.data());
    });

    // Files left to OpenImageIO: layers, other channel names, integer channels, more channels,
    // several parts.
    const std::vector<std::vector<std::string>> declined_names = {
        {"diffuse.R", "diffuse.G", "diffuse.B"},
        {"Z"},
        {"R", "G", "B", "A", "Z"},
        {"R", "G", "B", "Z"},
        {"R", "G"},
        {"A"},
        {"Y", "Z"},
        {"R", "G", "B", "A", "depth.Z"}};
    for (size_t i = 0; i < declined_names.size(); ++i) {
        const auto &names = declined_names[i];
        add(fmt::format("declined-names-{}.exr", i), Expect::Decline, [&](const std::string &p) {
            const std::vector<float> px = float_pixels(11, 7, int(names.size()), uint32_t(i));
            return oiio_write(p, exr_spec(11, 7, names, i % 2 ? FLOAT : HALF), FLOAT, px.data());
        });
    }
    add("lowercase-rgb.exr", Expect::Either, [&](const std::string &p) {
        const std::vector<float> px = float_pixels(11, 7, 3, 20);
        return oiio_write(p, exr_spec(11, 7, {"r", "g", "b"}, HALF), FLOAT, px.data());
    });
    add("uint-rgb.exr", Expect::Decline, [&](const std::string &p) {
        std::vector<uint32_t> px(11 * 7 * 3);
        for (size_t i = 0; i < px.size(); ++i) px[i] = hash32(uint32_t(i));
        return oiio_write(p, exr_spec(11, 7, {"R", "G", "B"}, OIIO::TypeDesc::UINT),
                          OIIO::TypeDesc::UINT, px.data());
    });
    add("uint-alpha.exr", Expect::Decline, [&](const std::string &p) {
        OIIO::ImageSpec spec = exr_spec(11, 7, {"R", "G", "B", "A"}, HALF);
        spec.channelformats = {HALF, HALF, HALF, OIIO::TypeDesc::UINT};
        std::vector<float> clean(11 * 7 * 4);
        for (size_t i = 0; i < clean.size(); ++i) clean[i] = float(i % 97);
        return oiio_write(p, spec, FLOAT, clean.data());
    });
    add("multipart.exr", Expect::Decline, [&](const std::string &p) {
        auto out = OIIO::ImageOutput::create(p);
        if (!out || !out->supports("multiimage")) return false;
        OIIO::ImageSpec specs[2] = {exr_spec(13, 9, {"R", "G", "B"}, HALF),
                                    exr_spec(13, 9, {"R", "G", "B"}, HALF)};
        specs[0].attribute("name", "first");
        specs[1].attribute("name", "second");
        const std::vector<float> px = float_pixels(13, 9, 3, 22);
        if (!out->open(p, 2, specs) || !out->write_image(FLOAT, px.data()) ||
            !out->open(p, specs[1], OIIO::ImageOutput::AppendSubimage) ||
            !out->write_image(FLOAT, px.data())) {
            ADD_FAILURE() << p << ": " << out->geterror();
            return false;
        }
        if (!out->close()) return false;
        EXPECT_EQ(structure(p).subimages, 2);
        return true;
    });

    // Written by OpenEXR itself.
    add("decreasing-y.exr", Expect::Read, [&](const std::string &p) {
        Imf::Header header = openexr_header(29, 41, {"R", "G", "B", "A"}, Imf::HALF);
        header.lineOrder() = Imf::DECREASING_Y;
        return openexr_write(p, header, ExrKind::Scanlines, 100);
    });
    add("tiled-random-y.exr", Expect::Read, [&](const std::string &p) {
        Imf::Header header = openexr_header(45, 37, {"Y"}, Imf::FLOAT, Imf::PIZ_COMPRESSION);
        header.lineOrder() = Imf::RANDOM_Y;
        header.setTileDescription(Imf::TileDescription(32, 8));
        return openexr_write(p, header, ExrKind::Tiles, 101);
    });
    add("tiled-mipmap-round-up.exr", Expect::Read, [&](const std::string &p) {
        Imf::Header header = openexr_header(45, 37, {"R", "G", "B"}, Imf::HALF);
        header.setTileDescription(Imf::TileDescription(8, 8, Imf::MIPMAP_LEVELS, Imf::ROUND_UP));
        return openexr_write(p, header, ExrKind::Tiles, 102);
    });
    add("tiled-ripmap.exr", Expect::Either, [&](const std::string &p) {
        Imf::Header header = openexr_header(45, 37, {"Y", "A"}, Imf::HALF);
        header.setTileDescription(Imf::TileDescription(16, 16, Imf::RIPMAP_LEVELS));
        if (!openexr_write(p, header, ExrKind::Tiles, 103)) return false;
        EXPECT_GT(structure(p).levels, 1);
        return true;
    });
    add("tiled-window.exr", Expect::Read, [&](const std::string &p) {
        Imf::Header header = openexr_header(45, 37, {"R", "G", "B"}, Imf::FLOAT);
        header.displayWindow() = Imath::Box2i({-10, -20}, {60, 40});
        header.dataWindow() = Imath::Box2i({-13, 7}, {31, 43});
        header.setTileDescription(Imf::TileDescription(16, 16));
        return openexr_write(p, header, ExrKind::Tiles, 104);
    });
    for (Imf::Compression compression :
         {Imf::NO_COMPRESSION, Imf::RLE_COMPRESSION, Imf::ZIPS_COMPRESSION, Imf::ZIP_COMPRESSION,
          Imf::PIZ_COMPRESSION, Imf::PXR24_COMPRESSION, Imf::B44_COMPRESSION, Imf::B44A_COMPRESSION,
          Imf::DWAA_COMPRESSION, Imf::DWAB_COMPRESSION})
        add(fmt::format("openexr-compression-{}.exr", int(compression)), Expect::Read,
            [&](const std::string &p) {
                Imf::Header header =
                    openexr_header(67, 53, {"R", "G", "B", "A"}, Imf::HALF, compression);
                return openexr_write(p, header, ExrKind::Scanlines, 105 + int(compression));
            });
    add("one-part-multipart.exr", Expect::Either, [&](const std::string &p) {
        return openexr_write(p, openexr_header(21, 13, {"R", "G", "B"}, Imf::HALF),
                             ExrKind::OnePart, 120);
    });
    // Luminance and subsampled chroma (Y, RY, BY, A): OpenImageIO refuses them.
    add("luminance-chroma.exr", Expect::Refuse, [&](const std::string &p) {
        return openexr_write(p, Imf::Header(22, 14), ExrKind::LuminanceChroma, 121);
    });
    check();
}

TEST_F(LeanReader, PngFilesMatchTheImageModule) {
    const auto UINT8 = OIIO::TypeDesc::UINT8, UINT16 = OIIO::TypeDesc::UINT16;
    // OpenImageIO's writer: 8 and 16 bits, grey, grey + alpha, RGB, RGBA, odd sizes.
    for (int bits : {8, 16})
        for (int channels = 1; channels <= 4; ++channels) {
            const int w = 37 + channels, h = 23 - channels;
            add(fmt::format("oiio-{}bit-{}ch.png", bits, channels), Expect::Read,
                [&](const std::string &p) {
                    OIIO::ImageSpec spec(w, h, channels, bits == 8 ? UINT8 : UINT16);
                    spec.attribute("oiio:UnassociatedAlpha", 1); // stored as given
                    spec.attribute("png:compressionLevel", channels * 2);
                    if (bits == 8) {
                        const std::vector<uint8_t> px = byte_pixels(w, h, channels, 30);
                        return oiio_write(p, spec, UINT8, px.data());
                    }
                    const std::vector<uint16_t> px = short_pixels(w, h, channels, 31);
                    return oiio_write(p, spec, UINT16, px.data());
                });
        }
    // Every 8-bit code in every channel, and every 16-bit code.
    add("every-byte.png", Expect::Read, [&](const std::string &p) {
        std::vector<uint8_t> px(256 * 3 * 4);
        for (size_t i = 0; i < px.size(); ++i) px[i] = uint8_t(i / 4 + 85 * (i % 4));
        OIIO::ImageSpec spec(256, 3, 4, UINT8);
        spec.attribute("oiio:UnassociatedAlpha", 1);
        return oiio_write(p, spec, UINT8, px.data());
    });
    add("every-short.png", Expect::Read, [&](const std::string &p) {
        std::vector<uint16_t> px(65536);
        for (size_t i = 0; i < px.size(); ++i) px[i] = uint16_t(i);
        return oiio_write(p, OIIO::ImageSpec(256, 256, 1, UINT16), UINT16, px.data());
    });
    add("one-pixel.png", Expect::Read, [&](const std::string &p) {
        const uint8_t px[3] = {0, 128, 255};
        return oiio_write(p, OIIO::ImageSpec(1, 1, 3, UINT8), UINT8, px);
    });

    // libpng: what OpenImageIO does not write.
    auto packed = [](int w, int h, int channels, int bits, uint32_t seed) {
        PngFile png;
        png.width = w, png.height = h, png.bit_depth = bits;
        png.color_type = channels == 1   ? PNG_COLOR_TYPE_GRAY
                         : channels == 2 ? PNG_COLOR_TYPE_GA
                         : channels == 3 ? PNG_COLOR_TYPE_RGB
                                         : PNG_COLOR_TYPE_RGB_ALPHA;
        png.data.resize(png.rowbytes() * size_t(h));
        for (size_t i = 0; i < png.data.size(); ++i)
            png.data[i] = uint8_t(hash32(uint32_t(i) + seed) >> ((i % 5) * 3));
        return png;
    };
    auto with = [&](PngFile png) {
        return [png](const std::string &p) { return libpng_write(p, png); };
    };
    add("libpng-rgb8.png", Expect::Read, with(packed(37, 23, 3, 8, 40)));
    add("libpng-ga16.png", Expect::Read, with(packed(19, 29, 2, 16, 41)));
    for (int channels = 1; channels <= 4; ++channels)
        for (int bits : {8, 16}) {
            PngFile png = packed(29 + channels, 31, channels, bits, uint32_t(42 + channels));
            png.interlace = true;
            add(fmt::format("interlaced-{}bit-{}ch.png", bits, channels), Expect::Either,
                with(png));
        }
    {
        PngFile tiny = packed(3, 2, 3, 8, 50); // smaller than Adam7's first passes
        tiny.interlace = true;
        add("interlaced-3x2.png", Expect::Either, with(tiny));
    }
    for (int bits : {1, 2, 4}) {
        add(fmt::format("grey-{}bit.png", bits), Expect::Either,
            with(packed(37, 23, 1, bits, uint32_t(51 + bits))));
        PngFile pal = packed(37, 23, 1, bits, uint32_t(55 + bits));
        pal.color_type = PNG_COLOR_TYPE_PALETTE;
        for (int i = 0; i < (1 << bits); ++i)
            pal.palette.push_back({png_byte(hash32(uint32_t(i)) & 255),
                                   png_byte(hash32(uint32_t(i) + 1) & 255), png_byte(i * 3)});
        add(fmt::format("palette-{}bit.png", bits), Expect::Either, with(pal));
    }
    {
        PngFile pal = packed(41, 17, 1, 8, 60);
        pal.color_type = PNG_COLOR_TYPE_PALETTE;
        for (int i = 0; i < 256; ++i)
            pal.palette.push_back({png_byte(i), png_byte(255 - i), png_byte(hash32(uint32_t(i)))});
        add("palette-8bit.png", Expect::Either, with(pal));
        for (int i = 0; i < 200; ++i) pal.trans_alpha.push_back(png_byte(hash32(uint32_t(i + 9))));
        add("palette-trns.png", Expect::Either, with(pal));
        pal.interlace = true;
        add("palette-trns-interlaced.png", Expect::Either, with(pal));
    }
    {
        PngFile grey = packed(23, 19, 1, 8, 61);
        grey.has_trans_color = true;
        grey.trans_color.gray = grey.data[5];
        add("grey-trns.png", Expect::Either, with(grey));
        PngFile grey16 = packed(23, 19, 1, 16, 62);
        grey16.has_trans_color = true;
        grey16.trans_color.gray = png_uint_16(grey16.data[0] << 8 | grey16.data[1]);
        add("grey16-trns.png", Expect::Either, with(grey16));
        PngFile grey2 = packed(23, 19, 1, 2, 63);
        grey2.has_trans_color = true;
        grey2.trans_color.gray = 1;
        add("grey2-trns.png", Expect::Either, with(grey2));
        PngFile rgb = packed(23, 19, 3, 8, 64);
        rgb.has_trans_color = true;
        rgb.trans_color.red = rgb.data[0], rgb.trans_color.green = rgb.data[1];
        rgb.trans_color.blue = rgb.data[2];
        add("rgb-trns.png", Expect::Either, with(rgb));
        PngFile rgb16 = packed(23, 19, 3, 16, 65);
        rgb16.has_trans_color = true;
        rgb16.trans_color.red = png_uint_16(rgb16.data[0] << 8 | rgb16.data[1]);
        add("rgb16-trns.png", Expect::Either, with(rgb16));
        PngFile gamma = packed(23, 19, 3, 8, 66);
        gamma.gamma = 1.0;
        add("rgb-gamma1.png", Expect::Either, with(gamma));
    }
    // A PNG whose name says JPEG: read by its contents, as OpenImageIO does.
    add("png-named.jpg", Expect::Either, with(packed(9, 7, 3, 8, 67)));
    {
        PngFile sbit = packed(23, 19, 4, 16, 68);
        sbit.significant_bits = 10;
        add("rgba16-sbit.png", Expect::Either, with(sbit));
    }
    // More rows than one band of the image module's reads (4096 rows of a narrow image).
    add("tall-grey.png", Expect::Read, with(packed(3, 5000, 1, 8, 69)));
    add("tall-rgb16.png", Expect::Read, with(packed(2, 4500, 3, 16, 70)));
    {
        PngFile tall = packed(2, 4200, 4, 8, 71);
        tall.interlace = true;
        add("tall-interlaced.png", Expect::Either, with(tall));
    }
    add("wide-ga.png", Expect::Read, with(packed(5000, 3, 2, 8, 72)));
    check();
}

TEST_F(LeanReader, JpegFilesMatchTheImageModule) {
    const auto UINT8 = OIIO::TypeDesc::UINT8;
    auto oiio_jpeg = [&](int w, int h, int channels, const char *subsampling, bool progressive,
                         uint32_t seed) {
        return [=](const std::string &p) {
            OIIO::ImageSpec spec(w, h, channels, UINT8);
            spec.attribute("Compression", "jpeg:90");
            spec.attribute("CompressionQuality", 90);
            if (subsampling) spec.attribute("jpeg:subsampling", subsampling);
            if (progressive) spec.attribute("jpeg:progressive", 1);
            const std::vector<uint8_t> px = byte_pixels(w, h, channels, seed);
            return oiio_write(p, spec, UINT8, px.data());
        };
    };
    add("grey-37x23.jpg", Expect::Read, oiio_jpeg(37, 23, 1, nullptr, false, 70));
    add("rgb-37x23.jpg", Expect::Read, oiio_jpeg(37, 23, 3, nullptr, false, 71));
    add("rgb-444.jpg", Expect::Read, oiio_jpeg(37, 23, 3, "4:4:4", false, 72));
    add("rgb-422.jpg", Expect::Read, oiio_jpeg(37, 23, 3, "4:2:2", false, 73));
    add("rgb-420.jpg", Expect::Read, oiio_jpeg(37, 23, 3, "4:2:0", false, 74));
    add("rgb-411.jpg", Expect::Either, oiio_jpeg(37, 23, 3, "4:1:1", false, 75));
    add("rgb-420-64x48.jpg", Expect::Read, oiio_jpeg(64, 48, 3, "4:2:0", false, 76));
    add("rgb-1x1.jpg", Expect::Read, oiio_jpeg(1, 1, 3, "4:2:0", false, 77));
    add("grey-every-byte.jpg", Expect::Read, [&](const std::string &p) {
        std::vector<uint8_t> px(256 * 3);
        for (size_t i = 0; i < px.size(); ++i) px[i] = uint8_t(i);
        OIIO::ImageSpec spec(256, 3, 1, UINT8);
        spec.attribute("Compression", "jpeg:90");
        return oiio_write(p, spec, UINT8, px.data());
    });
    add("rgb-progressive.jpg", Expect::Either, oiio_jpeg(37, 23, 3, "4:2:0", true, 78));
    add("grey-progressive.jpg", Expect::Either, oiio_jpeg(37, 23, 1, nullptr, true, 79));

    auto direct = [&](int w, int h, int components, J_COLOR_SPACE in, J_COLOR_SPACE file,
                      bool arithmetic, int restart, uint32_t seed) {
        JpegFile jpg;
        jpg.width = w, jpg.height = h, jpg.components = components;
        jpg.in_space = in, jpg.file_space = file;
        jpg.arithmetic = arithmetic, jpg.restart_rows = restart;
        jpg.data = byte_pixels(w, h, components, seed);
        return [jpg](const std::string &p) { return libjpeg_write(p, jpg); };
    };
    add("libjpeg-rgb.jpg", Expect::Read, direct(37, 23, 3, JCS_RGB, JCS_UNKNOWN, false, 0, 80));
    add("libjpeg-restarts.jpg", Expect::Read,
        direct(45, 40, 3, JCS_RGB, JCS_UNKNOWN, false, 1, 81));
    add("libjpeg-grey-restarts.jpg", Expect::Read,
        direct(45, 40, 1, JCS_GRAYSCALE, JCS_UNKNOWN, false, 2, 82));
    add("libjpeg-arithmetic.jpg", Expect::Either,
        direct(37, 23, 3, JCS_RGB, JCS_UNKNOWN, true, 0, 83));
    add("libjpeg-rgb-no-ycc.jpg", Expect::Either,
        direct(37, 23, 3, JCS_RGB, JCS_RGB, false, 0, 84));
    add("libjpeg-cmyk.jpg", Expect::Either, direct(37, 23, 4, JCS_CMYK, JCS_CMYK, false, 0, 85));
    add("libjpeg-ycck.jpg", Expect::Either, direct(37, 23, 4, JCS_CMYK, JCS_YCCK, false, 0, 86));
    add("rgb-orientation-6.jpg", Expect::Read, [&](const std::string &p) {
        OIIO::ImageSpec spec(31, 17, 3, UINT8);
        spec.attribute("Orientation", 6); // Exif: OpenImageIO reads the pixels as stored
        const std::vector<uint8_t> px = byte_pixels(31, 17, 3, 87);
        return oiio_write(p, spec, UINT8, px.data());
    });

    // Files whose names do not say what they are: read by their contents.
    auto renamed = [&](const char *ext, auto &&write) {
        return
            [=](const std::string &p) { return write(p + ext) && (fs::rename(p + ext, p), true); };
    };
    add("jpeg-named.png", Expect::Either,
        renamed(".jpg", oiio_jpeg(19, 11, 3, nullptr, false, 88)));
    add("jpeg-no-extension", Expect::Either,
        renamed(".jpg", oiio_jpeg(19, 11, 1, nullptr, false, 89)));
    add("exr-named.jpg", Expect::Either, renamed(".exr", [&](const std::string &p) {
            const std::vector<float> px = float_pixels(13, 9, 3, 90);
            return oiio_write(p, exr_spec(13, 9, {"R", "G", "B"}, OIIO::TypeDesc::HALF),
                              OIIO::TypeDesc::FLOAT, px.data());
        }));
    add("UPPER.JPG", Expect::Read, oiio_jpeg(19, 11, 3, nullptr, false, 91));
    add("tall-grey.jpg", Expect::Read, oiio_jpeg(5, 5000, 1, nullptr, false, 92));
    add("tall-rgb-420.jpg", Expect::Read, oiio_jpeg(3, 4400, 3, "4:2:0", false, 93));
    check();
}

TEST_F(LeanReader, TruncatedAndDamagedFilesAreDeclinedOrMatch) {
    // Valid files cut short or with flipped bytes: the lean reader may read what a reader of
    // the format reads, but only as the image module does (which then must not throw).
    std::vector<std::string> sources;
    {
        OIIO::ImageSpec spec = exr_spec(37, 23, {"R", "G", "B", "A"}, OIIO::TypeDesc::HALF);
        const std::vector<float> px = float_pixels(37, 23, 4, 90);
        ASSERT_TRUE(oiio_write(path("src.exr"), spec, OIIO::TypeDesc::FLOAT, px.data()));
        spec.tile_width = spec.tile_height = 16;
        ASSERT_TRUE(oiio_write(path("src-tiled.exr"), spec, OIIO::TypeDesc::FLOAT, px.data()));
        const std::vector<uint8_t> bytes = byte_pixels(37, 23, 3, 91);
        ASSERT_TRUE(oiio_write(path("src.png"), OIIO::ImageSpec(37, 23, 3, OIIO::TypeDesc::UINT8),
                               OIIO::TypeDesc::UINT8, bytes.data()));
        OIIO::ImageSpec jspec(37, 23, 3, OIIO::TypeDesc::UINT8);
        jspec.attribute("Compression", "jpeg:90");
        ASSERT_TRUE(oiio_write(path("src.jpg"), jspec, OIIO::TypeDesc::UINT8, bytes.data()));
        jspec.attribute("jpeg:progressive", 1);
        ASSERT_TRUE(
            oiio_write(path("src-progressive.jpg"), jspec, OIIO::TypeDesc::UINT8, bytes.data()));
        sources = {"src.exr", "src-tiled.exr", "src.png", "src.jpg", "src-progressive.jpg"};
    }
    for (const std::string &src : sources) {
        const std::string bytes = file_bytes(path(src));
        for (double keep : {0.1, 0.5, 0.9, 0.99}) {
            const std::string name = fmt::format("cut-{}-{}", keep, src);
            put_file(path(name), bytes.substr(0, size_t(double(bytes.size()) * keep)));
            m_files.emplace_back(name, Expect::Either);
        }
        for (int k = 0; k < 6; ++k) {
            std::string damaged = bytes;
            const size_t at = 8 + hash32(uint32_t(k) + 1000) % (damaged.size() - 8);
            damaged[at] = char(damaged[at] ^ 0x5a);
            const std::string name = fmt::format("flip-{}-{}", at, src);
            put_file(path(name), damaged);
            m_files.emplace_back(name, Expect::Either);
        }
    }
    check(/*damaged=*/true);
}

TEST_F(LeanReader, RepositoryImagesMatchTheImageModule) {
    // Every EXR, PNG and JPEG of the repository's tests and scenes.
    int files = 0;
    for (const char *folder : {"tests/data", "tests/chi2", "tests/compat/data", "scenes"}) {
        const fs::path root = fs::path(FACET_SOURCE_DIR) / folder;
        if (!fs::is_directory(root)) continue;
        for (const auto &e : fs::recursive_directory_iterator(root)) {
            if (!e.is_regular_file()) continue;
            std::string ext = e.path().extension().string();
            std::transform(ext.begin(), ext.end(), ext.begin(),
                           [](unsigned char ch) { return char(std::tolower(ch)); });
            if (ext != ".exr" && ext != ".png" && ext != ".jpg" && ext != ".jpeg") continue;
            if (e.path().string().find("/fuzz/") != std::string::npos) continue; // below
            compare_file(e.path().string(), Expect::Either);
            ++files;
        }
    }
    EXPECT_GT(files, 20);
}

TEST_F(LeanReader, FuzzInputsNeverDisagree) {
    // The image fuzzer's inputs: the first byte picks the extension (tests/fuzz/image.cpp), the
    // rest is the file. Hostile files: no crash, no exception from the lean reader, and
    // whatever it reads, the image module reads identically.
    const char *const extensions[] = {".exr", ".png", ".hdr", ".pfm",
                                      ".jpg", ".tga", ".bmp", ".tif"};
    const fs::path root = fs::path(FACET_TEST_DATA_DIR) / "fuzz" / "image";
    int files = 0, read = 0;
    for (const char *sub : {"corpus", "grown", "regressions"}) {
        if (!fs::is_directory(root / sub)) continue;
        std::vector<fs::path> inputs;
        for (const auto &e : fs::directory_iterator(root / sub))
            if (e.is_regular_file()) inputs.push_back(e.path());
        std::sort(inputs.begin(), inputs.end());
        for (const fs::path &input : inputs) {
            const std::string bytes = file_bytes(input.string());
            if (bytes.empty()) continue;
            const std::string file = path(fmt::format("{}-{}{}", sub, input.filename().string(),
                                                      extensions[uint8_t(bytes[0]) % 8]));
            put_file(file, bytes.substr(1));
            read += compare_file(file, Expect::Either, /*damaged=*/true) > 0;
            fs::remove(file);
            ++files;
        }
    }
    EXPECT_GT(files, 50);
    std::printf("lean_read: %d of %d fuzz inputs read by the lean reader\n", read, files);
}

TEST_F(LeanReader, ConcurrentReadsGiveTheSameImages) {
    // Textures are loaded on several threads: the lean readers keep no state between reads.
    const std::vector<float> f = float_pixels(45, 33, 4, 200);
    OIIO::ImageSpec spec = exr_spec(45, 33, {"R", "G", "B", "A"}, OIIO::TypeDesc::HALF);
    ASSERT_TRUE(oiio_write(path("a.exr"), spec, OIIO::TypeDesc::FLOAT, f.data()));
    spec.tile_width = spec.tile_height = 16;
    ASSERT_TRUE(oiio_write(path("t.exr"), spec, OIIO::TypeDesc::FLOAT, f.data()));
    const std::vector<uint8_t> b = byte_pixels(45, 33, 3, 201);
    ASSERT_TRUE(oiio_write(path("a.png"), OIIO::ImageSpec(45, 33, 3, OIIO::TypeDesc::UINT8),
                           OIIO::TypeDesc::UINT8, b.data()));
    ASSERT_TRUE(oiio_write(path("a.jpg"), OIIO::ImageSpec(45, 33, 3, OIIO::TypeDesc::UINT8),
                           OIIO::TypeDesc::UINT8, b.data()));
    const std::vector<std::string> names = {"a.exr", "t.exr", "a.png", "a.jpg"};
    std::vector<std::vector<float>> expected;
    for (const std::string &name : names) {
        detail::LeanRead read;
        ASSERT_TRUE(read_module()->read(path(name), read)) << name;
        expected.push_back(read.image.data);
    }
    auto same = [](const float *a, const std::vector<float> &b) { // NaNs by their bits
        return std::memcmp(a, b.data(), b.size() * sizeof(float)) == 0;
    };
    std::atomic<int> wrong{0}, declined{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
            for (int i = 0; i < 40; ++i) {
                const size_t k = size_t(t + i) % names.size();
                detail::LeanRead read;
                read.want_bytes = i % 3 == 0;
                if (!read_module()->read(path(names[k]), read)) {
                    ++declined;
                } else if (read.keeps_bytes) {
                    for (size_t v = 0; v < read.bytes.size(); ++v)
                        if (std::memcmp(&read.values[read.bytes[v]], &expected[k][v],
                                        sizeof(float)) != 0) {
                            ++wrong;
                            break;
                        }
                } else if (read.image.data.size() != expected[k].size() ||
                           !same(read.image.data.data(), expected[k])) {
                    ++wrong;
                }
            }
        });
    for (std::thread &t : threads) t.join();
    EXPECT_EQ(wrong.load(), 0);
    EXPECT_EQ(declined.load(), 0);
}
