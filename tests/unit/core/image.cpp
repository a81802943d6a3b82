// Image I/O: EXR round trips, 8-bit output through the OCIO display transform, atomic writes.
#include <facet/image.h>
#include <facet/logger.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <array>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
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

    // An unknown view names the problem and the display's views.
    ImageWriteOptions bad;
    bad.view = "NoSuchView";
    try {
        write_image(path("bad.png"), img, bad);
        FAIL() << "expected an error";
    } catch (const Error &e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find("NoSuchView"), std::string::npos) << msg;
        EXPECT_NE(msg.find("\"Standard\", \"ACES 1.0 - SDR Video\", \"Raw\""), std::string::npos)
            << msg;
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

TEST_F(ImageIO, PfmIsBottomRowFirstLittleEndianAndReadsBack) {
    // Every pixel different, so a flipped or transposed file cannot pass.
    Image img(4, 3, 3);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x)
            for (int c = 0; c < 3; ++c) img.at(x, y, c) = float(100 * y + 10 * x + c) + 0.25f;
    img.channel_names = {"R", "G", "B"};
    check_image_path(path("a.pfm")); // no OpenImageIO writer, but facet writes it
    write_image(path("a.pfm"), img);
    const std::string bytes = file_bytes(path("a.pfm"));
    const std::string header = "PF\n4 3\n-1.0\n"; // RGB, little-endian (negative scale)
    ASSERT_EQ(bytes.substr(0, header.size()), header);
    ASSERT_EQ(bytes.size(), header.size() + 4 * 3 * 3 * sizeof(float));
    auto stored = [&](size_t i) {
        float v;
        std::memcpy(&v, bytes.data() + header.size() + i * sizeof(float), sizeof(float));
        return v;
    };
    EXPECT_EQ(stored(0), img.at(0, 2, 0)); // the file starts with the bottom row
    EXPECT_EQ(stored(3 * 4 * 2 + 3 * 1 + 2), img.at(1, 0, 2));
    Image back = read_image(path("a.pfm"));
    ASSERT_EQ(back.width, 4);
    ASSERT_EQ(back.height, 3);
    ASSERT_EQ(back.channels, 3);
    EXPECT_EQ(back.data, img.data); // same orientation as written

    // Grey (and grey + alpha) become a one-channel "Pf"; RGBA drops alpha and AOVs.
    Image grey(2, 2, 2);
    for (int i = 0; i < 8; ++i) grey.data[size_t(i)] = float(i);
    grey.channel_names = {"Y", "A"};
    write_image(path("g.pfm"), grey);
    EXPECT_EQ(file_bytes(path("g.pfm")).substr(0, 10), "Pf\n2 2\n-1.");
    Image gback = read_image(path("g.pfm"));
    ASSERT_EQ(gback.channels, 1);
    EXPECT_EQ(gback.at(1, 1, 0), 6.f);
    Image rgba = gradient(3, 2, 5);
    rgba.channel_names = {"R", "G", "B", "A", "depth"};
    write_image(path("c.pfm"), rgba);
    Image cback = read_image(path("c.pfm"));
    ASSERT_EQ(cback.channels, 3);
    EXPECT_EQ(cback.at(2, 1, 2), rgba.at(2, 1, 2));
    EXPECT_EQ(listing(), (std::vector<std::string>{"a.pfm", "c.pfm", "g.pfm"}));
}

TEST_F(ImageIO, CheckImagePathRefusesWhatWriteImageWouldRefuse) {
    for (const char *ok : {"a.exr", "a.png", "a.jpg", "a.hdr", "a.pfm", "A.PFM", "a.tif"})
        EXPECT_NO_THROW(check_image_path(path(ok))) << ok;
    EXPECT_THROW(check_image_path(path("a.notaformat")), Error);
    EXPECT_THROW(check_image_path(path("missing/a.pfm")), Error);
    EXPECT_TRUE(listing().empty()); // checking writes nothing
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

namespace {

/// Noise, so that compressed files are large.
Image noise(int w, int h, int c) {
    Image img(w, h, c);
    uint32_t state = 12345u;
    for (float &v : img.data) {
        state = state * 1664525u + 1013904223u;
        v = float(state >> 8) / float(1u << 24);
    }
    return img;
}

/// Within its scope every write past `bytes` bytes of a file fails with EFBIG (SIGXFSZ is
/// ignored), as writes do on a full disk.
class FileSizeLimit {
public:
    explicit FileSizeLimit(rlim_t bytes) {
        m_old_handler = std::signal(SIGXFSZ, SIG_IGN);
        getrlimit(RLIMIT_FSIZE, &m_old);
        rlimit lim = m_old;
        lim.rlim_cur = bytes;
        m_ok = setrlimit(RLIMIT_FSIZE, &lim) == 0;
    }
    ~FileSizeLimit() {
        setrlimit(RLIMIT_FSIZE, &m_old);
        std::signal(SIGXFSZ, m_old_handler);
    }
    bool ok() const { return m_ok; }

private:
    rlimit m_old{};
    void (*m_old_handler)(int) = nullptr;
    bool m_ok = false;
};

} // namespace

TEST_F(ImageIO, WriteThatRunsOutOfSpaceKeepsTheOldFileAndFails) {
    for (const char *name : {"full.png", "full.exr", "full.pfm", "full.jpg", "full.hdr"}) {
        SCOPED_TRACE(name);
        Image small = noise(8, 8, 3);
        small.channel_names = {"R", "G", "B"};
        write_image(path(name), small);
        const std::string before = file_bytes(path(name));
        ASSERT_FALSE(before.empty());

        Image big = noise(96, 96, 3);
        big.channel_names = {"R", "G", "B"};
        {
            // Enough for the small file, far too little for the big one.
            FileSizeLimit limit(before.size() + 600);
            ASSERT_TRUE(limit.ok());
            try {
                write_image(path(name), big);
                ADD_FAILURE() << "a write that ran out of space reported success";
            } catch (const Error &e) {
                std::string msg = e.what();
                EXPECT_NE(msg.find(name), std::string::npos) << msg;
            }
        }
        EXPECT_EQ(file_bytes(path(name)), before); // the old file, untouched
        // No temporary file is left behind.
        for (const std::string &f : listing()) EXPECT_EQ(f.find(".tmp"), std::string::npos) << f;
        // Without the limit the same write works.
        write_image(path(name), big);
        EXPECT_EQ(read_image(path(name)).width, 96);
    }
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

TEST_F(ImageIO, ReadsItsFormatsByContentsAndNoOthers) {
    Image img = gradient(4, 3, 3);
    img.channel_names = {"R", "G", "B"};
    write_image(path("a.png"), img);
    const Image png = read_image(path("a.png"));
    // A PNG whose name says otherwise, or nothing, is read by the reader that recognises it.
    for (const char *name : {"named.jpg", "named.cr2", "no-extension"}) {
        fs::copy_file(path("a.png"), path(name));
        const Image back = read_image(path(name));
        ASSERT_EQ(back.width, 4) << name;
        EXPECT_EQ(back.data, png.data) << name;
    }
    // A file its contents name but cannot be read: that reader's error, not the extension's.
    // (An EXR: a cut PNG makes OpenImageIO's PNG reader leak its error string, .ci/lsan.supp.)
    {
        write_image(path("a.exr"), img);
        const std::string bytes = file_bytes(path("a.exr"));
        std::ofstream(path("cut"), std::ios::binary) << bytes.substr(0, 20);
        try {
            read_image(path("cut"));
            FAIL() << "expected an error";
        } catch (const Error &e) {
            EXPECT_NE(std::string(e.what()).find("read as openexr (by its contents)"),
                      std::string::npos)
                << e.what();
        }
    }
    // A format OpenImageIO reads but facet does not: refused by name, whatever reads it.
    {
        auto out = OIIO::ImageOutput::create(path("a.gif"));
        ASSERT_TRUE(out);
        OIIO::ImageSpec spec(4, 3, 3, OIIO::TypeDesc::UINT8);
        std::vector<unsigned char> pixels(4 * 3 * 3, 100);
        ASSERT_TRUE(out->open(path("a.gif"), spec));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
        out->close();
        ASSERT_TRUE(OIIO::ImageInput::open(path("a.gif"))) << OIIO::geterror();
    }
    std::ofstream(path("junk.cr2")) << "not a camera raw file";
    for (const auto &[name, says] : {std::pair<std::string, std::string>{"a.gif", "gif files"},
                                     {"junk.cr2", "raw files"},
                                     {"junk.unknown", "extension names no image format"}}) {
        if (!fs::exists(path(name))) std::ofstream(path(name)) << "junk";
        try {
            read_image(path(name));
            FAIL() << name << ": expected an error";
        } catch (const Error &e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(name), std::string::npos) << what;
            EXPECT_NE(what.find(says), std::string::npos) << what;
            EXPECT_NE(what.find("facet reads OpenEXR"), std::string::npos) << what;
        }
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

TEST_F(ImageIO, ExrTypedMetadataAndRec709Chromaticities) {
    Image img = gradient(4, 3, 3);
    img.channel_names = {"R", "G", "B"};
    ImageWriteOptions opts;
    opts.half = true;
    opts.int_metadata["samplesPerPixel"] = 488;
    opts.float_metadata["renderTimeSeconds"] = 12.5f;
    Matrix4f m;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) m.m[i][j] = float(4 * i + j) + 0.5f;
    opts.matrix_metadata["worldToCamera"] = m;
    write_image(path("m.exr"), img, opts);

    auto in = OIIO::ImageInput::open(path("m.exr"));
    ASSERT_TRUE(in);
    const OIIO::ImageSpec &spec = in->spec();
    const OIIO::ParamValue *p = spec.find_attribute("samplesPerPixel");
    ASSERT_TRUE(p);
    EXPECT_EQ(p->type(), OIIO::TypeInt);
    EXPECT_EQ(p->get_int(), 488);
    p = spec.find_attribute("renderTimeSeconds");
    ASSERT_TRUE(p);
    EXPECT_EQ(p->type(), OIIO::TypeFloat);
    EXPECT_EQ(p->get_float(), 12.5f);
    p = spec.find_attribute("worldToCamera");
    ASSERT_TRUE(p) << "attributes: " << spec.serialize(OIIO::ImageSpec::SerialText);
    EXPECT_EQ(p->type(), OIIO::TypeMatrix44);
    const float *v = static_cast<const float *>(p->data());
    for (int k = 0; k < 16; ++k) EXPECT_EQ(v[k], float(k) + 0.5f) << k; // row-major, in order
    p = spec.find_attribute("chromaticities");
    ASSERT_TRUE(p);
    ASSERT_EQ(p->type(), OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8));
    const float *c = static_cast<const float *>(p->data());
    const float rec709[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
    for (int k = 0; k < 8; ++k) EXPECT_FLOAT_EQ(c[k], rec709[k]) << k;
    in->close();

    // XYZ pixels are not Rec.709: no chromaticities are claimed for them.
    img.channel_names = {"X", "Y", "Z"};
    write_image(path("xyz.exr"), img, opts);
    in = OIIO::ImageInput::open(path("xyz.exr"));
    ASSERT_TRUE(in);
    EXPECT_FALSE(in->spec().find_attribute("chromaticities"));
}

TEST_F(ImageIO, ExrKeepsItsCropWindowAndStoresHalfsRoundedToNearest) {
    // A crop: 6x4 pixels at (5, 3) of a 20x10 image, half colour and a float AOV.
    Image img = gradient(6, 4, 4);
    img.channel_names = {"R", "G", "B", "depth"};
    img.x = 5;
    img.y = 3;
    img.full_width = 20;
    img.full_height = 10;
    img.at(0, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    img.at(1, 0, 0) = std::numeric_limits<float>::infinity();
    img.at(2, 0, 0) = 70000.f;            // past the largest half: infinity
    img.at(3, 0, 0) = 1.f + 1.f / 2048.f; // halfway between two halfs: to the even one, 1
    img.at(4, 0, 0) = 1.f + 3.f / 2048.f; // to the even one above, 1 + 2/1024
    img.at(5, 0, 0) = -1e-8f;             // below the smallest half: -0
    ImageWriteOptions opts;
    opts.half = true;
    write_image(path("crop.exr"), img, opts);

    auto in = OIIO::ImageInput::open(path("crop.exr"));
    ASSERT_TRUE(in);
    const OIIO::ImageSpec &spec = in->spec();
    EXPECT_EQ(spec.x, 5);
    EXPECT_EQ(spec.y, 3);
    EXPECT_EQ(spec.width, 6);
    EXPECT_EQ(spec.height, 4);
    EXPECT_EQ(spec.full_x, 0);
    EXPECT_EQ(spec.full_y, 0);
    EXPECT_EQ(spec.full_width, 20);
    EXPECT_EQ(spec.full_height, 10);
    in->close();
    Image back = read_image(path("crop.exr"));
    ASSERT_EQ(back.channels, 4);
    EXPECT_EQ(back.channel_names, img.channel_names);
    EXPECT_TRUE(std::isnan(back.at(0, 0, 0)));
    EXPECT_EQ(back.at(1, 0, 0), std::numeric_limits<float>::infinity());
    EXPECT_EQ(back.at(2, 0, 0), std::numeric_limits<float>::infinity());
    EXPECT_EQ(back.at(3, 0, 0), 1.f);
    EXPECT_EQ(back.at(4, 0, 0), 1.f + 2.f / 1024.f);
    EXPECT_EQ(back.at(5, 0, 0), 0.f);
    EXPECT_TRUE(std::signbit(back.at(5, 0, 0)));
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 6; ++x) EXPECT_EQ(back.at(x, y, 3), img.at(x, y, 3)); // float32

    // Two channels of one name cannot both be stored: refused, nothing written.
    img.channel_names = {"R", "G", "B", "G"};
    EXPECT_THROW(write_image(path("twice.exr"), img, opts), Error);
    EXPECT_EQ(listing(), std::vector<std::string>{"crop.exr"});
}

TEST_F(ImageIO, HalfExrKeepsAovChannelsFloat32) {
    Image img(3, 2, 6);
    img.channel_names = {"R", "G", "B", "A", "prim", "dd"};
    for (int i = 0; i < 6; ++i) {
        float *px = img.data.data() + size_t(i) * 6;
        px[0] = 0.3f + 0.1f * float(i);
        px[1] = px[2] = 0.5f;
        px[3] = 1.f;
        px[4] = float(980000 + i);    // a primitive index: infinity as a half
        px[5] = 1234.567f + float(i); // a depth: 1235 as a half
    }
    ImageWriteOptions opts;
    opts.half = true;
    write_image(path("aov.exr"), img, opts);
    auto in = OIIO::ImageInput::open(path("aov.exr"));
    ASSERT_TRUE(in);
    const OIIO::ImageSpec &spec = in->spec();
    for (int c = 0; c < spec.nchannels; ++c) {
        const std::string &name = spec.channelnames[c];
        OIIO::TypeDesc t = spec.channelformat(c);
        if (name == "prim" || name == "dd")
            EXPECT_EQ(t, OIIO::TypeDesc::FLOAT) << name;
        else
            EXPECT_EQ(t, OIIO::TypeDesc::HALF) << name; // colour and alpha stay half
    }
    in->close();
    Image back = read_image(path("aov.exr"));
    auto channel = [&](const std::string &n) {
        return int(std::find(back.channel_names.begin(), back.channel_names.end(), n) -
                   back.channel_names.begin());
    };
    const int prim = channel("prim"), dd = channel("dd");
    ASSERT_LT(prim, back.channels);
    ASSERT_LT(dd, back.channels);
    for (int i = 0; i < 6; ++i) {
        EXPECT_EQ(back.data[size_t(i) * back.channels + prim], float(980000 + i));
        EXPECT_EQ(back.data[size_t(i) * back.channels + dd], 1234.567f + float(i));
    }
}

namespace {

/// Points $OCIO at the test config (without an sRGB display) for one scope.
class StudioOcio {
public:
    StudioOcio() {
        const char *old = std::getenv("OCIO");
        m_had = old != nullptr;
        if (old) m_old = old;
        ::setenv("OCIO", FACET_TEST_DATA_DIR "/ocio/studio.config", 1);
    }
    ~StudioOcio() {
        if (m_had)
            ::setenv("OCIO", m_old.c_str(), 1);
        else
            ::unsetenv("OCIO");
    }

private:
    bool m_had = false;
    std::string m_old;
};

Image flat(float v) {
    Image img(2, 2, 3);
    std::fill(img.data.begin(), img.data.end(), v);
    img.channel_names = {"R", "G", "B"};
    return img;
}

} // namespace

TEST_F(ImageIO, PngUsesTheConfigsDefaultDisplayAndView) {
    StudioOcio studio;
    auto code = [&](const std::string &name, const ImageWriteOptions &opts, float v = 0.25f) {
        write_image(path(name), flat(v), opts);
        return int(std::lround(read_image(path(name)).at(1, 1, 0) * 255.f));
    };
    ImageWriteOptions opts;
    EXPECT_EQ(code("default.png", opts), 128); // Studio Monitor / Film: 0.25^(1/2)
    opts.view = "Linear";
    EXPECT_EQ(code("linear.png", opts), 64);
    opts.view = "Pushed Film";                // the view's own look doubles first
    EXPECT_EQ(code("pushed.png", opts), 180); // 255 sqrt(0.5)
    opts.view = "";
    opts.looks = "push";
    EXPECT_EQ(code("look.png", opts), 180);
    opts.looks = "push, dim"; // x2, then x0.5
    EXPECT_EQ(code("looks.png", opts), 128);
    opts.looks = "";
    opts.display = "Projector"; // its default view, Lin
    EXPECT_EQ(code("projector.png", opts), 64);

    DisplayView dv = resolve_display_view({});
    EXPECT_EQ(dv.display, "Studio Monitor");
    EXPECT_EQ(dv.view, "Film");

    OcioDisplays all = ocio_displays();
    EXPECT_EQ(all.default_display, "Studio Monitor");
    ASSERT_EQ(all.displays.size(), 2u);
    EXPECT_EQ(all.displays[0].views, (std::vector<std::string>{"Film", "Linear", "Pushed Film"}));
    EXPECT_EQ(all.looks, (std::vector<std::string>{"push", "dim"}));
}

TEST_F(ImageIO, WrongDisplayViewOrLookListsTheChoices) {
    StudioOcio studio;
    auto error = [&](const ImageWriteOptions &opts) -> std::string {
        try {
            write_image(path("x.png"), flat(0.5f), opts);
        } catch (const Error &e) {
            return e.what();
        }
        return "no error";
    };
    ImageWriteOptions opts;
    opts.display = "sRGB"; // the name facet's own config uses
    std::string msg = error(opts);
    EXPECT_NE(msg.find("no display \"sRGB\""), std::string::npos) << msg;
    EXPECT_NE(msg.find("\"Studio Monitor\", \"Projector\""), std::string::npos) << msg;
    opts.display = "Studio Monitor";
    opts.view = "Standard";
    msg = error(opts);
    EXPECT_NE(msg.find("no view \"Standard\""), std::string::npos) << msg;
    EXPECT_NE(msg.find("\"Film\", \"Linear\", \"Pushed Film\""), std::string::npos) << msg;
    opts.view = "";
    opts.looks = "push, +glow";
    msg = error(opts);
    EXPECT_NE(msg.find("no look \"glow\""), std::string::npos) << msg;
    EXPECT_NE(msg.find("\"push\", \"dim\""), std::string::npos) << msg;
    EXPECT_TRUE(listing().empty());
    // Linear formats do not go through the display: the same options only warn.
    EXPECT_NO_THROW(check_image_output(path("x.exr"), opts));
    EXPECT_THROW(check_image_output(path("x.png"), opts), Error);
}

TEST_F(ImageIO, FacetConfigHasAFilmicView) {
    // ACES 1.0 SDR video: highlights roll off instead of clipping, mid grey is darker than the
    // plain sRGB curve puts it, and the config needs no LUT file.
    ImageWriteOptions aces;
    aces.view = "ACES 1.0 - SDR Video";
    ImageWriteOptions standard;
    auto code = [&](const ImageWriteOptions &opts, float v) {
        write_image(path("v.png"), flat(v), opts);
        return int(std::lround(read_image(path("v.png")).at(0, 0, 1) * 255.f));
    };
    EXPECT_EQ(code(standard, 4.f), 255);
    EXPECT_EQ(code(standard, 8.f), 255);
    const int a4 = code(aces, 4.f), a8 = code(aces, 8.f), a18 = code(aces, 0.18f);
    EXPECT_LT(a4, 255);
    EXPECT_LT(a4, a8); // still distinguishes 4 from 8
    EXPECT_EQ(code(standard, 0.18f), 118);
    EXPECT_GT(a18, 60);
    EXPECT_LT(a18, 118);
    EXPECT_EQ(code(aces, 0.f), 0);
}

namespace {

/// A studio config whose scene_linear role is ACEScg, with a Rec.1886 (gamma 2.4) display and a
/// view without tone mapping, from OpenColorIO's built-in transforms. `extra_spaces` are added to
/// its colour spaces and `interchange` is the aces_interchange role line (or nothing).
std::string acescg_config(const std::string &interchange, const std::string &extra_spaces = "") {
    return R"(ocio_profile_version: 2.1
search_path: ""
strictparsing: true
roles:
  default: ACEScg
  scene_linear: ACEScg
  reference: ACES2065-1
  data: Raw
)" + interchange +
           R"(
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  Rec.1886:
    - !<View> {name: Plain, view_transform: Un-tone-mapped, display_colorspace: Rec.1886 - Display}
active_displays: [Rec.1886]
active_views: [Plain]
view_transforms:
  - !<ViewTransform>
    name: Un-tone-mapped
    from_scene_reference: !<BuiltinTransform> {style: "UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD"}
display_colorspaces:
  - !<ColorSpace>
    name: Rec.1886 - Display
    isdata: false
    from_display_reference: !<BuiltinTransform> {style: "DISPLAY - CIE-XYZ-D65_to_REC.1886-REC.709"}
colorspaces:
  - !<ColorSpace>
    name: ACES2065-1
    isdata: false
    encoding: scene-linear
  - !<ColorSpace>
    name: ACEScg
    isdata: false
    encoding: scene-linear
    to_scene_reference: !<BuiltinTransform> {style: "ACEScg_to_ACES2065-1"}
  - !<ColorSpace>
    name: Raw
    isdata: true
)" + extra_spaces;
}

std::array<int, 3> png_rgb(const std::string &file, const std::string &config) {
    Image img(1, 1, 3);
    img.data = {0.2f, 0.5f, 0.2f};
    img.channel_names = {"R", "G", "B"};
    ImageWriteOptions opts;
    opts.ocio_config = config;
    write_image(file, img, opts);
    Image back = read_image(file);
    std::array<int, 3> out;
    for (int c = 0; c < 3; ++c) out[size_t(c)] = int(std::lround(back.at(0, 0, c) * 255.f));
    return out;
}

} // namespace

TEST_F(ImageIO, PngConvertsFromLinearRec709NotTheConfigsSceneLinear) {
    // facet's pixels are linear Rec.709: under a config whose scene_linear is ACEScg they must be
    // converted from Rec.709 (found through the aces_interchange role), not read as ACEScg,
    // which gives (42, 198, 119).
    const std::array<int, 3> expected{{130, 191, 130}}; // 255 x^(1/2.4)
    auto write_config = [&](const std::string &name, const std::string &text) {
        std::ofstream(path(name)) << text;
        return path(name);
    };
    const std::string aces =
        write_config("aces.ocio", acescg_config("  aces_interchange: ACES2065-1\n"));
    EXPECT_EQ(png_rgb(path("aces.png"), aces), expected);

    // A space named as linear Rec.709 serves without any interchange role.
    const std::string named = write_config("named.ocio", acescg_config("", R"(  - !<ColorSpace>
    name: Linear Rec.709 (sRGB)
    aliases: [lin_rec709]
    isdata: false
    encoding: scene-linear
    to_scene_reference: !<GroupTransform>
      children:
        - !<MatrixTransform> {matrix: [0.4124564, 0.3575761, 0.1804375, 0, 0.2126729, 0.7151522, 0.0721750, 0, 0.0193339, 0.1191920, 0.9503041, 0, 0, 0, 0, 1]}
        - !<BuiltinTransform> {style: "UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD", direction: inverse}
)"));
    EXPECT_EQ(png_rgb(path("named.png"), named), expected);

    // A config that cannot say which space is Rec.709 is refused, clearly, before any write.
    const std::string bare = write_config("bare.ocio", acescg_config(""));
    try {
        png_rgb(path("bare.png"), bare);
        ADD_FAILURE() << "a config without linear Rec.709 was accepted";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("linear Rec.709"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("aces_interchange"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(path("bare.png")));
}
