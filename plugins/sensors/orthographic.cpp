static const char *DOC = R"DOC(
# orthographic: parallel projection

All rays travel along the camera's local +Z. The film covers [-1, 1] in local x (the camera's
+X is to the left of the image) and [-1/aspect, 1/aspect] in y; scale `to_world` to frame a
larger or smaller region, as in Mitsuba.

| Parameter | Type      | Default     | Description                                    |
|-----------|-----------|-------------|------------------------------------------------|
| to_world  | transform | identity    | Camera-to-world transform (scale sets the view)|
| near_clip | float     | 0.01        | Near clipping distance (local units)           |
| far_clip  | float     | 10000       | Far clipping distance (local units)            |
| shutter_open | float  | 0           | Accepted for compatibility (still images)      |
| shutter_close| float  | 0           | Accepted for compatibility (>= shutter_open)   |
| srf | spectrum | none | Spectral response function (the spectral modes only): the wavelengths are drawn from it and the radiance is weighted by it before the film develops it; not with a `specfilm` |
| (film)    | film      | hdrfilm     | Nested film                                    |
| (sampler) | sampler   | independent | Nested sampler                                 |

```xml
<sensor type="orthographic">
    <transform name="to_world">
        <scale value="5"/>
        <lookat origin="0, 10, 0" target="0, 0, 0" up="0, 0, 1"/>
    </transform>
</sensor>
```
)DOC";

#include <facet/plugin.h>
#include <facet/sensor.h>

namespace facet {

class OrthographicCamera final : public Sensor {
public:
    explicit OrthographicCamera(const Properties &props) : Sensor(props) {
        const Point2i size = m_film->size();
        m_inv_aspect = float(size.y) / float(size.x);
        m_near_clip = float(props.get_float("near_clip", 1e-2));
        m_far_clip = float(props.get_float("far_clip", 1e4));
        if (!(m_near_clip >= 0.f) || !(m_far_clip > m_near_clip))
            FACET_THROW_AT(props.location(),
                           "the clipping planes must satisfy 0 <= near_clip < far_clip");
        Vector3f d = m_to_world.apply_vector(Vector3f(0.f, 0.f, 1.f));
        m_scale_z = norm(d);
        if (!(m_scale_z > 0.f))
            FACET_THROW_AT(props.location(), "orthographic: to_world is singular");
        m_direction = d / m_scale_z;
        m_world_to_local = m_to_world.inverse();
        // The film spans local x in [-1, 1] and y in [-inv_aspect, inv_aspect].
        const float area =
            norm(cross(m_to_world.apply_vector(Vector3f(2.f, 0.f, 0.f)),
                       m_to_world.apply_vector(Vector3f(0.f, 2.f * m_inv_aspect, 0.f))));
        if (!(area > 0.f)) FACET_THROW_AT(props.location(), "orthographic: to_world is singular");
        m_inv_area = 1.f / area;
    }

    std::pair<Ray, Color3f> sample_ray(float time, const Point2f &film_pos,
                                       const Point2f &) const override {
        Point3f local((1.f - 2.f * film_pos.x), (1.f - 2.f * film_pos.y) * m_inv_aspect, 0.f);
        Ray ray(m_to_world.apply_point(local), m_direction, m_near_clip * m_scale_z,
                m_far_clip * m_scale_z);
        ray.time = time;
        return {ray, Color3f(1.f)};
    }

    bool supports_direction_sampling() const override { return true; }

    /// The ray through ref runs along the viewing direction: the sensor point is ref's projection
    /// onto the film rectangle. Uniform film positions with weight 1 make the importance
    /// 1 / (film area in world units) times a delta in direction (no 1/dist^2).
    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &) const override {
        DirectionSample ds;
        ds.delta = true;
        ds.d = -m_direction;
        ds.n = m_direction;
        const Point3f local = m_world_to_local.apply_point(ref.p);
        if (local.z < m_near_clip || local.z > m_far_clip) return {ds, Color3f(0.f)};
        const float u = 0.5f * (1.f - local.x), v = 0.5f * (1.f - local.y / m_inv_aspect);
        if (!(u >= 0.f && u < 1.f && v >= 0.f && v < 1.f)) return {ds, Color3f(0.f)};
        ds.p = m_to_world.apply_point(Point3f(local.x, local.y, 0.f));
        ds.dist = local.z * m_scale_z;
        const Point2i size = m_film->size();
        ds.uv = Point2f(u * float(size.x), v * float(size.y));
        ds.pdf = 1.f;
        return {ds, Color3f(m_inv_area)};
    }

    float pdf_direction(const Interaction &, const DirectionSample &) const override { return 0.f; }

    std::string to_string() const override {
        return fmt::format("OrthographicCamera[near_clip={}, far_clip={}, film={}, sampler={}]",
                           m_near_clip, m_far_clip, m_film->to_string(), m_sampler->to_string());
    }

private:
    float m_inv_aspect = 1.f, m_near_clip = 1e-2f, m_far_clip = 1e4f, m_scale_z = 1.f;
    Vector3f m_direction{0.f, 0.f, 1.f};
    Transform m_world_to_local;
    float m_inv_area = 0.25f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::OrthographicCamera, Sensor, "orthographic",
                          "Orthographic (parallel) camera", DOC, ::facet::AllModes)
