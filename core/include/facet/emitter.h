#pragma once

#include <facet/bbox.h>
#include <facet/color.h>
#include <facet/interaction.h>
#include <facet/logger.h>
#include <facet/object.h>

#include <optional>
#include <utility>

namespace facet {

enum class EmitterFlags : uint32_t {
    Empty = 0,
    DeltaPosition = 0x1,  ///< point-like (point, spot)
    DeltaDirection = 0x2, ///< one direction (directional)
    Infinite = 0x4,       ///< at infinity (constant, envmap, directional)
    Surface = 0x8,        ///< attached to a shape (area)
    SpatiallyVarying = 0x10,
    Delta = DeltaPosition | DeltaDirection,
};
constexpr EmitterFlags operator|(EmitterFlags a, EmitterFlags b) {
    return EmitterFlags(uint32_t(a) | uint32_t(b));
}
constexpr EmitterFlags operator&(EmitterFlags a, EmitterFlags b) {
    return EmitterFlags(uint32_t(a) & uint32_t(b));
}
constexpr bool has_flag(EmitterFlags a, EmitterFlags b) { return (uint32_t(a) & uint32_t(b)) != 0; }

/// Where an emitter lies and where its light goes, for choosing among emitters by their
/// importance to a point (the scene's light hierarchy). Light leaves from inside `bbox`, from
/// surfaces whose normals lie within the angle acos(cos_normals) of `axis` (every direction at
/// -1), each into directions within acos(cos_emission) of its normal, at most a hemisphere
/// (cos_emission 0, a Lambertian surface; an emitter whose light leaves in every direction says
/// cos_normals -1). `two_sided`: the opposite normals as well. `power`: Emitter::power(). Bounds
/// may be loose (the choice only gets worse), never too tight: an emitter the bounds rule out
/// for a point is never sampled from it.
struct LightBounds {
    BoundingBox3f bbox;
    Vector3f axis = Vector3f(0.f, 0.f, 1.f);
    float cos_normals = -1.f;
    float cos_emission = 0.f;
    float power = 0.f;
    bool two_sided = false;
};

/// How an estimator uses a light sample (Emitter::sample_direction_mis(),
/// Scene::sample_emitter_direction()). `Alone`: its estimate stands by itself (light tracing, an
/// integrator that samples only the emitters), so the samples must follow the light wherever it
/// is. `MIS`: it is weighted by multiple importance sampling against a BSDF sample of the same
/// direction, whose density pdf_emitter_direction(..., LightSampling::MIS) gives; an emitter may
/// then send fewer samples where BSDF sampling already does well. Both keep the expected image;
/// an estimator must use one mode for the samples and the densities it weights them with.
enum class LightSampling { Alone, MIS };

/// A light source.
///
/// Conventions: sample_direction() samples a point on the emitter as seen from `ref` and returns
/// the record (direction, distance, solid-angle pdf; pdf = 1 and delta = true for delta emitters)
/// and the weight L·G/pdf that the integrator multiplies by the BSDF, without any visibility test.
/// eval() gives the radiance arriving along a ray that hit the emitter: for area emitters `si` is
/// the hit (si.wi in the local shading frame); for infinite emitters `si` is a miss record whose
/// sh_frame is the identity and whose si.wi = -ray.d in world space.
class Emitter : public Object {
public:
    ObjectType type() const override { return ObjectType::Emitter; }

    virtual std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                                 const Point2f &u) const = 0;
    /// Solid-angle density of sample_direction() for the point ds.p seen from ref (0 for delta).
    virtual float pdf_direction(const Interaction &ref, const DirectionSample &ds) const = 0;
    /// The light sample of an estimator that weights it by MIS against BSDF sampling
    /// (LightSampling::MIS), and its density. The same conventions as sample_direction() and
    /// pdf_direction(); the density may be zero only where BSDF sampling is expected to carry the
    /// light, never for a whole lobe of light (some samples must still reach every direction
    /// with light: a BSDF without a density there would otherwise lose it). `side`: zero, or a
    /// unit world-space vector such that no light counts from directions d with
    /// dot(d, side) <= 0 (the BSDF at ref reflects only to that side: BSDFFlags::WiSideOnly);
    /// the emitter may then send no samples there, and its density there may be zero. The same
    /// `side` must reach both calls for a direction. Default: the samples of sample_direction(),
    /// whatever the side.
    virtual std::pair<DirectionSample, Color3f>
    sample_direction_mis(const Interaction &ref, const Point2f &u, const Vector3f &side) const {
        return sample_direction(ref, u);
    }
    virtual float pdf_direction_mis(const Interaction &ref, const DirectionSample &ds,
                                    const Vector3f &side) const {
        return pdf_direction(ref, ds);
    }
    /// Emitted radiance; zero for delta emitters.
    virtual Color3f eval(const SurfaceInteraction &si) const = 0;

    /// Samples a ray leaving the emitter (light tracing, photon emission) from two uniform pairs:
    /// `u_pos` for the position, `u_dir` for the direction. Returns the ray and the power
    /// weight (emitted intensity or radiance·cos over the joint density). In the spectral modes
    /// the weight is the power at the path's `wavelengths`, which the ray carries
    /// (Ray::wavelengths); in the others they are ignored. Not every emitter supports it; those
    /// that do not throw.
    virtual std::pair<Ray, Color3f> sample_ray(const Point2f &u_pos, const Point2f &u_dir,
                                               const Wavelengths &wavelengths) const {
        FACET_THROW("{} cannot sample emitted rays", to_string());
    }
    /// Solid-angle density of the directions sample_ray() draws, for emitters with one origin
    /// (point, spot); `d` is a unit world-space direction.
    virtual float pdf_ray_direction(const Vector3f &d) const {
        FACET_THROW("{} cannot sample emitted rays", to_string());
    }

    /// The emitter as a value, when it is the simplest surface emitter: one constant radiance
    /// leaving the front side of its shape (the side its normal points to), the same at every
    /// point and in every direction of that side, nothing from the back. An emitter that returns
    /// it promises that eval(), sample_direction() and pdf_direction() are those of this value
    /// with the shape's own direction sampling; the scene may then compute them from the value
    /// and the shape. Default: none (the scene always asks the emitter).
    virtual std::optional<Color3f> constant_radiance() const { return std::nullopt; }
    /// An estimate of the power the emitter sends into the scene (luminance; radiance · m² · sr),
    /// used only to choose which emitter a light sample goes to: it changes the noise, never the
    /// expected image. Called once the scene's bounds are known (after set_scene()). Negative:
    /// unknown (the default), and the scene then picks every emitter with the same probability.
    virtual float power() const { return -1.f; }
    /// Bounds for the scene's light hierarchy (LightBounds), once the scene is known; none (the
    /// default) for emitters without a place (at infinity) or whose bounds are unknown: the
    /// scene then gives them the share of light samples the uniform choice would.
    virtual std::optional<LightBounds> light_bounds() const { return std::nullopt; }
    /// The `sampling_weight` the scene gave the emitter (as in Mitsuba 3: light samples go to
    /// emitters in proportion to their weights), or a negative value when it gave none.
    float sampling_weight() const { return m_sampling_weight; }
    void set_sampling_weight(float weight) { m_sampling_weight = weight; }
    /// Position in the emitter list of the scene that holds it (set by the scene).
    uint32_t scene_index() const { return m_scene_index; }
    void set_scene_index(uint32_t index) { m_scene_index = index; }

    /// Called by the shape that owns an area emitter.
    virtual void set_shape(const Shape *shape) { m_shape = shape; }
    const Shape *shape() const { return m_shape; }
    /// Called once the scene's bounds are known (infinite emitters need them).
    virtual void set_scene(const Scene &scene) {}

    EmitterFlags flags() const { return m_flags; }
    bool is_delta() const { return has_flag(m_flags, EmitterFlags::Delta); }
    bool is_infinite() const { return has_flag(m_flags, EmitterFlags::Infinite); }

protected:
    /// light_bounds() of an emitter whose light leaves its shape into the hemisphere of each
    /// normal: the shape's box and normal_cone(), and power(); none without a shape.
    std::optional<LightBounds> surface_light_bounds() const;

    EmitterFlags m_flags = EmitterFlags::Empty;
    const Shape *m_shape = nullptr;
    uint32_t m_scene_index = uint32_t(-1);
    float m_sampling_weight = -1.f;
};

} // namespace facet
