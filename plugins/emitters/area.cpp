static const char *DOC = R"DOC(
# area: area light

Turns the shape it is nested in into a light source that emits `radiance` from the front side of
its surface (the side the shading normal points to; use `flip_normals` on the shape to turn it
around). Direction sampling uses the shape's own strategy (uniform area, or the visible cone for
spheres).

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| radiance | spectrum or texture | 1 | Emitted radiance (a number, `rgb`, `spectrum` or nested texture, evaluated at the surface uv) |
| to_world | transform | — | Not accepted (an error): the emitter follows the shape it is nested in |

An area emitter must be nested in a shape (or referenced by one).

```xml
<shape type="rectangle">
    <emitter type="area">
        <rgb name="radiance" value="10, 9, 8"/>
    </emitter>
</shape>
```
)DOC";

#include <facet/emitter.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/shape.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class AreaLight final : public Emitter {
public:
    explicit AreaLight(const Properties &props) {
        if (props.has("to_world"))
            FACET_THROW_AT(props.location("to_world"),
                           "area emitter: to_world is not supported, the emitter follows the "
                           "transform of the shape it is nested in");
        m_radiance = props.texture("radiance", 1.f, SpectrumKind::Emission);
        m_flags = EmitterFlags::Surface;
        if (m_radiance->is_spatially_varying()) m_flags = m_flags | EmitterFlags::SpatiallyVarying;
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &u) const override {
        const Shape &shape = require_shape();
        DirectionSample ds = shape.sample_direction(ref, u);
        ds.emitter = this;
        // Only the front side emits: the sampled point must face the reference point.
        if (!(ds.pdf > 0.f) || dot(ds.n, ds.d) >= 0.f) {
            ds.pdf = 0.f;
            return {ds, Color3f(0.f)};
        }
        return {ds, radiance_at(ds) / ds.pdf};
    }

    float pdf_direction(const Interaction &ref, const DirectionSample &ds) const override {
        const Shape &shape = require_shape();
        if (dot(ds.n, ds.d) >= 0.f) return 0.f;
        return shape.pdf_direction(ref, ds);
    }

    /// Emitted rays: a uniform point on the shape and a cosine-weighted direction on its front
    /// side; the weight L·π/pdf_area is the power the ray carries per unit of the joint density.
    std::pair<Ray, Color3f> sample_ray(const Point2f &u_pos, const Point2f &u_dir) const override {
        const Shape &shape = require_shape();
        PositionSample ps = shape.sample_position(u_pos);
        if (!(ps.pdf > 0.f)) return {Ray(), Color3f(0.f)};
        Frame frame(ps.n);
        Vector3f d = frame.to_world(warp::square_to_cosine_hemisphere(u_dir));
        Interaction origin;
        origin.p = ps.p;
        origin.n = ps.n;
        origin.t = 0.f;
        DirectionSample at;
        static_cast<PositionSample &>(at) = ps;
        return {origin.spawn_ray(d), radiance_at(at) * (Pi / ps.pdf)};
    }

    std::optional<Color3f> constant_radiance() const override {
        if (m_radiance->is_spatially_varying()) return std::nullopt;
        return m_radiance->mean();
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        if (Frame::cos_theta(si.wi) <= 0.f) return Color3f(0.f);
        return m_radiance->eval(si);
    }

    std::string to_string() const override {
        // Not the shape's to_string(): that one prints its emitter, i.e. this.
        return fmt::format("AreaLight[radiance = {}, {}]", m_radiance->to_string(),
                           m_shape ? fmt::format("on a shape of area {}", m_shape->surface_area())
                                   : std::string("not attached to a shape"));
    }

private:
    const Shape &require_shape() const {
        if (!m_shape)
            FACET_THROW("area emitter{}: not attached to a shape (an area emitter must be nested "
                        "in a <shape>)",
                        id().empty() ? std::string() : " \"" + id() + "\"");
        return *m_shape;
    }

    /// Radiance at a sampled point: textures are evaluated at the point's uv.
    Color3f radiance_at(const DirectionSample &ds) const {
        if (!m_radiance->is_spatially_varying()) return m_radiance->mean();
        SurfaceInteraction si;
        si.p = ds.p;
        si.n = ds.n;
        si.uv = ds.uv;
        si.sh_frame = Frame(ds.n);
        si.wi = Vector3f(0.f, 0.f, 1.f);
        si.t = ds.dist;
        si.shape = m_shape;
        return m_radiance->eval(si);
    }

    std::shared_ptr<Texture> m_radiance;
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::AreaLight, Emitter, "area", "Area light attached to a shape", DOC)
