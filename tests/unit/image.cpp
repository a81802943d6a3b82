// Image I/O: EXR round trips, 8-bit output through the OCIO display transform, atomic writes.
#include <facet/image.h>
#include <facet/logger.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

namespace {

/// A fresh folder per test, removed afterwards.
class ImageIO : public ::testing::Test {
protected:
    void SetUp() override {
        const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() / fmt::format("facet-image-{}-{}-{}", ::getpid(),
                                                        info->test_suite_name(), info->name());
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }
    std::string path(const std::string &name) const { return (m_dir / name).string(); }
    /// Files in the folder, hidden ones included.
    std::vector<std::string> listing() const {
        std::vector<std::string> names;
        for (const auto &e : fs::directory_iterator(m_dir))
            names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }
    fs::path m_dir;
};

std::string file_bytes(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

Image gradient(int w, int h, int c) {
    Image img(w, h, c);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < c; ++k)
                img.at(x, y, k) = 0.01f * float(x + 3 * y) + 0.37f * float(k) + 1e-3f * x * x;
    return img;
}

} // namespace

TEST_F(ImageIO, ExrFloat32RoundTripIsExact) {
    Image img = gradient(13, 7, 3);
    img.at(2, 3, 1) = 12345.678f;
    img.channel_names = {"R", "G", "B"};
    ImageWriteOptions opts;
    opts.half = false;
    opts.metadata["facet:spp"] = "64";
    write_image(path("a.exr"), img, opts);
    Image back = read_image(path("a.exr"));
    ASSERT_EQ(back.width, 13);
    ASSERT_EQ(back.height, 7);
    ASSERT_EQ(back.channels, 3);
    EXPECT_EQ(back.channel_names, img.channel_names);
    EXPECT_EQ(back.data, img.data);
    EXPECT_EQ(listing(), std::vector<std::string>{"a.exr"});

    // Metadata become string attributes; the file is zip-compressed.
    auto in = OIIO::ImageInput::open(path("a.exr"));
    ASSERT_TRUE(in);
    EXPECT_EQ(in->spec().get_string_attribute("facet:spp"), "64");
    EXPECT_EQ(in->spec().get_string_attribute("compression"), "zip");
    EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
}

TEST_F(ImageIO, ExrFloat16RoundTripWithinHalfPrecision) {
    Image img = gradient(9, 5, 4);
    img.channel_names = {"R", "G", "B", "A"};
    ImageWriteOptions opts;
    opts.half = true;
    write_image(path("h.exr"), img, opts);
    Image back = read_image(path("h.exr"));
    ASSERT_EQ(back.channels, 4);
    EXPECT_EQ(back.channel_names, img.channel_names);
    bool any_rounded = false;
    for (size_t i = 0; i < img.data.size(); ++i) {
        EXPECT_NEAR(back.data[i], img.data[i], std::abs(img.data[i]) * (1.f / 1024.f) + 1e-7f);
        any_rounded |= back.data[i] != img.data[i];
    }
    EXPECT_TRUE(any_rounded); // it really was stored as half
    // Half files are smaller than float ones.
    opts.half = false;
    write_image(path("f.exr"), img, opts);
    EXPECT_LT(fs::file_size(path("h.exr")), fs::file_size(path("f.exr")));
}

TEST_F(ImageIO, ExrKeepsAovChannelNames) {
    Image img = gradient(4, 4, 5);
    img.channel_names = {"R", "G", "B", "albedo.R", "depth.Y"};
    write_image(path("aov.exr"), img);
    Image back = read_image(path("aov.exr"));
    ASSERT_EQ(back.channels, 5);
    // EXR sorts channels inside a layer; find them by name.
    for (int c = 0; c < 5; ++c) {
        auto it =
            std::find(back.channel_names.begin(), back.channel_names.end(), img.channel_names[c]);
        ASSERT_NE(it, back.channel_names.end()) << img.channel_names[c];
        int bc = int(it - back.channel_names.begin());
        EXPECT_EQ(back.at(3, 2, bc), img.at(3, 2, c));
    }
}

TEST_F(ImageIO, PngGoesThroughTheSrgbDisplayTransform) {
    Image img(4, 1, 3);
    const float values[4] = {0.f, 0.5f, 1.f, 4.f};
    for (int x = 0; x < 4; ++x)
        for (int c = 0; c < 3; ++c) img.at(x, 0, c) = values[x];
    img.channel_names = {"R", "G", "B"};
    write_image(path("a.png"), img);
    Image back = read_image(path("a.png")); // 8-bit values as stored, / 255
    ASSERT_EQ(back.channels, 3);
    auto code = [&](int x) { return int(std::lround(back.at(x, 0, 0) * 255.f)); };
    EXPECT_EQ(code(0), 0);
    EXPECT_NEAR(code(1), 188, 1); // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354
    EXPECT_EQ(code(2), 255);
    EXPECT_EQ(code(3), 255); // clamped
    EXPECT_EQ(back.at(1, 0, 0), back.at(1, 0, 2));

    // The Raw view leaves the values alone: 0.5 -> 128.
    ImageWriteOptions raw;
    raw.view = "Raw";
    write_image(path("raw.png"), img, raw);
    Image r = read_image(path("raw.png"));
    EXPECT_NEAR(int(std::lround(r.at(1, 0, 0) * 255.f)), 128, 1);

    // An unknown view names the problem.
    ImageWriteOptions bad;
    bad.view = "Filmic";
    try {
        write_image(path("bad.png"), img, bad);
        FAIL() << "expected an error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("Filmic"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(path("bad.png")));
}

TEST_F(ImageIO, JpegAndAlpha) {
    Image img(8, 8, 4);
    for (size_t i = 0; i < img.data.size(); i += 4) {
        img.data[i] = img.data[i + 1] = img.data[i + 2] = 0.5f;
        img.data[i + 3] = 1.f;
    }
    img.channel_names = {"R", "G", "B", "A"};
    write_image(path("a.png"), img);
    Image png = read_image(path("a.png"));
    ASSERT_EQ(png.channels, 4);
    EXPECT_NEAR(png.at(3, 3, 0) * 255.f, 188.f, 1.f);
    EXPECT_EQ(png.at(3, 3, 3), 1.f);
    write_image(path("a.jpg"), img);
    Image jpg = read_image(path("a.jpg"));
    ASSERT_EQ(jpg.channels, 3);
    EXPECT_NEAR(jpg.at(3, 3, 1) * 255.f, 188.f, 2.f);
}

TEST_F(ImageIO, LinearFloatFormats) {
    Image img = gradient(5, 3, 3);
    img.channel_names = {"R", "G", "B"};
    write_image(path("a.pfm"), img);
    Image pfm = read_image(path("a.pfm"));
    ASSERT_EQ(pfm.channels, 3);
    EXPECT_EQ(pfm.data, img.data);
    write_image(path("a.hdr"), img);
    Image hdr = read_image(path("a.hdr"));
    ASSERT_EQ(hdr.channels, 3);
    // RGBE shares one exponent per pixel: 8 mantissa bits relative to the largest channel.
    for (size_t p = 0; p < img.data.size(); p += 3) {
        float m = std::max(img.data[p], std::max(img.data[p + 1], img.data[p + 2]));
        for (size_t c = p; c < p + 3; ++c) EXPECT_NEAR(hdr.data[c], img.data[c], m / 128.f);
    }
}

TEST_F(ImageIO, MissingFolderFailsClearlyWithoutTempFiles) {
    Image img = gradient(2, 2, 3);
    const std::string target = path("no/such/folder/out.exr");
    try {
        write_image(target, img);
        FAIL() << "expected an error";
    } catch (const Error &e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find(target), std::string::npos) << msg;
        EXPECT_NE(msg.find("does not exist"), std::string::npos) << msg;
    }
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageIO, FailedWriteLeavesTheOldFileUntouched) {
    Image img = gradient(6, 4, 3);
    write_image(path("keep.exr"), img);
    const std::string before = file_bytes(path("keep.exr"));
    ASSERT_FALSE(before.empty());

    // A broken image is refused before anything is written.
    Image broken = gradient(6, 4, 3);
    broken.data.resize(5);
    EXPECT_THROW(write_image(path("keep.exr"), broken), Error);
    EXPECT_EQ(file_bytes(path("keep.exr")), before);

    // The final rename fails (the target is a non-empty folder): the temporary file is removed
    // and the error names the target.
    fs::create_directories(m_dir / "dir.exr" / "inside");
    try {
        write_image(path("dir.exr"), img);
        FAIL() << "expected an error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("dir.exr"), std::string::npos) << e.what();
    }
    EXPECT_EQ(listing(), (std::vector<std::string>{"dir.exr", "keep.exr"}));
    EXPECT_TRUE(fs::is_directory(m_dir / "dir.exr" / "inside"));
    EXPECT_EQ(file_bytes(path("keep.exr")), before);

    // An extension no writer knows.
    EXPECT_THROW(write_image(path("keep.notaformat"), img), Error);
    EXPECT_EQ(listing(), (std::vector<std::string>{"dir.exr", "keep.exr"}));
}

TEST_F(ImageIO, OverwriteReplacesAtomically) {
    write_image(path("x.exr"), gradient(3, 3, 3));
    Image second = gradient(3, 3, 3);
    second.at(1, 1, 1) = 42.f;
    write_image(path("x.exr"), second);
    EXPECT_EQ(read_image(path("x.exr")).at(1, 1, 1), 42.f);
    EXPECT_EQ(listing(), std::vector<std::string>{"x.exr"});
}

TEST_F(ImageIO, ReadErrorsNameTheFile) {
    try {
        read_image(path("missing.exr"));
        FAIL() << "expected an error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("missing.exr"), std::string::npos);
    }
    std::ofstream(path("garbage.exr")) << "this is not an image";
    try {
        read_image(path("garbage.exr"));
        FAIL() << "expected an error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("garbage.exr"), std::string::npos);
    }
}

TEST(OcioConfig, SearchOrder) {
    EXPECT_EQ(ocio_config_path("/explicit/config.ocio"), "/explicit/config.ocio");
    const char *old = std::getenv("OCIO");
    std::string saved = old ? old : "";
    ::setenv("OCIO", "/from/env.ocio", 1);
    EXPECT_EQ(ocio_config_path(), "/from/env.ocio");
    ::unsetenv("OCIO");
    // Without both, the config next to the library (the build tree's share/facet).
    std::string installed = ocio_config_path();
    EXPECT_TRUE(fs::is_regular_file(installed)) << installed;
    EXPECT_EQ(fs::path(installed).filename(), "ocio.config");
    EXPECT_EQ(fs::weakly_canonical(installed),
              fs::weakly_canonical(fs::path(FACET_BINARY_DIR) / "share" / "facet" / "ocio.config"));
    if (old) ::setenv("OCIO", saved.c_str(), 1);
}
