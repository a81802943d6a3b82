// What `facet merge` refuses in the parts themselves, before it spends memory on them: a
// non-finite value (named by part, pixel and channel), a display window the parts' data windows
// do not cover (refused without a buffer of the display window's size, however large it
// claims to be), a data window outside its display window (refused from the header), and
// allocations over the limit (named). Parts are built in memory or written by the test.
#include <facet/checked.h>
#include <facet/image.h>
#include <facet/logger.h>
#include <facet/math.h>
#include <facet/merge.h>

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

#define EXPECT_CONTAINS(text, part)                                                                \
    EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

namespace {

/// Pass `pass` of a render in `passes` passes: the `w` x `h` rectangle at (x, y) of a W x H
/// image, every pixel 0.5 of weight 2 (R, G, B and, with passes, the raw sums and weight).
merge::Part part(const std::string &name, int pass, int passes, int x, int y, int w, int h, int W,
                 int H) {
    merge::Part p;
    p.name = name;
    p.full_width = W;
    p.full_height = H;
    p.x = x;
    p.y = y;
    p.image = Image(w, h, passes > 1 ? 7 : 3);
    p.image.channel_names = {"R", "G", "B"};
    if (passes > 1)
        for (const char *n : {"facet.sum.R", "facet.sum.G", "facet.sum.B", "facet.weight"})
            p.image.channel_names.push_back(n);
    for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px)
            for (int c = 0; c < p.image.channels; ++c)
                p.image.at(px, py, c) = c < 3 ? 0.5f : c < 6 ? 1.f : 2.f;
    p.metadata.strings[attr::pass] = std::to_string(pass);
    p.metadata.strings[attr::passes] = std::to_string(passes);
    p.metadata.strings[attr::spp] = "4";
    return p;
}

int channel(const merge::Part &p, const std::string &name) {
    const auto &n = p.image.channel_names;
    return int(std::find(n.begin(), n.end(), name) - n.begin());
}

std::string merge_error(const std::vector<merge::Part> &parts) {
    try {
        merge::merge_parts(parts);
    } catch (const Error &e) {
        return e.what();
    }
    return "(merged without an error)";
}

/// Peak resident memory of this process so far, in bytes.
size_t peak_bytes() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return size_t(usage.ru_maxrss) * 1024;
}

class MergeFiles : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() /
                ("facet_merge_checks_" + std::to_string(::getpid()) + "_" +
                 ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(m_dir);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(m_dir, ec);
    }
    /// Writes `p` as `facet render` writes a part (its data window in its display window).
    std::string write(const merge::Part &p, const std::string &name) const {
        Image img = p.image;
        img.x = p.x;
        img.y = p.y;
        img.full_width = p.full_width;
        img.full_height = p.full_height;
        ImageWriteOptions opts;
        add_metadata(opts, p.metadata);
        const std::string path = (m_dir / name).string();
        write_image(path, img, opts);
        return path;
    }
    fs::path m_dir;
};

} // namespace

TEST(MergeChecks, NonFiniteValuesAreRefusedByPartPixelAndChannel) {
    for (float bad : {std::numeric_limits<float>::quiet_NaN(), Infinity, -Infinity}) {
        // Two passes; the second split in two crops, the bad value in the right one.
        std::vector<merge::Part> parts = {part("p0.exr", 0, 2, 0, 0, 6, 4, 6, 4),
                                          part("p1-left.exr", 1, 2, 0, 0, 3, 4, 6, 4),
                                          part("p1-right.exr", 1, 2, 3, 0, 3, 4, 6, 4)};
        ASSERT_NO_THROW(merge::merge_parts(parts));
        merge::Part &p = parts[2];
        p.image.at(1, 2, channel(p, "facet.sum.G")) = bad;
        const std::string error = merge_error(parts);
        EXPECT_CONTAINS(error, "p1-right.exr: pixel (4, 2)"); // in the full image
        EXPECT_CONTAINS(error, "facet.sum.G");
        EXPECT_CONTAINS(error, std::isnan(bad) ? "nan" : "inf");
    }
    // A developed channel of a one-pass part too.
    std::vector<merge::Part> parts = {part("a.exr", 0, 1, 0, 0, 5, 5, 5, 5)};
    parts[0].image.at(0, 4, 0) = std::numeric_limits<float>::quiet_NaN();
    const std::string error = merge_error(parts);
    EXPECT_CONTAINS(error, "a.exr: pixel (0, 4)");
    EXPECT_CONTAINS(error, "channel R");
}

TEST(MergeChecks, NegativeWeightsOfNegativeLobesMergeAsOneRender) {
    // Filters with negative lobes (lanczos, mitchell) give a pixel a negative sum of weights
    // now and then (a lanczos pass at 1 spp: -0.54 at worst over 128x128 pixels); the film
    // divides by it, and so does the merge, to stay bit-identical with one render.
    std::vector<merge::Part> parts = {part("p0.exr", 0, 2, 0, 0, 2, 2, 2, 2),
                                      part("p1.exr", 1, 2, 0, 0, 2, 2, 2, 2)};
    parts[0].image.at(1, 1, channel(parts[0], "facet.weight")) = -0.5f;
    const merge::Merged merged = merge::merge_parts(parts);
    EXPECT_FLOAT_EQ(merged.image.at(1, 1, 0), float(2.0 / 1.5));
    EXPECT_FLOAT_EQ(merged.image.at(0, 0, 0), 0.5f);
}

TEST(MergeChecks, AHugeDisplayWindowIsRefusedWithoutAllocatingIt) {
    // A 4x4 part whose display window claims 30000x20000 pixels (7.2 GB as floats).
    const size_t before = peak_bytes();
    const std::string error = merge_error({part("huge.exr", 0, 1, 0, 0, 4, 4, 30000, 20000)});
    EXPECT_CONTAINS(error, "leave 599999984 of the 30000x20000 pixels uncovered, within [0, "
                           "30000) x [0, 20000)");
    EXPECT_LT(peak_bytes() - before, size_t(64) << 20) << "the merge allocated the display window";
    // Passes too.
    const std::string passes = merge_error({part("p0.exr", 0, 2, 0, 0, 4, 4, 30000, 20000),
                                            part("p1.exr", 1, 2, 0, 0, 4, 4, 30000, 20000)});
    EXPECT_CONTAINS(passes, "of pass 0 (of 2) leave 599999984");
    EXPECT_LT(peak_bytes() - before, size_t(64) << 20);
}

TEST(MergeChecks, UncoveredPixelsAreBoundedExactly) {
    // Parts of a 10x8 image leaving holes; the rectangle named is the holes' bounding box.
    struct Case {
        std::vector<std::array<int, 4>> parts; // x, y, w, h
        std::string box;
    };
    const Case cases[] = {
        {{{0, 0, 10, 3}, {0, 3, 4, 5}}, "[4, 10) x [3, 8)"},
        {{{0, 0, 10, 3}, {0, 5, 10, 3}}, "[0, 10) x [3, 5)"},
        {{{0, 0, 3, 8}, {7, 0, 3, 8}, {3, 0, 4, 2}}, "[3, 7) x [2, 8)"},
        {{{1, 1, 8, 6}}, "[0, 10) x [0, 8)"},
        {{{0, 0, 10, 7}, {0, 7, 9, 1}}, "[9, 10) x [7, 8)"},
    };
    for (const Case &c : cases) {
        std::vector<merge::Part> parts;
        for (const auto &r : c.parts)
            parts.push_back(part("p" + std::to_string(parts.size()) + ".exr", 0, 1, r[0], r[1],
                                 r[2], r[3], 10, 8));
        EXPECT_CONTAINS(merge_error(parts), "within " + c.box + ": a part is missing");
    }
}

TEST(MergeChecks, AllocationsOverTheLimitAreNamed) {
    const size_t saved = allocation_limit();
    set_allocation_limit(1000);
    const std::string error = merge_error(
        {part("p0.exr", 0, 2, 0, 0, 20, 20, 20, 20), part("p1.exr", 1, 2, 0, 0, 20, 20, 20, 20)});
    set_allocation_limit(saved);
    EXPECT_CONTAINS(error, "facet merge: the merged image (20x20 pixels of 3 channels)");
    EXPECT_CONTAINS(error, "allocation limit");
}

TEST_F(MergeFiles, ADataWindowOutsideItsDisplayWindowIsRefusedFromTheHeader) {
    merge::Part p = part("p.exr", 0, 1, 0, 0, 4, 4, 20, 20);
    p.x = 18; // [18, 22) of a 20-pixel-wide image
    const std::string path = write(p, "outside.exr");
    try {
        merge::read_part(path);
        ADD_FAILURE() << "read a part whose data window leaves its display window";
    } catch (const Error &e) {
        EXPECT_CONTAINS(e.what(), "outside.exr: its data window [18, 22) x [0, 4) is not "
                                  "inside its 20x20 display window");
    }
}

TEST_F(MergeFiles, AFilePartWithAHugeDisplayWindowIsRefused) {
    const merge::Part p = part("p.exr", 0, 1, 0, 0, 4, 4, 30000, 20000);
    const std::string path = write(p, "huge.exr");
    // The image library (OpenImageIO, ~120 MiB loaded once per process; read_part() reads a
    // part's attributes with it) is loaded first: the bound is on what the merge allocates.
    (void)read_image_file(path);
    const size_t before = peak_bytes();
    const std::string error = merge_error({merge::read_part(path)});
    EXPECT_CONTAINS(error, "uncovered, within [0, 30000) x [0, 20000)");
    EXPECT_LT(peak_bytes() - before, size_t(64) << 20);
}
