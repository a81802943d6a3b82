// The measurement sensors against closed forms: radiancemeter (the radiance of a constant
// environment and of an area light along one ray; origin/direction and to_world placement) and
// irradiancemeter (π·L under a constant environment, π·L·sin²α from a sphere light on the
// axis), distant (ρ·L off a diffuse plane under a constant sky, with a point, a shape or no
// target), plus their parameter errors.
#include <facet/plugin.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;

namespace {

const char *kFilm = R"(<film type="hdrfilm"><integer name="width" value="1"/>
    <integer name="height" value="1"/><string name="component_format" value="float32"/>
    <rfilter type="box"/></film>)";

std::string sampler(int spp) {
    return fmt::format(R"(<sampler type="independent"><integer name="sample_count" value="{}"/>
        </sampler>)",
                       spp);
}

/// Renders the scene's first sensor and returns its single pixel.
Color3f measure(const std::string &scene_body) {
    auto obj = load_string("<scene version=\"3.0.0\">" + scene_body + "</scene>");
    auto scene = std::dynamic_pointer_cast<Scene>(obj);
    EXPECT_TRUE(scene);
    EXPECT_EQ(scene->sensors().size(), 1u);
    RenderOptions opts;
    opts.progress = false;
    opts.threads = 2;
    RenderResult r = render(*scene, *scene->sensors().front(), opts);
    EXPECT_EQ(r.image.width, 1);
    EXPECT_EQ(r.image.height, 1);
    return Color3f(r.image.at(0, 0, 0), r.image.at(0, 0, 1), r.image.at(0, 0, 2));
}

std::string error_of(const std::string &scene_body) {
    try {
        load_string("<scene version=\"3.0.0\">" + scene_body + "</scene>");
    } catch (const Error &e) {
        return e.what();
    }
    ADD_FAILURE() << "expected an error";
    return "";
}

const char *kEnv =
    R"(<emitter type="constant"><rgb name="radiance" value="0.2, 0.5, 1"/></emitter>)";

} // namespace

TEST(RadianceMeter, ReadsTheEnvironmentAndAnAreaLightAlongItsRay) {
    // A black light panel at z = 3 facing -z (radiance 3, 2, 1), a constant environment
    // elsewhere.
    const std::string panel = R"(<shape type="rectangle"><transform name="to_world">
        <rotate x="1" angle="180"/><translate z="3"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="3, 2, 1"/></emitter></shape>)";
    auto meter = [&](const std::string &placement) {
        return "<sensor type=\"radiancemeter\">" + placement + kFilm + sampler(16) + "</sensor>";
    };
    Color3f at_panel =
        measure(std::string(kEnv) + panel + meter(R"(<point name="origin" value="0.2, 0.1, 0"/>
                                        <vector name="direction" value="0, 0, 2"/>)"));
    EXPECT_NEAR(at_panel.r, 3.f, 1e-5f);
    EXPECT_NEAR(at_panel.b, 1.f, 1e-5f);
    Color3f away =
        measure(std::string(kEnv) + panel + meter(R"(<point name="origin" value="0.2, 0.1, 0"/>
                                    <vector name="direction" value="0, 1, -1"/>)"));
    EXPECT_NEAR(away.r, 0.2f, 1e-5f);
    EXPECT_NEAR(away.b, 1.f, 1e-5f);
    // The default placement looks along +z from the origin; to_world wins over origin.
    Color3f by_default = measure(std::string(kEnv) + panel + meter(""));
    EXPECT_NEAR(by_default.g, 2.f, 1e-5f);
    Color3f by_to_world = measure(std::string(kEnv) + panel + meter(R"(<transform name="to_world">
            <lookat origin="0, 0, 1" target="0, 0, -1"/></transform>
            <point name="origin" value="0, 0, 0"/><vector name="direction" value="0, 0, 1"/>)"));
    EXPECT_NEAR(by_to_world.g, 0.5f, 1e-5f);
}

TEST(RadianceMeter, BadParameters) {
    EXPECT_NE(error_of(std::string(R"(<sensor type="radiancemeter">
        <point name="origin" value="0, 0, 0"/>)") +
                       kFilm + "</sensor>")
                  .find("both origin and direction"),
              std::string::npos);
    EXPECT_NE(error_of(R"(<sensor type="radiancemeter"><film type="hdrfilm">
        <integer name="width" value="2"/><integer name="height" value="1"/></film></sensor>)")
                  .find("1x1"),
              std::string::npos);
}

TEST(IrradianceMeter, ConstantEnvironmentGivesPiL) {
    Color3f e = measure(std::string(kEnv) + R"(<shape type="rectangle">
        <sensor type="irradiancemeter">)" +
                        kFilm + sampler(64) + "</sensor></shape>");
    EXPECT_NEAR(e.r, Pi * 0.2f, 1e-4f);
    EXPECT_NEAR(e.g, Pi * 0.5f, 1e-4f);
    EXPECT_NEAR(e.b, Pi * 1.f, 1e-4f);
}

TEST(IrradianceMeter, SphereLightOnTheAxis) {
    // A small meter facing +z under a sphere light of radius 1 centred 2 above it (nothing
    // else): E = π·L·sin²α with sin α = 1/2.
    const std::string body = R"(<shape type="sphere"><point name="center" value="0, 0, 2"/>
        <float name="radius" value="1"/><emitter type="area"><rgb name="radiance" value="4"/>
        </emitter></shape>
        <shape type="rectangle"><transform name="to_world"><scale value="0.005"/></transform>
        <sensor type="irradiancemeter">)" +
                             std::string(kFilm) + sampler(65536) + "</sensor></shape>";
    Color3f e = measure(body);
    const float expected = Pi * 4.f * 0.25f;
    // The fraction of cosine-weighted rays that hit: binomial, p = 1/4.
    const float sigma = Pi * 4.f * std::sqrt(0.25f * 0.75f / 65536.f);
    EXPECT_NEAR(e.g, expected, 4.f * sigma);
}

TEST(IrradianceMeter, MustBeNestedInAShapeWithoutToWorld) {
    EXPECT_NE(error_of(R"(<shape type="rectangle"><sensor type="irradiancemeter">
        <transform name="to_world"><translate x="1"/></transform></sensor></shape>)")
                  .find("to_world"),
              std::string::npos);
    EXPECT_NE(error_of(R"(<shape type="rectangle"><sensor type="perspective"/></shape>)")
                  .find("must measure on the shape"),
              std::string::npos);
}

TEST(DistantSensor, DiffusePlaneUnderAConstantSkyReflectsRhoL) {
    // A diffuse plane (ρ = 0.5) lit by a constant environment L: it leaves ρ·L in every
    // direction above it, whether the rays aim at a point or over a target shape's area.
    const std::string plane = R"(<shape type="rectangle"><transform name="to_world">
        <scale value="3"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>)";
    const std::string point_target = R"(<sensor type="distant">
        <vector name="direction" value="0.3, -1, 0.2"/><point name="target" value="0.5, 0, -0.4"/>
        )" + std::string(kFilm) + sampler(4096) +
                                     "</sensor>";
    Color3f e = measure(std::string(kEnv) + plane + point_target);
    EXPECT_NEAR(e.r, 0.5f * 0.2f, 0.02f * 0.1f);
    EXPECT_NEAR(e.b, 0.5f * 1.f, 0.02f * 0.5f);
    const std::string shape_target = R"(<sensor type="distant">
        <vector name="direction" value="0, -1, 0"/>
        <shape type="disk" name="target"><transform name="to_world"><rotate x="1" angle="-90"/>
        <translate y="0.01"/></transform></shape>)" +
                                     std::string(kFilm) + sampler(4096) + "</sensor>";
    e = measure(std::string(kEnv) + plane + shape_target);
    EXPECT_NEAR(e.g, 0.5f * 0.5f, 0.02f * 0.25f);
    // Without a target the rays cover the bounding sphere's cross-section: some miss the plane
    // (the disc of radius 3·√2 around a 6x6 square) and see the sky instead.
    const std::string no_target =
        R"(<sensor type="distant"><vector name="direction" value="0, -1, 0"/>)" +
        std::string(kFilm) + sampler(16384) + "</sensor>";
    e = measure(std::string(kEnv) + plane + no_target);
    const float covered = 36.f / (Pi * 18.f); // square area over the disc's
    const float expected = covered * 0.5f + (1.f - covered) * 1.f;
    EXPECT_NEAR(e.b, expected, 0.02f);
}

TEST(DistantSensor, BadParameters) {
    EXPECT_NE(error_of(R"(<sensor type="distant"><vector name="direction" value="0, 0, 1"/>
        <transform name="to_world"><translate x="1"/></transform></sensor>)")
                  .find("not both"),
              std::string::npos);
    EXPECT_NE(error_of(R"(<sensor type="distant"><film type="hdrfilm">
        <integer name="width" value="3"/><integer name="height" value="1"/></film></sensor>)")
                  .find("1x1"),
              std::string::npos);
}
