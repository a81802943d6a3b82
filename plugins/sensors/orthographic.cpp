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
    }

    std::pair<Ray, Color3f> sample_ray(float time, const Point2f &film_pos,
                                       const Point2f &) const override {
        Point3f local((1.f - 2.f * film_pos.x), (1.f - 2.f * film_pos.y) * m_inv_aspect, 0.f);
        Ray ray(m_to_world.apply_point(local), m_direction, m_near_clip * m_scale_z,
                m_far_clip * m_scale_z);
        ray.time = time;
        return {ray, Color3f(1.f)};
    }

    std::string to_string() const override {
        return fmt::format("OrthographicCamera[near_clip={}, far_clip={}, film={}, sampler={}]",
                           m_near_clip, m_far_clip, m_film->to_string(), m_sampler->to_string());
    }

private:
    float m_inv_aspect = 1.f, m_near_clip = 1e-2f, m_far_clip = 1e4f, m_scale_z = 1.f;
    Vector3f m_direction{0.f, 0.f, 1.f};
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::OrthographicCamera, Sensor, "orthographic",
                    "Orthographic (parallel) camera", DOC)
