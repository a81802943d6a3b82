#pragma once

#include <facet/shape.h>
#include <facet/transform.h>

#include <string>
#include <vector>

namespace facet {

/// Triangle mesh shared with Embree. Loader plugins (obj, ply, serialized, rectangle, cube) fill
/// the object-space arrays and call initialize().
class Mesh : public Shape {
public:
    explicit Mesh(const Properties &props);

    BoundingBox3f bbox() const override { return m_bbox; }
    float surface_area() const override { return m_area; }
    RTCGeometry embree_geometry(RTCDevice device) const override;
    void compute_surface_interaction(const Ray &ray, float t, uint32_t prim_index,
                                     const Point2f &uv, SurfaceInteraction &si) const override;
    PositionSample sample_position(const Point2f &u) const override;
    bool is_mesh() const override { return true; }
    std::string to_string() const override;

    size_t vertex_count() const { return m_positions.size() / 3; }
    size_t face_count() const { return m_faces.size() / 3; }
    Point3f vertex_position(size_t i) const {
        return {m_positions[3 * i], m_positions[3 * i + 1], m_positions[3 * i + 2]};
    }
    bool has_vertex_normals() const { return !m_normals.empty(); }
    bool has_uvs() const { return !m_uvs.empty(); }
    bool has_vertex_colors() const { return !m_colors.empty(); }
    const std::vector<float> &positions() const { return m_positions; }
    const std::vector<float> &normals() const { return m_normals; }
    const std::vector<float> &uvs() const { return m_uvs; }
    const std::vector<float> &colors() const { return m_colors; }
    const std::vector<uint32_t> &faces() const { return m_faces; }
    const std::string &name() const { return m_name; }

protected:
    /// Checks the arrays (indices in range, finite positions; errors name `m_name`), applies
    /// `to_world` (normals by its inverse transpose), drops vertex normals when `face_normals`,
    /// flips normals when `flip_normals`, and builds the area table for sampling.
    void initialize(const Transform &to_world, bool face_normals, bool flip_normals);
    /// Smooth vertex normals from the faces around each vertex (angle-weighted), for loaders
    /// whose file has none and `face_normals` is off (Mitsuba does the same). Call it after
    /// initialize() so the weights are those of the world-space triangles.
    void recompute_vertex_normals();

    std::string m_name;             ///< file name or plugin name, for messages
    std::vector<float> m_positions; ///< 3 per vertex (+1 padding float for Embree after initialize)
    std::vector<float> m_normals;   ///< 3 per vertex or empty
    std::vector<float> m_uvs;       ///< 2 per vertex or empty
    std::vector<float> m_colors;    ///< 3 per vertex or empty
    std::vector<uint32_t> m_faces;  ///< 3 per triangle
    bool m_flip_normals = false;

private:
    std::vector<float> m_area_cdf; ///< cumulative triangle areas, normalised
    float m_area = 0.f;
    BoundingBox3f m_bbox;
};

} // namespace facet
