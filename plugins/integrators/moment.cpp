static const char *DOC = R"DOC(
# moment: first and second moments of nested integrators

Renders the image of the first nested integrator and adds, for every nested integrator, its
sample values in CIE XYZ and its AOV channels as extra channels, plus their squares: once the
film has averaged them, `m2_<c>` - `<c>`² is the per-sample variance of channel `<c>`. The
channels are named as Mitsuba names them: `<name>.X/Y/Z` and `<name>.<aov>` for a nested
integrator called `<name>` (`_arg_0`, `_arg_1`, ... when it has no name attribute), then the same
list with the prefix `m2_`.

With a reconstruction filter wider than a pixel the moments are filter-weighted; use `box` for
plain per-sample moments. In the spectral modes a sample's XYZ is its spectral value's, the
render loop's development (the mean over the path's wavelengths of L·(x̄, ȳ, z̄)/pdf, over ∫ȳ),
so the moments are those of the XYZ samples the image averages, as in Mitsuba.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| (nested) | integrator | — | One or more sampling integrators (at least one) |
| timeout | float | -1 | Stop after this many seconds and develop what is done (like Ctrl-C); <= 0: no limit |
| samples_per_pass | integer | (all) | Render in passes over the image of this many samples per pixel (must divide the sample count) |
| block_size | integer | 0 | Side of the square image blocks, in pixels; 0 chooses 32 |

```xml
<integrator type="moment">
    <integrator name="path" type="path">
        <integer name="max_depth" value="8"/>
    </integrator>
</integrator>
```
)DOC";

#include <facet/film.h>
#include <facet/integrator.h>
#include <facet/mode.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/sensor.h>
#include <facet/spectrum.h>

#include <fmt/format.h>

namespace facet {

class MomentIntegrator final : public SamplingIntegrator {
public:
    explicit MomentIntegrator(const Properties &props)
        : SamplingIntegrator(props), m_spectral(is_spectral(props.mode())) {
        for (const auto &[name, obj] : props.objects()) {
            auto integrator = std::dynamic_pointer_cast<SamplingIntegrator>(obj);
            if (!integrator)
                FACET_THROW_AT(props.location(name),
                               "moment: nested objects must be sampling integrators (path, "
                               "direct, aov, ...), got {}",
                               obj ? obj->to_string() : std::string("nothing"));
            props.mark_queried(name);
            std::vector<std::string> aovs = integrator->aov_names();
            for (const std::string &aov : aovs) m_names.push_back(name + "." + aov);
            for (const char *c : {".X", ".Y", ".Z"}) m_names.push_back(name + c);
            m_nested.push_back({integrator, aovs.size()});
        }
        if (m_nested.empty())
            FACET_THROW_AT(props.location(), "moment: needs at least one nested integrator");
        const size_t first = m_names.size();
        for (size_t i = 0; i < first; ++i) m_names.push_back("m2_" + m_names[i]);
    }

    Color3f sample(const Scene &scene, Sampler &sampler, const Ray &ray,
                   float *aovs) const override {
        const size_t half = m_names.size() / 2;
        Color3f result(0.f);
        float *out = aovs;
        for (size_t i = 0; i < m_nested.size(); ++i) {
            const Nested &n = m_nested[i];
            // The nested AOVs go straight into their slots; the moments follow at half.
            Color3f L = n.integrator->sample(scene, sampler, ray, out);
            if (i == 0) result = L;
            const Color3f xyz = m_spectral ? spectral_to_xyz(L, ray.wavelengths,
                                                             wavelength_weights(ray.wavelengths))
                                           : srgb_to_xyz(L);
            out[n.aovs + 0] = xyz.r;
            out[n.aovs + 1] = xyz.g;
            out[n.aovs + 2] = xyz.b;
            for (size_t k = 0; k < n.aovs + 3; ++k) out[half + k] = out[k] * out[k];
            out += n.aovs + 3;
        }
        return result;
    }

    void begin_render(const Sensor &sensor) const override {
        if (sensor.draws_wavelengths())
            FACET_THROW("moment: its channels are the XYZ of the visible range's wavelengths: "
                        "it cannot be rendered with a film's spectral bands or a sensor's srf");
        for (const Nested &n : m_nested) n.integrator->begin_render(sensor);
    }

    std::vector<std::string> aov_names() const override { return m_names; }

    std::string to_string() const override {
        std::string list;
        for (const auto &n : m_nested)
            list += (list.empty() ? "" : ", ") + n.integrator->to_string();
        return fmt::format("MomentIntegrator[channels = {}, integrators = [{}]]", m_names.size(),
                           list);
    }

private:
    struct Nested {
        std::shared_ptr<SamplingIntegrator> integrator;
        size_t aovs;
    };
    bool m_spectral; ///< the nested integrators' values are spectral
    std::vector<Nested> m_nested;
    std::vector<std::string> m_names;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::MomentIntegrator, Integrator, "moment",
                          "First and second moments of nested integrators as extra channels", DOC,
                          ::facet::AllModes)
