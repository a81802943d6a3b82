static const char *DOC = R"DOC(
# distant: distant radiance meter

Records the radiance leaving the scene in one direction, averaged over a target (the adjoint
of the `directional` emitter). Every ray travels along the sensor's local +Z axis, which is the
`direction` parameter or given by `to_world` (not both); it starts outside the scene's
bounding sphere. Where the rays aim:

- no `target`: uniformly over the cross-section of the scene's bounding sphere (rays that miss
  everything record the environment, or zero);
- a `target` point: every ray passes through it;
- a nested `target` shape: uniformly over its surface area (the shape is only a sampling
  region, it is not added to the scene).

As in Mitsuba 3 the film must be 1x1 pixels (use the box filter).

| Parameter | Type | Default | Description |
|---|---|---|---|
| direction | vector | (0, 0, 1) | Direction the rays travel (instead of to_world) |
| to_world | transform | identity | Sensor-to-world transform; rays travel along its +Z axis |
| target | point or shape | (none) | Where the rays aim (see above) |
| shutter_open | float | 0 | Accepted for compatibility; facet renders still images |
| shutter_close | float | 0 | Accepted for compatibility (must be >= shutter_open) |
| srf | spectrum | none | Spectral response function (the spectral modes only): the wavelengths are drawn from it and the radiance is weighted by it before the film develops it; not with a `specfilm` |
| (film) | film | hdrfilm | Nested film; must be 1x1 pixels |
| (sampler) | sampler | independent | Nested sampler |

```xml
<sensor type="distant">
    <vector name="direction" value="0, -1, 0"/>
    <point name="target" value="0, 0, 0"/>
    <film type="hdrfilm">
        <integer name="width" value="1"/>
        <integer name="height" value="1"/>
        <rfilter type="box"/>
    </film>
</sensor>
```
)DOC";

#include <facet/frame.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/shape.h>
#include <facet/warp.h>

#include <cmath>

namespace facet {

class DistantSensor final : public Sensor, public SceneSensor {
public:
    enum class Target { None, Point, Shape };

    explicit DistantSensor(const Properties &props) : Sensor(props) {
        if (props.has("direction")) {
            if (props.has("to_world"))
                FACET_THROW_AT(props.location("direction"),
                               "distant: give either direction or to_world, not both");
            const Vector3f d = props.get_vector("direction");
            const float len = norm(d);
            if (!(len > 0.f) || !std::isfinite(len))
                FACET_THROW_AT(props.location("direction"),
                               "distant: direction must be a non-zero finite vector");
            Vector3f unused, up;
            coordinate_system(d / len, unused, up);
            m_to_world = Transform::look_at(Point3f(0.f), Point3f(d / len), up);
        }
        m_direction = normalize(m_to_world.apply_vector(Vector3f(0.f, 0.f, 1.f)));
        m_across_x = m_to_world.apply_vector(Vector3f(1.f, 0.f, 0.f));
        m_across_y = m_to_world.apply_vector(Vector3f(0.f, 1.f, 0.f));
        if (!is_finite(m_direction))
            FACET_THROW_AT(props.location("to_world"), "distant: to_world is degenerate");

        if (props.has("target")) {
            if (props.type("target") == Properties::Type::Vector) {
                m_target = Target::Point;
                m_target_point = props.get_vector("target");
            } else if (props.type("target") == Properties::Type::Object) {
                m_target_shape = props.get_object<Shape>("target");
                if (!m_target_shape)
                    FACET_THROW_AT(props.location("target"),
                                   "distant: target must be a point or a nested shape");
                m_target = Target::Shape;
            } else {
                FACET_THROW_AT(props.location("target"),
                               "distant: target must be a point or a nested shape");
            }
        }

        if (m_film->size() != Point2i(1, 1))
            FACET_THROW_AT(props.location(), "distant: the film must be 1x1 pixels, got {}x{}",
                           m_film->size().x, m_film->size().y);
        if (m_film->rfilter().radius() > 0.5f + 1e-5f)
            FACET_LOG(Warn,
                      "distant: use a reconstruction filter of radius 0.5 or less (e.g. box)");
    }

    void set_scene(const Scene &scene) override {
        const BoundingBox3f &b = scene.bbox();
        if (b.valid()) {
            m_center = (b.min + b.max) * 0.5f;
            m_radius = b.bounding_sphere_radius();
        }
        m_radius = std::max(RayEpsilon, m_radius * (1.f + RayEpsilon));
    }

    bool needs_aperture_sample() const override { return m_target != Target::Point; }

    std::pair<Ray, Color3f> sample_ray(float time, const Point2f &,
                                       const Point2f &aperture_sample) const override {
        Point3f o;
        switch (m_target) {
        case Target::Point:
            o = m_target_point - m_direction * (2.f * m_radius);
            break;
        case Target::Shape: {
            const PositionSample ps = m_target_shape->sample_position(aperture_sample);
            o = ps.p - m_direction * (2.f * m_radius);
            break;
        }
        case Target::None: {
            const Point2f q = warp::square_to_uniform_disk_concentric(aperture_sample);
            o = m_center + (m_across_x * q.x + m_across_y * q.y) * m_radius -
                m_direction * m_radius;
            break;
        }
        }
        Ray ray(o, m_direction);
        ray.time = time;
        return {ray, Color3f(1.f)};
    }

    std::string to_string() const override {
        static const char *targets[] = {"none", "point", "shape"};
        return fmt::format("DistantSensor[direction=({}, {}, {}), target={}, film={}]",
                           m_direction.x, m_direction.y, m_direction.z, targets[int(m_target)],
                           m_film->to_string());
    }

private:
    Target m_target = Target::None;
    Point3f m_target_point;
    std::shared_ptr<Shape> m_target_shape;
    Vector3f m_direction, m_across_x, m_across_y;
    Point3f m_center;
    float m_radius = 0.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::DistantSensor, Sensor, "distant",
                          "Distant radiance meter: radiance leaving the scene in one direction",
                          DOC, ::facet::AllModes)
