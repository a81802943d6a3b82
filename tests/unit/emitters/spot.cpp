// The spot light: falloff between beam_width and cutoff_angle, the inverse-square law towards a
// reference point.

#include <facet/emitter.h>
#include <facet/plugin.h>
#include <facet/spectrum.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;

namespace {

std::shared_ptr<Emitter> make_spot(float cutoff, float beam,
                                   const Transform &to_world = Transform()) {
    Properties props("spot");
    props.set_float("cutoff_angle", cutoff);
    props.set_float("beam_width", beam);
    props.set_color("intensity", Color3f(2.f, 3.f, 4.f));
    props.set_transform("to_world", to_world);
    return PluginRegistry::instance().create_as<Emitter>(ObjectType::Emitter, props);
}

/// Radiant intensity of the spot towards world point p at unit distance (via sample_direction).
Color3f intensity_towards(const Emitter &spot, const Point3f &light_pos, const Vector3f &dir) {
    Interaction ref;
    ref.p = light_pos + normalize(dir);
    return spot.sample_direction(ref, Point2f(0.5f, 0.5f)).second;
}

} // namespace

TEST(Spot, FalloffAndInverseSquare) {
    auto spot = make_spot(30.f, 20.f);
    const Point3f o(0.f);
    // On the axis: full intensity at distance 1, a quarter at distance 2.
    EXPECT_NEAR(intensity_towards(*spot, o, {0, 0, 1}).g, 3.f, 1e-5f);
    Interaction far;
    far.p = Point3f(0, 0, 2);
    EXPECT_NEAR(spot->sample_direction(far, Point2f(0.5f)).second.g, 0.75f, 1e-5f);
    // Inside the beam: full; halfway between beam (20°) and cutoff (30°): half; outside: zero.
    auto at = [&](float deg) {
        float r = deg_to_rad(deg);
        return intensity_towards(*spot, o, {std::sin(r), 0.f, std::cos(r)}).g;
    };
    EXPECT_NEAR(at(15.f), 3.f, 1e-4f);
    EXPECT_NEAR(at(25.f), 1.5f, 1e-3f);
    EXPECT_EQ(at(31.f), 0.f);
    EXPECT_EQ(spot->pdf_direction(far, DirectionSample()), 0.f);
}

TEST(Spot, AnInlineSpectrumTextureIsAnEmittersSpectrum) {
    // A <spectrum> given in an emitter is an emission spectrum (no D65, only clamped at 0), its
    // `texture` too: it was read as a reflectance (D65-weighted, clamped to 1).
    const SpectrumData s = parse_spectrum_pairs("400:2.5, 500:1.5, 600:0.5, 700:0.2");
    const Color3f emission = spectrum_to_rgb(s, SpectrumKind::Emission);
    const Color3f reflectance = spectrum_to_rgb(s, SpectrumKind::Reflectance);
    ASSERT_GT(std::abs(emission.b - reflectance.b), 0.1f) << "the test cannot tell them apart";
    Properties props("spot");
    props.set_color("intensity", Color3f(2.f, 3.f, 4.f));
    props.set("texture", s);
    auto spot = PluginRegistry::instance().create_as<Emitter>(ObjectType::Emitter, props);
    const Color3f on_axis = intensity_towards(*spot, Point3f(0.f), {0, 0, 1});
    EXPECT_NEAR(on_axis.r, 2.f * emission.r, 1e-4f);
    EXPECT_NEAR(on_axis.g, 3.f * emission.g, 1e-4f);
    EXPECT_NEAR(on_axis.b, 4.f * emission.b, 1e-4f);
}

TEST(Spot, InvalidAnglesAreRefused) {
    EXPECT_THROW(make_spot(95.f, 10.f), std::exception);
    EXPECT_THROW(make_spot(20.f, 25.f), std::exception);
}

// Chi-square tests of its emission sampling (directions inside the cone): the spot lines of
// tests/chi2/configs.txt (facet chi2 emitter --emission).
