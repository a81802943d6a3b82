// The direct integrator's sample counts: shading_samples is the default of emitter_samples and
// bsdf_samples, and a scene may give it together with either (Mitsuba 3 does the same).

#include <facet/integrator.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/properties.h>

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

using namespace facet;

namespace {

std::string direct_with(const std::vector<std::pair<std::string, int>> &ints) {
    Properties props("direct");
    for (const auto &[name, value] : ints) props.set_int(name, value);
    return PluginRegistry::instance().create(ObjectType::Integrator, props)->to_string();
}

std::string counts(int emitter, int bsdf) {
    return "emitter_samples = " + std::to_string(emitter) +
           ", bsdf_samples = " + std::to_string(bsdf);
}

} // namespace

TEST(DirectIntegrator, SampleCountsDefaultToOneEach) {
    EXPECT_NE(direct_with({}).find(counts(1, 1)), std::string::npos) << direct_with({});
}

TEST(DirectIntegrator, ShadingSamplesSetsBothCounts) {
    std::string s = direct_with({{"shading_samples", 3}});
    EXPECT_NE(s.find(counts(3, 3)), std::string::npos) << s;
}

TEST(DirectIntegrator, ShadingSamplesIsOnlyTheDefault) {
    std::string s = direct_with({{"shading_samples", 4}, {"bsdf_samples", 1}});
    EXPECT_NE(s.find(counts(4, 1)), std::string::npos) << s;
    s = direct_with({{"shading_samples", 4}, {"emitter_samples", 2}});
    EXPECT_NE(s.find(counts(2, 4)), std::string::npos) << s;
    s = direct_with({{"shading_samples", 5}, {"emitter_samples", 0}});
    EXPECT_NE(s.find(counts(0, 5)), std::string::npos) << s;
    s = direct_with({{"shading_samples", 2}, {"emitter_samples", 3}, {"bsdf_samples", 7}});
    EXPECT_NE(s.find(counts(3, 7)), std::string::npos) << s;
}

TEST(DirectIntegrator, RejectsBadSampleCounts) {
    EXPECT_THROW(direct_with({{"shading_samples", 0}}), Error);
    EXPECT_THROW(direct_with({{"shading_samples", 0}, {"emitter_samples", 0}}), Error);
    EXPECT_THROW(direct_with({{"shading_samples", 3}, {"emitter_samples", 0}, {"bsdf_samples", 0}}),
                 Error);
    EXPECT_THROW(direct_with({{"shading_samples", -1}, {"emitter_samples", 1}}), Error);
    EXPECT_THROW(direct_with({{"bsdf_samples", 70000}}), Error);
}
