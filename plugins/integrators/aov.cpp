static const char *DOC = R"DOC(
# aov: arbitrary output variables

Writes geometric and material information about the first surface each camera ray hits into
extra image channels, next to the RGB of an optional nested integrator (black without one).
Used for denoisers (albedo, normals) and compositing (depth, position, ids).

`aovs` is a comma-separated list of `name:type` pairs; the channels are called `name.X`,
`name.Y`, `name.Z` for vectors, `name.R/G/B` for colours, `name.U/V` for uv and `name` for
scalars. Types: `albedo`, `depth`, `position`, `uv`, `geo_normal`, `sh_normal`, `dp_du`,
`dp_dv`, `prim_index`, `shape_index`. Escaped rays give zeros (and -1 for the indices).

In the spectral modes the albedo (a reflectance at the path's wavelengths) is developed to
linear Rec.709 as the image is, as in Mitsuba; the geometric channels are written as they are.

| Parameter  | Type       | Default | Description                                     |
|------------|------------|---------|-------------------------------------------------|
| aovs       | string     | —       | The list of `name:type` pairs (required)        |
| (nested)   | integrator | —       | Integrator that renders the RGB channels        |
| timeout | float | -1 | Stop after this many seconds and develop what is done (like Ctrl-C); <= 0: no limit |
| samples_per_pass | integer | (all) | Render in passes over the image of this many samples per pixel (must divide the sample count) |
| block_size | integer | 0 | Side of the square image blocks, in pixels; 0 chooses 32 |

```xml
<integrator type="aov">
    <string name="aovs" value="albedo:albedo, nn:sh_normal, dd:depth"/>
    <integrator type="path"/>
</integrator>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/film.h>
#include <facet/integrator.h>
#include <facet/mode.h>
#include <facet/plugin.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/shape.h>
#include <facet/spectrum.h>

#include <sstream>

namespace facet {

class AovIntegrator final : public SamplingIntegrator {
    enum class Kind {
        Albedo,
        Depth,
        Position,
        UV,
        GeoNormal,
        ShNormal,
        DpDu,
        DpDv,
        PrimIndex,
        ShapeIndex
    };
    struct Aov {
        std::string name;
        Kind kind;
    };

public:
    explicit AovIntegrator(const Properties &props)
        : SamplingIntegrator(props), m_spectral(is_spectral(props.mode())) {
        std::string list = props.get_string("aovs");
        std::stringstream ss(list);
        std::string item;
        while (std::getline(ss, item, ',')) {
            item = trim(item);
            if (item.empty()) continue;
            size_t colon = item.find(':');
            if (colon == std::string::npos)
                FACET_THROW_AT(props.location("aovs"), "aov: entry \"{}\" must read name:type",
                               item);
            std::string name = trim(item.substr(0, colon)), type = trim(item.substr(colon + 1));
            m_aovs.push_back({name, parse_kind(type, props)});
        }
        if (m_aovs.empty())
            FACET_THROW_AT(props.location("aovs"), "aov: the list \"aovs\" is empty");
        for (auto &[name, obj] : props.objects()) {
            auto integrator = std::dynamic_pointer_cast<SamplingIntegrator>(obj);
            if (!integrator)
                FACET_THROW_AT(props.location(name),
                               "aov: nested objects must be sampling integrators");
            if (m_nested)
                FACET_THROW_AT(props.location(name),
                               "aov: only one nested integrator is supported");
            m_nested = integrator;
            props.mark_queried(name);
        }
        m_nested_aovs = m_nested ? m_nested->aov_names().size() : 0;
    }

    std::vector<std::string> aov_names() const override {
        std::vector<std::string> names;
        if (m_nested) names = m_nested->aov_names();
        for (const Aov &a : m_aovs) {
            for (const char *suffix : suffixes(a.kind))
                names.push_back(*suffix ? a.name + "." + suffix : a.name);
        }
        return names;
    }

    void begin_render(const Sensor &sensor) const override {
        // The albedo is developed to RGB from the visible range's wavelengths; a film's bands
        // draw others.
        if (m_spectral && sensor.draws_wavelengths())
            for (const Aov &a : m_aovs)
                if (a.kind == Kind::Albedo)
                    FACET_THROW("aov: the albedo AOV \"{}\" is developed to RGB from the "
                                "visible range's wavelengths: it cannot be rendered with a "
                                "film's spectral bands or a sensor's srf (the geometric AOVs "
                                "can)",
                                a.name);
        if (m_nested) m_nested->begin_render(sensor);
    }

    Color3f sample(const Scene &scene, Sampler &sampler, const Ray &ray,
                   float *aovs) const override {
        Color3f result(0.f);
        if (m_nested) result = m_nested->sample(scene, sampler, ray, aovs);
        float *out = aovs + m_nested_aovs;
        SurfaceInteraction si;
        bool hit = scene.ray_intersect(ray, si);
        for (const Aov &a : m_aovs) out = write(a.kind, scene, si, hit, out);
        return result;
    }

    std::string to_string() const override {
        return fmt::format("AovIntegrator[{} aovs, nested={}]", m_aovs.size(),
                           m_nested ? m_nested->to_string() : "none");
    }

private:
    static std::string trim(const std::string &s) {
        size_t b = s.find_first_not_of(" \t\n"), e = s.find_last_not_of(" \t\n");
        return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
    }

    static Kind parse_kind(const std::string &t, const Properties &props) {
        static const std::pair<const char *, Kind> table[] = {
            {"albedo", Kind::Albedo},        {"depth", Kind::Depth},
            {"position", Kind::Position},    {"uv", Kind::UV},
            {"geo_normal", Kind::GeoNormal}, {"sh_normal", Kind::ShNormal},
            {"dp_du", Kind::DpDu},           {"dp_dv", Kind::DpDv},
            {"prim_index", Kind::PrimIndex}, {"shape_index", Kind::ShapeIndex}};
        std::string known;
        for (auto &[name, kind] : table) {
            if (t == name) return kind;
            known += known.empty() ? name : std::string(", ") + name;
        }
        FACET_THROW_AT(props.location("aovs"), "aov: unknown AOV type \"{}\" (known: {})", t,
                       known);
    }

    static std::vector<const char *> suffixes(Kind k) {
        switch (k) {
        case Kind::Albedo:
            return {"R", "G", "B"};
        case Kind::UV:
            return {"U", "V"};
        case Kind::Depth:
        case Kind::PrimIndex:
        case Kind::ShapeIndex:
            return {""};
        default:
            return {"X", "Y", "Z"};
        }
    }

    static float *put3(float *out, const Vector3f &v) {
        out[0] = v.x;
        out[1] = v.y;
        out[2] = v.z;
        return out + 3;
    }

    float *write(Kind k, const Scene &scene, const SurfaceInteraction &si, bool hit,
                 float *out) const {
        switch (k) {
        case Kind::Albedo: {
            Color3f c = hit ? si.bsdf()->eval_diffuse_reflectance(si) : Color3f(0.f);
            if (m_spectral && hit)
                c = spectral_to_srgb(c, si.wavelengths, wavelength_weights(si.wavelengths));
            out[0] = c.r;
            out[1] = c.g;
            out[2] = c.b;
            return out + 3;
        }
        case Kind::Depth:
            *out = hit ? si.t : 0.f;
            return out + 1;
        case Kind::Position:
            return put3(out, hit ? si.p : Vector3f(0.f));
        case Kind::UV:
            out[0] = hit ? si.uv.x : 0.f;
            out[1] = hit ? si.uv.y : 0.f;
            return out + 2;
        case Kind::GeoNormal:
            return put3(out, hit ? si.n : Vector3f(0.f));
        case Kind::ShNormal:
            return put3(out, hit ? si.sh_frame.n : Vector3f(0.f));
        case Kind::DpDu:
            return put3(out, hit ? si.dp_du : Vector3f(0.f));
        case Kind::DpDv:
            return put3(out, hit ? si.dp_dv : Vector3f(0.f));
        case Kind::PrimIndex:
            *out = hit ? float(si.prim_index) : -1.f;
            return out + 1;
        case Kind::ShapeIndex:
            *out = hit ? float(shape_index(scene, si.shape)) : -1.f;
            return out + 1;
        }
        return out;
    }

    static int shape_index(const Scene &scene, const Shape *shape) {
        const auto &shapes = scene.shapes();
        for (size_t i = 0; i < shapes.size(); ++i)
            if (shapes[i].get() == shape) return int(i);
        return -1;
    }

    bool m_spectral; ///< the albedo is a spectral value to develop
    std::vector<Aov> m_aovs;
    std::shared_ptr<SamplingIntegrator> m_nested;
    size_t m_nested_aovs = 0;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::AovIntegrator, Integrator, "aov",
                          "Geometric and material AOVs (albedo, normals, depth, ...) as extra "
                          "channels",
                          DOC, ::facet::AllModes)
