// The spot light: falloff between beam_width and cutoff_angle, the inverse-square law towards a
// reference point, and a chi-square test of its emission sampling (directions inside the cone).

#include <facet/chi2.h>
#include <facet/emitter.h>
#include <facet/plugin.h>

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

/// Emission directions of a spot, seen by the chi-square test.
class SpotEmissionAdapter final : public Chi2Adapter {
public:
    explicit SpotEmissionAdapter(std::shared_ptr<Emitter> e) : m_emitter(std::move(e)) {}
    int sample_dim() const override { return 2; }
    Chi2Sample sample(const float *u) const override {
        auto [ray, weight] = m_emitter->sample_ray(Point2f(0.5f, 0.5f), Point2f(u[0], u[1]));
        Chi2Sample s;
        s.kind = weight.is_black() ? Chi2Sample::Kind::Failed : Chi2Sample::Kind::Smooth;
        s.d = ray.d;
        s.pdf = m_emitter->pdf_ray_direction(ray.d);
        s.has_weight = true;
        s.weight = weight;
        return s;
    }
    double pdf(const Vector3f &d) const override { return m_emitter->pdf_ray_direction(d); }
    std::string to_string() const override { return m_emitter->to_string(); }

private:
    std::shared_ptr<Emitter> m_emitter;
};

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

TEST(Spot, InvalidAnglesAreRefused) {
    EXPECT_THROW(make_spot(95.f, 10.f), std::exception);
    EXPECT_THROW(make_spot(20.f, 25.f), std::exception);
}

TEST(SpotChi2, EmissionDirections) {
    for (float cutoff : {10.f, 45.f, 80.f}) {
        auto spot = make_spot(cutoff, 0.5f * cutoff, Transform::rotate(Vector3f(1, 1, 0), 50.f));
        SpotEmissionAdapter adapter(spot);
        Chi2Options opts;
        opts.samples = 300000;
        opts.test_count = 3;
        Chi2Result r = run_chi2(adapter, opts);
        EXPECT_TRUE(r.passed) << r.summary();
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-2) << r.summary();
    }
}
