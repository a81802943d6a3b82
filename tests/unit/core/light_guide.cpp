// The light-sample guide (Scene::prepare_light_sampling()): where the scene's survey found few
// light samples useful, a point takes one with probability q < 1, its weight divided by q and
// its density multiplied by it; and the emitter it samples is chosen by a mixture of a tenth of
// the scene's own rule for the point's cell and nine tenths of what the survey learned there.
// The densities are those of that sampling, the expected image is the same, and the guide
// depends on the scene alone.
#include "light_guide.h"

#include "draws.h"

#include <facet/integrator.h>
#include <facet/params.h>
#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/render.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace facet;

namespace {

/// A maze: a closed box (side 8, normals inwards) split into eight rooms by seven thin slabs,
/// every surface diffuse of reflectance 1/2. As a furnace (`lamps` false) every surface is also
/// an area light of radiance 1: whatever the geometry, the radiance everywhere is
/// 1 / (1 - 1/2) = 2. With `lamps`, seven rooms have a small bright cube light each instead,
/// picked uniformly (fewer than eight lights): from inside a room most light samples go to
/// lamps it cannot see, and the path tracer stops at direct light (max_depth 2): light samples
/// carry most of the image.
std::string maze_xml(bool guide, bool lamps = false, int spp = 4, float middle_slab_x = 0.f) {
    const std::string glow =
        lamps ? "" : R"(<emitter type="area"><rgb name="radiance" value="1"/></emitter>)";
    std::string shapes;
    for (int i = -3; i <= 3; ++i)
        shapes += fmt::format(R"(
        <shape type="cube">
            <transform name="to_world"><scale x="0.05" y="3.6" z="3.6"/><translate x="{}"/></transform>
            <ref id="grey"/>{}
        </shape>)",
                              i == 0 ? middle_slab_x : float(i), glow);
    for (int i = -3; i <= 3 && lamps; ++i)
        shapes += fmt::format(R"(
        <shape type="cube">
            <transform name="to_world"><scale value="0.25"/><translate x="{}" y="{}" z="-1"/></transform>
            <ref id="grey"/><emitter type="area"><rgb name="radiance" value="10"/></emitter>
        </shape>)",
                              float(i) + 0.5f, 0.4f * float(i % 3));
    return fmt::format(R"(<scene version="3.0.0">
        <boolean name="light_guide" value="{}"/>
        <integrator type="path">{}</integrator>
        <sensor type="perspective">
            <float name="fov" value="80"/>
            <transform name="to_world"><lookat origin="0.5, 0.3, 3.8" target="0.5, 0, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="{}"/></sampler>
            <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>
                <rfilter type="box"/></film>
        </sensor>
        <bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.5"/></bsdf>
        <shape type="cube">
            <boolean name="flip_normals" value="true"/>
            <transform name="to_world"><scale value="4"/></transform>
            <ref id="grey"/>{}
        </shape>{}
    </scene>)",
                       guide ? "true" : "false",
                       lamps ? R"(<integer name="max_depth" value="2"/>)" : "", spp, glow, shapes);
}

/// The mean over a res x res grid of pixels of `spp` path samples each, and its standard error;
/// `guided_pixels` counts the pixels whose centre sees a point where q < 1.
struct Estimate {
    double mean = 0.0, error = 0.0;
    size_t guided_pixels = 0;
};
Estimate estimate(const Scene &scene, int res, int spp) {
    const Sensor &sensor = *scene.sensors().at(0);
    const auto &integrator = dynamic_cast<const SamplingIntegrator &>(*scene.integrator());
    auto sampler = PluginRegistry::instance()
                       .create_as<Sampler>(ObjectType::Sampler, Properties("independent"))
                       ->clone();
    Estimate e;
    double var_sum = 0.0;
    for (int y = 0; y < res; ++y)
        for (int x = 0; x < res; ++x) {
            sampler->seed(uint64_t(y * res + x) + 17u);
            double s1 = 0.0, s2 = 0.0;
            for (int s = 0; s < spp; ++s) {
                const Point2f u = sampler->next_2d();
                const Point2f film((float(x) + u.x) / float(res), (float(y) + u.y) / float(res));
                const Ray ray = sensor.sample_ray(0.f, film, Point2f(0.5f, 0.5f)).first;
                const double L = integrator.sample(scene, *sampler, ray, nullptr).g;
                sampler->advance();
                s1 += L;
                s2 += L * L;
            }
            const double mean = s1 / spp;
            e.mean += mean;
            var_sum += std::max(0.0, s2 / spp - mean * mean) / spp;
            const Point2f centre((float(x) + 0.5f) / float(res), (float(y) + 0.5f) / float(res));
            SurfaceInteraction si;
            if (scene.ray_intersect(sensor.sample_ray(0.f, centre, Point2f(0.5f, 0.5f)).first,
                                    si) &&
                scene.light_sample_probability(si.p) < 1.f)
                ++e.guided_pixels;
        }
    const double n = double(res) * double(res);
    e.mean /= n;
    e.error = std::sqrt(var_sum) / n;
    return e;
}

std::shared_ptr<Scene> load(const std::string &xml) {
    return std::dynamic_pointer_cast<Scene>(load_string(xml, LoadOptions()));
}

/// Surface points the camera sees, through a grid of its film.
std::vector<SurfaceInteraction> seen_points(const Scene &scene, int n) {
    std::vector<SurfaceInteraction> out;
    const Sensor &sensor = *scene.sensors().at(0);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const Point2f film((float(x) + 0.5f) / float(n), (float(y) + 0.5f) / float(n));
            const Ray ray = sensor.sample_ray(0.f, film, Point2f(0.5f, 0.5f)).first;
            SurfaceInteraction si;
            if (scene.ray_intersect(ray, si)) out.push_back(si);
        }
    return out;
}

} // namespace

TEST(LightGuide, GuidedSamplesAreTakenAtRateQWithTheirDensities) {
    auto guided = load(maze_xml(true)), plain = load(maze_xml(false));
    ASSERT_TRUE(guided && plain);
    const std::vector<SurfaceInteraction> points = seen_points(*guided, 12);
    ASSERT_GT(points.size(), 100u);
    for (const SurfaceInteraction &si : points) // nothing before the survey
        ASSERT_EQ(guided->light_sample_probability(si.p), 1.f);
    guided->prepare_light_sampling();
    plain->prepare_light_sampling();

    PCG32 rng(7);
    size_t below_one = 0;
    double taken = 0.0, expected_taken = 0.0, taken_variance = 0.0;
    for (const SurfaceInteraction &si : points) {
        const float q = guided->light_sample_probability(si.p);
        ASSERT_GE(q, 0.1f);
        ASSERT_LE(q, 1.f);
        EXPECT_EQ(plain->light_sample_probability(si.p), 1.f); // the option turns it off
        if (q < 1.f) ++below_one;
        for (int i = 0; i < 64; ++i) {
            const Point2f u = next_point2f(rng);
            const auto [ds, weight] =
                guided->sample_emitter_direction(si, u, false, LightSampling::Alone);
            expected_taken += q;
            taken_variance += q * (1.0 - q);
            if (!(u.x < q)) { // no sample
                EXPECT_EQ(ds.pdf, 0.f);
                EXPECT_TRUE(weight.is_black());
                continue;
            }
            ++taken;
            if (!(ds.pdf > 0.f)) continue;
            // The sample of the emitter the guided choice picked, taken at rate q: its density
            // is q times the emitter's probability there times the emitter's own density, and
            // its weight the radiance (1 everywhere in the furnace) over that density.
            ASSERT_TRUE(ds.emitter);
            EXPECT_EQ(guided->pdf_emitter_direction(si, ds, LightSampling::Alone), ds.pdf);
            const float pmf = guided->emitter_pmf(si, *ds.emitter);
            const float own = ds.emitter->pdf_direction(si, ds);
            EXPECT_NEAR(ds.pdf, q * pmf * own, 1e-5f * ds.pdf);
            EXPECT_NEAR(weight.g * ds.pdf, 1.f, 1e-5f);
        }
        // Whatever the survey learned, the choice leaves out no emitter the scene's own rule
        // gives a probability at the point (its floor: EveryCellKeepsATenthOfItsOwnRule).
        for (const auto &emitter : guided->emitters()) {
            const Emitter &twin = *plain->emitters().at(emitter->scene_index());
            if (plain->emitter_pmf(si, twin) > 0.f) {
                EXPECT_GT(guided->emitter_pmf(si, *emitter), 0.f);
            }
        }
    }
    // The maze makes most light samples useless somewhere the camera looks.
    EXPECT_GT(below_one, points.size() / 4) << "the guide changed nothing";
    // Samples are taken at the rate q (a binomial count).
    EXPECT_NEAR(taken, expected_taken, 4.0 * std::sqrt(taken_variance) + 1.0);
}

TEST(LightGuide, EveryCellKeepsATenthOfItsOwnRule) {
    // The guide alone, over a box 10 x 4 x 6 with five emitters, from a survey that found light
    // from emitters 0 to 3 only (by position), never from 4. The scene's own rule (`own`) is
    // asked for each cell of the choice's box: at every point the choice is a probability
    // distribution (running sums included), the point lies in a box the rule was asked for,
    // and each emitter keeps at least OwnChoiceShare of that rule's share there (normalised:
    // emitter 3 gets nothing from the rule where x > 5): emitter 4 too.
    const BoundingBox3f bounds(Point3f(0.f), Point3f(10.f, 4.f, 6.f));
    constexpr size_t E = 5;
    detail::LightGuide guide(bounds, E);
    PCG32 rng(5);
    auto point = [&] {
        const float x = 10.f * rng.next_float(), y = 4.f * rng.next_float();
        return Point3f(x, y, 6.f * rng.next_float());
    };
    for (int i = 0; i < 400000; ++i) {
        const Point3f p = point();
        const size_t e = size_t(p.x / 2.5f + p.z / 6.f) % 4;
        guide.record(p, true, e, 0.1f + rng.next_float());
    }
    std::vector<BoundingBox3f> boxes;
    std::vector<std::vector<float>> rules;
    auto own = [&](const BoundingBox3f &box, float *out) {
        const Point3f c = box.center();
        for (size_t e = 0; e < E; ++e) out[e] = 1.f / (1.f + float(e) * c.y);
        if (c.x > 5.f) out[3] = 0.f;
        boxes.push_back(box);
        rules.emplace_back(out, out + E);
    };
    EXPECT_GT(guide.finish({}, own), 0u);
    ASSERT_TRUE(guide.chooses());
    ASSERT_FALSE(boxes.empty());
    // A point outside the grid lies in no cell's box: no choice there (the scene's own rule
    // at the point decides); the box's far corner is inside.
    EXPECT_EQ(guide.choice(Point3f(-0.5f, 2.f, 3.f)), nullptr);
    EXPECT_EQ(guide.choice(Point3f(5.f, 2.f, 8.f)), nullptr);
    EXPECT_EQ(guide.choice(Point3f(std::nanf(""), 2.f, 3.f)), nullptr);
    EXPECT_NE(guide.choice(Point3f(10.f, 4.f, 6.f)), nullptr);
    constexpr float Own = detail::LightGuide::OwnChoiceShare;
    for (int i = 0; i < 2000; ++i) {
        const Point3f p = point();
        const float *choice = guide.choice(p);
        ASSERT_NE(choice, nullptr);
        double sum = 0.0;
        for (size_t e = 0; e < E; ++e) {
            sum += choice[e];
            EXPECT_NEAR(choice[E + e], sum, 1e-6);
        }
        EXPECT_NEAR(sum, 1.0, 1e-5);
        // The cells' boxes overlap by their margins: the point's cell is one of those holding it.
        bool floor_kept = false, inside = false;
        for (size_t b = 0; b < boxes.size(); ++b) {
            const BoundingBox3f &box = boxes[b];
            if (!(p.x >= box.min.x && p.x <= box.max.x && p.y >= box.min.y && p.y <= box.max.y &&
                  p.z >= box.min.z && p.z <= box.max.z))
                continue;
            inside = true;
            double total = 0.0;
            for (float v : rules[b]) total += v;
            bool kept = true;
            for (size_t e = 0; e < E; ++e)
                kept = kept && choice[e] >= Own * float(rules[b][e] / total) * (1.f - 1e-5f);
            floor_kept = floor_kept || kept;
        }
        EXPECT_TRUE(inside) << "(" << p.x << ", " << p.y << ", " << p.z << ") in no cell's box";
        EXPECT_TRUE(floor_kept) << "(" << p.x << ", " << p.y << ", " << p.z << ")";
        EXPECT_GT(choice[4], 0.f);
        if (p.x > 5.5f) { // no share from the rule there: the learned share alone
            EXPECT_LE(choice[3], (1.f - Own) * (1.f + 1e-6f));
        }
    }
}

TEST(LightGuide, TheLearnedChoiceOfEmittersIsTheOneSampled) {
    // The lamps in the maze: from most points only the lamps of the same room give light, and
    // the survey learns it. At every point the choice's probabilities sum to 1, sample_emitter()
    // picks each emitter as often as emitter_pmf() says and reports that probability, and the
    // choice differs from the scene's own rule (the guide turned off) somewhere.
    auto guided = load(maze_xml(true, true)), plain = load(maze_xml(false, true));
    guided->prepare_light_sampling();
    plain->prepare_light_sampling();
    const auto &emitters = guided->emitters();
    ASSERT_EQ(emitters.size(), 7u);
    const std::vector<SurfaceInteraction> points = seen_points(*guided, 8);
    ASSERT_GT(points.size(), 40u);
    PCG32 rng(11);
    size_t learned = 0;
    for (const SurfaceInteraction &si : points) {
        double sum = 0.0;
        bool differs = false;
        for (const auto &e : emitters) {
            const float pmf = guided->emitter_pmf(si, *e);
            const float own = plain->emitter_pmf(si, *plain->emitters().at(e->scene_index()));
            sum += pmf;
            differs = differs || std::abs(pmf - own) > 1e-3f;
        }
        EXPECT_NEAR(sum, 1.0, 1e-5);
        if (differs) ++learned;
    }
    EXPECT_GT(learned, points.size() / 2) << "the guide learned no choice";
    // Frequencies at a few points: each emitter's count against its binomial bounds.
    const int n = 20000;
    for (size_t k = 0; k < points.size(); k += points.size() / 4) {
        const SurfaceInteraction &si = points[k];
        std::vector<int> count(emitters.size(), 0);
        for (int i = 0; i < n; ++i) {
            float u = rng.next_float();
            const auto [emitter, pmf] = guided->sample_emitter(si, u);
            ASSERT_TRUE(emitter);
            ASSERT_TRUE(u >= 0.f && u < 1.f);
            EXPECT_EQ(pmf, guided->emitter_pmf(si, *emitter));
            ++count[emitter->scene_index()];
        }
        for (const auto &e : emitters) {
            const double p = guided->emitter_pmf(si, *e);
            EXPECT_NEAR(count[e->scene_index()], n * p, 5.0 * std::sqrt(n * p * (1.0 - p)) + 1.0)
                << "emitter " << e->scene_index() << " at point " << k;
        }
    }
}

TEST(LightGuide, SamplingWeightsKeepTheScenesChoice) {
    // A scene that gives its emitters a sampling_weight asks for Mitsuba's choice: the survey
    // learns none (the probability q still applies).
    std::string xml = maze_xml(true, true);
    const std::string lamp = R"(<emitter type="area"><rgb name="radiance" value="10"/></emitter>)";
    const std::string weighted =
        R"(<emitter type="area"><rgb name="radiance" value="10"/><float name="sampling_weight" value="1"/></emitter>)";
    for (size_t at = xml.find(lamp); at != std::string::npos; at = xml.find(lamp, at))
        xml.replace(at, lamp.size(), weighted);
    auto scene = load(xml);
    scene->prepare_light_sampling();
    const auto &emitters = scene->emitters();
    ASSERT_EQ(emitters.size(), 7u);
    for (const SurfaceInteraction &si : seen_points(*scene, 8))
        for (const auto &e : emitters) EXPECT_EQ(scene->emitter_pmf(si, *e), 1.f / 7.f);
}

TEST(LightGuide, DependsOnTheSceneAlone) {
    // Two loads of the scene survey it to the same guide; a render prepares it once and then
    // renders the same image whatever its thread count.
    auto a = load(maze_xml(true)), b = load(maze_xml(true));
    RenderOptions opts;
    opts.progress = false;
    opts.threads = 1;
    const RenderResult one = render(*a, *a->sensors().at(0), opts);
    b->prepare_light_sampling();
    for (const SurfaceInteraction &si : seen_points(*a, 16)) {
        EXPECT_EQ(a->light_sample_probability(si.p), b->light_sample_probability(si.p));
        for (size_t e = 0; e < a->emitters().size(); ++e)
            EXPECT_EQ(a->emitter_pmf(si, *a->emitters()[e]), b->emitter_pmf(si, *b->emitters()[e]));
    }
    opts.threads = 2;
    const RenderResult two = render(*a, *a->sensors().at(0), opts);
    ASSERT_EQ(one.image.data.size(), two.image.data.size());
    EXPECT_TRUE(one.image.data == two.image.data);
}

TEST(LightGuide, TheFurnaceMazeKeepsItsRadiance) {
    // Every pixel of the furnace has expectation 2, with the guide and without it: the mean over
    // the pixels is checked against its standard error (single pixels' errors, from paths whose
    // Russian roulette gives heavy tails, are too rough an estimate to test each).
    for (bool guide : {true, false}) {
        SCOPED_TRACE(guide ? "guided" : "unguided");
        auto scene = load(maze_xml(guide));
        scene->prepare_light_sampling();
        const Estimate e = estimate(*scene, 12, 256);
        EXPECT_NEAR(e.mean, 2.0, 4.0 * e.error);
        EXPECT_LT(e.error, 0.01);
        if (guide)
            EXPECT_GT(e.guided_pixels, 144u / 4) << "the guide changed nothing";
        else
            EXPECT_EQ(e.guided_pixels, 0u);
    }
}

TEST(LightGuide, LampsInTheMazeGiveTheSameImage) {
    // Light samples carry most of this image, and the guide skips many of them: the guided and
    // unguided estimates agree within their standard errors.
    auto guided = load(maze_xml(true, true)), plain = load(maze_xml(false, true));
    guided->prepare_light_sampling();
    plain->prepare_light_sampling();
    const Estimate g = estimate(*guided, 12, 1024), p = estimate(*plain, 12, 1024);
    EXPECT_GT(g.guided_pixels, 144u / 4) << "the guide changed nothing";
    const double error = std::hypot(g.error, p.error);
    // A bias of 20% would show. (Light samples that are skipped are mostly useless ones, so a
    // wrong weight or density of the skipping moves this image by only ~8%: the exact checks of
    // GuidedSamplesAreTakenAtRateQWithTheirDensities catch those.)
    EXPECT_LT(error, 0.05 * p.mean);
    EXPECT_NEAR(g.mean, p.mean, 4.0 * error);
}

TEST(LightGuide, AnUpdateSurveysTheEditedScene) {
    // After an edit the guide is surveyed again: the render is that of the edited scene loaded
    // afresh, bit for bit (a guide kept from before the edit would give other pixels).
    auto scene = load(maze_xml(true, true, 16));
    RenderOptions opts;
    opts.progress = false;
    const RenderResult before = render(*scene, *scene->sensors().at(0), opts);
    SceneParameters params = traverse(scene);
    const std::string key = "shape_4.to_world"; // the middle slab, beside the camera
    ASSERT_TRUE(params.has(key));
    params.set(key, Transform::translate(Vector3f(0.3f, 0.f, 0.f)) *
                        Transform::scale(Vector3f(0.05f, 3.6f, 3.6f)));
    params.update();
    for (const SurfaceInteraction &si : seen_points(*scene, 8))
        ASSERT_EQ(scene->light_sample_probability(si.p), 1.f) << "the old guide was kept";
    const RenderResult edited = render(*scene, *scene->sensors().at(0), opts);
    auto fresh = load(maze_xml(true, true, 16, 0.3f));
    const RenderResult loaded = render(*fresh, *fresh->sensors().at(0), opts);
    EXPECT_TRUE(edited.image.data == loaded.image.data);
    EXPECT_FALSE(edited.image.data == before.image.data);
}
