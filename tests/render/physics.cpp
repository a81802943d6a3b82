// Light transport against known answers: the white furnace, a diffuse plane under a point light,
// and path tracing against direct illumination where both must agree.

#include <facet/integrator.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/render.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

using namespace facet;

namespace {

std::shared_ptr<Scene> load_scene_string(const std::string &xml,
                                         const std::map<std::string, std::string> &params = {}) {
    LoadOptions opts;
    opts.params = params;
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml, opts));
    if (!scene) throw std::runtime_error("not a scene");
    return scene;
}

std::unique_ptr<Sampler> make_sampler() {
    auto proto = PluginRegistry::instance().create_as<Sampler>(ObjectType::Sampler,
                                                               Properties("independent"));
    return proto->clone();
}

std::shared_ptr<SamplingIntegrator>
make_integrator(const std::string &type, const std::vector<std::pair<std::string, int>> &ints = {},
                bool hide_emitters = false) {
    Properties props(type);
    for (const auto &[name, value] : ints) props.set_int(name, value);
    if (hide_emitters) props.set_bool("hide_emitters", true);
    return std::dynamic_pointer_cast<SamplingIntegrator>(
        PluginRegistry::instance().create(ObjectType::Integrator, props));
}

/// Camera-less furnace scene: spheres of reflectance 1 inside constant environments.
std::string furnace_xml(const std::string &integrator, const std::string &emitters,
                        const std::string &shapes, int spp, int size = 64) {
    return R"(<scene version="3.0.0">
    )" + integrator +
           R"(
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world">
            <lookat origin="0, 0, 7" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value=")" +
           std::to_string(spp) + R"("/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value=")" +
           std::to_string(size) + R"("/>
            <integer name="height" value=")" +
           std::to_string(size) + R"("/>
            <rfilter type="box"/>
        </film>
    </sensor>
    )" + emitters +
           shapes + R"(
</scene>)";
}

const char *WHITE_SPHERES = R"(
    <bsdf type="diffuse" id="white">
        <rgb name="reflectance" value="1, 1, 1"/>
    </bsdf>
    <shape type="sphere">
        <point name="center" x="-1.02" y="-0.3" z="0"/>
        <float name="radius" value="1"/>
        <ref id="white"/>
    </shape>
    <shape type="sphere">
        <point name="center" x="1.02" y="-0.3" z="0"/>
        <float name="radius" value="1"/>
        <ref id="white"/>
    </shape>
    <shape type="sphere">
        <point name="center" x="0" y="1.1" z="-0.6"/>
        <float name="radius" value="0.9"/>
        <ref id="white"/>
    </shape>
)";

struct PixelEstimates {
    std::vector<double> mean, var; ///< per pixel and channel: mean and variance of the mean
};

/// Ray for one sample through pixel (x, y) of a res × res grid.
using RayGenerator = std::function<Ray(int x, int y, int res, Sampler &sampler)>;

/// Radiance through every pixel of a res × res grid, `spp` samples each, with the variance of
/// each pixel's mean.
PixelEstimates estimate(const Scene &scene, const SamplingIntegrator &integrator,
                        const RayGenerator &generate, int res, int spp, uint64_t seed) {
    PixelEstimates e;
    e.mean.assign(size_t(res) * res * 3, 0.0);
    e.var.assign(size_t(res) * res * 3, 0.0);
    auto sampler = make_sampler();
    for (int y = 0; y < res; ++y)
        for (int x = 0; x < res; ++x) {
            size_t pixel = size_t(y) * res + x;
            sampler->seed(seed * 1000003u + pixel);
            double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
            for (int s = 0; s < spp; ++s) {
                Ray ray = generate(x, y, res, *sampler);
                Color3f L = integrator.sample(scene, *sampler, ray, nullptr);
                sampler->advance();
                for (int c = 0; c < 3; ++c) {
                    sum[c] += L[c];
                    sum2[c] += double(L[c]) * L[c];
                }
            }
            for (int c = 0; c < 3; ++c) {
                double m = sum[c] / spp;
                e.mean[pixel * 3 + c] = m;
                e.var[pixel * 3 + c] = std::max(0.0, sum2[c] / spp - m * m) / (spp - 1);
            }
        }
    return e;
}

RenderResult render_scene(const Scene &scene, uint64_t seed = 0) {
    RenderOptions opts;
    opts.progress = false;
    opts.seed = seed;
    return render(scene, *scene.sensors().at(0), opts);
}

/// Rays of the scene's camera, jittered over each pixel of a res × res film.
RayGenerator camera_rays(const Sensor &sensor) {
    return [&sensor](int x, int y, int res, Sampler &sampler) {
        Point2f u = sampler.next_2d();
        Point2f pos((x + u.x) / res, (y + u.y) / res);
        return sensor.sample_ray(0.f, pos, Point2f(0.5f, 0.5f)).first;
    };
}

/// Every pixel's estimate agrees with `expected` within `max_z` standard errors (pixels without
/// variance, background only, exactly), and so does the mean over all pixels.
void expect_pixels_near(const PixelEstimates &e, double expected, double max_z) {
    double worst = 0, sum = 0, var_sum = 0;
    size_t worst_index = 0, noisy = 0, exact_mismatches = 0, first_mismatch = 0;
    for (size_t i = 0; i < e.mean.size(); ++i) {
        sum += e.mean[i];
        var_sum += e.var[i];
        if (e.var[i] == 0) {
            if (!(std::abs(e.mean[i] - expected) <= 1e-6) && exact_mismatches++ == 0)
                first_mismatch = i;
            continue;
        }
        ++noisy;
        double z = std::abs(e.mean[i] - expected) / std::sqrt(e.var[i]);
        if (z > worst) {
            worst = z;
            worst_index = i;
        }
    }
    EXPECT_EQ(exact_mismatches, 0u)
        << "pixels without noise that are not " << expected << ", the first: pixel "
        << first_mismatch / 3 << " = " << e.mean[first_mismatch];
    EXPECT_GT(noisy, e.mean.size() / 5);
    EXPECT_LT(worst, max_z) << "pixel " << worst_index / 3 << ": " << e.mean[worst_index] << " ± "
                            << std::sqrt(e.var[worst_index]);
    // The channels of a white furnace are identical, so their variances add up as one.
    double n = double(e.mean.size());
    EXPECT_NEAR(sum / n, expected, 4.0 * std::sqrt(3.0 * var_sum) / n) << "mean over all pixels";
}

/// The white furnace: every pixel, sphere or background, must be 1. The image the render loop
/// makes has to average 1; the per-pixel test uses the same camera with a variance per pixel.
void check_furnace(const Scene &scene, int res, int spp) {
    RenderResult r = render_scene(scene);
    const Image &img = r.image;
    ASSERT_GE(img.channels, 3);
    double sum = 0;
    bool finite = true;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < 3; ++c) {
                sum += img.at(x, y, c);
                finite = finite && std::isfinite(img.at(x, y, c));
            }
    EXPECT_TRUE(finite);
    EXPECT_NEAR(sum / (3.0 * img.width * img.height), 1.0, 2e-3) << "rendered image mean";

    auto integrator = std::dynamic_pointer_cast<SamplingIntegrator>(scene.integrator());
    ASSERT_TRUE(integrator);
    PixelEstimates e =
        estimate(scene, *integrator, camera_rays(*scene.sensors().at(0)), res, spp, 7);
    // res² · 3 z-scores (of which a third are independent): 5.5 σ keeps false alarms rare.
    expect_pixels_near(e, 1.0, 5.5);
}

} // namespace

// ---- white furnace --------------------------------------------------------------------------

TEST(Furnace, PathInterreflectingSpheres) {
    // Russian roulette from the first bounce on, so that it matters on every path.
    auto scene = load_scene_string(furnace_xml(
        R"(<integrator type="path">
               <integer name="max_depth" value="-1"/>
               <integer name="rr_depth" value="1"/>
           </integrator>)",
        R"(<emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>)",
        WHITE_SPHERES, 64));
    check_furnace(*scene, 32, 64);
}

TEST(Furnace, PathTwoEnvironments) {
    // Two environment emitters: emitter sampling picks one of them, so MIS has to weigh each
    // escaped ray against each emitter's own density.
    auto scene = load_scene_string(furnace_xml(
        R"(<integrator type="path"/>)",
        R"(<emitter type="constant"><rgb name="radiance" value="0.25, 0.25, 0.25"/></emitter>
           <emitter type="constant"><rgb name="radiance" value="0.75, 0.75, 0.75"/></emitter>)",
        WHITE_SPHERES, 64));
    check_furnace(*scene, 32, 64);
}

TEST(Furnace, PathDeltaAndDiffuse) {
    // A glass sphere (radiance scaled by 1/η² inside and back on the way out) and an ideal mirror
    // among white diffuse spheres: everything is lossless, so every pixel is still 1. Emitters
    // reached after a delta bounce must count in full, and only those. No Russian roulette here:
    // behind glass the estimate would be 0 or 1/q, a distribution whose variance 64 samples
    // cannot estimate for the per-pixel test (PathInterreflectingSpheres covers roulette).
    const std::string shapes = std::string(WHITE_SPHERES) + R"(
    <shape type="sphere">
        <point name="center" x="-1.4" y="1.3" z="1"/>
        <float name="radius" value="0.6"/>
        <bsdf type="dielectric"/>
    </shape>
    <shape type="sphere">
        <point name="center" x="1.4" y="1.3" z="1"/>
        <float name="radius" value="0.6"/>
        <bsdf type="conductor"/>
    </shape>)";
    auto scene = load_scene_string(furnace_xml(
        R"(<integrator type="path"><integer name="rr_depth" value="1000"/></integrator>)",
        R"(<emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>)", shapes,
        64));
    check_furnace(*scene, 32, 64);
}

TEST(Furnace, DirectSingleSphere) {
    // Light reflected once off a convex body escapes: direct illumination is the whole answer.
    const char *sphere = R"(
    <shape type="sphere">
        <float name="radius" value="1.5"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="1, 1, 1"/></bsdf>
    </shape>)";
    for (const char *integrator :
         {R"(<integrator type="direct"/>)",
          R"(<integrator type="direct"><integer name="emitter_samples" value="3"/></integrator>)",
          R"(<integrator type="path"><integer name="max_depth" value="2"/></integrator>)"}) {
        auto scene = load_scene_string(furnace_xml(
            integrator,
            R"(<emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>)", sphere,
            32));
        SCOPED_TRACE(integrator);
        check_furnace(*scene, 32, 32);
    }
}

// ---- point light over a diffuse plane ----------------------------------------------------------

TEST(PointLight, DiffusePlaneRadiance) {
    // Radiance leaving a diffuse plane lit by a point light of intensity I at height h:
    // L = ρ/π · I cos θ / d² = ρ/π · I cos³θ / h². Emitter sampling of a single point light is
    // exact, so both integrators must agree with it to float precision.
    const float rho[3] = {0.2f, 0.5f, 0.8f}, intensity = 10.f, h = 2.f;
    auto scene = load_scene_string(R"(<scene version="3.0.0">
    <emitter type="point">
        <point name="position" x="0" y="0" z="2"/>
        <rgb name="intensity" value="10, 10, 10"/>
    </emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="20"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.5, 0.8"/></bsdf>
    </shape>
</scene>)");
    auto sampler = make_sampler();
    for (const auto &integrator :
         {make_integrator("path"), make_integrator("path", {{"max_depth", 2}}),
          make_integrator("direct"), make_integrator("direct", {{"emitter_samples", 4}})}) {
        ASSERT_TRUE(integrator);
        SCOPED_TRACE(integrator->to_string());
        for (float x : {0.f, 0.5f, 1.f, 2.f, 3.5f, 6.f}) {
            Ray ray(Point3f(x, 0.3f * x, 5.f), Vector3f(0.f, 0.f, -1.f));
            float cos_theta = h / std::sqrt(sqr(x) + sqr(0.3f * x) + sqr(h));
            sampler->seed(uint64_t(x * 100));
            Color3f L = integrator->sample(*scene, *sampler, ray, nullptr);
            for (int c = 0; c < 3; ++c) {
                float expected = rho[c] * InvPi * intensity * std::pow(cos_theta, 3.f) / sqr(h);
                EXPECT_NEAR(L[c], expected, 1e-4f * expected) << "x = " << x << ", channel " << c;
            }
        }
        // The light cannot be seen and the plane's back side is black.
        sampler->seed(1);
        EXPECT_TRUE(integrator
                        ->sample(*scene, *sampler,
                                 Ray(Point3f(0.f, 0.f, 5.f), Vector3f(0.f, 0.f, 1.f)), nullptr)
                        .is_black());
        EXPECT_TRUE(integrator
                        ->sample(*scene, *sampler,
                                 Ray(Point3f(0.f, 0.f, -5.f), Vector3f(0.f, 0.f, 1.f)), nullptr)
                        .is_black());
    }
}

TEST(PointLight, RenderedPlaneRadiance) {
    // The same through the whole render loop: a camera looking straight down at the plane; the
    // centre pixel sees the point below the light.
    auto scene = load_scene_string(R"(<scene version="3.0.0">
    <integrator type="path"/>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world">
            <lookat origin="0, 0, 10" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="33"/>
            <integer name="height" value="33"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="point">
        <point name="position" x="0" y="0" z="1"/>
        <rgb name="intensity" value="5, 5, 5"/>
    </emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="20"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5, 0.5, 0.5"/></bsdf>
    </shape>
</scene>)");
    RenderResult r = render_scene(*scene);
    const Image &img = r.image;
    ASSERT_EQ(img.width, 33);
    // The centre pixel spans about ±0.08 around the axis; the radiance there is within 3% of
    // the on-axis value ρ/π · I/h² and slightly below it.
    float expected = 0.5f * InvPi * 5.f;
    float centre = img.at(16, 16, 1);
    EXPECT_LT(centre, expected);
    EXPECT_GT(centre, 0.97f * expected);
    // Symmetry: mirrored pixels agree, and radiance falls off away from the centre.
    EXPECT_NEAR(img.at(4, 16, 0), img.at(28, 16, 0), 3e-2f * img.at(4, 16, 0));
    EXPECT_NEAR(img.at(16, 4, 0), img.at(16, 28, 0), 3e-2f * img.at(16, 4, 0));
    EXPECT_LT(img.at(4, 16, 0), 0.5f * centre);
}

// ---- path vs direct ------------------------------------------------------------------------

namespace {

// Diffuse floor, wall and sphere lit by a large area light (so that BSDF sampling carries a good
// share of the MIS estimate), a small spherical light and a point light: three emitters, so
// emitter selection matters too.
const char *CORNER_SCENE = R"(<scene version="3.0.0">
    <shape type="rectangle">
        <transform name="to_world"><scale value="4"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.5, 0.3"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="4"/>
            <rotate x="1" angle="90"/>
            <translate y="2" z="2"/>
        </transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.4, 0.6, 0.5"/></bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="0.5" y="0" z="0.8"/>
        <float name="radius" value="0.8"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.3, 0.4, 0.9"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="1.5"/>
            <rotate x="1" angle="180"/>
            <translate x="0" y="0.5" z="2.2"/>
        </transform>
        <emitter type="area"><rgb name="radiance" value="3, 2.5, 2"/></emitter>
    </shape>
    <shape type="sphere">
        <point name="center" x="-1.6" y="-0.5" z="0.5"/>
        <float name="radius" value="0.3"/>
        <emitter type="area"><rgb name="radiance" value="6, 5, 4"/></emitter>
    </shape>
    <emitter type="point">
        <point name="position" x="2" y="-1" z="1.5"/>
        <rgb name="intensity" value="3, 3, 3"/>
    </emitter>
</scene>)";

void compare(const PixelEstimates &a, const PixelEstimates &b, double max_z) {
    double sum_a = 0, sum_b = 0, var_sum = 0, worst = 0;
    size_t worst_index = 0, lit = 0;
    for (size_t i = 0; i < a.mean.size(); ++i) {
        sum_a += a.mean[i];
        sum_b += b.mean[i];
        double var = a.var[i] + b.var[i];
        var_sum += var;
        if (a.mean[i] > 0 || b.mean[i] > 0) ++lit;
        double diff = std::abs(a.mean[i] - b.mean[i]);
        if (var == 0) {
            EXPECT_NEAR(a.mean[i], b.mean[i], 1e-5 * std::max(1.0, a.mean[i])) << "pixel " << i / 3;
            continue;
        }
        double z = diff / std::sqrt(var);
        if (z > worst) {
            worst = z;
            worst_index = i;
        }
    }
    EXPECT_GT(lit, a.mean.size() / 2);
    EXPECT_LT(worst, max_z) << "pixel " << worst_index / 3 << " channel " << worst_index % 3 << ": "
                            << a.mean[worst_index] << " vs " << b.mean[worst_index];
    double z_mean = std::abs(sum_a - sum_b) / std::sqrt(var_sum);
    EXPECT_LT(z_mean, 4.0) << "image means " << sum_a / a.mean.size() << " vs "
                           << sum_b / b.mean.size();
}

} // namespace

TEST(PathVsDirect, DirectIllumination) {
    auto scene = load_scene_string(CORNER_SCENE);
    const int res = 24, spp = 128;
    auto path = make_integrator("path", {{"max_depth", 2}});
    auto direct = make_integrator("direct");
    auto direct_more = make_integrator("direct", {{"emitter_samples", 2}, {"bsdf_samples", 3}});
    // A fixed ray per pixel from a pinhole looking along +y.
    RayGenerator rays = [](int x, int y, int res, Sampler &) {
        Vector3f d(-1.4f + 2.8f * (x + 0.5f) / res, 6.f, 0.9f - 2.7f * (y + 0.5f) / res);
        return Ray(Point3f(0.5f, -6.f, 1.2f), normalize(d));
    };
    PixelEstimates p = estimate(*scene, *path, rays, res, spp, 1);
    PixelEstimates d = estimate(*scene, *direct, rays, res, spp, 2);
    PixelEstimates d2 = estimate(*scene, *direct_more, rays, res, spp / 2, 3);
    // 24·24·3 z-scores per comparison: 5.5 σ keeps the family-wise false alarm rate low.
    compare(p, d, 5.5);
    compare(d, d2, 5.5);
}

TEST(PathVsDirect, CoatedSurfacesSeeLightsAndSky) {
    // The path tracer counts what a delta lobe beside a smooth one (a plastic's coat) sees in
    // every sample, and not again when the path follows the lobe; the direct integrator's BSDF
    // samples find the same light through the coat only when they pick it. A plastic floor and
    // a plastic sphere (one twosided) mirror an area light, a spherical light and a constant
    // sky: at depth 2 both integrators must agree.
    auto scene = load_scene_string(R"(<scene version="3.0.0">
    <emitter type="constant"><rgb name="radiance" value="0.3, 0.5, 0.8"/></emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="4"/></transform>
        <bsdf type="plastic">
            <rgb name="diffuse_reflectance" value="0.5, 0.3, 0.1"/>
            <float name="int_ior" value="1.7"/>
        </bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="0.8" y="0.6" z="0.6"/>
        <float name="radius" value="0.6"/>
        <bsdf type="twosided"><bsdf type="plastic">
            <rgb name="diffuse_reflectance" value="0.2, 0.6, 0.4"/>
        </bsdf></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="0.8"/>
            <rotate x="1" angle="120"/>
            <translate y="2.5" z="2"/>
        </transform>
        <emitter type="area"><rgb name="radiance" value="4, 3, 2"/></emitter>
    </shape>
    <shape type="sphere">
        <point name="center" x="-1.2" y="1.5" z="1.2"/>
        <float name="radius" value="0.25"/>
        <emitter type="area"><rgb name="radiance" value="8, 6, 5"/></emitter>
    </shape>
</scene>)");
    const int res = 24, spp = 128;
    auto path = make_integrator("path", {{"max_depth", 2}});
    auto direct = make_integrator("direct", {{"emitter_samples", 2}, {"bsdf_samples", 2}});
    // A pinhole above the floor, looking along +y and down at it.
    RayGenerator rays = [](int x, int y, int res, Sampler &) {
        Vector3f d(-1.6f + 3.2f * (x + 0.5f) / res, 4.f, -0.4f - 1.8f * (y + 0.5f) / res);
        return Ray(Point3f(0.f, -3.5f, 1.8f), normalize(d));
    };
    PixelEstimates p = estimate(*scene, *path, rays, res, spp, 4);
    PixelEstimates d = estimate(*scene, *direct, rays, res, spp / 2, 5);
    compare(p, d, 5.5);
}

TEST(PathDeltaLobes, CoatReflectionIsInEverySample) {
    // A plastic whose base is black where the rays land (checks of black and white, so that
    // the plastic still samples its base about half the time) under a constant sky: all it
    // returns is the coat's Fresnel reflectance times the sky, and the path tracer counts that
    // in every sample, whichever lobe the sample follows. Closed form: F from the s- and
    // p-polarised amplitudes at η = 1.5 / 1.000277.
    auto scene = load_scene_string(R"(<scene version="3.0.0">
    <emitter type="constant"><rgb name="radiance" value="0.5, 1, 2"/></emitter>
    <shape type="rectangle">
        <bsdf type="plastic">
            <float name="int_ior" value="1.5"/>
            <texture type="checkerboard" name="diffuse_reflectance">
                <rgb name="color0" value="0, 0, 0"/>
                <rgb name="color1" value="1, 1, 1"/>
            </texture>
        </bsdf>
    </shape>
</scene>)");
    const float eta = 1.5f / 1.000277f, sky[3] = {0.5f, 1.f, 2.f};
    auto sampler = make_sampler();
    for (const auto &integrator :
         {make_integrator("path"), make_integrator("path", {{"max_depth", 2}}),
          make_integrator("path", {{"rr_depth", 1}})}) {
        SCOPED_TRACE(integrator->to_string());
        for (float degrees : {0.f, 30.f, 60.f, 80.f}) {
            const float theta = degrees * Pi / 180.f;
            const float cos_i = std::cos(theta), sin_i = std::sin(theta);
            const float cos_t = std::sqrt(1.f - sqr(sin_i / eta));
            const float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
            const float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
            const float F = 0.5f * (rs * rs + rp * rp);
            // Aimed at (0.5, 0.5) and (-0.5, -0.5): checks where u and v agree (black).
            for (float at : {0.5f, -0.5f}) {
                const Vector3f towards(sin_i, 0.f, cos_i);
                const Ray ray(Point3f(at, at, 0.f) + towards * 3.f, -towards);
                sampler->seed(uint64_t(degrees * 10 + at * 4 + 8));
                for (int s = 0; s < 64; ++s) {
                    const Color3f L = integrator->sample(*scene, *sampler, ray, nullptr);
                    sampler->advance();
                    for (int c = 0; c < 3; ++c)
                        ASSERT_NEAR(L[c], F * sky[c], 1e-5f * sky[c])
                            << degrees << " degrees, at " << at << ", sample " << s;
                }
            }
        }
    }
}

TEST(PathVsDirect, DepthOneAndHiddenEmitters) {
    auto scene = load_scene_string(CORNER_SCENE);
    auto sampler = make_sampler();
    sampler->seed(4);
    // Straight at the area light from below: its radiance, and nothing else at depth 1.
    Ray up(Point3f(-0.5f, 0.5f, 0.5f), Vector3f(0.f, 0.f, 1.f));
    Ray floor(Point3f(-1.f, -1.f, 2.f), Vector3f(0.f, 0.f, -1.f));
    for (const char *type : {"path", "direct"}) {
        // The emitter's own surface reflects light too: same samples, with and without emission.
        auto emitted = make_integrator(type, {});
        sampler->seed(4);
        Color3f L = emitted->sample(*scene, *sampler, up, nullptr);
        EXPECT_GE(L.r, 3.f) << type;
        auto hidden = make_integrator(type, {}, true);
        sampler->seed(4);
        Color3f Lh = hidden->sample(*scene, *sampler, up, nullptr);
        EXPECT_NEAR(Lh.r, L.r - 3.f, 1e-5f) << type;
    }
    auto depth1 = make_integrator("path", {{"max_depth", 1}});
    Color3f L = depth1->sample(*scene, *sampler, up, nullptr);
    EXPECT_NEAR(L.r, 3.f, 1e-5f);
    EXPECT_NEAR(L.g, 2.5f, 1e-5f);
    EXPECT_TRUE(depth1->sample(*scene, *sampler, floor, nullptr).is_black());
    auto depth0 = make_integrator("path", {{"max_depth", 0}});
    EXPECT_TRUE(depth0->sample(*scene, *sampler, up, nullptr).is_black());
}

TEST(PathVsDirect, HiddenEnvironment) {
    auto scene = load_scene_string(R"(<scene version="3.0.0">
    <emitter type="constant"><rgb name="radiance" value="0.5, 1, 2"/></emitter>
    <shape type="sphere"><float name="radius" value="1"/></shape>
</scene>)");
    auto sampler = make_sampler();
    sampler->seed(5);
    Ray miss(Point3f(0.f, 0.f, 5.f), Vector3f(0.f, 0.f, 1.f));
    for (const char *type : {"path", "direct"}) {
        Color3f L = make_integrator(type)->sample(*scene, *sampler, miss, nullptr);
        EXPECT_NEAR(L.r, 0.5f, 1e-6f);
        EXPECT_NEAR(L.b, 2.f, 1e-6f);
        EXPECT_TRUE(
            make_integrator(type, {}, true)->sample(*scene, *sampler, miss, nullptr).is_black());
    }
}

TEST(Integrators, RejectBadParameters) {
    EXPECT_THROW(make_integrator("path", {{"max_depth", -2}}), Error);
    EXPECT_THROW(make_integrator("path", {{"rr_depth", 0}}), Error);
    EXPECT_THROW(make_integrator("direct", {{"emitter_samples", 0}, {"bsdf_samples", 0}}), Error);
    EXPECT_THROW(make_integrator("direct", {{"bsdf_samples", -1}}), Error);
}
