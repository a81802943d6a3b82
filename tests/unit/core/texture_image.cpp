// The images textures and emitters hold (facet/texture_image.h): an image file is decoded once
// per set of decoding parameters and shared by every reference, the cache keeps nothing alive by
// itself, an edited file is read again, 8-bit files keep a byte per value with exactly the
// values of the float path, and the texture memory budget refuses an image by its header, before
// decoding it, with the scene location of the texture and the name of the file.
#include "texture_lookup.h"

#include <facet/emitter.h>
#include <facet/image.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/scene.h>
#include <facet/texture.h>
#include <facet/texture_image.h>
#include <facet/xml.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>
#include <unistd.h>
#include <zlib.h>

using namespace facet;
namespace fs = std::filesystem;

#define EXPECT_CONTAINS(text, part)                                                                \
    EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

namespace {

class TextureImage : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() /
                ("facet_texture_image_" + std::to_string(::getpid()) + "_" +
                 ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(m_dir);
    }
    void TearDown() override {
        set_texture_memory_budget(0);
        std::error_code ec;
        fs::remove_all(m_dir, ec);
    }
    std::string path(const std::string &name) const { return (m_dir / name).string(); }

    /// Writes an 8-bit image of `channels` channels whose value at (x, y, c) is
    /// (x * 7 + y * 13 + c * 101 + seed) mod 256: every byte value, at every position mod 4.
    std::string write_8bit(const std::string &name, int w, int h, int channels,
                           int seed = 0) const {
        std::vector<uint8_t> pixels(size_t(w) * h * channels);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < channels; ++c)
                    pixels[(size_t(y) * w + x) * channels + c] =
                        uint8_t((x * 7 + y * 13 + c * 101 + seed) & 255);
        const std::string file = path(name);
        auto out = OIIO::ImageOutput::create(file);
        OIIO::ImageSpec spec(w, h, channels, OIIO::TypeDesc::UINT8);
        EXPECT_TRUE(out && out->open(file, spec) &&
                    out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) && out->close());
        return file;
    }

    static std::shared_ptr<Texture> bitmap(const std::string &file, bool raw = false) {
        Properties props("bitmap");
        props.set_plugin_name("bitmap");
        props.set_string("filename", file);
        if (raw) props.set_bool("raw", true);
        return PluginRegistry::instance().create_as<Texture>(ObjectType::Texture, props);
    }

    fs::path m_dir;
};

/// A PNG whose header declares a `w` x `h` RGB image, followed by the first row only.
std::string png_claiming(uint32_t w, uint32_t h) {
    auto be32 = [](uint32_t v) {
        return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
    };
    auto chunk = [&](const std::string &type, const std::string &data) {
        const std::string body = type + data;
        const uLong crc = crc32(0, reinterpret_cast<const Bytef *>(body.data()), uInt(body.size()));
        return be32(uint32_t(data.size())) + body + be32(uint32_t(crc));
    };
    const std::string ihdr = be32(w) + be32(h) + std::string{8, 2, 0, 0, 0};
    std::string row(1 + size_t(w) * 3, '\0');
    std::string idat(compressBound(uLong(row.size())), '\0');
    uLongf n = uLongf(idat.size());
    compress(reinterpret_cast<Bytef *>(idat.data()), &n,
             reinterpret_cast<const Bytef *>(row.data()), uLong(row.size()));
    idat.resize(n);
    return "\x89PNG\r\n\x1a\n" + chunk("IHDR", ihdr) + chunk("IDAT", idat) + chunk("IEND", "");
}

/// Resident memory of this process, in bytes.
size_t resident_bytes() {
    std::ifstream statm("/proc/self/statm");
    size_t pages = 0, resident = 0;
    statm >> pages >> resident;
    return resident * size_t(sysconf(_SC_PAGESIZE));
}

} // namespace

TEST_F(TextureImage, BitmapsOfOneFileShareOneCopy) {
    // 8 references to a 2048x2048 RGB PNG: once 8 float copies (8 x 48 MiB), now one copy of
    // its bytes (12 MiB). The image library is loaded first: its own memory is not the test's.
    bitmap(write_8bit("small.png", 4, 4, 3));
    const std::string file = write_8bit("big.png", 2048, 2048, 3);
    const size_t before = resident_bytes();
    std::vector<std::shared_ptr<Texture>> textures;
    for (int i = 0; i < 8; ++i) textures.push_back(bitmap(file));
    const size_t grown = resident_bytes() - std::min(before, resident_bytes());
    const size_t one_float_copy = size_t(2048) * 2048 * 3 * sizeof(float);
    EXPECT_LT(grown, 2 * one_float_copy)
        << "8 bitmaps of one file took " << grown / (1 << 20) << " MiB";
    EXPECT_EQ(texture_memory_used(), size_t(2048) * 2048 * 3);
    // They read alike.
    const Color3f a = textures[0]->eval(at_uv(0.3f, 0.7f));
    for (const auto &t : textures) EXPECT_EQ(t->eval(at_uv(0.3f, 0.7f)), a);
    textures.clear();
    EXPECT_EQ(texture_memory_used(), 0u) << "the cache keeps a decoded image alive";
}

TEST_F(TextureImage, SharedByFileAndDecodingOnly) {
    const std::string file = write_8bit("a.png", 16, 8, 3);
    TexelDecoding srgb{true, true}, raw{false, true};
    auto a = load_texels(file, srgb), b = load_texels(file, srgb);
    EXPECT_EQ(a.get(), b.get());
    auto c = load_texels(file, raw);
    EXPECT_NE(a.get(), c.get());
    // The same file under another name (a hard link) is the same file.
    fs::create_hard_link(file, path("link.png"));
    EXPECT_EQ(load_texels(path("link.png"), srgb).get(), a.get());
    // Another file with the same contents is another file.
    fs::copy_file(file, path("copy.png"));
    EXPECT_NE(load_texels(path("copy.png"), srgb).get(), a.get());
    // read_shared_image() shares too, and its images count against the budget.
    auto i1 = read_shared_image(file), i2 = read_shared_image(file);
    EXPECT_EQ(i1.get(), i2.get());
    EXPECT_EQ(i1->width, 16);
    const size_t held = texture_memory_used();
    i1.reset();
    i2.reset();
    EXPECT_EQ(texture_memory_used(), held - 16 * 8 * 3 * sizeof(float));
}

TEST_F(TextureImage, AnEditedFileIsReadAgain) {
    const std::string file = write_8bit("a.png", 8, 8, 1, 0);
    auto before = load_texels(file, {});
    const uint8_t first = before->bytes[0];
    // Rewritten with other values (and another modification time) while the old one is held.
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    write_8bit("a.png", 8, 8, 1, 50);
    fs::last_write_time(file, fs::last_write_time(file) + std::chrono::seconds(2));
    auto after = load_texels(file, {});
    EXPECT_NE(before.get(), after.get());
    EXPECT_EQ(after->bytes[0], uint8_t(first + 50));
}

TEST_F(TextureImage, BytesHoldTheValuesOfTheFloatPath) {
    // Every byte value at every position modulo the conversion's vector width, grey to RGBA.
    for (int channels = 1; channels <= 4; ++channels) {
        const std::string file =
            write_8bit("v" + std::to_string(channels) + ".png", 37, 11, channels);
        const Image floats = read_image(file);
        const ByteImage bytes = read_image_bytes(file);
        ASSERT_EQ(bytes.bytes.size(), floats.data.size());
        EXPECT_TRUE(bytes.image.data.empty());
        EXPECT_EQ(bytes.image.width, 37);
        EXPECT_EQ(bytes.image.channels, channels);
        for (size_t i = 0; i < floats.data.size(); ++i) {
            const float v = bytes.values[bytes.bytes[i]];
            ASSERT_EQ(std::memcmp(&v, &floats.data[i], sizeof v), 0)
                << "value " << i << " of " << channels << " channels";
        }
        EXPECT_TRUE(read_image_header(file).bytes);
        // The texels: one byte per kept channel, the decoded value of each in the table.
        for (bool srgb : {false, true}) {
            auto t = load_texels(file, {srgb, true});
            const int kept = channels <= 2 ? 1 : 3;
            ASSERT_EQ(t->bytes.size(), size_t(37) * 11 * kept);
            EXPECT_TRUE(t->floats.empty());
            EXPECT_EQ(t->memory(), size_t(37) * 11 * kept);
            for (size_t p = 0; p < size_t(37) * 11; ++p)
                for (int c = 0; c < kept; ++c)
                    ASSERT_EQ(t->bytes[p * kept + c], bytes.bytes[p * channels + c]);
        }
    }
    // Float files stay floats.
    Image img(5, 3, 3);
    img.channel_names = {"R", "G", "B"};
    for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = 0.25f * float(i);
    write_image(path("f.exr"), img);
    EXPECT_FALSE(read_image_header(path("f.exr")).bytes);
    auto t = load_texels(path("f.exr"), {});
    EXPECT_TRUE(t->bytes.empty());
    EXPECT_EQ(t->floats, img.data);
}

TEST_F(TextureImage, TheBudgetRefusesAnImageByItsHeader) {
    // A PNG of a few bytes that claims 8000x8000 RGB pixels (183 MiB as bytes): refused from its
    // header with a budget of 64 MiB, before a row is decoded, with the texture's line in the
    // scene and the file's name.
    std::ofstream(path("claims.png"), std::ios::binary) << png_claiming(8000, 8000);
    set_texture_memory_budget(size_t(64) << 20);
    const std::string scene = path("scene.xml");
    std::ofstream(scene) << R"(<scene version="3.0.0">
    <shape type="sphere">
        <bsdf type="diffuse">
            <texture type="bitmap" name="reflectance">
                <string name="filename" value="claims.png"/>
            </texture>
        </bsdf>
    </shape>
</scene>
)";
    try {
        load_scene(scene);
        ADD_FAILURE() << "the scene loaded over the budget";
    } catch (const Error &e) {
        EXPECT_CONTAINS(e.what(), "scene.xml:5:");
        EXPECT_CONTAINS(e.what(), "claims.png");
        EXPECT_CONTAINS(e.what(), "8000x8000 pixels of 3 channels");
        EXPECT_CONTAINS(e.what(), "texture memory");
        EXPECT_CONTAINS(e.what(), "FACET_TEXTURE_MEMORY_MB");
    }
    EXPECT_EQ(texture_memory_used(), 0u);
    // The budget is for all images together: a second one that does not fit with the first is
    // refused while the first is held, and loads once it is gone.
    const std::string a = write_8bit("a.png", 64, 64, 3), b = write_8bit("b.png", 64, 64, 3, 1);
    const size_t one = 64 * 64 * 3;
    set_texture_memory_budget(2 * one + one / 2); // decoding takes the file's bytes and the texels
    auto first = load_texels(a, {});
    EXPECT_EQ(texture_memory_used(), one);
    EXPECT_THROW(load_texels(b, {}), Error);
    EXPECT_EQ(texture_memory_used(), one);
    first.reset();
    EXPECT_NO_THROW(load_texels(b, {}));
}

TEST_F(TextureImage, TheEnvironmentMapReadsThroughTheCache) {
    Image img(8, 4, 3);
    img.channel_names = {"R", "G", "B"};
    for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = 1.f;
    write_image(path("sky.exr"), img);
    set_texture_memory_budget(100);
    Properties props("envmap");
    props.set_plugin_name("envmap");
    props.set_string("filename", path("sky.exr"));
    try {
        PluginRegistry::instance().create_as<Emitter>(ObjectType::Emitter, props);
        ADD_FAILURE() << "an environment map over the budget loaded";
    } catch (const Error &e) {
        EXPECT_CONTAINS(e.what(), "sky.exr");
        EXPECT_CONTAINS(e.what(), "texture memory");
    }
    set_texture_memory_budget(0);
    EXPECT_NO_THROW(PluginRegistry::instance().create_as<Emitter>(ObjectType::Emitter, props));
    EXPECT_EQ(texture_memory_used(), 0u); // the map keeps its own pixels, not the file's
}

TEST_F(TextureImage, ABrokenPngGivesFacetsErrorLineAlone) {
    // libpng printed "libpng error: IDAT: incorrect data check" on stderr before facet's own
    // line. Run through the facet program: a program that links libpng itself (these tests
    // link OpenImageIO) binds OpenImageIO to libpng directly.
    std::string png;
    {
        std::ifstream in(write_8bit("good.png", 16, 16, 3), std::ios::binary);
        png.assign(std::istreambuf_iterator<char>(in), {});
    }
    const size_t idat = png.find("IDAT");
    ASSERT_NE(idat, std::string::npos);
    png[idat + 8] = char(png[idat + 8] ^ 0x55); // the compressed data, its CRC left as it was
    std::ofstream(path("broken.png"), std::ios::binary) << png;
    std::ofstream(path("scene.xml")) << R"(<scene version="3.0.0">
    <sensor type="perspective">
        <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film>
    </sensor>
    <shape type="sphere">
        <bsdf type="diffuse">
            <texture type="bitmap" name="reflectance">
                <string name="filename" value="broken.png"/>
            </texture>
        </bsdf>
    </shape>
</scene>
)";
    const std::string command = std::string("'") + FACET_BINARY_DIR + "/bin/facet' render '" +
                                path("scene.xml") + "' -q -o '" + path("out.exr") + "' 2>'" +
                                path("stderr.txt") + "'";
    EXPECT_NE(std::system(command.c_str()), 0);
    std::ifstream err(path("stderr.txt"));
    std::vector<std::string> lines;
    for (std::string line; std::getline(err, line);) lines.push_back(line);
    ASSERT_EQ(lines.size(), 1u) << "stderr: " << (lines.empty() ? "" : lines[0]) << " ...";
    EXPECT_EQ(lines[0].rfind("facet: error: ", 0), 0u) << lines[0];
    EXPECT_CONTAINS(lines[0], "scene.xml:8:");
    EXPECT_CONTAINS(lines[0], "broken.png");
}
