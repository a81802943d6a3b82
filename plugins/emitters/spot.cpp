static const char *DOC = R"DOC(
# spot: spot light

A point light at the origin of `to_world` that shines along its local +Z axis into a cone.
Inside `beam_width` the intensity is full; between `beam_width` and `cutoff_angle` it falls
off linearly in angle to zero. An optional `texture` is projected through the cone (uv spans
the cone's cross-section at the cutoff angle) and multiplies the intensity.

| Parameter    | Type            | Default              | Description                              |
|--------------|-----------------|----------------------|------------------------------------------|
| intensity    | spectrum or rgb | 1                    | Radiant intensity on the axis (W/sr)     |
| cutoff_angle | float           | 20                   | Half-angle of the cone, degrees          |
| beam_width   | float           | 3/4 · cutoff_angle   | Half-angle of full intensity, degrees    |
| texture      | texture         | —                    | Pattern projected through the cone       |
| to_world     | transform       | identity             | Position and orientation (looks along +Z)|
| sampling_weight | float | — | How often light samples pick this emitter, relative to the others (Mitsuba 3's; unset: facet's choice, see README) |

```xml
<emitter type="spot">
    <transform name="to_world">
        <lookat origin="0, 5, 0" target="0, 0, 0" up="0, 0, 1"/>
    </transform>
    <rgb name="intensity" value="20"/>
    <float name="cutoff_angle" value="30"/>
</emitter>
```
)DOC";

#include <facet/emitter.h>
#include <facet/plugin.h>
#include <facet/texture.h>
#include <facet/transform.h>
#include <facet/warp.h>

namespace facet {

class SpotEmitter final : public Emitter {
public:
    explicit SpotEmitter(const Properties &props) {
        try {
            m_intensity = SpectralValue(props.texture("intensity", 1.f, SpectrumKind::Emission));
        } catch (const Error &e) {
            throw Error(props.location("intensity"), e.message());
        }
        m_texture =
            props.has("texture") ? props.texture("texture", SpectrumKind::Emission) : nullptr;
        m_to_world = props.get_transform("to_world", Transform());
        float cutoff = float(props.get_float("cutoff_angle", 20.0));
        float beam = float(props.get_float("beam_width", cutoff * 0.75));
        if (!(cutoff > 0.f && cutoff < 90.f))
            FACET_THROW_AT(props.location(),
                           "spot: cutoff_angle must be in (0, 90) degrees, got {}", cutoff);
        if (!(beam >= 0.f && beam <= cutoff))
            FACET_THROW_AT(props.location(),
                           "spot: beam_width must be in [0, cutoff_angle], got {}", beam);
        m_cutoff = deg_to_rad(cutoff);
        m_beam = deg_to_rad(beam);
        m_cos_cutoff = std::cos(m_cutoff);
        m_cos_beam = std::cos(m_beam);
        m_uv_factor = std::tan(m_cutoff);
        m_position = m_to_world.apply_point(Point3f(0.f));
        m_flags = EmitterFlags::DeltaPosition;
        if (m_texture && m_texture->is_spatially_varying())
            m_flags = m_flags | EmitterFlags::SpatiallyVarying;
    }

    /// Intensity towards the local direction d (unit vector) at the path's wavelengths `lambda`
    /// (spectral mode).
    Color3f intensity(const Vector3f &d, const Wavelengths &lambda) const {
        float cos_theta = d.z;
        if (cos_theta <= m_cos_cutoff) return Color3f(0.f);
        float falloff = 1.f;
        if (cos_theta < m_cos_beam && m_cutoff > m_beam)
            falloff = (m_cutoff - safe_acos(cos_theta)) / (m_cutoff - m_beam);
        Color3f result = m_intensity.at(lambda) * falloff;
        if (m_texture) {
            SurfaceInteraction si;
            si.wavelengths = lambda;
            si.uv = Point2f(0.5f + 0.5f * d.x / (d.z * m_uv_factor),
                            0.5f + 0.5f * d.y / (d.z * m_uv_factor));
            result *= m_texture->eval(si);
        }
        return result;
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &) const override {
        DirectionSample ds;
        ds.p = m_position;
        Vector3f to_light = m_position - ref.p;
        float dist2 = squared_norm(to_light);
        ds.dist = std::sqrt(dist2);
        ds.d = to_light / ds.dist;
        ds.n = -ds.d;
        ds.pdf = 1.f;
        ds.delta = true;
        ds.emitter = this;
        Vector3f local = normalize(m_to_world.inverse().apply_vector(-ds.d));
        return {ds, intensity(local, ref.wavelengths) / dist2};
    }

    float pdf_direction(const Interaction &, const DirectionSample &) const override { return 0.f; }

    /// Directions uniformly inside the cone (the falloff is smooth enough not to need more).
    std::pair<Ray, Color3f> sample_ray(const Point2f &, const Point2f &u_dir,
                                       const Wavelengths &wavelengths) const override {
        Vector3f local = warp::square_to_uniform_cone(u_dir, m_cos_cutoff);
        float pdf = warp::square_to_uniform_cone_pdf(local, m_cos_cutoff);
        Ray ray(m_position, normalize(m_to_world.apply_vector(local)));
        ray.wavelengths = wavelengths;
        return {ray, intensity(local, ray.wavelengths) / pdf};
    }

    float pdf_ray_direction(const Vector3f &d) const override {
        Vector3f local = normalize(m_to_world.inverse().apply_vector(d));
        return warp::square_to_uniform_cone_pdf(local, m_cos_cutoff);
    }
    Color3f eval(const SurfaceInteraction &) const override { return Color3f(0.f); }

    /// The intensity over the cone, counting the falloff's ring as half lit.
    float power() const override {
        return 2.f * Pi * (1.f - 0.5f * (m_cos_cutoff + m_cos_beam)) *
               std::max(m_intensity.mean().luminance(), 0.f);
    }

    /// A point whose light leaves within the cutoff angle of the axis.
    std::optional<LightBounds> light_bounds() const override {
        LightBounds b;
        b.bbox.expand(m_position);
        b.axis = normalize(m_to_world.apply_vector(Vector3f(0.f, 0.f, 1.f)));
        // The cone is the local one turned into the world; a transform that stretches or shears
        // widens it unevenly: then every direction.
        b.cos_normals = is_similarity(m_to_world) ? m_cos_cutoff : -1.f;
        b.cos_emission = std::cos(1e-3f); // (a margin for rounding)
        b.power = power();
        return b;
    }

    std::string to_string() const override {
        return fmt::format("SpotEmitter[position=[{}, {}, {}], cutoff={}°, beam={}°]", m_position.x,
                           m_position.y, m_position.z, rad_to_deg(m_cutoff), rad_to_deg(m_beam));
    }

private:
    /// Whether the linear part of `t` only turns and scales uniformly (angles are kept).
    static bool is_similarity(const Transform &t) {
        const Vector3f x = t.apply_vector(Vector3f(1.f, 0.f, 0.f)),
                       y = t.apply_vector(Vector3f(0.f, 1.f, 0.f)),
                       z = t.apply_vector(Vector3f(0.f, 0.f, 1.f));
        const float s2 = squared_norm(x), tol = 1e-4f * s2;
        return s2 > 0.f && std::abs(squared_norm(y) - s2) <= tol &&
               std::abs(squared_norm(z) - s2) <= tol && std::abs(dot(x, y)) <= tol &&
               std::abs(dot(x, z)) <= tol && std::abs(dot(y, z)) <= tol;
    }

    SpectralValue m_intensity;
    std::shared_ptr<Texture> m_texture;
    Transform m_to_world;
    Point3f m_position;
    float m_cutoff, m_beam, m_cos_cutoff, m_cos_beam, m_uv_factor;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::SpotEmitter, Emitter, "spot",
                          "Spot light with a linear angular falloff", DOC, ::facet::AllModes)
