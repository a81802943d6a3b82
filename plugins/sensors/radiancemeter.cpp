static const char *DOC = R"DOC(
# radiancemeter: radiance meter

Measures the radiance arriving at one point from one direction: every sample traces the same
ray, from the origin of `to_world` along its local +Z axis (the limit of a perspective camera
whose field of view tends to zero). For measurements and tests of the renderer. The film must
be 1x1 pixels; a filter wider than the box logs a warning (it does not change the value).

The sensor is placed either by `to_world` or by the pair `origin`/`direction` (both needed);
when `to_world` is given, `origin` and `direction` are ignored, as in Mitsuba 3.

| Parameter | Type | Default | Description |
|---|---|---|---|
| to_world | transform | identity | Sensor-to-world transform (looks along local +Z) |
| origin | point | (0, 0, 0) | Position of the meter (with `direction`) |
| direction | vector | (0, 0, 1) | Viewing direction (with `origin`) |
| shutter_open | float | 0 | Accepted for compatibility; facet renders still images |
| shutter_close | float | 0 | Accepted for compatibility (must be >= shutter_open) |
| srf | spectrum | none | Spectral response function (the spectral modes only): the wavelengths are drawn from it and the radiance is weighted by it before the film develops it; not with a `specfilm` |
| (film) | film | hdrfilm | Nested film; must be 1x1 pixels |
| (sampler) | sampler | independent | Nested sampler |

```xml
<sensor type="radiancemeter">
    <point name="origin" value="0, 1, 4"/>
    <vector name="direction" value="0, 0, -1"/>
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
#include <facet/sensor.h>

#include <cmath>

namespace facet {

class RadianceMeter final : public Sensor {
public:
    explicit RadianceMeter(const Properties &props) : Sensor(props) {
        if (props.has("to_world")) {
            props.mark_queried("origin");
            props.mark_queried("direction");
        } else if (props.has("origin") != props.has("direction")) {
            FACET_THROW_AT(props.location(),
                           "radiancemeter: give both origin and direction (or to_world)");
        } else if (props.has("origin")) {
            const Point3f origin = props.get_vector("origin");
            const Vector3f direction = props.get_vector("direction");
            const float len = norm(direction);
            if (!(len > 0.f) || !std::isfinite(len) || !is_finite(origin))
                FACET_THROW_AT(props.location("direction"),
                               "radiancemeter: direction must be a non-zero finite vector");
            Vector3f up, unused;
            coordinate_system(direction / len, up, unused);
            m_to_world = Transform::look_at(origin, origin + direction, up);
        }
        check_film(props, *m_film, "radiancemeter");
        m_origin = m_to_world.apply_point(Point3f(0.f));
        m_direction = normalize(m_to_world.apply_vector(Vector3f(0.f, 0.f, 1.f)));
        if (!is_finite(m_origin) || !is_finite(m_direction))
            FACET_THROW_AT(props.location("to_world"), "radiancemeter: to_world is degenerate");
    }

    /// The same ray for every film position.
    std::pair<Ray, Color3f> sample_ray(float time, const Point2f &,
                                       const Point2f &) const override {
        Ray ray(m_origin, m_direction);
        ray.time = time;
        return {ray, Color3f(1.f)};
    }

    std::string to_string() const override {
        return fmt::format("RadianceMeter[origin=({}, {}, {}), direction=({}, {}, {}), film={}]",
                           m_origin.x, m_origin.y, m_origin.z, m_direction.x, m_direction.y,
                           m_direction.z, m_film->to_string());
    }

    /// 1x1 film; a warning for a filter wider than a pixel's half-width.
    static void check_film(const Properties &props, const Film &film, const char *name) {
        if (film.size() != Point2i(1, 1))
            FACET_THROW_AT(props.location(), "{}: the film must be 1x1 pixels, got {}x{}", name,
                           film.size().x, film.size().y);
        if (film.rfilter().radius() > 0.5f + 1e-5f)
            FACET_LOG(Warn,
                      "{}: use a reconstruction filter of radius 0.5 or less (e.g. box); {} "
                      "spreads samples beyond the single pixel",
                      name, film.rfilter().to_string());
    }

private:
    Point3f m_origin;
    Vector3f m_direction;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::RadianceMeter, Sensor, "radiancemeter",
                          "Radiance meter: the radiance along one ray", DOC, ::facet::AllModes)
