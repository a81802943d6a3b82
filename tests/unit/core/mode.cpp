// resolve_mode(): the colour mode of a name a user typed (`facet render -m`, Python's `mode=`).
#include <facet/logger.h>
#include <facet/mode.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

using namespace facet;

#define EXPECT_CONTAINS(text, part)                                                                \
    EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

namespace {

/// What resolve_mode(name) returned and what it logged; `error` is its facet::Error's message.
struct Resolved {
    std::string mode, log, error;
};

Resolved resolve(const std::string &name) {
    Resolved r;
    ::testing::internal::CaptureStderr();
    try {
        r.mode = resolve_mode(name);
    } catch (const Error &e) {
        r.error = e.what();
    }
    r.log = ::testing::internal::GetCapturedStderr();
    return r;
}

} // namespace

TEST(Mode, ListStartsWithTheDefault) {
    ASSERT_FALSE(modes().empty());
    EXPECT_EQ(modes().front(), "scalar_rgb");
    EXPECT_EQ(default_mode(), "scalar_rgb");
}

TEST(Mode, EveryListedModeResolvesToItselfSilently) {
    for (const std::string &mode : modes()) {
        const Resolved r = resolve(mode);
        EXPECT_EQ(r.mode, mode);
        EXPECT_EQ(r.error, "");
        EXPECT_EQ(r.log, "") << mode;
    }
}

TEST(Mode, VectorisedNamesRenderAsTheScalarModeWithOneNote) {
    for (const char *colour : {"rgb", "mono", "spectral"})
        for (const char *prefix : {"llvm_", "cuda_", "llvm_ad_", "cuda_ad_"}) {
            const std::string name = std::string(prefix) + colour;
            const Resolved r = resolve(name);
            EXPECT_EQ(r.mode, std::string("scalar_") + colour) << name;
            EXPECT_EQ(r.error, "") << name;
            EXPECT_EQ(r.log, fmt::format("[I] mode \"{}\": facet renders it as scalar_{} (facet "
                                         "has no vectorised or differentiable modes)\n",
                                         name, colour));
        }
}

TEST(Mode, EveryModeHasItsColourMode) {
    EXPECT_EQ(colour_mode("scalar_rgb"), ColourMode::RGB);
    EXPECT_EQ(colour_mode("scalar_mono"), ColourMode::Mono);
    EXPECT_EQ(colour_mode("scalar_spectral"), ColourMode::Spectral);
    for (const std::string &mode : modes()) EXPECT_EQ(mode_name(colour_mode(mode)), mode);
    try {
        colour_mode("llvm_mono");
        ADD_FAILURE() << "an unresolved name was accepted";
    } catch (const Error &e) {
        EXPECT_CONTAINS(e.what(), "scalar_rgb, scalar_mono");
    }
}

TEST(Mode, MonoIsTheLuminanceInEveryChannel) {
    const Color3f c(0.8f, 0.4f, 0.1f);
    EXPECT_EQ(in_mode(c, ColourMode::RGB), c);
    const float y = 0.212671f * 0.8f + 0.715160f * 0.4f + 0.072169f * 0.1f;
    EXPECT_EQ(in_mode(c, ColourMode::Mono), Color3f(y));
}

TEST(Mode, TheNoteFollowsTheLogLevel) {
    const LogLevel level = Logger::level();
    Logger::set_level(LogLevel::Warn);
    const Resolved r = resolve("llvm_rgb");
    Logger::set_level(level);
    EXPECT_EQ(r.mode, "scalar_rgb");
    EXPECT_EQ(r.log, "");
}

TEST(Mode, MitsubaModesFacetLacksAreRefusedByName) {
    for (const char *name :
         {"scalar_mono_polarized", "scalar_rgb_polarized", "scalar_spectral_polarized_double",
          "scalar_spectral_double", "scalar_rgb_double", "scalar_mono_polarized_double"}) {
        const Resolved r = resolve(name);
        EXPECT_EQ(r.mode, "") << name;
        EXPECT_EQ(r.error, fmt::format("facet does not render the mode \"{}\"; the modes it "
                                       "renders: scalar_rgb, scalar_mono, scalar_spectral, "
                                       "scalar_spectral_polarized",
                                       name));
        EXPECT_EQ(r.log, "") << name;
    }
}

TEST(Mode, VectorisedNamesOfModesFacetLacksNameTheirScalarForm) {
    const std::vector<std::pair<const char *, const char *>> cases = {
        {"cuda_ad_mono_polarized", "scalar_mono_polarized"},
        {"cuda_rgb_polarized", "scalar_rgb_polarized"},
        {"llvm_ad_rgb_double", "scalar_rgb_double"},
    };
    for (const auto &[name, scalar] : cases) {
        const Resolved r = resolve(name);
        EXPECT_EQ(r.error, fmt::format("facet does not render the mode \"{}\" (nor {}, its scalar "
                                       "form); the modes it renders: scalar_rgb, scalar_mono, "
                                       "scalar_spectral, scalar_spectral_polarized",
                                       name, scalar));
        EXPECT_EQ(r.log, "") << name;
    }
}

TEST(Mode, UnknownNamesListTheModesWithTheNearestName) {
    EXPECT_EQ(resolve("foo").error,
              "unknown mode \"foo\"; the modes facet renders: scalar_rgb, scalar_mono, "
              "scalar_spectral, scalar_spectral_polarized");
    EXPECT_EQ(resolve("").error,
              "unknown mode \"\"; the modes facet renders: scalar_rgb, scalar_mono, "
              "scalar_spectral, scalar_spectral_polarized");
    EXPECT_EQ(resolve("scalar_rbg").error,
              "unknown mode \"scalar_rbg\" (did you mean "
              "\"scalar_rgb\"?); the modes facet renders: scalar_rgb, "
              "scalar_mono, scalar_spectral, scalar_spectral_polarized");
    EXPECT_CONTAINS(resolve("llvm_rg").error, "(did you mean \"llvm_rgb\"?)");
    EXPECT_CONTAINS(resolve("SCALAR_RGB").error, "(did you mean \"scalar_rgb\"?)");
    // Not Mitsuba's names: scalar has no _ad_ form, and rgb comes before _polarized.
    for (const char *name : {"scalar_ad_rgb", "scalar_polarized_rgb", "rgb", "scalar_rgb_"})
        EXPECT_EQ(resolve(name).error.rfind("unknown mode", 0), 0u) << name;
}
