#pragma once

#include <facet/bbox.h>
#include <facet/interaction.h>
#include <facet/object.h>
#include <facet/properties.h>

#include <embree3/rtcore.h>

#include <memory>

namespace facet {

/// A sensor that measures on the surface of the shape it is nested in (irradiancemeter, as in
/// Mitsuba 3). The shape calls attach_shape() while it is constructed; the scene then renders
/// the sensor like a top-level one.
class ShapeSensor {
public:
    virtual ~ShapeSensor();
    virtual void attach_shape(const Shape *shape) = 0;
};

/// Geometry. Plugins derive from Shape (exact primitives, Embree user geometry) or Mesh
/// (triangles). The base class takes the nested `bsdf` and `emitter` children.
class Shape : public Object {
public:
    explicit Shape(const Properties &props);
    ObjectType type() const override { return ObjectType::Shape; }

    virtual BoundingBox3f bbox() const = 0;
    virtual float surface_area() const = 0;
    /// A cone holding every normal of the surface (shading normals included): its axis and the
    /// cosine of its half-angle. Default: every direction (cosine -1).
    virtual std::pair<Vector3f, float> normal_cone() const {
        return {Vector3f(0.f, 0.f, 1.f), -1.f};
    }

    /// Creates and commits this shape's Embree geometry on `device`. The scene attaches it and
    /// keeps the mapping from geometry id back to the shape. nullptr: nothing to attach (a
    /// shapegroup, which is only visible through its instances).
    virtual RTCGeometry embree_geometry(RTCDevice device) const = 0;

    /// For instances: fills `si` for a hit on geometry `geom_id` of the instanced group (Embree's
    /// hit.geomID when hit.instID[0] is this shape's geometry). Other shapes throw.
    virtual void compute_instance_interaction(const Ray &ray, float t, uint32_t geom_id,
                                              uint32_t prim_index, const Point2f &uv,
                                              SurfaceInteraction &si) const {
        FACET_THROW("shape {} is not an instance", to_string());
    }

    /// Fills the geometry of `si` (p, n, uv, dp_du, dp_dv, sh_frame, and shape and prim_index)
    /// for a hit at distance t on primitive `prim_index`; `uv` is what Embree reported
    /// (barycentrics for triangles, whatever the user geometry stored otherwise). The scene
    /// then sets t, shape, prim_index and wi (in sh_frame) for a direct hit; an instance sets
    /// t and wi for the hits on its members. Shapes may set them too (the same values).
    virtual void compute_surface_interaction(const Ray &ray, float t, uint32_t prim_index,
                                             const Point2f &uv, SurfaceInteraction &si) const = 0;

    /// Uniform point on the surface; pdf per unit area.
    virtual PositionSample sample_position(const Point2f &u) const = 0;
    virtual float pdf_position(const PositionSample &ps) const { return 1.f / surface_area(); }

    /// A point on the surface seen from `ref`, with a solid-angle pdf. The default converts
    /// sample_position(); shapes with a better strategy (spheres) override both. An override
    /// may leave the sample's uv at zero when the shape's emitter is not SpatiallyVarying (its
    /// radiance does not read it).
    virtual DirectionSample sample_direction(const Interaction &ref, const Point2f &u) const;
    virtual float pdf_direction(const Interaction &ref, const DirectionSample &ds) const;

    /// For shapes whose uv is a one-to-one map of [0, 1]² onto the whole surface (rectangle):
    /// the point of texture coordinates `uv` (p, n, uv; pdf unset) and the area of surface per
    /// unit of uv area there, |∂p/∂u × ∂p/∂v|. An area light samples its texture through it.
    /// Other shapes return false (the default), and their area lights sample by area.
    virtual bool eval_parameterization(const Point2f &uv, PositionSample &ps,
                                       float &area_per_uv) const {
        (void)uv, (void)ps, (void)area_per_uv;
        return false;
    }

    const BSDF *bsdf() const { return m_bsdf.get(); }
    const Emitter *emitter() const { return m_emitter.get(); }
    /// A nested sensor (see ShapeSensor), or nullptr.
    std::shared_ptr<Sensor> sensor_ptr() const { return m_sensor; }
    std::shared_ptr<BSDF> bsdf_ptr() const { return m_bsdf; }
    std::shared_ptr<Emitter> emitter_ptr() const { return m_emitter; }
    /// The scene gives shapes without a BSDF a default diffuse one.
    void set_bsdf(std::shared_ptr<BSDF> bsdf) { m_bsdf = std::move(bsdf); }
    /// Attaches an area emitter (traverse() relinks a re-created one); the emitter is told its
    /// shape, as when the shape is constructed with it.
    void set_emitter(std::shared_ptr<Emitter> emitter);
    virtual bool is_mesh() const { return false; }
    std::string to_string() const override;

protected:
    /// For shapes that interpret their nested objects themselves (shapegroup, instance).
    Shape() = default;
    /// Short description of the attached emitter for to_string() ("none", or its id): the
    /// emitter's own to_string() prints its shape, so printing it here would recurse.
    std::string emitter_label() const;

    std::shared_ptr<BSDF> m_bsdf;
    std::shared_ptr<Emitter> m_emitter;
    std::shared_ptr<Sensor> m_sensor;
};

} // namespace facet
