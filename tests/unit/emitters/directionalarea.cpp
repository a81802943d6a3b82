// The directionalarea emitter: rays leave uniformly distributed points of the shape along its
// normal and carry radiance x area (the emitted power); cameras and emitter sampling never see it.

#include "draws.h"

#include <facet/emitter.h>
#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/shape.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;

namespace {

std::shared_ptr<Emitter> make_emitter(const Color3f &radiance) {
    Properties props("directionalarea");
    props.set_color("radiance", radiance);
    return PluginRegistry::instance().create_as<Emitter>(ObjectType::Emitter, props);
}

std::shared_ptr<Shape> make_shape(Properties props, std::shared_ptr<Emitter> emitter) {
    props.set_object("emitter", emitter);
    return PluginRegistry::instance().create_as<Shape>(ObjectType::Shape, props);
}

} // namespace

TEST(DirectionalArea, FlagsAndInvisibility) {
    auto e = make_emitter(Color3f(1.f));
    auto shape = make_shape(Properties("rectangle"), e);
    EXPECT_TRUE(has_flag(e->flags(), EmitterFlags::Surface));
    EXPECT_TRUE(has_flag(e->flags(), EmitterFlags::DeltaDirection));
    EXPECT_TRUE(e->is_delta());
    Interaction ref;
    ref.p = Point3f(0.f, 0.f, 2.f);
    ref.t = 0.f;
    auto [ds, weight] = e->sample_direction(ref, Point2f(0.5f));
    EXPECT_TRUE(weight.is_black());
    EXPECT_EQ(e->pdf_direction(ref, ds), 0.f);
    SurfaceInteraction si;
    si.wi = Vector3f(0.f, 0.f, 1.f);
    EXPECT_TRUE(e->eval(si).is_black());
}

TEST(DirectionalArea, SampleRayIsUniformAlongTheNormalWithThePower) {
    // A 3 x 1 rectangle (scaled 1.5 x 0.5) rotated about x: normal (0, -sin, cos).
    auto e = make_emitter(Color3f(3.f, 2.5f, 2.f));
    Properties rect("rectangle");
    const Transform xf = Transform::translate(Vector3f(0.f, 2.f, 0.f)) *
                         Transform::rotate(Vector3f(1.f, 0.f, 0.f), 30.f) *
                         Transform::scale(Vector3f(1.5f, 0.5f, 1.f));
    rect.set_transform("to_world", xf);
    auto shape = make_shape(rect, e);
    const Vector3f normal = normalize(xf.apply_vector(Vector3f(0.f, 0.f, 1.f))); // rigid part only
    const Transform inv = xf.inverse();
    PCG32 rng(21);
    const int n = 64000, bins = 8;
    std::vector<int> hist(size_t(bins * bins), 0);
    for (int i = 0; i < n; ++i) {
        const Point2f u_pos = next_point2f(rng);
        auto [ray, weight] = e->sample_ray(u_pos, next_point2f(rng), Wavelengths());
        // Power: radiance x area (3 x 1) for every ray.
        EXPECT_NEAR(weight.r, 9.f, 1e-4f);
        EXPECT_NEAR(weight.b, 6.f, 1e-4f);
        EXPECT_NEAR(dot(ray.d, normal), 1.f, 1e-5f);
        Point3f local = inv.apply_point(ray.o);
        ASSERT_LE(std::abs(local.x), 1.f + 1e-4f);
        ASSERT_LE(std::abs(local.y), 1.f + 1e-4f);
        EXPECT_NEAR(local.z, 0.f, 1e-3f);
        int bx = std::min(bins - 1, int((local.x + 1.f) * 0.5f * bins));
        int by = std::min(bins - 1, int((local.y + 1.f) * 0.5f * bins));
        ++hist[size_t(by * bins + bx)];
    }
    // Uniform over the surface: Pearson's statistic of the 64 cells against 1000 each stays
    // below the 99.9 % quantile of chi² with 63 degrees of freedom (103.4).
    const double expected = double(n) / (bins * bins);
    double chi2 = 0.0;
    for (int c : hist) chi2 += (c - expected) * (c - expected) / expected;
    EXPECT_LT(chi2, 103.4);
}

TEST(DirectionalArea, RefusesToWorld) {
    Properties props("directionalarea");
    props.set_transform("to_world", Transform());
    EXPECT_THROW(PluginRegistry::instance().create(ObjectType::Emitter, props), std::exception);
}
