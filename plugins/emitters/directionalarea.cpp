static const char *DOC = R"DOC(
# directionalarea: area light emitting only along the surface normal

Like `area`, but every point of the shape emits only in the direction of the shape's normal
there: `radiance` is the power per unit area leaving the surface along the normal (a flat shape
sends a parallel beam, a sphere a radial one). Since cameras and surfaces have zero probability
of looking along exactly that direction, the emitter is invisible to camera rays and to emitter
sampling: only a particle tracer (`ptracer`), which starts paths on the emitter, renders its
light. The emitted power is `radiance` times the shape's surface area.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| radiance | spectrum or texture | 1 | Emitted power per unit area along the normal (a number, `rgb`, `spectrum` or nested texture, evaluated at the surface uv) |
| to_world | transform | — | Not accepted (an error): the emitter follows the shape it is nested in |
| sampling_weight | float | — | How often light samples pick this emitter, relative to the others (Mitsuba 3's; unset: facet's choice, see README) |

```xml
<shape type="rectangle">
    <emitter type="directionalarea">
        <rgb name="radiance" value="3, 2.5, 2"/>
    </emitter>
</shape>
```
)DOC";

#include <facet/emitter.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/shape.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class DirectionalAreaLight final : public Emitter {
public:
    explicit DirectionalAreaLight(const Properties &props) {
        if (props.has("to_world"))
            FACET_THROW_AT(props.location("to_world"),
                           "directionalarea emitter: to_world is not supported, the emitter "
                           "follows the transform of the shape it is nested in");
        m_radiance = props.texture("radiance", 1.f, SpectrumKind::Emission);
        m_flags = EmitterFlags::Surface | EmitterFlags::DeltaDirection;
        if (m_radiance->is_spatially_varying()) m_flags = m_flags | EmitterFlags::SpatiallyVarying;
    }

    /// No direction from a reference point is the emission direction with non-zero probability.
    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &,
                                                         const Point2f &) const override {
        DirectionSample ds;
        ds.emitter = this;
        return {ds, Color3f(0.f)};
    }
    float pdf_direction(const Interaction &, const DirectionSample &) const override { return 0.f; }
    Color3f eval(const SurfaceInteraction &) const override { return Color3f(0.f); }

    /// A uniform point on the shape and the normal there; the weight is radiance / pdf_area
    /// (radiance times the area for uniform sampling): the power of the ray.
    std::pair<Ray, Color3f> sample_ray(const Point2f &u_pos, const Point2f &,
                                       const Wavelengths &wavelengths) const override {
        const Shape &shape = require_shape();
        PositionSample ps = shape.sample_position(u_pos);
        if (!(ps.pdf > 0.f)) return {Ray(), Color3f(0.f)};
        Interaction origin;
        origin.p = ps.p;
        origin.n = ps.n;
        origin.t = 0.f;
        origin.wavelengths = wavelengths;
        return {origin.spawn_ray(ps.n), radiance_at(ps, wavelengths) / ps.pdf};
    }

    float power() const override {
        if (!m_shape) return -1.f;
        return m_shape->surface_area() * std::max(m_radiance->mean().luminance(), 0.f);
    }

    /// The shape's box and normals (light leaves along them; bounded here by their hemispheres).
    std::optional<LightBounds> light_bounds() const override { return surface_light_bounds(); }

    std::string to_string() const override {
        return fmt::format("DirectionalAreaLight[radiance = {}, {}]", m_radiance->to_string(),
                           m_shape ? fmt::format("on a shape of area {}", m_shape->surface_area())
                                   : std::string("not attached to a shape"));
    }

private:
    const Shape &require_shape() const {
        if (!m_shape)
            FACET_THROW("directionalarea emitter{}: not attached to a shape (it must be nested "
                        "in a <shape>)",
                        id().empty() ? std::string() : " \"" + id() + "\"");
        return *m_shape;
    }

    /// The radiance at a sampled point and the path's wavelengths (the spectral modes).
    Color3f radiance_at(const PositionSample &ps, const Wavelengths &wavelengths) const {
        SurfaceInteraction si;
        si.wavelengths = wavelengths;
        si.p = ps.p;
        si.n = ps.n;
        si.uv = ps.uv;
        si.sh_frame = Frame(ps.n);
        si.wi = Vector3f(0.f, 0.f, 1.f);
        si.t = 0.f;
        si.shape = m_shape;
        return m_radiance->eval(si);
    }

    std::shared_ptr<Texture> m_radiance;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::DirectionalAreaLight, Emitter, "directionalarea",
                          "Area light that emits only along the surface normal", DOC,
                          ::facet::AllModes)
