// The out-of-tree `plainarea` light, `plainsampler`, `plaindiffuse` BSDF and `plainforward`
// integrator against facet's `area`, `independent`, `diffuse` and `path`: a scene lit by mesh
// lights and by a sphere's and a disk's renders the same image whether the scene samples a light
// from its constant_radiance() or through the emitter's own methods, whether the render draws
// from the sampler's generator or through next_1d()/next_2d(), whether the path tracer
// prefetches the BSDF's texels and samples it after the light sample or does neither, and
// whether the render loop traces the camera rays of eight pixels as one packet or each path
// traces its own (the two textures, one read as bytes and one as floats, are written next to the
// plugins). Usage: plain_check <scene.xml> <folder of the plugins>; exits with 1 when an image
// differs.

#include <facet/image.h>
#include <facet/plugin.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/xml.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>

namespace {

std::string g_sphere_texture, g_floor_texture;

facet::Image render_with(const char *scene_path, const char *emitter, const char *sampler,
                         const char *bsdf = "diffuse", const char *integrator = "path") {
    facet::LoadOptions load;
    load.params["integrator"] = integrator;
    load.params["emitter"] = emitter;
    load.params["sampler"] = sampler;
    load.params["bsdf"] = bsdf;
    load.params["sphere_texture"] = g_sphere_texture;
    load.params["floor_texture"] = g_floor_texture;
    std::shared_ptr<facet::Scene> scene = facet::load_scene(scene_path, load);
    facet::RenderOptions opts;
    opts.seed = 7;
    return facet::render(*scene, *scene->sensors().at(0), opts).image;
}

/// A texture of w x h pixels whose neighbours differ (so that a lookup's four pixels matter).
facet::Image pattern(int w, int h) {
    facet::Image image(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                uint32_t v =
                    uint32_t(x) * 73856093u ^ uint32_t(y) * 19349663u ^ uint32_t(c) * 83492791u;
                v = (v ^ (v >> 13)) * 0x5bd1e995u;
                image.at(x, y, c) = 0.1f + 0.8f * float((v >> 8) & 0xffff) / 65535.f;
            }
    return image;
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
        g_sphere_texture = std::string(argv[2]) + "/plain_sphere.exr";
        g_floor_texture = std::string(argv[2]) + "/plain_floor.png";
        facet::write_image(g_sphere_texture, pattern(61, 37));
        facet::write_image(g_floor_texture, pattern(173, 149));
        const facet::Image facets = render_with(argv[1], "area", "independent");
        const bool light = same("plainarea against area",
                                render_with(argv[1], "plainarea", "independent"), facets);
        const bool sampler = same("plainsampler against independent",
                                  render_with(argv[1], "area", "plainsampler"), facets);
        const bool bsdf = same("plaindiffuse against diffuse",
                               render_with(argv[1], "area", "independent", "plaindiffuse"), facets);
        const bool unflagged =
            same("plaindiffuse_unflagged against diffuse",
                 render_with(argv[1], "area", "independent", "plaindiffuse_unflagged"), facets);
        const bool forward =
            same("plainforward against path",
                 render_with(argv[1], "area", "independent", "diffuse", "plainforward"), facets);
        return light && sampler && bsdf && unflagged && forward ? 0 : 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "plain_check: %s\n", e.what());
        return 1;
    }
}
