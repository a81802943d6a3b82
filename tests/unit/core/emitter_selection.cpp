// Which emitter a light sample goes to: by power where the scene says nothing (half by power,
// half uniformly), by `sampling_weight` where it gives them (Mitsuba 3's rule), and the same
// expected image either way, for the path tracer's MIS and for the light tracer.
#include "direction_cone.h" // (core/src: the hierarchy's cone arithmetic)
#include "draws.h"
#include "light_bvh.h" // (core/src: the hierarchy itself, for its choice over a box)

#include <facet/emitter.h>
#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/shape.h>
#include <facet/transform.h>
#include <facet/xml.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace facet;

namespace {

/// A diffuse floor (the square [−4, 4]² at z = 0) lit by a large dim panel (side 2 at z = 3,
/// radiance `dim`), a small bright one (side 0.2 at z = 2, off to the side, radiance
/// `bright`) and a point lamp of intensity 5, each emitter with the extra XML `weights[i]`;
/// seen from above by a 16x16 camera through `integrator` at `spp`.
std::string scene_xml(const std::vector<std::string> &weights, float dim = 1.f,
                      float bright = 400.f, const std::string &integrator = "path", int spp = 16,
                      int seed = 0) {
    return fmt::format(R"(<scene version="3.0.0">
        <integrator type="{}"><integer name="max_depth" value="3"/></integrator>
        <sensor type="perspective">
            <float name="fov" value="60"/>
            <transform name="to_world"><lookat origin="0, -5, 6" target="0, 0, 0" up="0, 0, 1"/></transform>
            <sampler type="independent"><integer name="sample_count" value="{}"/>
                <integer name="seed" value="{}"/></sampler>
            <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>
                <rfilter type="box"/></film>
        </sensor>
        <shape type="rectangle">
            <transform name="to_world"><scale value="4"/></transform>
            <bsdf type="diffuse"/>
        </shape>
        <shape type="rectangle">
            <transform name="to_world"><rotate x="1" angle="180"/><translate z="3"/></transform>
            <emitter type="area"><rgb name="radiance" value="{}"/>{}</emitter>
        </shape>
        <shape type="rectangle">
            <transform name="to_world"><scale value="0.1"/><rotate x="1" angle="180"/><translate x="1.5" z="2"/></transform>
            <emitter type="area"><rgb name="radiance" value="{}"/>{}</emitter>
        </shape>
        <emitter type="point">
            <point name="position" x="-1" y="0.5" z="2.5"/>
            <rgb name="intensity" value="5"/>{}
        </emitter>
    </scene>)",
                       integrator, spp, seed, dim, weights.at(0), bright, weights.at(1),
                       weights.at(2));
}

std::shared_ptr<Scene> load(const std::string &xml) {
    return std::dynamic_pointer_cast<Scene>(load_string(xml, LoadOptions()));
}

std::string weight(float w) {
    return fmt::format(R"(<float name="sampling_weight" value="{}"/>)", w);
}

/// The scene's emitters in the order scene_xml() lists them (the point lamp, a child of the
/// scene, is found by its type).
std::vector<const Emitter *> emitters_of(const Scene &scene) {
    std::vector<const Emitter *> out(3, nullptr);
    for (const auto &emitter : scene.emitters()) {
        if (!emitter->shape())
            out[2] = emitter.get();
        else
            out[emitter->shape()->surface_area() > 1.f ? 0 : 1] = emitter.get();
    }
    return out;
}

double mean(const std::vector<double> &v) {
    double s = 0.0;
    for (double x : v) s += x;
    return s / double(v.size());
}

/// The variance of the mean of the values `v`, estimated from their spread.
double var_of_mean(const std::vector<double> &v) {
    const double m = mean(v);
    double s = 0.0;
    for (double x : v) s += (x - m) * (x - m);
    return s / double(v.size() - 1) / double(v.size());
}

/// The mean of a render's pixels (all three channels).
double render_mean(const Scene &scene) {
    RenderOptions ro;
    ro.progress = false;
    const Image image = render(scene, *scene.sensors().at(0), ro).image;
    double sum = 0.0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 3; ++c) sum += image.at(x, y, c);
    return sum / double(3 * image.width * image.height);
}

} // namespace

TEST(EmitterSelection, HalfByPowerHalfUniformWhereTheSceneSaysNothing) {
    auto scene = load(scene_xml({"", "", ""}));
    const auto e = emitters_of(*scene);
    // Power: π · area · radiance for the panels (areas 4 and 0.04), 4π · intensity for the lamp.
    const double power[3] = {Pi * 4.0 * 1.0, Pi * 0.04 * 400.0, 4.0 * Pi * 5.0};
    const double total = power[0] + power[1] + power[2];
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) {
        const double expected = 0.5 * power[i] / total + 0.5 / 3.0;
        EXPECT_NEAR(scene->emitter_pmf(*e[size_t(i)]), expected, 1e-6) << i;
        sum += scene->emitter_pmf(*e[size_t(i)]);
    }
    EXPECT_NEAR(sum, 1.0, 1e-6);
    // sample_emitter() picks them with those probabilities: the share of a fine even grid of
    // u that goes to each, and u comes back as a fresh variate spread over [0, 1).
    const int n = 300000;
    int count[3] = {0, 0, 0};
    double u_sum = 0.0;
    for (int k = 0; k < n; ++k) {
        float u = (float(k) + 0.5f) / float(n);
        const auto [emitter, pmf] = scene->sample_emitter(u);
        ASSERT_TRUE(u >= 0.f && u < 1.f);
        u_sum += double(u);
        for (int i = 0; i < 3; ++i)
            if (emitter == e[size_t(i)]) {
                ++count[i];
                EXPECT_EQ(pmf, scene->emitter_pmf(*emitter));
            }
    }
    for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(double(count[i]) / n, scene->emitter_pmf(*e[size_t(i)]), 1e-4) << i;
    EXPECT_NEAR(u_sum / n, 0.5, 1e-3);
}

TEST(EmitterSelection, SamplingWeightIsMitsubas) {
    // Given on one emitter: that weight, 1 for the others.
    auto scene = load(scene_xml({weight(3.f), "", ""}));
    auto e = emitters_of(*scene);
    EXPECT_NEAR(scene->emitter_pmf(*e[0]), 0.6f, 1e-6f);
    EXPECT_NEAR(scene->emitter_pmf(*e[1]), 0.2f, 1e-6f);
    EXPECT_NEAR(scene->emitter_pmf(*e[2]), 0.2f, 1e-6f);
    // All 1: uniform, as Mitsuba 3 picks when no weight differs from 1.
    scene = load(scene_xml({weight(1.f), weight(1.f), weight(1.f)}));
    e = emitters_of(*scene);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(scene->emitter_pmf(*e[size_t(i)]), 1.f / 3.f);
    // A weight of 0: never picked, and its density for MIS is 0 (BSDF sampling alone finds it).
    scene = load(scene_xml({"", weight(0.f), ""}));
    e = emitters_of(*scene);
    EXPECT_EQ(scene->emitter_pmf(*e[1]), 0.f);
    for (int k = 0; k < 10000; ++k) {
        float u = (float(k) + 0.5f) / 10000.f;
        EXPECT_NE(scene->sample_emitter(u).first, e[1]);
    }
    DirectionSample ds;
    ds.emitter = e[1];
    ds.p = Point3f(1.5f, 0.f, 2.f);
    ds.n = Normal3f(0.f, 0.f, -1.f);
    ds.d = Vector3f(0.f, 0.f, 1.f);
    ds.dist = 2.f;
    Interaction ref;
    ref.p = Point3f(1.5f, 0.f, 0.f);
    EXPECT_EQ(scene->pdf_emitter_direction(ref, ds, LightSampling::Alone), 0.f);
}

TEST(EmitterSelection, BadSamplingWeightsAreLocatedErrors) {
    auto message = [](const std::string &xml) {
        try {
            load(xml);
        } catch (const Error &error) {
            return std::string(error.what());
        }
        return std::string("no error");
    };
    const std::string xml = scene_xml({"", weight(-1.f), ""});
    std::string m = message(xml);
    EXPECT_NE(m.find("sampling_weight must be a finite number >= 0, got -1"), std::string::npos)
        << m;
    // Located at the <float>'s line.
    const size_t at = xml.find("sampling_weight");
    const long line = 1 + std::count(xml.begin(), xml.begin() + long(at), '\n');
    EXPECT_NE(m.find(fmt::format(":{}:", line)), std::string::npos) << m;
    m = message(scene_xml({"", R"(<float name="sampling_weight" value="1e60"/>)", ""}));
    EXPECT_NE(m.find("\"sampling_weight\" contains an infinite or out-of-range number"),
              std::string::npos)
        << m;
    m = message(scene_xml({weight(0.f), weight(0.f), weight(0.f)}));
    EXPECT_NE(m.find("all have sampling_weight 0"), std::string::npos) << m;
}

TEST(EmitterSelection, TheExpectedImageIsTheSame) {
    // The path tracer (emitter samples and BSDF samples combined by MIS, whose weights need the
    // selection's probability) and the light tracer (which starts its paths at the picked
    // emitter) against the uniform choice, each over four seeds: the image means agree within
    // four standard errors of their difference.
    const std::vector<std::string> uniform = {weight(1.f), weight(1.f), weight(1.f)};
    const std::vector<std::string> skewed = {weight(1.f), weight(8.f), weight(1.f)};
    for (const std::string integrator : {"path", "ptracer"}) {
        for (const auto &choice : {std::vector<std::string>{"", "", ""}, skewed}) {
            std::vector<double> a, b;
            for (int seed = 0; seed < 4; ++seed) {
                a.push_back(
                    render_mean(*load(scene_xml(choice, 1.f, 400.f, integrator, 1024, seed))));
                b.push_back(render_mean(
                    *load(scene_xml(uniform, 1.f, 400.f, integrator, 1024, seed + 10))));
            }
            const double diff = mean(a) - mean(b);
            const double sigma = std::sqrt(var_of_mean(a) + var_of_mean(b));
            EXPECT_LT(std::abs(diff), 4.0 * sigma + 1e-4 * mean(b))
                << integrator << ": " << mean(a) << " vs " << mean(b) << " (σ " << sigma << ")";
            // The noise is small enough for the test to see a wrong weight: under 1 %.
            EXPECT_LT(sigma, 0.01 * mean(b)) << integrator;
        }
    }
}

TEST(EmitterSelection, EmittersAtInfinityKeepTheirUniformShare) {
    // A sky and a sun keep 1/5 each of the light samples, as the uniform choice gives them (their
    // power, the light crossing the scene's bounding sphere, is no measure of what the surfaces
    // receive); the two panels and the lamp share the other 3/5 by the rule.
    std::string xml = scene_xml({"", "", ""});
    const std::string extra =
        R"(<emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
        <emitter type="directional"><vector name="direction" x="0" y="0" z="-1"/></emitter>
        <emitter type="point" id="gone">)";
    xml.replace(xml.find("<emitter type=\"point\">"), 22, extra);
    auto scene = load(xml);
    ASSERT_EQ(scene->emitters().size(), 5u);
    const double power[3] = {Pi * 4.0, Pi * 0.04 * 400.0, 4.0 * Pi * 5.0};
    const double total = power[0] + power[1] + power[2];
    for (const auto &emitter : scene->emitters()) {
        const float pmf = scene->emitter_pmf(*emitter);
        if (emitter->is_infinite()) {
            EXPECT_NEAR(pmf, 0.2f, 1e-6f) << emitter->to_string();
            continue;
        }
        const int i = !emitter->shape() ? 2 : emitter->shape()->surface_area() > 1.f ? 0 : 1;
        EXPECT_NEAR(pmf, 0.6 * (0.5 * power[i] / total + 0.5 / 3.0), 1e-6) << i;
    }
    // A sky and one lamp: the uniform choice, exactly.
    scene = load(R"(<scene version="3.0.0">
        <emitter type="constant"/>
        <emitter type="point"><point name="position" x="0" y="0" z="1"/></emitter>
    </scene>)");
    for (const auto &emitter : scene->emitters()) EXPECT_EQ(scene->emitter_pmf(*emitter), 0.5f);
}

namespace {

/// A corridor: a diffuse floor 24 long at z = 0 under `lamps` small panels facing down along it
/// (radiance 20, side 0.3, height 1.5, every 2 along x; their normals a few roundings apart), with
/// a point lamp, a spot looking down (and another whose cone a stretching transform widens along x)
/// and a glowing ball at the far end, seen from above by a 32x8 camera through `integrator`.
/// `extra`: XML added to every emitter.
std::string corridor_xml(int lamps, const std::string &extra, const std::string &integrator,
                         int spp, int seed) {
    std::string panels;
    for (int i = 0; i < lamps; ++i)
        panels += fmt::format(R"(<shape type="rectangle">
            <transform name="to_world"><scale value="0.15"/><rotate x="1" angle="{:.5f}"/>
                <translate x="{}" z="1.5"/></transform>
            <emitter type="area"><rgb name="radiance" value="20"/>{}</emitter>
        </shape>)",
                              180.0 + 3e-5 * i, -11 + 2 * i, extra);
    return fmt::format(R"(<scene version="3.0.0">
        <integrator type="{}"><integer name="max_depth" value="3"/></integrator>
        <sensor type="orthographic">
            <transform name="to_world"><scale x="12" y="3"/><lookat origin="0, 0, 10" target="0, 0, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="{}"/>
                <integer name="seed" value="{}"/></sampler>
            <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="8"/>
                <rfilter type="box"/></film>
        </sensor>
        <shape type="rectangle">
            <transform name="to_world"><scale x="12" y="3"/></transform>
            <bsdf type="diffuse"/>
        </shape>
        {}
        <emitter type="point"><point name="position" x="3" y="1" z="0.5"/>
            <rgb name="intensity" value="2"/>{}</emitter>
        <emitter type="spot">
            <transform name="to_world"><lookat origin="-6, 0, 3" target="-6, 0, 0" up="0, 1, 0"/></transform>
            <rgb name="intensity" value="30"/>{}</emitter>
        <emitter type="spot">
            <transform name="to_world"><scale x="4"/><lookat origin="8, 0, 2" target="8, 0, 0" up="0, 1, 0"/></transform>
            <rgb name="intensity" value="30"/>{}</emitter>
        <shape type="sphere"><point name="center" x="11" y="-1" z="0.6"/><float name="radius" value="0.3"/>
            <emitter type="area"><rgb name="radiance" value="5"/>{}</emitter>
        </shape>
    </scene>)",
                       integrator, spp, seed, panels, extra, extra, extra, extra);
}

/// Reference points on the floor, on walls that are not there (normals along x and y), and in
/// space (no normal), spread over the corridor.
std::vector<Interaction> reference_points() {
    std::vector<Interaction> points;
    PCG32 rng(3);
    for (int i = 0; i < 400; ++i) {
        Interaction ref;
        const float x = 26.f * rng.next_float() - 13.f, y = 6.f * rng.next_float() - 3.f;
        const float z = 2.f * rng.next_float();
        const int kind = i % 4;
        ref.p = Point3f(x, y, kind == 0 ? 0.f : z);
        ref.n = kind == 0   ? Normal3f(0.f, 0.f, 1.f)
                : kind == 1 ? Normal3f(1.f, 0.f, 0.f)
                : kind == 2 ? Normal3f(0.f, -1.f, 0.f)
                            : Normal3f(0.f);
        ref.t = 1.f;
        points.push_back(ref);
    }
    return points;
}

} // namespace

namespace {

/// sample_emitter() against emitter_pmf() and the lights every point can see, in the corridor
/// of `lamps` lamps.
void expect_hierarchy_agrees_with_its_pmf(int lamps) {
    auto scene = load(corridor_xml(lamps, "", "path", 1, 0));
    ASSERT_EQ(scene->emitters().size(), size_t(lamps) + 4u);
    PCG32 rng(9);
    int unreachable = 0;
    for (const Interaction &ref : reference_points()) {
        // The probabilities of the emitters sum to at most 1: a pick may end in a group whose
        // bounds reach ref but none of whose emitters do, and then picks nothing (all 0:
        // nothing reaches ref).
        double sum = 0.0;
        for (const auto &emitter : scene->emitters()) sum += scene->emitter_pmf(ref, *emitter);
        if (sum == 0.0) ++unreachable;
        EXPECT_LE(sum, 1.0 + 1e-5) << ref.p.x << ", " << ref.p.y << ", " << ref.p.z;
        // sample_emitter() picks them with those probabilities and reports them exactly.
        const int n = 4000;
        std::vector<int> count(scene->emitters().size(), 0);
        int none = 0;
        for (int k = 0; k < n; ++k) {
            float u = (float(k) + 0.5f) / float(n);
            const auto [emitter, pmf] = scene->sample_emitter(ref, u);
            if (!emitter) {
                ++none;
                continue;
            }
            ASSERT_TRUE(u >= 0.f && u < 1.f);
            EXPECT_EQ(pmf, scene->emitter_pmf(ref, *emitter));
            ++count[emitter->scene_index()];
        }
        for (const auto &emitter : scene->emitters())
            EXPECT_NEAR(double(count[emitter->scene_index()]) / n,
                        scene->emitter_pmf(ref, *emitter), 2e-3);
        EXPECT_NEAR(double(none) / n, 1.0 - sum, 2e-3);
        // A light sample's density is what pdf_emitter_direction() gives the same point.
        for (int k = 0; k < 32; ++k) {
            const Point2f u(rng.next_float(), rng.next_float());
            const auto [ds, weight] =
                scene->sample_emitter_direction(ref, u, false, LightSampling::Alone);
            if (!(ds.pdf > 0.f) || ds.delta) continue;
            EXPECT_NEAR(scene->pdf_emitter_direction(ref, ds, LightSampling::Alone), ds.pdf,
                        1e-5f * ds.pdf);
        }
        // An emitter the hierarchy never picks for ref sends it no light: its own samples from
        // ref all have weight 0, or arrive along ref's plane.
        for (const auto &emitter : scene->emitters()) {
            if (scene->emitter_pmf(ref, *emitter) > 0.f) continue;
            for (int k = 0; k < 64; ++k) {
                const Point2f u(rng.next_float(), rng.next_float());
                const auto [ds, weight] = emitter->sample_direction(ref, u);
                const bool in_plane =
                    ref.n != Normal3f(0.f) && std::abs(dot(ds.d, Vector3f(ref.n))) < 1e-3f;
                EXPECT_TRUE(weight.is_black() || in_plane)
                    << emitter->to_string() << " reaches (" << ref.p.x << ", " << ref.p.y << ", "
                    << ref.p.z << ") but is never picked there";
            }
        }
    }
    // Every point sees some light (the point lamp shines everywhere).
    EXPECT_EQ(unreachable, 0);
}

} // namespace

TEST(EmitterSelection, TheLightHierarchyAgreesWithItsPmfAndMissesNoLight) {
    // 9, 16 and 44 emitters: trees of one, two and three levels of four children, with nodes
    // that have two, three and four.
    for (const int lamps : {5, 12, 40}) {
        SCOPED_TRACE(::testing::Message() << lamps << " lamps");
        expect_hierarchy_agrees_with_its_pmf(lamps);
    }
}

TEST(EmitterSelection, TheLightHierarchyKeepsTheImageAndLowersItsNoise) {
    // The corridor by the path tracer (MIS between the hierarchy's choice and BSDF samples) and
    // the light tracer (which picks by power), against the uniform choice (sampling_weight 1):
    // the image means agree within four standard errors of their difference (four seeds each),
    // and the path tracer's pixels are less noisy: each lamp lights the floor under it, and
    // the uniform choice sends 14 of 15 samples to lamps that are far away.
    const std::string uniform = weight(1.f);
    for (const std::string integrator : {"path", "ptracer"}) {
        std::vector<double> a, b;
        double noise_a = 0.0, noise_b = 0.0;
        for (int seed = 0; seed < 4; ++seed) {
            RenderOptions ro;
            ro.progress = false;
            auto scene_a = load(corridor_xml(12, "", integrator, 1024, seed));
            auto scene_b = load(corridor_xml(12, uniform, integrator, 1024, seed + 10));
            const Image ia = render(*scene_a, *scene_a->sensors().at(0), ro).image;
            const Image ib = render(*scene_b, *scene_b->sensors().at(0), ro).image;
            double ma = 0.0, mb = 0.0;
            for (int y = 0; y < ia.height; ++y)
                for (int x = 0; x < ia.width; ++x) {
                    ma += ia.at(x, y, 1);
                    mb += ib.at(x, y, 1);
                }
            a.push_back(ma / double(ia.width * ia.height));
            b.push_back(mb / double(ib.width * ib.height));
            if (seed == 1) {
                // The pixels' spread between two seeds of each choice.
                auto scene_a0 = load(corridor_xml(12, "", integrator, 256, 0));
                auto scene_b0 = load(corridor_xml(12, uniform, integrator, 256, 10));
                const Image ja = render(*scene_a0, *scene_a0->sensors().at(0), ro).image;
                const Image jb = render(*scene_b0, *scene_b0->sensors().at(0), ro).image;
                for (int y = 0; y < ia.height; ++y)
                    for (int x = 0; x < ia.width; ++x) {
                        noise_a += std::pow(double(ia.at(x, y, 1)) - ja.at(x, y, 1), 2.0);
                        noise_b += std::pow(double(ib.at(x, y, 1)) - jb.at(x, y, 1), 2.0);
                    }
            }
        }
        const double diff = mean(a) - mean(b);
        const double sigma = std::sqrt(var_of_mean(a) + var_of_mean(b));
        EXPECT_LT(std::abs(diff), 4.0 * sigma + 1e-4 * mean(b))
            << integrator << ": " << mean(a) << " vs " << mean(b) << " (σ " << sigma << ")";
        EXPECT_LT(sigma, 0.01 * mean(b)) << integrator;
        if (integrator == "path") {
            EXPECT_LT(noise_a, 0.5 * noise_b) << "the hierarchy's pixel variance against the "
                                                 "uniform choice's";
        }
    }
}

TEST(EmitterSelection, TheHierarchysChoiceForABoxKeepsEveryLightItsPointsCanReach) {
    // The light guide's floor: the hierarchy's probabilities for a box as a whole. Boxes from a
    // twentieth of a lamp's spacing to twice it, in and around the corridor of 40 lamps: an
    // emitter the hierarchy picks with some probability for a point of the box (any normal,
    // or none) has a probability for the box, they sum to at most 1, and some emitters are still
    // ruled out (the boxes above the panels, which face down).
    auto scene = load(corridor_xml(40, "", "path", 1, 0));
    std::vector<std::pair<uint32_t, LightBounds>> items;
    for (const auto &emitter : scene->emitters())
        if (auto bounds = emitter->light_bounds())
            items.emplace_back(emitter->scene_index(), *bounds);
    ASSERT_EQ(items.size(), scene->emitters().size());
    detail::LightBVH bvh;
    bvh.build(items);
    PCG32 rng(23);
    size_t reached = 0, ruled_out = 0;
    for (int i = 0; i < 400; ++i) {
        const float side = 0.1f * std::pow(40.f, rng.next_float());
        const Point3f lo(26.f * rng.next_float() - 13.f, 6.f * rng.next_float() - 3.f,
                         3.f * rng.next_float() - 0.5f);
        const Vector3f size(side * (0.5f + rng.next_float()), side * (0.5f + rng.next_float()),
                            side * (0.5f + rng.next_float()));
        const BoundingBox3f box(lo, lo + size);
        std::vector<float> box_pmf;
        bvh.pmf(box, box_pmf);
        ASSERT_EQ(box_pmf.size(), scene->emitters().size());
        double sum = 0.0;
        for (const auto &item : items) {
            EXPECT_GE(box_pmf[item.first], 0.f);
            sum += box_pmf[item.first];
            if (!(box_pmf[item.first] > 0.f)) ++ruled_out;
        }
        // At most 1 (as for a point: a group's bound may reach the box where none of its
        // emitters' does).
        EXPECT_LE(sum, 1.0 + 1e-5) << "box " << i;
        for (int k = 0; k < 64; ++k) {
            const Point3f p(lo.x + size.x * rng.next_float(), lo.y + size.y * rng.next_float(),
                            lo.z + size.z * rng.next_float());
            Normal3f n(0.f);
            if (k % 4 != 0) {
                const Vector3f v = next_vector3f(rng) - Vector3f(0.5f);
                if (norm(v) > 0.05f) n = Normal3f(normalize(v));
            }
            for (const auto &item : items) {
                if (!(bvh.pmf(p, n, item.first) > 0.f)) continue;
                ++reached;
                EXPECT_GT(box_pmf[item.first], 0.f)
                    << "emitter " << item.first << " reaches (" << p.x << ", " << p.y << ", " << p.z
                    << ") of box " << i << " but has no probability for the box";
            }
        }
    }
    EXPECT_GT(reached, 100000u);
    EXPECT_GT(ruled_out, 400u) << "the box bound rules no emitter out";
}

TEST(EmitterSelection, AFlatLightsNormalsMakeANarrowCone) {
    // A rectangle's two triangles have normals a rounding apart, turned any way: their cone
    // stays within the margin around the rectangle's normal (a cone of every direction would
    // keep the hierarchy from ruling out the points behind the light).
    PCG32 rng(17);
    for (int i = 0; i < 200; ++i) {
        Vector3f axis = next_vector3f(rng) - Vector3f(0.5f);
        if (!(norm(axis) > 0.05f)) continue;
        axis = normalize(axis);
        const Transform rotation = Transform::rotate(axis, 360.f * rng.next_float());
        Properties props("rectangle");
        props.set_transform("to_world", rotation * Transform::scale(Vector3f(0.3f, 2.f, 1.f)));
        auto shape = std::dynamic_pointer_cast<Shape>(
            PluginRegistry::instance().create(ObjectType::Shape, props));
        const auto [cone_axis, cos_angle] = shape->normal_cone();
        EXPECT_GT(cos_angle, std::cos(2e-3f)) << i;
        const Vector3f normal = normalize(rotation.apply_vector(Vector3f(0.f, 0.f, 1.f)));
        EXPECT_GT(dot(cone_axis, normal), std::cos(2e-3f)) << i;
    }
}

TEST(EmitterSelection, ConesOfNormalsMergeTightly) {
    using detail::DirectionCone;
    // Axes a rounding or a few apart (too close for their cross product to give a direction to
    // turn about): the cone widens by their angle, it does not become every direction, which
    // would keep the hierarchy from ruling out the points behind a group of flat lights.
    const Vector3f z(0.f, 0.f, 1.f);
    for (float angle : {0.f, 1e-7f, 3e-7f, 1e-6f, 1e-5f, 1e-3f, 0.3f, 2.f}) {
        const Vector3f tilted(std::sin(angle), 0.f, std::cos(angle));
        const DirectionCone c =
            detail::merge(DirectionCone{z, 1e-4f}, DirectionCone{tilted, 1e-4f});
        EXPECT_FALSE(c.everything()) << angle;
        EXPECT_NEAR(c.theta, 1e-4f + 0.5f * angle, 2e-6f + 1e-5f * angle) << angle;
        // Both axes and the far edges of both cones are inside.
        for (float edge : {-1e-4f, 0.f, angle + 1e-4f}) {
            const Vector3f d(std::sin(edge), 0.f, std::cos(edge));
            EXPECT_GE(dot(c.axis, d), std::cos(c.theta) - 1e-6f) << angle << " " << edge;
        }
    }
    // Opposite axes: every direction; a cone inside another: the other.
    EXPECT_TRUE(detail::merge(DirectionCone{z, 0.1f}, DirectionCone{-z, 0.1f}).everything());
    const DirectionCone wide{z, 1.f};
    EXPECT_EQ(
        detail::merge(wide, DirectionCone{Vector3f(std::sin(0.5f), 0.f, std::cos(0.5f)), 0.2f})
            .theta,
        1.f);
}
