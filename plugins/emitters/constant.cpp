static const char *DOC = R"DOC(
# constant: constant environment light

An environment that surrounds the scene and sends the same `radiance` from every direction.
Directions are sampled uniformly over the sphere (pdf 1/4π); the sampled point lies beyond the
scene's bounding sphere, so shadow rays towards it cross the whole scene. Emitted rays (for the
particle tracer) come from a uniform direction and a uniform point of the disk of the bounding
sphere's radius facing it, just outside the sphere, as in Mitsuba.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| radiance | spectrum or texture | 1 | Emitted radiance (a number, `rgb`, `spectrum` or texture) |
| sampling_weight | float | — | How often light samples pick this emitter, relative to the others (Mitsuba 3's; unset: facet's choice, see README) |

```xml
<emitter type="constant">
    <rgb name="radiance" value="1.0"/>
</emitter>
```
)DOC";

#include <facet/emitter.h>
#include <facet/frame.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/scene.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class ConstantLight final : public Emitter {
public:
    explicit ConstantLight(const Properties &props) {
        m_radiance = props.texture("radiance", 1.f, SpectrumKind::Emission);
        m_flags = EmitterFlags::Infinite;
        if (m_radiance->is_spatially_varying()) m_flags = m_flags | EmitterFlags::SpatiallyVarying;
    }

    void set_scene(const Scene &scene) override {
        const BoundingBox3f &bbox = scene.bbox();
        float radius = bbox.bounding_sphere_radius();
        if (bbox.valid() && std::isfinite(radius) && radius > 0.f) {
            m_center = bbox.center();
            // Slightly larger than the bounding sphere, so the sampled points lie outside it.
            m_radius = radius * (1.f + RayEpsilon);
        } else {
            m_center = Point3f(0.f);
            m_radius = 1.f;
        }
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &u) const override {
        DirectionSample ds;
        ds.d = warp::square_to_uniform_sphere(u);
        // A point at distance 2r: beyond the bounding sphere for every reference point inside it.
        ds.dist = 2.f * m_radius;
        ds.p = ref.p + ds.d * ds.dist;
        ds.n = -ds.d;
        ds.uv = u;
        ds.pdf = InvFourPi;
        ds.delta = false;
        ds.emitter = this;
        return {ds, radiance_along(ds.d, ref.wavelengths) * (4.f * Pi)};
    }

    float pdf_direction(const Interaction &, const DirectionSample &) const override {
        return InvFourPi;
    }

    /// A ray entering the bounding sphere: travel direction w uniform on the sphere, origin on
    /// the disk of radius r facing it (centre c - w r). Power per ray: L 4π · π r².
    std::pair<Ray, Color3f> sample_ray(const Point2f &u_pos, const Point2f &u_dir,
                                       const Wavelengths &wavelengths) const override {
        const Vector3f w = warp::square_to_uniform_sphere(u_dir);
        const Point2f disk = warp::square_to_uniform_disk_concentric(u_pos);
        const Frame frame(w);
        const Point3f o = m_center + (frame.s * disk.x + frame.t * disk.y - w) * m_radius;
        const float area = Pi * m_radius * m_radius;
        Ray ray(o, w);
        ray.wavelengths = wavelengths;
        return {ray, radiance_along(-w, wavelengths) * (4.f * Pi * area)};
    }

    Color3f eval(const SurfaceInteraction &si) const override { return m_radiance->eval(si); }

    /// The radiance arriving from every direction at the scene's bounding sphere.
    float power() const override {
        return 4.f * Pi * Pi * m_radius * m_radius * std::max(m_radiance->mean().luminance(), 0.f);
    }

    std::string to_string() const override {
        return fmt::format("ConstantLight[radiance = {}, bounding sphere = ({}, {}, {}) r {}]",
                           m_radiance->to_string(), m_center.x, m_center.y, m_center.z, m_radius);
    }

private:
    /// Radiance arriving from direction d (a miss record, as Scene passes to eval()) at the
    /// path's wavelengths `lambda` (spectral mode).
    Color3f radiance_along(const Vector3f &d, const Wavelengths &lambda) const {
        if (!m_radiance->is_spatially_varying()) return m_radiance->mean();
        SurfaceInteraction si;
        si.wi = -d;
        si.wavelengths = lambda;
        return m_radiance->eval(si);
    }

    std::shared_ptr<Texture> m_radiance;
    Point3f m_center{0.f, 0.f, 0.f};
    float m_radius = 1.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::ConstantLight, Emitter, "constant", "Constant environment light",
                          DOC, ::facet::AllModes)
