static const char *DOC = R"DOC(
# point: point light

An isotropic point light. The irradiance it gives a surface at distance d whose normal makes an
angle θ with the direction to the light is `intensity`·cos θ/d². It cannot be hit by rays.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| intensity | spectrum | 1 | Radiant intensity (power per unit solid angle; a number, `rgb` or `spectrum`) |
| position | point | (0, 0, 0) | Position of the light (give this or `to_world`, not both) |
| to_world | transform | identity | Places the light at the image of the origin |
| sampling_weight | float | — | How often light samples pick this emitter, relative to the others (Mitsuba 3's; unset: facet's choice, see README) |

```xml
<emitter type="point">
    <point name="position" x="0" y="5" z="0"/>
    <rgb name="intensity" value="10"/>
</emitter>
```
)DOC";

#include <facet/emitter.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class PointLight final : public Emitter {
public:
    explicit PointLight(const Properties &props) {
        if (props.has("position") && props.has("to_world"))
            FACET_THROW_AT(props.location("to_world"),
                           "point emitter: give either position or to_world, not both");
        if (props.has("position"))
            m_position = props.get_vector("position");
        else
            m_position = props.get_transform("to_world", Transform()).apply_point(Point3f(0.f));
        try {
            m_intensity = SpectralValue(props.texture("intensity", 1.f, SpectrumKind::Emission));
        } catch (const Error &e) {
            throw Error(props.location("intensity"), e.message());
        }
        if (!is_finite(m_position))
            FACET_THROW_AT(props.location(), "point emitter: the position must be finite");
        m_flags = EmitterFlags::DeltaPosition;
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &) const override {
        DirectionSample ds;
        ds.p = m_position;
        ds.n = Normal3f(0.f);
        ds.uv = Point2f(0.f);
        ds.pdf = 1.f;
        ds.delta = true;
        ds.emitter = this;
        Vector3f d = m_position - ref.p;
        float dist2 = squared_norm(d);
        ds.dist = std::sqrt(dist2);
        if (!(ds.dist > 0.f)) {
            ds.pdf = 0.f;
            return {ds, Color3f(0.f)};
        }
        ds.d = d / ds.dist;
        return {ds, m_intensity.at(ref.wavelengths) / dist2};
    }

    float pdf_direction(const Interaction &, const DirectionSample &) const override { return 0.f; }
    Color3f eval(const SurfaceInteraction &) const override { return Color3f(0.f); }

    /// Emitted rays: uniform directions; the weight is the total power per unit of the
    /// direction density, 4π·intensity.
    std::pair<Ray, Color3f> sample_ray(const Point2f &, const Point2f &u_dir,
                                       const Wavelengths &wavelengths) const override {
        Ray ray(m_position, warp::square_to_uniform_sphere(u_dir));
        ray.wavelengths = wavelengths;
        return {ray, m_intensity.at(wavelengths) * (4.f * Pi)};
    }

    float pdf_ray_direction(const Vector3f &d) const override {
        return warp::square_to_uniform_sphere_pdf(d);
    }

    float power() const override {
        return 4.f * Pi * std::max(m_intensity.mean().luminance(), 0.f);
    }

    std::optional<LightBounds> light_bounds() const override {
        LightBounds b;
        b.bbox.expand(m_position);
        b.cos_normals = -1.f; // every direction
        b.power = power();
        return b;
    }

    std::string to_string() const override {
        return fmt::format("PointLight[position = ({}, {}, {}), intensity = ({}, {}, {})]",
                           m_position.x, m_position.y, m_position.z, m_intensity.mean().r,
                           m_intensity.mean().g, m_intensity.mean().b);
    }

private:
    Point3f m_position;
    SpectralValue m_intensity;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::PointLight, Emitter, "point", "Isotropic point light", DOC,
                          ::facet::AllModes)
