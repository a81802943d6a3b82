static const char *DOC = R"DOC(
# irradiancemeter: irradiance meter

Measures the irradiance (incident power per unit area) averaged over the surface of the shape
it is nested in, on the side its normals point to: each sample picks a uniform point of the
surface and a cosine-weighted direction around the normal, and carries the weight π. Under a
constant environment of radiance L with nothing in the way it reads π·L. As in Mitsuba 3 it
must be nested in a `<shape>` (it takes that shape's placement, so `to_world` is an error) and
is meant for a 1x1 film with the box filter.

| Parameter | Type | Default | Description |
|---|---|---|---|
| to_world | transform | — | Not accepted (an error): the meter follows the shape it is nested in |
| shutter_open | float | 0 | Accepted for compatibility; facet renders still images |
| shutter_close | float | 0 | Accepted for compatibility (must be >= shutter_open) |
| srf | spectrum | none | Spectral response function (the spectral modes only): the wavelengths are drawn from it and the radiance is weighted by it before the film develops it; not with a `specfilm` |
| (film) | film | hdrfilm | Nested film; 1x1 pixels (another size measures the same in every pixel) |
| (sampler) | sampler | independent | Nested sampler |

```xml
<shape type="rectangle">
    <sensor type="irradiancemeter">
        <film type="hdrfilm">
            <integer name="width" value="1"/>
            <integer name="height" value="1"/>
            <rfilter type="box"/>
        </film>
    </sensor>
</shape>
```
)DOC";

#include <facet/frame.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/sensor.h>
#include <facet/shape.h>
#include <facet/warp.h>

namespace facet {

class IrradianceMeter final : public Sensor, public ShapeSensor {
public:
    explicit IrradianceMeter(const Properties &props) : Sensor(props) {
        if (props.has("to_world"))
            FACET_THROW_AT(props.location("to_world"),
                           "irradiancemeter: to_world is not allowed; the meter takes the "
                           "placement of the shape it is nested in");
        if (m_film->size() != Point2i(1, 1))
            FACET_LOG(Warn,
                      "irradiancemeter: meant for a 1x1 film; every pixel of the {}x{} film "
                      "measures the same",
                      m_film->size().x, m_film->size().y);
        if (m_film->rfilter().radius() > 0.5f + 1e-5f)
            FACET_LOG(Warn,
                      "irradiancemeter: use a reconstruction filter of radius 0.5 or less (e.g. "
                      "box)");
    }

    void attach_shape(const Shape *shape) override { m_shape = shape; }

    bool needs_aperture_sample() const override { return true; }

    /// `film_pos` picks the point on the surface (the film is one pixel, so it is uniform),
    /// `aperture_sample` the cosine-weighted direction.
    std::pair<Ray, Color3f> sample_ray(float time, const Point2f &film_pos,
                                       const Point2f &aperture_sample) const override {
        if (!m_shape)
            FACET_THROW("irradiancemeter: not nested in a shape (it measures on the surface of "
                        "the shape that holds it)");
        const PositionSample ps = m_shape->sample_position(film_pos);
        const Vector3f d = Frame(ps.n).to_world(warp::square_to_cosine_hemisphere(aperture_sample));
        Interaction it;
        it.p = ps.p;
        it.n = ps.n;
        it.t = 0.f;
        Ray ray = it.spawn_ray(d);
        ray.time = time;
        return {ray, Color3f(Pi)};
    }

    std::string to_string() const override {
        return fmt::format("IrradianceMeter[{}, film={}]",
                           m_shape ? fmt::format("surface area {}", m_shape->surface_area())
                                   : std::string("not attached to a shape"),
                           m_film->to_string());
    }

private:
    const Shape *m_shape = nullptr;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::IrradianceMeter, Sensor, "irradiancemeter",
                          "Irradiance meter on the surface of its shape", DOC, ::facet::AllModes)
