// The directional emitter: its sample towards any point, and the radiance of a diffuse plane
// it lights (ρ/π·E·cos θ).

#include <facet/emitter.h>
#include <facet/integrator.h>
#include <facet/plugin.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;

TEST(Directional, SampleIsTheDirectionWithItsIrradiance) {
    Properties props("directional");
    props.set_vector("direction", Vector3f(0, -2, 0));
    props.set_color("irradiance", Color3f(1.f, 2.f, 3.f));
    auto e = PluginRegistry::instance().create_as<Emitter>(ObjectType::Emitter, props);
    Interaction ref;
    ref.p = Point3f(3, 4, 5);
    auto [ds, w] = e->sample_direction(ref, Point2f(0.2f, 0.7f));
    EXPECT_TRUE(ds.delta);
    EXPECT_EQ(ds.d, Vector3f(0, 1, 0));
    EXPECT_EQ(w, Color3f(1.f, 2.f, 3.f));
    EXPECT_TRUE(std::isinf(ds.dist));
    EXPECT_EQ(e->pdf_direction(ref, ds), 0.f);
}

TEST(Directional, DirectionAndToWorldTogetherAreAnError) {
    Properties props("directional");
    props.set_vector("direction", Vector3f(0, -1, 0));
    props.set_transform("to_world", Transform());
    EXPECT_THROW(PluginRegistry::instance().create(ObjectType::Emitter, props), std::exception);
}

TEST(Directional, LitDiffusePlane) {
    // Light travelling down and sideways at 60° from the normal; plane albedo 0.5; E = 2.
    const float theta = deg_to_rad(60.f);
    std::string xml = R"(<scene version="3.0.0">
        <emitter type="directional">
            <vector name="direction" x=")" +
                      std::to_string(std::sin(theta)) + R"(" y=")" +
                      std::to_string(-std::cos(theta)) + R"(" z="0"/>
            <rgb name="irradiance" value="2"/>
        </emitter>
        <shape type="rectangle">
            <transform name="to_world"><scale value="10"/><rotate x="1" angle="-90"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
        </shape>
    </scene>)";
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml));
    Properties ip("path");
    ip.set_int("max_depth", 2);
    auto integrator =
        PluginRegistry::instance().create_as<SamplingIntegrator>(ObjectType::Integrator, ip);
    auto sampler = PluginRegistry::instance()
                       .create_as<Sampler>(ObjectType::Sampler, Properties("independent"))
                       ->clone();
    sampler->seed(1);
    Color3f L =
        integrator->sample(*scene, *sampler, Ray(Point3f(0, 1, 0), Vector3f(0, -1, 0)), nullptr);
    const float expected = 0.5f / Pi * 2.f * std::cos(theta);
    EXPECT_NEAR(L.r, expected, 1e-4f);
    EXPECT_NEAR(L.g, expected, 1e-4f);
}
