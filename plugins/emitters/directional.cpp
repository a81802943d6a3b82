static const char *DOC = R"DOC(
# directional: distant directional light

Light arriving from one direction everywhere in the scene, like sunlight. The direction is
given by `direction` or as the +Z axis of `to_world` (not both). `irradiance` is the power per
unit area on a surface perpendicular to the direction.

| Parameter  | Type             | Default | Description                                         |
|------------|------------------|---------|-----------------------------------------------------|
| irradiance | spectrum or rgb  | 1       | Irradiance on a surface facing the light (W/m²)     |
| direction  | vector           | —       | Direction the light travels in (world space)        |
| to_world   | transform        | —       | Alternatively: the light travels along local +Z     |
| sampling_weight | float | — | How often light samples pick this emitter, relative to the others (Mitsuba 3's; unset: facet's choice, see README) |

```xml
<emitter type="directional">
    <vector name="direction" value="0, -1, -1"/>
    <rgb name="irradiance" value="3"/>
</emitter>
```
)DOC";

#include <facet/emitter.h>
#include <facet/plugin.h>
#include <facet/scene.h>
#include <facet/texture.h>
#include <facet/warp.h>

namespace facet {

class DirectionalEmitter final : public Emitter {
public:
    explicit DirectionalEmitter(const Properties &props) {
        try {
            m_irradiance = SpectralValue(props.texture("irradiance", 1.f, SpectrumKind::Emission));
        } catch (const Error &e) {
            throw Error(props.location("irradiance"), e.message());
        }
        bool has_dir = props.has("direction"), has_xf = props.has("to_world");
        if (has_dir && has_xf)
            FACET_THROW_AT(props.location(),
                           "directional: give either \"direction\" or \"to_world\", not both");
        Vector3f d(0.f, 0.f, 1.f);
        if (has_dir)
            d = props.get_vector("direction");
        else if (has_xf)
            d = props.get_transform("to_world").apply_vector(Vector3f(0.f, 0.f, 1.f));
        if (!(norm(d) > 0.f) || !is_finite(d))
            FACET_THROW_AT(props.location(),
                           "directional: the direction must be a non-zero vector");
        m_direction = normalize(d);
        m_flags = EmitterFlags::DeltaDirection | EmitterFlags::Infinite;
    }

    void set_scene(const Scene &scene) override {
        m_radius = std::max(scene.bbox().bounding_sphere_radius(), 1e-3f);
        if (scene.bbox().valid()) m_center = scene.bbox().center();
    }

    /// Emitted rays (light tracing): a uniform point on the disk of the scene's bounding sphere
    /// that faces the light, one radius up-beam of the centre, travelling along the direction;
    /// the weight irradiance x disk area is the power each ray carries.
    std::pair<Ray, Color3f> sample_ray(const Point2f &u_pos, const Point2f &,
                                       const Wavelengths &wavelengths) const override {
        const Frame frame(m_direction);
        const Point2f p = warp::square_to_uniform_disk_concentric(u_pos) * m_radius;
        const Point3f o = m_center - m_direction * m_radius + frame.s * p.x + frame.t * p.y;
        Ray ray(o, m_direction);
        ray.wavelengths = wavelengths;
        return {ray, m_irradiance.at(wavelengths) * (Pi * m_radius * m_radius)};
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &) const override {
        DirectionSample ds;
        ds.d = -m_direction;
        ds.dist = Infinity;
        ds.p = ref.p + ds.d * (2.f * m_radius);
        ds.n = m_direction;
        ds.pdf = 1.f;
        ds.delta = true;
        ds.emitter = this;
        return {ds, m_irradiance.at(ref.wavelengths)};
    }

    float pdf_direction(const Interaction &, const DirectionSample &) const override { return 0.f; }
    Color3f eval(const SurfaceInteraction &) const override { return Color3f(0.f); }

    /// The irradiance over the disk of the scene's bounding sphere.
    float power() const override {
        return Pi * m_radius * m_radius * std::max(m_irradiance.mean().luminance(), 0.f);
    }

    std::string to_string() const override {
        return fmt::format("DirectionalEmitter[direction=[{}, {}, {}], irradiance=[{}, {}, {}]]",
                           m_direction.x, m_direction.y, m_direction.z, m_irradiance.mean().r,
                           m_irradiance.mean().g, m_irradiance.mean().b);
    }

private:
    SpectralValue m_irradiance;
    Vector3f m_direction;
    float m_radius = 1.f;
    Point3f m_center{0.f, 0.f, 0.f};
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::DirectionalEmitter, Emitter, "directional",
                          "Distant light from a single direction (sun-like)", DOC,
                          ::facet::AllModes)
