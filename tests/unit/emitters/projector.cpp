// The projector light: irradiance on facing and tilted planes against the closed form
// E = π·scale·irradiance / z² (z along the axis), the frustum from fov and the texture's aspect,
// the orientation of the projected image, and its emitted rays (weights and a chi-square test).
#include "draws.h"

#include <facet/chi2.h>
#include <facet/emitter.h>
#include <facet/image.h>
#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/spectrum.h>
#include <facet/texture.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

namespace {

std::shared_ptr<Emitter> make_projector(Properties props) {
    props.set_plugin_name("projector");
    return PluginRegistry::instance().create_as<Emitter>(ObjectType::Emitter, props);
}

/// Irradiance the projector delivers at p on a surface with unit normal n.
Color3f irradiance_at(const Emitter &e, const Point3f &p, const Vector3f &n) {
    Interaction ref;
    ref.p = p;
    ref.n = n;
    ref.t = 0.f;
    auto [ds, weight] = e.sample_direction(ref, Point2f(0.5f, 0.5f));
    EXPECT_TRUE(ds.delta);
    return weight * std::max(0.f, dot(n, ds.d));
}

double deg(double d) { return d * M_PI / 180.0; }

} // namespace

TEST(Projector, AnInlineSpectrumIrradianceIsAnEmittersSpectrum) {
    // A <spectrum> given in an emitter is an emission spectrum (no D65, only clamped at 0), the
    // projector's `irradiance` too: it was read as a reflectance (D65-weighted, clamped to 1).
    const SpectrumData s = parse_spectrum_pairs("400:2.5, 500:1.5, 600:0.5, 700:0.2");
    const Color3f emission = spectrum_to_rgb(s, SpectrumKind::Emission);
    ASSERT_GT(std::abs(emission.b - spectrum_to_rgb(s, SpectrumKind::Reflectance).b), 0.1f);
    Properties props;
    props.set("irradiance", s);
    auto proj = make_projector(props);
    // E = π·irradiance on the axis at unit distance.
    const Color3f e = irradiance_at(*proj, Point3f(0.f, 0.f, 1.f), Vector3f(0, 0, -1));
    EXPECT_NEAR(e.r, Pi * emission.r, 1e-4f * Pi * emission.r);
    EXPECT_NEAR(e.g, Pi * emission.g, 1e-4f * Pi * emission.g);
    EXPECT_NEAR(e.b, Pi * emission.b, 1e-4f * Pi * emission.b);
}

TEST(Projector, FacingPlaneIsLitEvenlyByTheClosedForm) {
    Properties props;
    props.set_color("irradiance", Color3f(0.3f, 0.6f, 1.f));
    props.set_float("scale", 2.0);
    props.set_float("fov", 40.0);
    auto proj = make_projector(props);
    EXPECT_TRUE(proj->is_delta());
    const float tan_half = float(std::tan(deg(20.0)));
    for (float z : {1.f, 2.5f}) {
        // E = π·scale·irradiance / z² anywhere on the plane inside the (square) frustum.
        const Color3f expected = Color3f(0.3f, 0.6f, 1.f) * (Pi * 2.f / (z * z));
        for (auto xy : {Point2f(0.f, 0.f), Point2f(0.3f, -0.2f), Point2f(-0.9f, 0.95f)}) {
            const Point3f p(xy.x * z * tan_half, xy.y * z * tan_half, z);
            Color3f e = irradiance_at(*proj, p, Vector3f(0, 0, -1));
            EXPECT_NEAR(e.r, expected.r, 1e-4f * expected.r) << z << " " << xy.x;
            EXPECT_NEAR(e.b, expected.b, 1e-4f * expected.b);
        }
        // Beyond the edge of the frustum, and behind the projector: dark.
        EXPECT_TRUE(irradiance_at(*proj, Point3f(1.02f * z * tan_half, 0.f, z), Vector3f(0, 0, -1))
                        .is_black());
        EXPECT_TRUE(irradiance_at(*proj, Point3f(0.f, 1.02f * z * tan_half, z), Vector3f(0, 0, -1))
                        .is_black());
    }
    EXPECT_TRUE(irradiance_at(*proj, Point3f(0.f, 0.f, -1.f), Vector3f(0, 0, 1)).is_black());
}

TEST(Projector, TiltedPlaneAndToWorld) {
    // A projector at (1, 2, 3) looking along -x; a plane tilted 50° about y through the axis.
    Properties props;
    props.set_float("fov", 60.0);
    props.set_transform("to_world",
                        Transform::look_at(Point3f(1, 2, 3), Point3f(-5, 2, 3), Vector3f(0, 1, 0)));
    auto proj = make_projector(props);
    const Vector3f n =
        normalize(Vector3f(std::cos(float(deg(50.0))), 0.f, std::sin(float(deg(50.0)))));
    PCG32 rng(3);
    for (int i = 0; i < 20; ++i) {
        // Points of the plane x = -1 + (tilted) around the axis point (-1, 2, 3).
        const Vector3f t1 = Vector3f(0, 1, 0), t2 = cross(n, t1);
        const float a = rng.next_float() - 0.5f;
        const float b = rng.next_float() - 0.5f;
        const Point3f p = Point3f(-1, 2, 3) + t1 * a + t2 * b;
        const float z = 1.f - p.x; // distance along the axis (-x) from the projector
        const Vector3f to_light = normalize(Point3f(1, 2, 3) - p);
        // Irradiance = intensity·cos/dist² with intensity π/cos³θ (θ off the axis).
        const float cos_axis = z / norm(Point3f(1, 2, 3) - p);
        const float dist2 = squared_norm(Point3f(1, 2, 3) - p);
        const float expected =
            Pi / (cos_axis * cos_axis * cos_axis) * std::max(0.f, dot(n, to_light)) / dist2;
        Color3f e = irradiance_at(*proj, p, n);
        EXPECT_NEAR(e.g, expected, 1e-4f * expected) << i;
    }
}

TEST(Projector, ImageOrientationAndAspectFromTheTexture) {
    // A 4x2 image: the left half red, the right half green, the top row bright, the bottom dim.
    const fs::path dir = fs::temp_directory_path() / fmt::format("facet_projector_{}", ::getpid());
    fs::create_directories(dir);
    Image img(4, 2, 3);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x) {
            const float level = y == 0 ? 1.f : 0.25f;
            img.at(x, y, 0) = x < 2 ? level : 0.f;
            img.at(x, y, 1) = x < 2 ? 0.f : level;
            img.at(x, y, 2) = 0.f;
        }
    const std::string path = (dir / "slide.exr").string();
    write_image(path, img);
    Properties tp("bitmap");
    tp.set_string("filename", path);
    tp.set_string("filter_type", "nearest");
    auto tex = PluginRegistry::instance().create_as<Texture>(ObjectType::Texture, tp);
    EXPECT_EQ(tex->resolution(), Point2i(4, 2));

    Properties props;
    props.set_object("irradiance", tex);
    props.set_float("fov", 90.0); // tan(45°) = 1: the image spans x in [-z, z], y in [-z/2, z/2]
    auto proj = make_projector(props);
    const Vector3f n(0, 0, -1);
    const float z = 2.f, k = Pi / (z * z);
    // Local +x is the image's left (as for the camera), +y its top.
    Color3f top_left = irradiance_at(*proj, Point3f(1.5f, 0.5f, z), n);
    Color3f top_right = irradiance_at(*proj, Point3f(-1.5f, 0.5f, z), n);
    Color3f bottom_left = irradiance_at(*proj, Point3f(1.5f, -0.5f, z), n);
    EXPECT_NEAR(top_left.r, k, 1e-4f * k);
    EXPECT_EQ(top_left.g, 0.f);
    EXPECT_NEAR(top_right.g, k, 1e-4f * k);
    EXPECT_NEAR(bottom_left.r, 0.25f * k, 1e-4f * k);
    // The aspect ratio 2 halves the vertical extent.
    EXPECT_FALSE(irradiance_at(*proj, Point3f(0.f, 0.9f, z), n).is_black());
    EXPECT_TRUE(irradiance_at(*proj, Point3f(0.f, 1.1f, z), n).is_black());
    std::error_code ec;
    fs::remove_all(dir, ec);
}

TEST(Projector, EmittedRaysCarryIntensityOverDensity) {
    Properties props;
    props.set_color("irradiance", Color3f(0.5f, 1.f, 2.f));
    props.set_float("scale", 3.0);
    props.set_float("fov", 50.0);
    props.set_transform("to_world",
                        Transform::look_at(Point3f(0, 1, 0), Point3f(0, 1, 5), Vector3f(0, 1, 0)));
    auto proj = make_projector(props);
    PCG32 rng(11);
    for (int i = 0; i < 100; ++i) {
        auto [ray, weight] =
            proj->sample_ray(Point2f(0.5f, 0.5f), next_point2f(rng), Wavelengths());
        ASSERT_FALSE(weight.is_black());
        EXPECT_NEAR(norm(ray.d), 1.f, 1e-5f);
        // Intensity towards ray.d: the sample_direction weight times dist².
        Interaction ref;
        ref.p = ray(2.f);
        const Color3f intensity = proj->sample_direction(ref, Point2f(0.5f)).second * 4.f;
        const float pdf = proj->pdf_ray_direction(ray.d);
        ASSERT_GT(pdf, 0.f);
        EXPECT_NEAR(weight.g, intensity.g / pdf, 1e-3f * weight.g);
    }
    // The chi-square test of these directions: the projector lines of tests/chi2/configs.txt.
}

TEST(Projector, BadParameters) {
    Properties props;
    props.set_float("scale", -1.0);
    EXPECT_THROW(make_projector(props), Error);
    Properties both;
    both.set_float("fov", 30.0);
    both.set_string("focal_length", "50mm");
    EXPECT_THROW(make_projector(both), Error);
}
