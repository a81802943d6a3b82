static const char *DOC = R"DOC(
# perspective

Pinhole perspective camera. It looks down +Z of its local frame with +X to the left and +Y up,
which is the frame `<lookat>` builds; image x grows to the right and y downwards. The field of
view is given either by `fov` (with `fov_axis`) or by a 35 mm equivalent `focal_length`; without
either, the camera has a 50 mm lens on a 36x24 mm film, measured along the diagonal.

| Parameter | Type | Default | Description |
|---|---|---|---|
| to_world | transform | identity | Camera-to-world transform (usually a `<lookat>`; rigid: no scale, as in Mitsuba) |
| fov | float | (from focal_length) | Field of view in degrees, 0 < fov < 180, along `fov_axis` |
| fov_axis | string | x | Axis of `fov`: x, y, diagonal, smaller or larger (read only with `fov`) |
| focal_length | string | 50mm | 35 mm equivalent focal length ("<f>mm", or a bare number in mm); not with `fov` |
| near_clip | float | 0.01 | Distance of the near clipping plane (> 0) |
| far_clip | float | 10000 | Distance of the far clipping plane (> near_clip) |
| principal_point_offset_x | float | 0 | Shift of the image centre, in units of the film width |
| principal_point_offset_y | float | 0 | Shift of the image centre, in units of the film height |
| focus_distance | float | (none) | Accepted for Mitsuba scenes that give it; a pinhole is always in focus |
| shutter_open | float | 0 | Accepted for compatibility; facet renders still images |
| shutter_close | float | 0 | Accepted for compatibility (must be >= shutter_open) |
| srf | spectrum | none | Spectral response function (the spectral modes only): the wavelengths are drawn from it and the radiance is weighted by it before the film develops it; not with a `specfilm` |
| (film) | film | hdrfilm | Nested film |
| (sampler) | sampler | independent | Nested sampler |

```xml
<sensor type="perspective">
    <float name="fov" value="39.3"/>
    <transform name="to_world">
        <lookat origin="0, 1, 6.8" target="0, 1, 0" up="0, 1, 0"/>
    </transform>
    <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
    <film type="hdrfilm"><integer name="width" value="512"/><integer name="height" value="512"/></film>
</sensor>
```
)DOC";

#include <facet/fov.h>
#include <facet/plugin.h>
#include <facet/sensor.h>

#include <cmath>

namespace facet {

class PerspectiveCamera final : public Sensor {
public:
    explicit PerspectiveCamera(const Properties &props) : Sensor(props) {
        const Point2i size = m_film->size();
        const double aspect = double(size.x) / double(size.y);
        m_x_fov = perspective_x_fov(props, aspect);

        m_near_clip = float(props.get_float("near_clip", 1e-2));
        m_far_clip = float(props.get_float("far_clip", 1e4));
        if (!(m_near_clip > 0.f) || !(m_far_clip > m_near_clip) || !std::isfinite(m_far_clip))
            FACET_THROW_AT(
                props.location(),
                "the clipping planes must satisfy 0 < near_clip < far_clip (finite), got "
                "near_clip = {}, far_clip = {}",
                m_near_clip, m_far_clip);
        m_principal_offset = Point2f(float(props.get_float("principal_point_offset_x", 0.0)),
                                     float(props.get_float("principal_point_offset_y", 0.0)));
        if (props.has("focus_distance")) {
            double fd = props.get_float("focus_distance");
            if (!(fd > 0.0))
                FACET_THROW_AT(props.location("focus_distance"),
                               "focus_distance must be positive, got {}", fd);
        }

        m_tan_x = float(std::tan(0.5 * m_x_fov * 3.14159265358979323846 / 180.0));
        m_tan_y = float(double(m_tan_x) / aspect);
        // As in Mitsuba: the importance and the lens density are those of a rigid camera.
        if (has_scale(m_to_world))
            FACET_THROW_AT(props.location("to_world"),
                           "scale factors in the camera-to-world transformation are not allowed "
                           "(to_world = {})",
                           m_to_world.to_string());
        m_origin = m_to_world.apply_point(Point3f(0.f));
        m_world_to_local = m_to_world.inverse();
        for (int i = 0; i < 3; ++i) {
            const auto &row = m_to_world.matrix.m[i];
            m_rotation[i] = Vector3f(row[0], row[1], row[2]);
        }
    }

    std::pair<Ray, Color3f> sample_ray(float time, const Point2f &film_pos,
                                       const Point2f &aperture_sample) const override {
        // Film x grows to the right, which is local -X (local +X is the camera's left).
        const float u = film_pos.x + m_principal_offset.x, v = film_pos.y + m_principal_offset.y;
        // The point on the plane z = 1, rotated (m_to_world.apply_vector(), inline) and then
        // normalised once: the rotation keeps lengths, so its length alone gives the clipping
        // distances (near and far depths over cos θ = 1 / |local|). One square root and one
        // division on the chain where normalising before the rotation put two of each.
        const Vector3f local((1.f - 2.f * u) * m_tan_x, (1.f - 2.f * v) * m_tan_y, 1.f);
        const float length = norm(local);
        const Vector3f d(dot(m_rotation[0], local), dot(m_rotation[1], local),
                         dot(m_rotation[2], local));
        Ray ray(m_origin, normalize(d), m_near_clip * length, m_far_clip * length);
        ray.time = time;
        return {ray, Color3f(1.f)};
    }

    bool supports_direction_sampling() const override { return true; }

    /// Pinhole importance: with a uniform film position and weight 1 per camera ray, the
    /// importance per solid angle is We = 1 / (A cos^4 theta) (A = 4 tan_x tan_y, the film's
    /// area on the plane z = 1); times the camera's cos theta and the 1/dist^2 of the connection.
    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &) const override {
        DirectionSample ds;
        ds.p = m_origin;
        ds.delta = true;
        const Vector3f to_camera = m_origin - ref.p;
        const float dist2 = dot(to_camera, to_camera);
        if (!(dist2 > 0.f)) return {ds, Color3f(0.f)};
        const float dist = std::sqrt(dist2);
        ds.dist = dist;
        ds.d = to_camera / dist;
        const Vector3f local = m_world_to_local.apply_vector(ref.p - m_origin);
        if (!(local.z > 0.f)) return {ds, Color3f(0.f)};
        const float ln = norm(local);
        // Camera rays span near_clip / cos theta .. far_clip / cos theta: depths near..far.
        if (local.z < m_near_clip || local.z > m_far_clip) return {ds, Color3f(0.f)};
        const float u = 0.5f * (1.f - local.x / (local.z * m_tan_x)) - m_principal_offset.x;
        const float v = 0.5f * (1.f - local.y / (local.z * m_tan_y)) - m_principal_offset.y;
        if (!(u >= 0.f && u < 1.f && v >= 0.f && v < 1.f)) return {ds, Color3f(0.f)};
        const Point2i size = m_film->size();
        ds.uv = Point2f(u * float(size.x), v * float(size.y));
        ds.pdf = 1.f;
        const float cos_theta = local.z / ln;
        const float importance =
            1.f / (4.f * m_tan_x * m_tan_y * cos_theta * cos_theta * cos_theta);
        return {ds, Color3f(importance / dist2)};
    }

    float pdf_direction(const Interaction &, const DirectionSample &) const override { return 0.f; }

    std::string to_string() const override {
        return fmt::format(
            "PerspectiveCamera[x_fov={:.4f}, near_clip={}, far_clip={}, origin=({}, {}, {}), "
            "film={}, sampler={}]",
            m_x_fov, m_near_clip, m_far_clip, m_origin.x, m_origin.y, m_origin.z,
            m_film->to_string(), m_sampler->to_string());
    }

private:
    double m_x_fov = 0.0;
    float m_near_clip = 1e-2f, m_far_clip = 1e4f;
    float m_tan_x = 1.f, m_tan_y = 1.f;
    Point2f m_principal_offset;
    Point3f m_origin;
    Vector3f m_rotation[3]; ///< the rows of m_to_world's upper 3x3 block, for sample_ray()
    Transform m_world_to_local;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::PerspectiveCamera, Sensor, "perspective",
                          "Pinhole perspective camera", DOC, ::facet::AllModes)
