static const char *DOC = R"DOC(
# depth: distance to the first surface

Writes the distance along each camera ray to the first surface it hits (0 where the ray
escapes) into all three channels. Useful for debugging scenes and as a depth pass.

In the spectral modes the distance is a radiance like any other, flat over the wavelengths, and
is developed as one (as in Mitsuba): a distance d becomes d times the equal-energy white
(about 1.205, 0.948, 0.909 · d in R, G, B), up to the noise of the path's wavelengths. Use the
`aov` integrator's `depth` for a raw distance channel in every mode.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| timeout | float | -1 | Stop after this many seconds and develop what is done (like Ctrl-C); <= 0: no limit |
| samples_per_pass | integer | (all) | Render in passes over the image of this many samples per pixel (must divide the sample count) |
| block_size | integer | 0 | Side of the square image blocks, in pixels; 0 chooses 32 |

```xml
<integrator type="depth"/>
```
)DOC";

#include <facet/integrator.h>
#include <facet/plugin.h>
#include <facet/scene.h>

namespace facet {

class DepthIntegrator final : public SamplingIntegrator {
public:
    explicit DepthIntegrator(const Properties &props) : SamplingIntegrator(props) {}

    Color3f sample(const Scene &scene, Sampler &, const Ray &ray, float *) const override {
        SurfaceInteraction si;
        if (!scene.ray_intersect(ray, si)) return Color3f(0.f);
        // Rays from the sensor have unit directions, so t is the distance.
        return Color3f(si.t * norm(ray.d));
    }

    std::string to_string() const override { return "DepthIntegrator[]"; }
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::DepthIntegrator, Integrator, "depth",
                          "Distance from the sensor to the first surface", DOC, ::facet::AllModes)
