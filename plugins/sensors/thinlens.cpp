static const char *DOC = R"DOC(
# thinlens: perspective camera with a thin lens (depth of field)

A perspective camera whose rays start on a circular aperture of radius `aperture_radius` and
converge on the plane at `focus_distance`: objects on that plane are sharp, others blur. The
frame and field of view are those of `perspective` (looks down local +Z, +X is left).

| Parameter       | Type      | Default            | Description                                               |
|-----------------|-----------|--------------------|-----------------------------------------------------------|
| to_world        | transform | identity           | Camera-to-world transform (usually a `<lookat>`)          |
| aperture_radius | float     | —                  | Radius of the lens aperture in scene units (required, ≥ 0)|
| focus_distance  | float     | —                  | Distance of the plane in focus (required, > 0)            |
| fov             | float     | (from focal_length)| Field of view in degrees along `fov_axis`                 |
| fov_axis        | string    | x                  | x, y, diagonal, smaller or larger                         |
| focal_length    | string    | 50mm               | 35 mm equivalent focal length; not with `fov`             |
| near_clip       | float     | 0.01               | Near clipping distance                                    |
| far_clip        | float     | 10000              | Far clipping distance                                     |
| shutter_open    | float     | 0                  | Accepted for compatibility; facet renders still images    |
| shutter_close   | float     | 0                  | Accepted for compatibility (>= shutter_open)              |
| srf | spectrum | none | Spectral response function (the spectral modes only): the wavelengths are drawn from it and the radiance is weighted by it before the film develops it; not with a `specfilm` |
| (film)          | film      | hdrfilm            | Nested film                                               |
| (sampler)       | sampler   | independent        | Nested sampler                                            |

```xml
<sensor type="thinlens">
    <float name="aperture_radius" value="0.1"/>
    <float name="focus_distance" value="5"/>
    <float name="fov" value="40"/>
</sensor>
```
)DOC";

#include <facet/fov.h>
#include <facet/plugin.h>
#include <facet/sensor.h>
#include <facet/warp.h>

namespace facet {

class ThinLensCamera final : public Sensor {
public:
    explicit ThinLensCamera(const Properties &props) : Sensor(props) {
        const Point2i size = m_film->size();
        const double aspect = double(size.x) / double(size.y);
        double x_fov = perspective_x_fov(props, aspect);
        m_tan_x = float(std::tan(0.5 * x_fov * (Pi / 180.0)));
        m_tan_y = float(double(m_tan_x) / aspect);
        m_aperture_radius = float(props.get_float("aperture_radius"));
        m_focus_distance = float(props.get_float("focus_distance"));
        m_near_clip = float(props.get_float("near_clip", 1e-2));
        m_far_clip = float(props.get_float("far_clip", 1e4));
        if (!(m_aperture_radius >= 0.f))
            FACET_THROW_AT(props.location("aperture_radius"),
                           "aperture_radius must be >= 0, got {}", m_aperture_radius);
        if (!(m_focus_distance > 0.f))
            FACET_THROW_AT(props.location("focus_distance"),
                           "focus_distance must be positive, got {}", m_focus_distance);
        if (!(m_near_clip > 0.f) || !(m_far_clip > m_near_clip))
            FACET_THROW_AT(props.location(),
                           "the clipping planes must satisfy 0 < near_clip < far_clip");
        // As in Mitsuba: the importance and the lens density are those of a rigid camera.
        if (has_scale(m_to_world))
            FACET_THROW_AT(props.location("to_world"),
                           "scale factors in the camera-to-world transformation are not allowed "
                           "(to_world = {})",
                           m_to_world.to_string());
        m_world_to_local = m_to_world.inverse();
        m_forward = normalize(m_to_world.apply_vector(Vector3f(0.f, 0.f, 1.f)));
    }

    bool needs_aperture_sample() const override { return true; }

    std::pair<Ray, Color3f> sample_ray(float time, const Point2f &film_pos,
                                       const Point2f &aperture_sample) const override {
        // Point on the plane in focus that the pinhole ray through film_pos would reach.
        Vector3f pinhole((1.f - 2.f * film_pos.x) * m_tan_x, (1.f - 2.f * film_pos.y) * m_tan_y,
                         1.f);
        Point3f focus = pinhole * m_focus_distance;
        Point2f lens = warp::square_to_uniform_disk_concentric(aperture_sample) * m_aperture_radius;
        Point3f origin(lens.x, lens.y, 0.f);
        Vector3f d = normalize(focus - origin);
        float inv_z = 1.f / d.z;
        Ray ray(m_to_world.apply_point(origin), normalize(m_to_world.apply_vector(d)),
                m_near_clip * inv_z, m_far_clip * inv_z);
        ray.time = time;
        return {ray, Color3f(1.f)};
    }

    bool supports_direction_sampling() const override { return true; }

    /// A uniform point on the lens (as sample_ray draws it) connected to ref; the film position
    /// is where the ray from that lens point through ref crosses the plane in focus. With uniform
    /// film and lens samples of weight 1 the importance is We = 1 / (A pi r^2 cos^4 theta)
    /// (A = 4 tan_x tan_y), so We / pdf_solid_angle = 1 / (A cos^3 theta dist^2), as for a
    /// pinhole at the lens point.
    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &u) const override {
        DirectionSample ds;
        const Point3f local = m_world_to_local.apply_point(ref.p);
        const Point2f lens = warp::square_to_uniform_disk_concentric(u) * m_aperture_radius;
        const Point3f lens_p(lens.x, lens.y, 0.f);
        ds.p = m_to_world.apply_point(lens_p);
        ds.n = m_forward;
        ds.delta = !(m_aperture_radius > 0.f);
        const Vector3f to_lens = ds.p - ref.p;
        const float dist2 = dot(to_lens, to_lens);
        if (!(dist2 > 0.f)) return {ds, Color3f(0.f)};
        ds.dist = std::sqrt(dist2);
        ds.d = to_lens / ds.dist;
        Point2f film;
        if (!film_position(local, lens_p, film)) return {ds, Color3f(0.f)};
        const Point2i size = m_film->size();
        ds.uv = Point2f(film.x * float(size.x), film.y * float(size.y));
        const Vector3f w = local - lens_p;
        const float cos_theta = w.z / norm(w);
        ds.pdf = ds.delta ? 1.f : dist2 / (cos_theta * Pi * m_aperture_radius * m_aperture_radius);
        const float weight =
            1.f / (4.f * m_tan_x * m_tan_y * cos_theta * cos_theta * cos_theta * dist2);
        return {ds, Color3f(weight)};
    }

    float pdf_direction(const Interaction &ref, const DirectionSample &ds) const override {
        if (!(m_aperture_radius > 0.f)) return 0.f;
        const Point3f lens = m_world_to_local.apply_point(ds.p);
        // A little slack: a rim point sample_direction() drew comes back from world space
        // rounded, and must keep its density.
        const float r2 = m_aperture_radius * m_aperture_radius;
        if (lens.x * lens.x + lens.y * lens.y > r2 * (1.f + 1e-4f)) return 0.f;
        const Point3f local = m_world_to_local.apply_point(ref.p);
        const Point3f lens_p(lens.x, lens.y, 0.f);
        // Zero where sample_direction() gives no sample: the ray from this lens point to the
        // reference point must pass through the film (and the point lie in the clipping range).
        Point2f film;
        if (!film_position(local, lens_p, film)) return 0.f;
        const Vector3f w = local - lens_p;
        const float dist2 = dot(w, w);
        if (!(dist2 > 0.f)) return 0.f;
        const float cos_theta = w.z / std::sqrt(dist2);
        return dist2 / (cos_theta * Pi * m_aperture_radius * m_aperture_radius);
    }

    std::string to_string() const override {
        return fmt::format(
            "ThinLensCamera[aperture_radius={}, focus_distance={}, film={}, sampler={}]",
            m_aperture_radius, m_focus_distance, m_film->to_string(), m_sampler->to_string());
    }

private:
    /// The film position in [0, 1)² of the camera ray from lens point `lens_p` through the local
    /// point `local`: false when there is none (outside the clipping range, behind the lens, or
    /// off the film).
    bool film_position(const Point3f &local, const Point3f &lens_p, Point2f &film) const {
        if (local.z < m_near_clip || local.z > m_far_clip) return false;
        const Vector3f w = local - lens_p;
        if (!(w.z > 0.f)) return false;
        const float t = m_focus_distance / w.z;
        const float fx = lens_p.x + w.x * t, fy = lens_p.y + w.y * t;
        film.x = 0.5f * (1.f - fx / (m_focus_distance * m_tan_x));
        film.y = 0.5f * (1.f - fy / (m_focus_distance * m_tan_y));
        return film.x >= 0.f && film.x < 1.f && film.y >= 0.f && film.y < 1.f;
    }

    float m_tan_x = 1.f, m_tan_y = 1.f;
    float m_aperture_radius = 0.f, m_focus_distance = 1.f;
    float m_near_clip = 1e-2f, m_far_clip = 1e4f;
    Transform m_world_to_local;
    Vector3f m_forward{0.f, 0.f, 1.f};
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::ThinLensCamera, Sensor, "thinlens",
                          "Perspective camera with a thin lens (depth of field)", DOC,
                          ::facet::AllModes)
