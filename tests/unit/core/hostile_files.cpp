// Hostile mesh and image files: sizes taken from headers that wrap around, exceed the file or the
// allocation limit, offsets near 2^64, devices given as file names, non-numbers where counts and
// indices belong. Every one must end in a facet::Error naming the file, never in a crash, a read or
// write outside a buffer, or memory exhaustion.
#include <facet/checked.h>
#include <facet/image.h>
#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/texture.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <unistd.h>
#include <zlib.h>

using namespace facet;
namespace fs = std::filesystem;

#define EXPECT_CONTAINS(text, part)                                                                \
    EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

namespace {

/// Restores the allocation limit when a test that lowers it ends.
struct LimitGuard {
    size_t saved = allocation_limit();
    ~LimitGuard() { set_allocation_limit(saved); }
};

} // namespace

// --- the checked arithmetic itself ---------------------------------------------------------------

TEST(CheckedArithmetic, OverflowIsDetected) {
    size_t r = 0;
    EXPECT_TRUE(checked_mul<size_t>(3, 5, r));
    EXPECT_EQ(r, 15u);
    EXPECT_FALSE(checked_mul<size_t>(6148914691236517206ull, 3, r));
    EXPECT_FALSE(checked_add<size_t>(std::numeric_limits<size_t>::max(), 1, r));
    EXPECT_TRUE(checked_add<size_t>(2, 3, r));
    EXPECT_EQ(r, 5u);
    int32_t i = 0;
    EXPECT_FALSE(checked_mul<int32_t>(65536, 65536, i));
    LimitGuard guard;
    set_allocation_limit(1000);
    EXPECT_EQ(allocation_bytes(10, 100, "f", "x"), 1000u);
    EXPECT_THROW(allocation_bytes(11, 100, "f", "x"), Error);
    EXPECT_THROW(allocation_bytes(size_t(1) << 62, 8, "f", "x"), Error);
    try {
        allocation_bytes(11, 100, "mesh.ply:3", "vertex positions");
    } catch (const Error &e) {
        EXPECT_CONTAINS(e.what(), "mesh.ply:3: vertex positions");
    }
}
namespace {

class TempDir {
public:
    TempDir() {
        static int counter = 0;
        m_path = fs::temp_directory_path() /
                 fmt::format("facet_hostile_{}_{}", long(::getpid()), counter++);
        fs::create_directories(m_path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(m_path, ec);
    }
    std::string write(const std::string &name, const std::string &content) const {
        std::string p = (m_path / name).string();
        std::ofstream(p, std::ios::binary) << content;
        return p;
    }

private:
    fs::path m_path;
};

std::shared_ptr<Object> load(ObjectType kind, const std::string &type, const std::string &path) {
    Properties props(type);
    props.set_string("filename", path);
    return PluginRegistry::instance().create(kind, props);
}

/// The facet::Error message of loading `path` with plugin `type` (a test failure otherwise,
/// including for any other exception type).
std::string error_of(const std::string &type, const std::string &path,
                     ObjectType kind = ObjectType::Shape) {
    try {
        load(kind, type, path);
    } catch (const Error &e) {
        return e.what();
    } catch (const std::exception &e) {
        ADD_FAILURE() << "expected a facet::Error, got " << typeid(e).name() << ": " << e.what();
        return "";
    }
    ADD_FAILURE() << "expected a facet::Error";
    return "";
}

} // namespace

// --- devices and other non-files -----------------------------------------------------------------

TEST(HostileFiles, DevicesAreNotReadUntilMemoryRunsOut) {
    if (!fs::exists("/dev/zero")) GTEST_SKIP() << "no /dev/zero on this system";
    for (const char *type : {"ply", "obj", "serialized"}) {
        SCOPED_TRACE(type);
        std::string msg = error_of(type, "/dev/zero");
        EXPECT_CONTAINS(msg, "/dev/zero");
        EXPECT_CONTAINS(msg, "not a regular file");
    }
    std::string msg = error_of("bitmap", "/dev/zero", ObjectType::Texture);
    EXPECT_CONTAINS(msg, "not a regular file");
    TempDir dir;
    fs::path folder = fs::temp_directory_path() / fmt::format("facet_hostile_dir_{}", ::getpid());
    fs::create_directories(folder);
    msg = error_of("obj", folder.string());
    EXPECT_CONTAINS(msg, "not a regular file");
    fs::remove_all(folder);
}

namespace {

template <typename T> void put(std::string &s, T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    s.append(b, sizeof(T));
}

std::string deflate(const std::string &raw) {
    uLongf size = compressBound(uLong(raw.size()));
    std::string packed(size, '\0');
    EXPECT_EQ(compress(reinterpret_cast<Bytef *>(packed.data()), &size,
                       reinterpret_cast<const Bytef *>(raw.data()), uLong(raw.size())),
              Z_OK);
    packed.resize(size);
    return packed;
}

/// A version-4 serialized file holding one mesh whose stream is `raw`, and whose offset table entry
/// is `offset` (the real offset, 0, unless a test forges one).
std::string serialized_file(const std::string &raw, uint64_t offset = 0) {
    std::string file;
    put<uint16_t>(file, 0x041C);
    put<uint16_t>(file, 4);
    file += deflate(raw);
    put<uint64_t>(file, offset);
    put<uint32_t>(file, 1);
    return file;
}

/// The inflated stream of a single-precision mesh: flags, name, counts, then the arrays.
std::string serialized_stream(uint64_t nv, uint64_t nf, size_t real_values, size_t indices) {
    std::string raw;
    put<uint32_t>(raw, 0x1000);
    raw += "m";
    raw.push_back('\0');
    put<uint64_t>(raw, nv);
    put<uint64_t>(raw, nf);
    for (size_t i = 0; i < real_values; ++i) put<float>(raw, float(i % 3));
    for (size_t i = 0; i < indices; ++i) put<uint32_t>(raw, uint32_t(i % 3));
    return raw;
}

} // namespace

// --- serialized ----------------------------------------------------------------------------------

TEST(HostileSerialized, OffsetNearTwoToThe64) {
    TempDir dir;
    // begin + 4 wrapped to 2, passed `begin + 4 <= end`, and the header was read 2 bytes before the
    // buffer.
    std::string file = serialized_file(serialized_stream(3, 1, 9, 3), ~uint64_t(0) - 1);
    std::string msg = error_of("serialized", dir.write("offset.serialized", file));
    EXPECT_CONTAINS(msg, "offset.serialized");
    EXPECT_CONTAINS(msg, "corrupt offset for mesh 0");
}

TEST(HostileSerialized, CountsWhoseSizesWrapAround) {
    TempDir dir;
    // 2^62 vertices: 12 bytes each wraps to 0, which passed the size check.
    std::string file = serialized_file(serialized_stream(uint64_t(1) << 62, 1, 9, 3));
    std::string msg = error_of("serialized", dir.write("nv.serialized", file));
    EXPECT_CONTAINS(msg, "nv.serialized");
    // 2^62 + 1 triangles: 12 bytes each wraps to 12.
    file = serialized_file(serialized_stream(3, (uint64_t(1) << 62) + 1, 9, 3));
    msg = error_of("serialized", dir.write("nf.serialized", file));
    EXPECT_CONTAINS(msg, "nf.serialized");
}

TEST(HostileSerialized, MemoryGrowsWithTheDataNotWithTheHeader) {
    TempDir dir;
    LimitGuard guard;
    set_allocation_limit(size_t(1) << 20);
    // 10^6 vertices fit the (lowered) limit for no array: refused before inflating anything.
    std::string file = serialized_file(serialized_stream(1000000, 1, 9, 3));
    std::string msg = error_of("serialized", dir.write("limit.serialized", file));
    EXPECT_CONTAINS(msg, "limit.serialized");
    EXPECT_CONTAINS(msg, "allocation limit");
    // Within the limit but truncated: an error about the data, after reading what there is.
    set_allocation_limit(size_t(1) << 30);
    file = serialized_file(serialized_stream(1000000, 1, 9, 3));
    msg = error_of("serialized", dir.write("short.serialized", file));
    EXPECT_CONTAINS(msg, "short.serialized");
    EXPECT_CONTAINS(msg, "truncated");
}

TEST(HostileSerialized, FlagsAndVersion) {
    TempDir dir;
    std::string raw = serialized_stream(3, 1, 9, 3);
    uint32_t both = 0x3000;
    std::memcpy(raw.data(), &both, 4);
    std::string msg = error_of("serialized", dir.write("flags.serialized", serialized_file(raw)));
    EXPECT_CONTAINS(msg, "flags.serialized");
    EXPECT_CONTAINS(msg, "both single and double precision");
    // A mesh header of version 5 inside a version-4 file.
    std::string file = serialized_file(serialized_stream(3, 1, 9, 3));
    file[2] = 5;
    msg = error_of("serialized", dir.write("version.serialized", file));
    EXPECT_CONTAINS(msg, "version 5");
}

namespace {

const char *ply_xyz = "property float x\nproperty float y\nproperty float z\n";

} // namespace

// --- PLY -----------------------------------------------------------------------------------------

TEST(HostilePly, VertexCountWhoseTripleWrapsAround) {
    TempDir dir;
    // 3 * 6148914691236517206 = 2^64 + 2: a wrapped 3n would size the buffer for 2 floats and the
    // loop would write the file's bytes past it.
    std::string file = std::string("ply\nformat binary_little_endian 1.0\nelement vertex "
                                   "6148914691236517206\n") +
                       ply_xyz + "element face 1\nproperty list uchar int vertex_indices\n" +
                       "end_header\n";
    for (int i = 0; i < 9; ++i) put<float>(file, float(i));
    put<uint8_t>(file, 3);
    for (int i = 0; i < 3; ++i) put<int32_t>(file, i);
    std::string msg = error_of("ply", dir.write("wrap.ply", file));
    EXPECT_CONTAINS(msg, "wrap.ply");
    EXPECT_CONTAINS(msg, "more than the file holds");
}

TEST(HostilePly, CountsAreCheckedAgainstTheFileBeforeAllocating) {
    TempDir dir;
    // 4e9 vertices in a file of a few bytes: refused before 48 GB are allocated.
    std::string file = std::string("ply\nformat ascii 1.0\nelement vertex 4000000000\n") + ply_xyz +
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n" +
                       "0 0 0\n";
    std::string msg = error_of("ply", dir.write("big.ply", file));
    EXPECT_CONTAINS(msg, "big.ply");
    EXPECT_CONTAINS(msg, "4000000000 vertex elements");
}

TEST(HostilePly, ListCountsAndIndicesMustBeIntegersInRange) {
    TempDir dir;
    std::string head = std::string("ply\nformat ascii 1.0\nelement vertex 3\n") + ply_xyz +
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n" +
                       "0 0 0\n1 0 0\n0 1 0\n";
    // A count of 1e30 (converted to an integer: undefined behaviour) or 2.5.
    std::string msg = error_of("ply", dir.write("count.ply", head + "1e30 0 1 2\n"));
    EXPECT_CONTAINS(msg, "count.ply:13");
    EXPECT_CONTAINS(msg, "list count");
    msg = error_of("ply", dir.write("frac.ply", head + "2.5 0 1 2\n"));
    EXPECT_CONTAINS(msg, "frac.ply:13");
    EXPECT_CONTAINS(msg, "list count");
    // A NaN index passed the range check (NaN compares false) and became an index.
    msg = error_of("ply", dir.write("nan.ply", head + "3 nan 1 2\n"));
    EXPECT_CONTAINS(msg, "nan.ply:13");
    EXPECT_CONTAINS(msg, "bad vertex index");
    msg = error_of("ply", dir.write("half.ply", head + "3 0.5 1 2\n"));
    EXPECT_CONTAINS(msg, "bad vertex index");
    // A list that skips over more values than the file has.
    std::string other = std::string("ply\nformat binary_little_endian 1.0\nelement vertex 3\n") +
                        ply_xyz + "property list uint double junk\n" +
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    for (int i = 0; i < 3; ++i) put<float>(other, 0.f);
    put<uint32_t>(other, 0xffffffffu);
    msg = error_of("ply", dir.write("skip.ply", other));
    EXPECT_CONTAINS(msg, "skip.ply");
}

TEST(HostilePly, TwoVertexElementsAreAnError) {
    TempDir dir;
    std::string file = std::string("ply\nformat ascii 1.0\nelement vertex 1\n") + ply_xyz +
                       "element vertex 1\n" + ply_xyz + "end_header\n0 0 0\n0 0 0\n";
    std::string msg = error_of("ply", dir.write("two.ply", file));
    EXPECT_CONTAINS(msg, "two.ply");
    EXPECT_CONTAINS(msg, "more than one vertex element");
}

// --- images --------------------------------------------------------------------------------------

TEST(HostileImages, HeaderDimensionsAreCheckedBeforeAllocating) {
    TempDir dir;
    // A float map that claims 100000 x 100000 RGB pixels (120 GB) and holds 12 bytes.
    std::string pfm = "PF\n100000 100000\n-1.0\n";
    put<float>(pfm, 1.f);
    put<float>(pfm, 2.f);
    put<float>(pfm, 3.f);
    std::string path = dir.write("huge.pfm", pfm);
    try {
        read_image(path);
        ADD_FAILURE() << "expected an error";
    } catch (const Error &e) {
        EXPECT_CONTAINS(e.what(), "huge.pfm");
        EXPECT_CONTAINS(e.what(), "allocation limit");
    }
    // Within the limit but truncated: refused once the data runs out, without first zeroing the
    // whole buffer (the test would run out of memory or time otherwise).
    pfm = "PF\n20000 20000\n-1.0\n";
    for (int i = 0; i < 30; ++i) put<float>(pfm, 1.f);
    path = dir.write("short.pfm", pfm);
    try {
        read_image(path);
        ADD_FAILURE() << "expected an error";
    } catch (const Error &e) {
        EXPECT_CONTAINS(e.what(), "short.pfm");
    }
    // The envmap and bitmap plugins report it with the file name too.
    std::string msg = error_of("envmap", dir.write("huge2.pfm", "PF\n100000 100000\n-1.0\n"),
                               ObjectType::Emitter);
    EXPECT_CONTAINS(msg, "huge2.pfm");
}

TEST(HostileImages, ExrAttributesLargerThanTheFile) {
    TempDir dir;
    // Found by the image fuzz target: a string attribute claiming 1.7 GB made OpenEXR allocate
    // and fill that much (40 s and 1.8 GB for a 1 KB file).
    std::string exr = "\x76\x2f\x31\x01";
    put<uint32_t>(exr, 2);
    exr += std::string("capDate") + '\0' + "string" + '\0';
    put<int32_t>(exr, 1701994871);
    exr += "2024:01:01 00:00:00";
    std::string path = dir.write("attr.exr", exr);
    try {
        read_image(path);
        ADD_FAILURE() << "expected an error";
    } catch (const Error &e) {
        EXPECT_CONTAINS(e.what(), "attr.exr");
        EXPECT_CONTAINS(e.what(), "\"capDate\" (string) claims 1701994871 bytes");
    }
}

namespace {

/// A small valid EXR (written by OpenImageIO) as bytes.
std::string small_exr(const TempDir &dir, int w = 4, int h = 3, const char *compression = "zip") {
    std::string path = dir.write("valid.exr", "");
    OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::HALF);
    spec.attribute("compression", compression);
    std::vector<float> pixels(size_t(w) * size_t(h) * 3, 0.5f);
    auto out = OIIO::ImageOutput::create(path);
    EXPECT_TRUE(out && out->open(path, spec));
    EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
    out->close();
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

/// `exr` with the size field of the attribute `name` of type `type` changed by `delta`.
std::string resize_attribute(std::string exr, const std::string &name, const std::string &type,
                             int delta) {
    const std::string key = name + '\0' + type + '\0';
    const size_t at = exr.find(key);
    EXPECT_NE(at, std::string::npos) << key;
    int32_t size;
    std::memcpy(&size, exr.data() + at + key.size(), 4);
    size += delta;
    std::memcpy(exr.data() + at + key.size(), &size, 4);
    return exr;
}

std::string read_error(const std::string &path) {
    try {
        read_image(path);
    } catch (const Error &e) {
        return e.what();
    }
    ADD_FAILURE() << path << ": expected an error";
    return "";
}

} // namespace

TEST(HostileImages, ExrAttributesReadPastOrShortOfTheirSize) {
    // Found by the image fuzz target: OpenEXR reads a channel list up to its terminating empty
    // name, not up to its declared size. A list that ran on past its size made OpenEXR read the
    // next "attribute" from the middle of a value, one claiming 1.6 GB, in a 223-byte file.
    TempDir dir;
    const std::string exr = small_exr(dir);
    ASSERT_EQ(read_image(dir.write("ok.exr", exr)).width, 4);
    struct Case {
        const char *name, *type;
        int delta;
        const char *says;
    } cases[] = {
        {"channels", "chlist", -1, "\"channels\" (chlist) runs past its size"},
        {"channels", "chlist", +1, "\"channels\" (chlist) ends before its size"},
        {"compression", "compression", +1, "(compression) has 2 bytes instead of 1"},
        {"dataWindow", "box2i", -4, "(box2i) has 12 bytes instead of 16"},
        {"screenWindowWidth", "float", +3, "(float) has 7 bytes instead of 4"},
    };
    for (const Case &c : cases) {
        SCOPED_TRACE(c.says);
        const std::string msg =
            read_error(dir.write("bad.exr", resize_attribute(exr, c.name, c.type, c.delta)));
        EXPECT_CONTAINS(msg, "bad.exr");
        EXPECT_CONTAINS(msg, c.says);
    }
}

TEST(HostileImages, ExrDataWindowWithinTheAllocationLimit) {
    // The data window's pixels are checked before OpenEXR sizes its buffers by them.
    TempDir dir;
    const std::string path = dir.write("big.exr", small_exr(dir, 64, 64));
    LimitGuard guard;
    set_allocation_limit(64 * 64 * 6 - 1); // three half channels
    const std::string msg = read_error(path);
    EXPECT_CONTAINS(msg, "big.exr");
    EXPECT_CONTAINS(msg, "EXR data window: 4096 items of 6 bytes");
    set_allocation_limit(64 * 64 * 3 * sizeof(float)); // what read_image itself allocates
    EXPECT_EQ(read_image(path).width, 64);
}

TEST(HostileImages, ExrPixelsMustFitTheFilesCompression) {
    // Found by the image fuzz target: a data window widened to 655368x8 in a 661-byte ZIP file
    // read as 31 MB of pixels (OpenEXR pads a short chunk without an error), 20 s under the
    // sanitizers.
    TempDir dir;
    std::string exr = small_exr(dir, 8, 8);
    const std::string key = std::string("dataWindow") + '\0' + "box2i" + '\0';
    const size_t at = exr.find(key);
    ASSERT_NE(at, std::string::npos);
    const int32_t xmax = 655367;
    std::memcpy(exr.data() + at + key.size() + 4 + 8, &xmax, 4);
    const std::string msg = read_error(dir.write("wide.exr", exr));
    EXPECT_CONTAINS(msg, "wide.exr");
    EXPECT_CONTAINS(msg, "655368x8 pixels (31457664 bytes), more than its compression can hold");

    // Neither a second, empty channel list nor a renamed compression attribute (OpenEXR then
    // uses ZIP, its default) takes the check away.
    const std::string channels = std::string("channels") + '\0' + "chlist" + '\0';
    const size_t list = exr.find(channels);
    ASSERT_NE(list, std::string::npos);
    int32_t list_size;
    std::memcpy(&list_size, exr.data() + list + channels.size(), 4);
    std::string extra = exr;
    extra.insert(list + channels.size() + 4 + size_t(list_size),
                 std::string("zz") + '\0' + "chlist" + '\0' + std::string("\1\0\0\0\0", 5));
    EXPECT_CONTAINS(read_error(dir.write("extra.exr", extra)),
                    "more than its compression can hold");
    std::string renamed = exr;
    const size_t comp = renamed.find(std::string("compression") + '\0' + "compression");
    ASSERT_NE(comp, std::string::npos);
    renamed[comp + 10] = 'X';
    EXPECT_CONTAINS(read_error(dir.write("renamed.exr", renamed)),
                    "more than its compression can hold");

    // PIZ and DWA too: a 64x64 PIZ file of 1,394 bytes widened to 1,000,000 x 64 pixels read
    // in 11 s to 2.9 GB (release, an envmap), and exited 0.
    for (const char *compression : {"piz", "dwaa", "dwab"}) {
        SCOPED_TRACE(compression);
        std::string flat = small_exr(dir, 64, 64, compression);
        ASSERT_EQ(read_image(dir.write("flat.exr", flat)).width, 64);
        const size_t window = flat.find(key);
        ASSERT_NE(window, std::string::npos);
        const int32_t wide = 999999;
        std::memcpy(flat.data() + window + key.size() + 4 + 8, &wide, 4);
        EXPECT_CONTAINS(read_error(dir.write("wide.exr", flat)),
                        "1000000x64 pixels (384000000 bytes), more than its compression can hold");
    }
}

TEST(HostileImages, TilesArePaddingOnlyWithinReason) {
    // Found by the image fuzz target: a 20x12 EXR in tiles of 8 x 16777224 pixels (654 bytes)
    // made OpenEXR and OpenImageIO allocate whole tiles: 2.2 GB and 4 s.
    TempDir dir;
    const std::string path = dir.write("tiled.exr", "");
    OIIO::ImageSpec spec(20, 12, 3, OIIO::TypeDesc::FLOAT);
    spec.tile_width = spec.tile_height = 16;
    const std::vector<float> pixels(20 * 12 * 3, 0.25f);
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out && out->open(path, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
    out->close();
    EXPECT_EQ(read_image(path).data, pixels); // tiles larger than the image are fine

    std::ifstream in(path, std::ios::binary);
    std::string exr((std::istreambuf_iterator<char>(in)), {});
    const std::string key = std::string("tiles") + '\0' + "tiledesc" + '\0';
    const size_t at = exr.find(key);
    ASSERT_NE(at, std::string::npos);
    const uint32_t tall = 16777224;
    std::memcpy(exr.data() + at + key.size() + 4 + 4, &tall, 4);
    std::string msg = read_error(dir.write("tall.exr", exr));
    EXPECT_CONTAINS(msg, "tall.exr");
    EXPECT_CONTAINS(msg, "its tiles of 268435584 pixels are larger than 256x256 and 4 times its "
                         "20x12-pixel data window");
    // Found by the image fuzz target (13.5 s under the sanitizers): without a data window,
    // OpenEXR takes its default one, 64x64, and the tiles are checked against that.
    std::string unnamed = exr;
    unnamed[exr.find(std::string("dataWindow") + '\0')] = 'f';
    msg = read_error(dir.write("unnamed.exr", unnamed));
    EXPECT_CONTAINS(msg, "its tiles of 268435584 pixels are larger than 256x256 and 4 times its "
                         "64x64-pixel data window");

    // Whatever the format, a row of tiles (converted by OpenImageIO in a buffer of its own)
    // passes the allocation limit before it is read.
    const std::string tif = dir.write("tiled.tif", "");
    out = OIIO::ImageOutput::create(tif);
    ASSERT_TRUE(out && out->open(tif, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
    out->close();
    EXPECT_EQ(read_image(tif).data, pixels);
    LimitGuard guard;
    set_allocation_limit(20 * 12 * 3 * sizeof(float)); // the image, but not 32x16 of tiles
    msg = read_error(tif);
    EXPECT_CONTAINS(msg, "tiled.tif");
    EXPECT_CONTAINS(msg, "a row of image tiles: 1536 items of 4 bytes");
}

TEST(HostileImages, ConstantExrsOfEveryCompressionStillRead) {
    // The most compressible images there are, in every compression OpenEXR has: the ratio bound
    // above must leave them alone.
    TempDir dir;
    const int w = 512, h = 512;
    for (const char *compression :
         {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"})
        for (OIIO::TypeDesc type : {OIIO::TypeDesc::HALF, OIIO::TypeDesc::FLOAT}) {
            SCOPED_TRACE(fmt::format("{} {}", compression, type.c_str()));
            const std::string path = dir.write("flat.exr", "");
            OIIO::ImageSpec spec(w, h, 3, type);
            spec.attribute("compression", compression);
            const std::vector<float> pixels(size_t(w) * h * 3, 0.f);
            auto out = OIIO::ImageOutput::create(path);
            ASSERT_TRUE(out && out->open(path, spec));
            ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
            out->close();
            const Image back = read_image(path);
            EXPECT_EQ(back.width, w);
            EXPECT_EQ(back.data, pixels);
        }
    // PIZ and DWA reach their best ratios on wide chunks, and DWA on channels that are not
    // colour (run-length coded, then deflated): 4096x512 of RGBA halves.
    for (const char *compression : {"piz", "dwaa", "dwab"}) {
        SCOPED_TRACE(compression);
        const std::string path = dir.write("wide.exr", "");
        OIIO::ImageSpec spec(4096, 512, 4, OIIO::TypeDesc::HALF);
        spec.attribute("compression", compression);
        const std::vector<float> pixels(size_t(4096) * 512 * 4, 0.f);
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out && out->open(path, spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
        out->close();
        EXPECT_EQ(read_image(path).data, pixels);
    }
}

TEST(HostileImages, BmpHeadersAreCheckedBeforeOpenImageIODecodes) {
    // Found by the image fuzz target: OpenImageIO decodes an RLE BMP whole as it opens it, into
    // a buffer sized from the header (1.9 GB and 2 s for these 55 bytes).
    TempDir dir;
    const unsigned char rle[] = {0x42, 0x4d, 0x5a, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x36,
                                 0x00, 0x00, 0x00, 0x28, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x24,
                                 0x03, 0x00, 0x00, 0x00, 0x01, 0x00, 0x18, 0x00, 0x02, 0x00, 0x00,
                                 0x00, 0x0c, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x5d,
                                 0xff, 0xff, 0xf9, 0x00, 0x00, 0x00, 0xff, 0xfb, 0xff, 0xff, 0x00};
    std::string msg = read_error(dir.write("rle.bmp", std::string(rle, rle + sizeof rle)));
    EXPECT_CONTAINS(msg, "rle.bmp");
    EXPECT_CONTAINS(msg, "RLE-compressed BMP declares 603979780x3 pixels");
    // Found by the image fuzz target: RLE8 with 24 bits per pixel crashed OpenImageIO (a
    // segmentation fault reading the rows). The header alone says so; the pixel data is junk.
    std::string deep(rle, rle + 54);
    deep[21] = 0; // 4 pixels wide
    deep[30] = 1; // RLE8
    deep += std::string(64, '\1');
    msg = read_error(dir.write("rle8.bmp", deep));
    EXPECT_CONTAINS(msg, "rle8.bmp");
    EXPECT_CONTAINS(msg, "RLE8-compressed with 24 bits per pixel instead of 8");
    // The OS/2 magics OpenImageIO's reader also takes.
    for (const char *magic : {"BA", "CI", "CP", "PT"}) {
        std::string os2(rle, rle + sizeof rle);
        os2.replace(0, 2, magic);
        EXPECT_CONTAINS(read_error(dir.write("os2.bmp", os2)), "RLE-compressed BMP declares");
    }

    // An uncompressed BMP reads, and its pixels count against the allocation limit first.
    std::string path = dir.write("ok.bmp", "");
    OIIO::ImageSpec spec(40, 30, 3, OIIO::TypeDesc::UINT8);
    std::vector<unsigned char> pixels(40 * 30 * 3, 77);
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out && out->open(path, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
    out->close();
    EXPECT_EQ(read_image(path).width, 40);
    LimitGuard guard;
    set_allocation_limit(40 * 30 * sizeof(float) - 1);
    msg = read_error(path);
    EXPECT_CONTAINS(msg, "ok.bmp");
    EXPECT_CONTAINS(msg, "BMP pixels: 1200 items of 4 bytes");
}

namespace {

/// A deflate-compressed TIFF of one strip (8-bit pixels; BigTIFF when `big`) whose
/// RowsPerStrip says `rows_per_strip`: RGB, or `channels` of the given photometric
/// interpretation (0 MinIsWhite, 1 MinIsBlack, 2 RGB), its bytes negated when `negative`.
std::string deflate_tiff(int width, int height, uint64_t rows_per_strip, bool big = false,
                         int channels = 3, int photometric = 2, bool negative = false) {
    std::string pixels;
    for (int i = 0; i < width * height * channels; ++i)
        pixels += char(negative ? 255 - ((i * 37) & 255) : (i * 37) & 255);
    uLongf packed_size = compressBound(uLong(pixels.size()));
    std::string packed(packed_size, '\0');
    compress(reinterpret_cast<Bytef *>(packed.data()), &packed_size,
             reinterpret_cast<const Bytef *>(pixels.data()), uLong(pixels.size()));
    packed.resize(packed_size);
    struct Entry {
        uint16_t tag, type;
        uint64_t value;
    };
    const int entry_count = 9;
    const uint64_t data_at = big ? 16 + 8 + 20 * entry_count + 8 : 8 + 2 + 12 * entry_count + 4;
    const Entry entries[entry_count] = {
        {256, 4, uint64_t(width)},
        {257, 4, uint64_t(height)},
        {258, 3, 8},
        {259, 3, 8},
        {262, 3, uint64_t(photometric)},
        {273, 4, data_at},
        {277, 3, uint64_t(channels)},
        {278, 4, rows_per_strip},
        {279, 4, packed.size()},
    };
    std::string f = big ? std::string("II+\0", 4) : std::string("II*\0", 4);
    if (big) {
        put<uint16_t>(f, 8);
        put<uint16_t>(f, 0);
        put<uint64_t>(f, 16);
        put<uint64_t>(f, entry_count);
    } else {
        put<uint32_t>(f, 8);
        put<uint16_t>(f, entry_count);
    }
    for (const Entry &e : entries) {
        put<uint16_t>(f, e.tag);
        put<uint16_t>(f, e.type);
        if (big) {
            put<uint64_t>(f, 1);
            if (e.type == 3)
                put<uint16_t>(f, uint16_t(e.value)), f.append(6, '\0');
            else
                put<uint32_t>(f, uint32_t(e.value)), f.append(4, '\0');
        } else {
            put<uint32_t>(f, 1);
            if (e.type == 3)
                put<uint16_t>(f, uint16_t(e.value)), f.append(2, '\0');
            else
                put<uint32_t>(f, uint32_t(e.value));
        }
    }
    if (big)
        put<uint64_t>(f, 0);
    else
        put<uint32_t>(f, 0);
    return f + packed;
}

} // namespace

TEST(HostileImages, TiffStripsAreCheckedBeforeOpenImageIOBuffersThem) {
    TempDir dir;
    // OpenImageIO keeps RowsPerStrip in an int and sizes its strip buffers by it, not by the
    // image's rows. Found by the image fuzz target: a 217-byte TIFF whose 65,056 rows per strip
    // of 65,284 x 3 values overflowed that int, and OpenImageIO asked for 5.6e15 bytes.
    const unsigned char tif[] = {
        0x49, 0x49, 0x2a, 0x00, 0x08, 0x00, 0x00, 0x00, 0x0e, 0x00, 0x00, 0x01, 0x03, 0x00, 0x01,
        0x00, 0x00, 0x00, 0x04, 0xff, 0xff, 0x00, 0x01, 0x01, 0x03, 0x00, 0x01, 0x00, 0x00, 0x00,
        0x03, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xb6, 0x00, 0x00,
        0x00, 0x03, 0x01, 0x03, 0x00, 0x01, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00, 0x00, 0x06, 0x01,
        0x03, 0x00, 0x01, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x11, 0x01, 0x04, 0x00, 0x01,
        0x00, 0x00, 0x00, 0xd6, 0x00, 0x00, 0x00, 0x12, 0x01, 0x03, 0x00, 0x01, 0x00, 0x00, 0x00,
        0x01, 0x00, 0x00, 0x00, 0x15, 0x01, 0x03, 0x00, 0x01, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00,
        0x00, 0x16, 0x01, 0x03, 0x00, 0x01, 0x00, 0x00, 0x00, 0x20, 0xfe, 0x00, 0x00, 0x17, 0x01,
        0x04, 0x00, 0x01, 0x00, 0x00, 0x00, 0x20, 0x00, 0x00, 0x00, 0x1c, 0x01, 0x03, 0x00, 0x01,
        0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x32, 0x01, 0x02, 0x00, 0x14, 0x00, 0x00, 0x00,
        0xc2, 0x00, 0x00, 0x00, 0x3d, 0x01, 0x03, 0x01, 0x00, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00,
        0x00, 0x53, 0x01, 0x03, 0x00, 0x03, 0x00, 0x00, 0x00, 0xbc, 0x00, 0x00, 0x00, 0x00, 0x00,
        0x00, 0x00, 0x20, 0x00, 0x20, 0x00, 0x20, 0x00, 0x03, 0x00, 0x03, 0x00, 0x03, 0x00, 0x32,
        0x30, 0x32, 0x36, 0x3a, 0x31, 0x32, 0x3a, 0x30, 0x31, 0x20, 0x71, 0x01, 0xe2, 0xd5, 0x93,
        0x6a, 0x32, 0x00, 0xb7, 0x25, 0x12, 0x01,
    };
    std::string msg = read_error(dir.write("strip.tif", std::string(tif, tif + sizeof tif)));
    EXPECT_CONTAINS(msg, "strip.tif");
    EXPECT_CONTAINS(msg, "more than the TIFF reader can address");
    // 2^31 rows per strip is a negative strip height there: a 300 x 50 image corrupted the heap.
    for (bool big : {false, true}) {
        SCOPED_TRACE(big ? "BigTIFF" : "TIFF");
        msg = read_error(dir.write("negative.tif", deflate_tiff(300, 50, uint64_t(1) << 31, big)));
        EXPECT_CONTAINS(msg, "more than the TIFF reader can address");
    }
    // A strip over the allocation limit, however few of its rows the image has.
    {
        LimitGuard guard;
        set_allocation_limit(size_t(1) << 20);
        msg = read_error(dir.write("tall.tif", deflate_tiff(1000, 2, 1000)));
        EXPECT_CONTAINS(msg, "a TIFF strip");
    }
    // Valid strips read the same pixels: the image's own rows, more rows than the image has
    // (within the limit), and 2^32 - 1, TIFF's "the whole image in one strip".
    const Image plain = read_image(dir.write("plain.tif", deflate_tiff(30, 7, 7)));
    ASSERT_EQ(plain.width, 30);
    ASSERT_EQ(plain.height, 7);
    for (uint64_t rows : {uint64_t(64), uint64_t(0xffffffffu)})
        for (bool big : {false, true}) {
            SCOPED_TRACE(fmt::format("{} rows per strip, {}", rows, big ? "BigTIFF" : "TIFF"));
            const Image same = read_image(dir.write("same.tif", deflate_tiff(30, 7, rows, big)));
            EXPECT_EQ(same.data, plain.data);
        }
}

namespace {

/// In a death test's child: reads `big` with 512 MiB of address space beyond what the process
/// has after reading `small` (which loads the image library); exits 0 when that ends in an
/// out-of-memory facet::Error naming the file.
[[noreturn]] void read_with_512_mib_more(const std::string &small, const std::string &big) {
    read_image(small);
    long pages = 0;
    std::ifstream("/proc/self/statm") >> pages;
    const rlim_t limit = rlim_t(pages) * rlim_t(::sysconf(_SC_PAGESIZE)) + (rlim_t(512) << 20);
    const rlimit r{limit, limit};
    if (::setrlimit(RLIMIT_AS, &r) != 0) std::_Exit(2);
    try {
        read_image(big);
    } catch (const Error &e) {
        std::fprintf(stderr, "%s\n", e.what());
        const bool named = std::strstr(e.what(), fs::path(big).filename().c_str()) != nullptr;
        std::_Exit(named && std::strstr(e.what(), "out of memory") ? 0 : 3);
    }
    std::_Exit(4);
}

} // namespace

TEST(HostileImages, MinIsWhiteTiffsOfSeveralChannelsRead) {
    // Found by the image fuzz target: OpenImageIO 2.4 inverts a MinIsWhite strip it decompresses
    // itself over channels x its values, past the end of the buffer; a valid 16x64 grey + alpha
    // file aborted the process ("munmap_chunk(): invalid pointer"). The same pixels stored
    // negated as MinIsBlack are what it must read.
    TempDir dir;
    for (int channels : {2, 4, 11}) {
        SCOPED_TRACE(fmt::format("{} channels", channels));
        const Image white =
            read_image(dir.write("white.tif", deflate_tiff(16, 64, 64, false, channels, 0, false)));
        const Image black =
            read_image(dir.write("black.tif", deflate_tiff(16, 64, 64, false, channels, 1, true)));
        ASSERT_EQ(white.channels, channels);
        EXPECT_EQ(white.data, black.data);
    }
}

TEST(HostileImages, AllocationFailuresInsideTheImageLibraryAreErrors) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space: no RLIMIT_AS under it";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
    GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space: no RLIMIT_AS under it";
#endif
#endif
    // A size that passes every check can still be more than the machine has: std::bad_alloc from
    // inside OpenImageIO once ended the process. A valid TIFF of 3 rows in strips of 8,000 rows
    // of 60,000 RGB pixels makes OpenImageIO allocate a 1.4 GB strip buffer; in a child process
    // limited to 512 MiB more address space, that allocation fails.
    TempDir dir;
    const std::string small = dir.write("small.tif", deflate_tiff(4, 2, 2));
    const std::string tall = dir.write("tall.tif", deflate_tiff(60000, 3, 8000));
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_EXIT(read_with_512_mib_more(small, tall), ::testing::ExitedWithCode(0), "");
}

TEST(HostileImages, ValidImagesStillRead) {
    TempDir dir;
    std::string pfm = "PF\n2 1\n-1.0\n";
    for (int i = 0; i < 6; ++i) put<float>(pfm, float(i));
    Image img = read_image(dir.write("ok.pfm", pfm));
    ASSERT_EQ(img.width, 2);
    ASSERT_EQ(img.height, 1);
    ASSERT_EQ(img.channels, 3);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(img.data[size_t(i)], float(i));

    // Tiled (8 x 8 tiles, partial at the edges) and scanline files with a data window that does not
    // start at the origin, read in bands of rows: every pixel in its place.
    const int w = 20, h = 13, c = 2;
    std::vector<float> pixels(size_t(w) * h * c);
    for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = float(i);
    for (bool tiled : {true, false}) {
        SCOPED_TRACE(tiled ? "tiled" : "scanlines");
        std::string path = dir.write(tiled ? "tiled.exr" : "lines.exr", "");
        OIIO::ImageSpec spec(w, h, c, OIIO::TypeDesc::FLOAT);
        spec.x = 3;
        spec.y = -5;
        if (tiled) spec.tile_width = spec.tile_height = 8;
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out && out->open(path, spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
        out->close();
        Image back = read_image(path);
        ASSERT_EQ(back.width, w);
        ASSERT_EQ(back.height, h);
        ASSERT_EQ(back.channels, c);
        EXPECT_EQ(back.data, pixels);
    }
}
