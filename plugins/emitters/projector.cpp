static const char *DOC = R"DOC(
# projector: projection light

The reciprocal of the `perspective` camera: a point light at the origin of `to_world` that
projects the `irradiance` texture through a pinhole along its local +Z axis (local +X is the
left of the image, +Y up, as for the camera; `<lookat>` builds this frame). It has the camera's
field-of-view parameters; the image's aspect ratio is that of the texture (1 for a constant).

The texture gives the irradiance on the virtual image plane at distance 1: a plane at distance
z that faces the projector receives E = π·scale·irradiance(uv) / z² everywhere inside the
frustum (as in Mitsuba 3, the emitted intensity carries the inverse of a perspective camera's
sensitivity profile, so a constant texture lights a facing plane evenly). Outside the frustum
there is no light. A delta-position light: it is reached only by direct light sampling.

| Parameter | Type | Default | Description |
|---|---|---|---|
| irradiance | texture or rgb | 1 | Irradiance on the image plane at distance 1 (evaluated at the image uv: u right, v down) |
| scale | float | 1 | Factor on the irradiance |
| fov | float | (from focal_length) | Field of view in degrees, 0 < fov < 180, along `fov_axis` |
| fov_axis | string | x | Axis of `fov`: x, y, diagonal, smaller or larger (read only with `fov`) |
| focal_length | string | 50mm | 35 mm equivalent focal length; not with `fov` |
| to_world | transform | identity | Projector-to-world transform (usually a `<lookat>`) |
| sampling_weight | float | — | How often light samples pick this emitter, relative to the others (Mitsuba 3's; unset: facet's choice, see README) |

```xml
<emitter type="projector">
    <texture type="bitmap" name="irradiance">
        <string name="filename" value="slide.png"/>
    </texture>
    <float name="scale" value="4"/>
    <float name="fov" value="30"/>
    <transform name="to_world">
        <lookat origin="0, 1, 4" target="0, 0, 0" up="0, 1, 0"/>
    </transform>
</emitter>
```
)DOC";

#include <facet/emitter.h>
#include <facet/fov.h>
#include <facet/plugin.h>
#include <facet/texture.h>
#include <facet/transform.h>

#include <cmath>

namespace facet {

class Projector final : public Emitter {
public:
    explicit Projector(const Properties &props) {
        m_irradiance = props.texture("irradiance", 1.f, SpectrumKind::Emission);
        const double scale = props.get_float("scale", 1.0);
        if (!std::isfinite(scale) || scale < 0.0)
            FACET_THROW_AT(props.location("scale"),
                           "projector: scale must be a non-negative number, got {}", scale);
        m_scale = float(scale);
        m_to_world = props.get_transform("to_world", Transform());
        m_to_local = m_to_world.inverse();

        const Point2i res = m_irradiance->resolution();
        m_aspect = float(double(res.x) / double(res.y));
        m_x_fov = float(perspective_x_fov(props, double(m_aspect)));
        m_tan_x = float(std::tan(0.5 * double(m_x_fov) * 3.14159265358979323846 / 180.0));
        m_tan_y = m_tan_x / m_aspect;
        // Area of the image rectangle on the plane z = 1.
        m_plane_area = 4.f * m_tan_x * m_tan_y;

        m_position = m_to_world.apply_point(Point3f(0.f));
        m_axis = normalize(m_to_world.apply_vector(Vector3f(0.f, 0.f, 1.f)));
        if (!is_finite(m_position) || !is_finite(m_axis))
            FACET_THROW_AT(props.location("to_world"), "projector: to_world is degenerate ({})",
                           m_to_world.to_string());
        m_flags = EmitterFlags::DeltaPosition;
        if (m_irradiance->is_spatially_varying())
            m_flags = m_flags | EmitterFlags::SpatiallyVarying;
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &) const override {
        DirectionSample ds;
        ds.p = m_position;
        ds.n = m_axis;
        ds.pdf = 1.f;
        ds.delta = true;
        ds.emitter = this;
        Vector3f to_light = m_position - ref.p;
        ds.dist = norm(to_light);
        if (!(ds.dist > 0.f)) {
            ds.pdf = 0.f;
            return {ds, Color3f(0.f)};
        }
        ds.d = to_light / ds.dist;

        Point2f uv;
        if (!image_uv(m_to_local.apply_vector(-to_light), uv)) return {ds, Color3f(0.f)};
        ds.uv = uv;
        // Intensity π·E(uv)/cos³θ (E on the plane at distance 1) over dist²; with the distance
        // along the axis z = dist·cos θ this is π·E / (z²·cos θ).
        const float z = dot(-to_light, m_axis);
        const float cos_theta = z / ds.dist;
        return {ds, eval_irradiance(uv, ref.wavelengths) * (Pi * m_scale / (z * z * cos_theta))};
    }

    float pdf_direction(const Interaction &, const DirectionSample &) const override { return 0.f; }

    /// Emitted rays: a uniform point of the image rectangle at distance 1 (the texture is not
    /// importance-sampled); the weight is intensity over the direction density, π·E(uv)·area.
    std::pair<Ray, Color3f> sample_ray(const Point2f &, const Point2f &u_dir,
                                       const Wavelengths &wavelengths) const override {
        const Vector3f local((1.f - 2.f * u_dir.x) * m_tan_x, (1.f - 2.f * u_dir.y) * m_tan_y, 1.f);
        Ray ray(m_position, normalize(m_to_world.apply_vector(local)));
        ray.wavelengths = wavelengths;
        return {ray, eval_irradiance(u_dir, ray.wavelengths) * (Pi * m_scale * m_plane_area)};
    }

    /// Density per solid angle of sample_ray(): 1/area on the plane z = 1, i.e. 1/(area·cos³θ).
    float pdf_ray_direction(const Vector3f &d) const override {
        Point2f uv;
        const Vector3f local = m_to_local.apply_vector(d);
        if (!image_uv(local, uv)) return 0.f;
        const float cos_theta = dot(normalize(d), m_axis);
        return 1.f / (m_plane_area * cos_theta * cos_theta * cos_theta);
    }

    Color3f eval(const SurfaceInteraction &) const override { return Color3f(0.f); }

    /// The irradiance on the plane at unit distance, over the image's extent there.
    float power() const override {
        return Pi * m_scale * m_plane_area * std::max(m_irradiance->mean().luminance(), 0.f);
    }

    std::string to_string() const override {
        return fmt::format(
            "Projector[position=[{}, {}, {}], axis=[{}, {}, {}], x_fov={}, aspect={}, scale={}, "
            "irradiance={}]",
            m_position.x, m_position.y, m_position.z, m_axis.x, m_axis.y, m_axis.z, m_x_fov,
            m_aspect, m_scale, m_irradiance->to_string());
    }

private:
    /// Image coordinates of the local direction `v` (u right, v down, as the camera's film);
    /// false outside the frustum.
    bool image_uv(const Vector3f &v, Point2f &uv) const {
        if (!(v.z > 0.f)) return false;
        uv = Point2f(0.5f * (1.f - v.x / (v.z * m_tan_x)), 0.5f * (1.f - v.y / (v.z * m_tan_y)));
        return uv.x >= 0.f && uv.x <= 1.f && uv.y >= 0.f && uv.y <= 1.f;
    }

    /// The irradiance texture at `uv` and the path's wavelengths `lambda` (spectral mode).
    Color3f eval_irradiance(const Point2f &uv, const Wavelengths &lambda) const {
        if (!m_irradiance->is_spatially_varying()) return m_irradiance->mean();
        SurfaceInteraction si;
        si.wavelengths = lambda;
        si.uv = uv;
        si.p = m_position;
        return m_irradiance->eval(si);
    }

    std::shared_ptr<Texture> m_irradiance;
    Transform m_to_world, m_to_local;
    Point3f m_position;
    Vector3f m_axis;
    float m_scale = 1.f, m_aspect = 1.f, m_x_fov = 0.f, m_tan_x = 0.f, m_tan_y = 0.f;
    float m_plane_area = 0.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Projector, Emitter, "projector",
                          "Projection light: a texture projected through a pinhole", DOC,
                          ::facet::AllModes)
