static const char *DOC = R"DOC(
# area: area light

Turns the shape it is nested in into a light source that emits `radiance` from the front side of
its surface (the side the shading normal points to; use `flip_normals` on the shape to turn it
around). Direction sampling uses the shape's own strategy (uniform area, or the visible cone for
spheres); a textured `radiance` on a rectangle samples its texture instead (a `bitmap` by the
luminance of its texels), so a light of very uneven brightness is sampled where it is bright.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| radiance | spectrum or texture | 1 | Emitted radiance (a number, `rgb`, `spectrum` or nested texture, evaluated at the surface uv) |
| to_world | transform | — | Not accepted (an error): the emitter follows the shape it is nested in |
| sampling_weight | float | — | How often light samples pick this emitter, relative to the others (Mitsuba 3's; unset: facet's choice, see README) |

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

    /// A textured light on a shape whose uv spans it once (rectangle) samples its texture; any
    /// other samples its shape.
    void set_scene(const Scene &) override {
        m_texture_sampling = false;
        PositionSample ps;
        float area_per_uv = 0.f;
        if (m_shape && m_radiance->is_spatially_varying() &&
            m_shape->eval_parameterization(Point2f(0.5f, 0.5f), ps, area_per_uv))
            m_texture_sampling = m_radiance->prepare_position_sampling();
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &u) const override {
        const Shape &shape = require_shape();
        if (m_texture_sampling) return sample_texture(ref, u);
        DirectionSample ds = shape.sample_direction(ref, u);
        ds.emitter = this;
        // Only the front side emits: the sampled point must face the reference point.
        if (!(ds.pdf > 0.f) || dot(ds.n, ds.d) >= 0.f) {
            ds.pdf = 0.f;
            return {ds, Color3f(0.f)};
        }
        return {ds, radiance_at(ds, ref.wavelengths) / ds.pdf};
    }

    float pdf_direction(const Interaction &ref, const DirectionSample &ds) const override {
        const Shape &shape = require_shape();
        if (dot(ds.n, ds.d) >= 0.f) return 0.f;
        if (m_texture_sampling) {
            PositionSample at;
            float area_per_uv = 0.f;
            if (!shape.eval_parameterization(ds.uv, at, area_per_uv)) return 0.f;
            return m_radiance->pdf_position(ds.uv) / area_per_uv * solid_angle_factor(ds);
        }
        return shape.pdf_direction(ref, ds);
    }

    /// Emitted rays: a uniform point on the shape and a cosine-weighted direction on its front
    /// side; the weight L·π/pdf_area is the power the ray carries per unit of the joint density.
    std::pair<Ray, Color3f> sample_ray(const Point2f &u_pos, const Point2f &u_dir,
                                       const Wavelengths &wavelengths) const override {
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
        origin.wavelengths = wavelengths;
        return {origin.spawn_ray(d), radiance_at(at, wavelengths) * (Pi / ps.pdf)};
    }

    std::optional<Color3f> constant_radiance() const override {
        if (m_radiance->is_spatially_varying()) return std::nullopt;
        return m_radiance->mean();
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        if (Frame::cos_theta(si.wi) <= 0.f) return Color3f(0.f);
        return m_radiance->eval(si);
    }

    /// Radiance times area times π (every direction of the front side).
    float power() const override {
        if (!m_shape) return -1.f;
        return Pi * m_shape->surface_area() * std::max(m_radiance->mean().luminance(), 0.f);
    }

    /// The shape's box and normals; light leaves into the hemisphere of each normal.
    std::optional<LightBounds> light_bounds() const override { return surface_light_bounds(); }

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

    /// dist² / cos θ at the emitter point: from a density over area to one over solid angle
    /// (0 seen from behind).
    static float solid_angle_factor(const DirectionSample &ds) {
        const float cos_theta = -dot(ds.n, ds.d);
        return cos_theta > 0.f ? ds.dist * ds.dist / cos_theta : 0.f;
    }

    /// A uv drawn by the texture, mapped onto the shape: its density over uv, over the surface
    /// (÷ the area per unit uv), then over solid angle.
    std::pair<DirectionSample, Color3f> sample_texture(const Interaction &ref,
                                                       const Point2f &u) const {
        DirectionSample ds;
        ds.emitter = this;
        const auto [uv, pdf_uv] = m_radiance->sample_position(u);
        float area_per_uv = 0.f;
        if (!(pdf_uv > 0.f) ||
            !m_shape->eval_parameterization(uv, static_cast<PositionSample &>(ds), area_per_uv))
            return {ds, Color3f(0.f)};
        ds.d = ds.p - ref.p;
        ds.dist = norm(ds.d);
        if (!(ds.dist > 0.f)) return {ds, Color3f(0.f)};
        ds.d /= ds.dist;
        // Only the front side emits: the sampled point must face the reference point.
        ds.pdf = pdf_uv / area_per_uv * solid_angle_factor(ds);
        if (!(ds.pdf > 0.f) || !std::isfinite(ds.pdf)) {
            ds.pdf = 0.f;
            return {ds, Color3f(0.f)};
        }
        return {ds, radiance_at(ds, ref.wavelengths) / ds.pdf};
    }

    /// Radiance at a sampled point: textures are evaluated at the point's uv and at the path's
    /// wavelengths `lambda` (spectral mode).
    Color3f radiance_at(const DirectionSample &ds, const Wavelengths &lambda) const {
        if (!m_radiance->is_spatially_varying()) return m_radiance->mean();
        SurfaceInteraction si;
        si.p = ds.p;
        si.n = ds.n;
        si.uv = ds.uv;
        si.sh_frame = Frame(ds.n);
        si.wi = Vector3f(0.f, 0.f, 1.f);
        si.t = ds.dist;
        si.shape = m_shape;
        si.wavelengths = lambda;
        return m_radiance->eval(si);
    }

    std::shared_ptr<Texture> m_radiance;
    bool m_texture_sampling = false; ///< set by set_scene(): sample_texture(), not the shape
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::AreaLight, Emitter, "area", "Area light attached to a shape", DOC,
                          ::facet::AllModes)
