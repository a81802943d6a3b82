// The out-of-tree `plainarea` light against facet's `area`: a scene lit by mesh lights renders
// the same image either way, whether the scene samples a light from its constant_radiance() or
// through the emitter's own methods. Usage: plainarea_check <scene.xml> <folder of plainarea.so>;
// exits with 1 when the images differ.

#include <facet/plugin.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/xml.h>

#include <cmath>
#include <cstdio>
#include <exception>

namespace {

facet::Image render_with(const char *scene_path, const char *emitter) {
    facet::LoadOptions load;
    load.params["emitter"] = emitter;
    std::shared_ptr<facet::Scene> scene = facet::load_scene(scene_path, load);
    facet::RenderOptions opts;
    opts.seed = 7;
    return facet::render(*scene, *scene->sensors().at(0), opts).image;
}

} // namespace

int main(int argc, char **argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: plainarea_check <scene.xml> <folder of plainarea.so>\n");
        return 2;
    }
    try {
        facet::PluginRegistry::instance().add_search_dir(argv[2]);
        const facet::Image ours = render_with(argv[1], "plainarea");
        const facet::Image theirs = render_with(argv[1], "area");
        if (ours.data.size() != theirs.data.size()) {
            std::printf("plainarea_check: the images differ in size\n");
            return 1;
        }
        size_t differing = 0;
        double max_diff = 0.0, sum = 0.0;
        for (size_t i = 0; i < ours.data.size(); ++i) {
            const double d = std::fabs(double(ours.data[i]) - double(theirs.data[i]));
            if (ours.data[i] != theirs.data[i]) ++differing;
            if (d > max_diff) max_diff = d;
            sum += double(theirs.data[i]);
        }
        std::printf("plainarea_check: %zu of %zu values differ (max %g), mean %g\n", differing,
                    ours.data.size(), max_diff, sum / double(ours.data.size()));
        return differing == 0 && sum > 0.0 ? 0 : 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "plainarea_check: %s\n", e.what());
        return 1;
    }
}
