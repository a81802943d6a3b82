// `facet compare`, the one implementation of the peer rule the compat suite applies, checked on
// images derived from a peer reference: the reference agrees with itself and with itself plus
// noise of its own per-sample variance; scaled by 1.03, or with one wrong quadrant, it does not.
// Also the verdict line's figures and the z image.

#include <facet/image.h>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;
using facet::Image;

namespace {

const std::string FACET = FACET_BINARY_DIR "/bin/facet";
const std::string REFS = FACET_SOURCE_DIR "/tests/compat/data/peer-renders/";
// A 64×64 reference whose constant background has (almost) no variance, so a 3 % error is many
// standard deviations there, at the scene's test spp.
const std::string NAME = "filters-gaussian";
const int SPP = 488;

struct Verdict {
    int code = -1;
    std::string out;
    bool pass = false;
    double agreeing = -1.0, rel_error = 0.0, ratio = 0.0;
};

class CompareCli : public ::testing::Test {
protected:
    void SetUp() override {
        const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() /
                (std::string("facet_compare_") + info->name() + "_" + std::to_string(getpid()));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
        m_mean = facet::read_image(mean_path());
        m_var = facet::read_image(var_path());
        ASSERT_EQ(m_mean.channels, 3);
        ASSERT_EQ(m_var.channels, 3);
        ASSERT_EQ(2000000 / (m_mean.width * m_mean.height), SPP); // the test spp of the rule
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(m_dir);
    }

    static std::string mean_path() { return REFS + NAME + "_mean_rgb.exr"; }
    static std::string var_path() { return REFS + NAME + "_var_xyz.exr"; }

    /// `facet compare <ours> <reference> --spp SPP [extra]`, with the verdict line parsed.
    Verdict compare(const std::string &ours, const std::string &extra = "") {
        fs::path out = m_dir / "stdout.txt";
        std::string cmd = "'" + FACET + "' compare '" + ours + "' '" + mean_path() + "' '" +
                          var_path() + "' --spp " + std::to_string(SPP) + " " + extra + " > '" +
                          out.string() + "' 2>&1 < /dev/null";
        int status = std::system(cmd.c_str());
        Verdict v;
        v.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        std::ifstream in(out);
        std::stringstream ss;
        ss << in.rdbuf();
        v.out = ss.str();
        // The last line: PASS|FAIL agreeing=<%> required=99.75% rel_error=<%> ratio=<x>
        static const std::regex line(
            R"((PASS|FAIL) agreeing=([0-9.]+)% required=99\.75% rel_error=([-+0-9.]+)% )"
            R"(ratio=([0-9.]+)\n$)");
        std::smatch m;
        if (std::regex_search(v.out, m, line)) {
            v.pass = m[1] == "PASS";
            v.agreeing = std::stod(m[2]);
            v.rel_error = std::stod(m[3]);
            v.ratio = std::stod(m[4]);
        } else {
            ADD_FAILURE() << "no verdict line in:\n" << v.out;
        }
        EXPECT_EQ(v.code, v.pass ? 0 : 1) << v.out;
        return v;
    }

    std::string write(const std::string &name, const Image &img) {
        std::string path = (m_dir / name).string();
        facet::write_image(path, img);
        return path;
    }

    fs::path m_dir;
    Image m_mean, m_var;
};

/// Linear Rec.709 ↔ CIE XYZ, the matrix of the rule.
const double M[3][3] = {
    {0.412453, 0.357580, 0.180423}, {0.212671, 0.715160, 0.072169}, {0.019334, 0.119193, 0.950227}};

std::array<double, 3> rgb_to_xyz(const Image &img, int x, int y) {
    std::array<double, 3> r{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r[size_t(i)] += M[i][j] * img.at(x, y, j);
    return r;
}

std::array<double, 3> xyz_to_rgb(const std::array<double, 3> &xyz) {
    // Cramer's rule on M.
    auto det3 = [](const double a[3][3]) {
        return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
               a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    };
    double det = det3(M);
    std::array<double, 3> rgb{};
    for (int k = 0; k < 3; ++k) {
        double a[3][3];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) a[i][j] = j == k ? xyz[size_t(i)] : M[i][j];
        rgb[size_t(k)] = det3(a) / det;
    }
    return rgb;
}

} // namespace

TEST_F(CompareCli, ReferenceAgreesWithItself) {
    Verdict v = compare(mean_path());
    EXPECT_TRUE(v.pass) << v.out;
    EXPECT_EQ(v.agreeing, 100.0);
    EXPECT_EQ(v.rel_error, 0.0);
    EXPECT_EQ(v.ratio, 1.0);
}

TEST_F(CompareCli, ReferencePlusItsOwnNoiseAgrees) {
    // A render at SPP samples differs from the mean by noise of variance var/SPP per XYZ channel
    // (the variance floor of the rule only makes this easier).
    Image ours = m_mean;
    std::mt19937 rng(12345);
    std::normal_distribution<double> gauss;
    for (int y = 0; y < ours.height; ++y)
        for (int x = 0; x < ours.width; ++x) {
            auto xyz = rgb_to_xyz(m_mean, x, y);
            for (int k = 0; k < 3; ++k)
                xyz[size_t(k)] += gauss(rng) * std::sqrt(double(m_var.at(x, y, k)) / SPP);
            auto rgb = xyz_to_rgb(xyz);
            for (int c = 0; c < 3; ++c) ours.at(x, y, c) = float(rgb[size_t(c)]);
        }
    Verdict v = compare(write("noisy.exr", ours), "--mean-sigmas 4");
    EXPECT_TRUE(v.pass) << v.out;
    EXPECT_GT(v.agreeing, 99.9) << v.out;
    EXPECT_NEAR(v.ratio, 1.0, 2e-3) << v.out;
}

TEST_F(CompareCli, ReferenceScaledBy103Fails) {
    Image ours = m_mean;
    for (float &value : ours.data) value *= 1.03f;
    std::string z_path = (m_dir / "z.exr").string();
    Verdict v = compare(write("scaled.exr", ours), "--z-image '" + z_path + "'");
    EXPECT_FALSE(v.pass) << v.out;
    EXPECT_LT(v.agreeing, 99.75) << v.out;
    EXPECT_NEAR(v.rel_error, 3.0, 1e-3) << v.out;
    EXPECT_NEAR(v.ratio, 1.03, 1e-5) << v.out;

    // The z image holds |ours − ref|·sqrt(N / max(var, 1e-4)) per XYZ channel.
    Image z = facet::read_image(z_path);
    ASSERT_EQ(z.width, m_mean.width);
    ASSERT_EQ(z.channels, 3);
    for (int y = 0; y < z.height; y += 7)
        for (int x = 0; x < z.width; x += 5) {
            auto ref = rgb_to_xyz(m_mean, x, y);
            for (int k = 0; k < 3; ++k) {
                double expected = 0.03 * std::abs(ref[size_t(k)]) *
                                  std::sqrt(SPP / std::max(double(m_var.at(x, y, k)), 1e-4));
                EXPECT_NEAR(z.at(x, y, k), expected, 1e-4 * expected + 1e-5)
                    << "pixel " << x << ", " << y << ", channel " << k;
            }
        }
}

TEST_F(CompareCli, OneWrongQuadrantFails) {
    // The bottom-right quadrant 25 % too bright; the other three quadrants agree exactly, so
    // three quarters of the pixel-channels at least pass and the render still fails.
    Image ours = m_mean;
    for (int y = ours.height / 2; y < ours.height; ++y)
        for (int x = ours.width / 2; x < ours.width; ++x)
            for (int c = 0; c < 3; ++c) ours.at(x, y, c) *= 1.25f;
    Verdict v = compare(write("quadrant.exr", ours));
    EXPECT_FALSE(v.pass) << v.out;
    EXPECT_GE(v.agreeing, 75.0) << v.out;
    EXPECT_LT(v.agreeing, 99.75) << v.out;
    EXPECT_GT(v.ratio, 1.0) << v.out;
}

TEST_F(CompareCli, MismatchedSizesAreAnError) {
    Image small(8, 8, 3);
    fs::path out = m_dir / "stdout.txt";
    std::string cmd = "'" + FACET + "' compare '" + write("small.exr", small) + "' '" +
                      mean_path() + "' '" + var_path() + "' --spp 1 > '" + out.string() + "' 2>&1";
    int status = std::system(cmd.c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1);
    std::ifstream in(out);
    std::stringstream ss;
    ss << in.rdbuf();
    EXPECT_NE(ss.str().find("image sizes differ"), std::string::npos) << ss.str();
}

TEST_F(CompareCli, HalfAPercentBrighterFailsOnlyTheMeanBound) {
    // 0.5 % brighter everywhere: every pixel is well within its noise at the test spp, but the
    // image mean is about ten standard errors off (filters-gaussian: 0.036 % at 488 spp).
    Image ours = m_mean;
    for (float &value : ours.data) value *= 1.005f;
    std::string path = write("brighter.exr", ours);
    Verdict plain = compare(path);
    EXPECT_TRUE(plain.pass) << plain.out;
    EXPECT_GT(plain.agreeing, 99.9) << plain.out;
    Verdict bounded = compare(path, "--mean-sigmas 4");
    EXPECT_FALSE(bounded.pass) << bounded.out;
    EXPECT_EQ(bounded.agreeing, plain.agreeing) << bounded.out;
    EXPECT_NEAR(bounded.rel_error, 0.5, 1e-3) << bounded.out;
    EXPECT_NE(bounded.out.find("FAILS the bound of 4"), std::string::npos) << bounded.out;
}
