static const char *DOC = R"DOC(
# stokes: the polarisation of the image

Renders the image of its nested integrator and adds the four Stokes components of the light
reaching each pixel as extra channels, `S0.R, S0.G, S0.B, S1.R, ... S3.B` (each component
developed to RGB as the image is; in the spectral modes through CIE XYZ), followed by the nested
integrator's own channels. S0 is the intensity (the image itself); S1 is horizontal minus
vertical linear polarisation, S2 linear at +45° minus −45°, S3 right minus left circular
polarisation (positive: the field turns counter-clockwise as seen by the camera looking at the
source).

The components are expressed in the camera's frame: for the light arriving along a camera ray
of direction d, "horizontal" is the direction d × up, where up is the sensor's vertical axis
(its `to_world` applied to +Y), "vertical" is perpendicular to it and to d. Use it in the
`scalar_spectral_polarized` mode; in the other modes light is unpolarised (S1 = S2 = S3 = 0) and
a warning says so.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| (nested) | integrator | — | A sampling integrator that follows polarisation (`path`) |
| timeout | float | -1 | Stop after this many seconds and develop what is done (like Ctrl-C); <= 0: no limit |
| samples_per_pass | integer | (all) | Render in passes over the image of this many samples per pixel (must divide the sample count) |
| block_size | integer | 0 | Side of the square image blocks, in pixels; 0 chooses 32 |

```xml
<integrator type="stokes">
    <integrator type="path"/>
</integrator>
```
)DOC";

#include <facet/film.h>
#include <facet/integrator.h>
#include <facet/mode.h>
#include <facet/mueller.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/sensor.h>
#include <facet/spectrum.h>
#include <facet/transform.h>

#include <fmt/format.h>

#include <atomic>

namespace facet {

class StokesIntegrator final : public SamplingIntegrator {
public:
    explicit StokesIntegrator(const Properties &props) : SamplingIntegrator(props) {
        m_mode = props.mode();
        for (const auto &[name, obj] : props.objects()) {
            auto integrator = std::dynamic_pointer_cast<SamplingIntegrator>(obj);
            if (!integrator)
                FACET_THROW_AT(props.location(name),
                               "stokes: the nested object must be a sampling integrator, got {}",
                               obj ? obj->to_string() : std::string("nothing"));
            if (m_nested)
                FACET_THROW_AT(props.location(name),
                               "stokes: only one nested integrator is supported");
            if (!integrator->has_stokes())
                FACET_THROW_AT(props.location(name),
                               "stokes: the nested integrator {} does not follow the "
                               "polarisation of light (use path)",
                               integrator->to_string());
            m_nested = integrator;
            props.mark_queried(name);
        }
        if (!m_nested)
            FACET_THROW_AT(props.location(), "stokes: needs a nested integrator (e.g. path)");
        if (!is_polarized(m_mode))
            FACET_LOG(Warn,
                      "{}the stokes integrator in the mode {}: light is unpolarised there "
                      "(S1 = S2 = S3 = 0); render in scalar_spectral_polarized",
                      props.location().valid() ? props.location().to_string() + ": " : "",
                      mode_name(m_mode));
    }

    std::vector<std::string> aov_names() const override {
        std::vector<std::string> names;
        for (int k = 0; k < 4; ++k)
            for (const char *c : {"R", "G", "B"}) names.push_back(fmt::format("S{}.{}", k, c));
        for (const std::string &n : m_nested->aov_names()) names.push_back(n);
        return names;
    }

    void begin_render(const Sensor &sensor) const override {
        if (sensor.draws_wavelengths())
            FACET_THROW("stokes: its S0-S3 channels are developed to RGB from the visible "
                        "range's wavelengths: it cannot be rendered with a film's spectral bands "
                        "or a sensor's srf");
        const Vector3f up = normalize(sensor.to_world().apply_vector(Vector3f(0.f, 1.f, 0.f)));
        m_up_x.store(up.x);
        m_up_y.store(up.y);
        m_up_z.store(up.z);
        m_nested->begin_render(sensor);
    }

    Color3f sample(const Scene &scene, Sampler &sampler, const Ray &ray,
                   float *aovs) const override {
        Stokes s = m_nested->sample_stokes(scene, sampler, ray, aovs + 12);
        // From the implicit frame of the light's direction of travel (−d) to the camera's.
        const Vector3f up(m_up_x.load(std::memory_order_relaxed),
                          m_up_y.load(std::memory_order_relaxed),
                          m_up_z.load(std::memory_order_relaxed));
        const Vector3f target = cross(ray.d, up);
        if (dot(target, target) > 0.f)
            s = mueller::rotate_stokes_basis(-ray.d, mueller::stokes_basis(-ray.d), target) * s;
        const Color3f weight =
            is_spectral(m_mode) ? wavelength_weights(ray.wavelengths) : Color3f(1.f);
        for (int k = 0; k < 4; ++k) {
            const Color3f c =
                is_spectral(m_mode) ? spectral_to_srgb(s.s[k], ray.wavelengths, weight) : s.s[k];
            aovs[3 * k] = c.r;
            aovs[3 * k + 1] = c.g;
            aovs[3 * k + 2] = c.b;
        }
        return s.s[0];
    }

    std::string to_string() const override {
        return fmt::format("StokesIntegrator[nested = {}]", m_nested->to_string());
    }

private:
    std::shared_ptr<SamplingIntegrator> m_nested;
    ColourMode m_mode;
    /// The sensor's vertical axis in the world (begin_render()), read by every render thread.
    mutable std::atomic<float> m_up_x{0.f}, m_up_y{1.f}, m_up_z{0.f};
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::StokesIntegrator, Integrator, "stokes",
                          "Stokes components of the light reaching the image, as extra channels",
                          DOC, ::facet::AllModes)
