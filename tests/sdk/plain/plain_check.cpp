// The out-of-tree `plainarea` light and `plainsampler` against facet's `area` and `independent`:
// a scene lit by mesh lights and by a sphere's and a disk's renders the same image whether the
// scene samples a light from its constant_radiance() or through the emitter's own methods, and
// whether the render draws from the sampler's generator or through next_1d()/next_2d(). Usage:
// plain_check <scene.xml> <folder of the plugins>; exits with 1 when an image differs.

#include <facet/plugin.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/xml.h>

#include <cmath>
#include <cstdio>
#include <exception>

namespace {

facet::Image render_with(const char *scene_path, const char *emitter, const char *sampler) {
    facet::LoadOptions load;
    load.params["emitter"] = emitter;
    load.params["sampler"] = sampler;
    std::shared_ptr<facet::Scene> scene = facet::load_scene(scene_path, load);
    facet::RenderOptions opts;
    opts.seed = 7;
    return facet::render(*scene, *scene->sensors().at(0), opts).image;
}

/// Counts the values of `ours` that differ from `theirs`; prints the comparison.
bool same(const char *what, const facet::Image &ours, const facet::Image &theirs) {
    if (ours.data.size() != theirs.data.size()) {
        std::printf("plain_check: %s: the images differ in size\n", what);
        return false;
    }
    size_t differing = 0;
    double max_diff = 0.0, sum = 0.0;
    for (size_t i = 0; i < ours.data.size(); ++i) {
        if (ours.data[i] != theirs.data[i]) ++differing;
        max_diff = std::fmax(max_diff, std::fabs(double(ours.data[i]) - double(theirs.data[i])));
        sum += double(theirs.data[i]);
    }
    std::printf("plain_check: %s: %zu of %zu values differ (max %g), mean %g\n", what, differing,
                ours.data.size(), max_diff, sum / double(ours.data.size()));
    return differing == 0 && sum > 0.0;
}

} // namespace

int main(int argc, char **argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: plain_check <scene.xml> <folder of the plugins>\n");
        return 2;
    }
    try {
        facet::PluginRegistry::instance().add_search_dir(argv[2]);
        const facet::Image facets = render_with(argv[1], "area", "independent");
        const bool light = same("plainarea against area",
                                render_with(argv[1], "plainarea", "independent"), facets);
        const bool sampler = same("plainsampler against independent",
                                  render_with(argv[1], "area", "plainsampler"), facets);
        return light && sampler ? 0 : 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "plain_check: %s\n", e.what());
        return 1;
    }
}
