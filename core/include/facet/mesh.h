#pragma once

#include <facet/shape.h>
#include <facet/transform.h>
#include <facet/warp.h>

#include <algorithm>
#include <string>
#include <vector>

namespace facet {

/// Triangle mesh shared with Embree. Loader plugins (obj, ply, serialized, rectangle, cube) fill
/// the object-space arrays and call initialize().
class Mesh : public Shape {
public:
    explicit Mesh(const Properties &props);

    BoundingBox3f bbox() const override { return m_bbox; }
    /// The faces' normals and, with vertex normals, those too (flip_normals applied).
    std::pair<Vector3f, float> normal_cone() const override;
    float surface_area() const override { return m_area; }
    RTCGeometry embree_geometry(RTCDevice device) const override;
    /// Final: every mesh, whatever loader filled it, computes its hits the same way.
    void compute_surface_interaction(const Ray &ray, float t, uint32_t prim_index,
                                     const Point2f &uv, SurfaceInteraction &si) const final;
    /// Final: a point uniform in area, whatever loader filled the mesh.
    PositionSample sample_position(const Point2f &u) const final;
    bool is_mesh() const override { return true; }
    std::string to_string() const override;

    size_t vertex_count() const { return m_positions.size() / 3; }
    size_t face_count() const { return m_faces.size() / 3; }
    Point3f vertex_position(size_t i) const {
        return {m_positions[3 * i], m_positions[3 * i + 1], m_positions[3 * i + 2]};
    }
    bool has_vertex_normals() const { return !m_normals.empty(); }
    bool has_uvs() const { return !m_uvs.empty(); }
    bool has_vertex_colors() const { return attribute("vertex_color") != nullptr; }
    const std::vector<float> &positions() const { return m_positions; }
    const std::vector<float> &normals() const { return m_normals; }
    const std::vector<float> &uvs() const { return m_uvs; }
    const std::vector<uint32_t> &faces() const { return m_faces; }
    const std::string &name() const { return m_name; }
    bool flip_normals() const { return m_flip_normals; }
    /// The shading normal is constant over every face, so normals and shading frames of the
    /// faces were computed at load (hits only interpolate the position and uv).
    bool flat_faces() const { return !m_face_table.empty(); }

    /// A named per-vertex or per-face quantity carried by the mesh (Mitsuba's mesh attributes:
    /// `vertex_color`, `vertex_tint_color`, `face_weight`, ...), read by `mesh_attribute`.
    struct Attribute {
        std::string name;      ///< starts with "vertex_" or "face_"
        uint32_t channels = 0; ///< values per vertex or face (1 to 4)
        bool per_face = false; ///< name starts with "face_"
        std::vector<float> data;
    };
    /// The attribute called `name`, or nullptr (no allocation: a linear search by name).
    const Attribute *attribute(const std::string &name) const;
    const std::vector<Attribute> &attributes() const { return m_attributes; }
    /// The attribute names, comma-separated ("none" without any), for error messages.
    std::string attribute_names() const;
    /// `a` at the hit `si` on this mesh (si.prim_index, si.p): a vertex attribute interpolated
    /// with the barycentric coordinates of si.p in its triangle, a face attribute constant over
    /// the triangle. Writes a.channels values to `out`.
    void eval_attribute(const Attribute &a, const SurfaceInteraction &si, float *out) const;

protected:
    /// Checks the arrays (indices in range, finite positions; errors name `m_name`), applies
    /// `to_world` (normals by its inverse transpose), drops vertex normals when `face_normals`,
    /// flips normals when `flip_normals`, and builds the area table for sampling.
    void initialize(const Transform &to_world, bool face_normals, bool flip_normals);
    /// Smooth vertex normals from the faces around each vertex (angle-weighted), for loaders
    /// whose file has none and `face_normals` is off (Mitsuba does the same). Call it after
    /// initialize() so the weights are those of the world-space triangles.
    void recompute_vertex_normals();
    /// Adds a named attribute (loaders; before initialize(), which checks its size against the
    /// vertex or face count). The name must start with vertex_ or face_ and be new.
    void add_attribute(std::string name, uint32_t channels, std::vector<float> data);

    std::string m_name;             ///< file name or plugin name, for messages
    std::vector<float> m_positions; ///< 3 per vertex (+1 padding float for Embree after initialize)
    std::vector<float> m_normals;   ///< 3 per vertex or empty
    std::vector<float> m_uvs;       ///< 2 per vertex or empty
    std::vector<float> m_colors;    ///< 3 per vertex or empty; initialize() makes it vertex_color
    std::vector<uint32_t> m_faces;  ///< 3 per triangle
    bool m_flip_normals = false;

    /// Fills m_face_table when the shading normal is constant over every face (no vertex
    /// normals, or equal ones at the three corners of each face): then the geometric normal and
    /// the shading frame of each face are computed once here instead of at every hit. Called by
    /// initialize() and recompute_vertex_normals(); again by a shape that edits m_normals after.
    void build_face_table();

private:
    friend class Scene; // reaches the two below without a virtual call (core/src/mesh_inline.h)
    /// True for a flat mesh without texture coordinates, whose hits flat_hit() computes.
    bool has_flat_hit() const { return !m_face_table.empty() && m_uvs.empty(); }
    /// compute_surface_interaction() of a mesh with has_flat_hit().
    void flat_hit(uint32_t prim_index, const Point2f &uv, SurfaceInteraction &si) const;
    /// sample_position() written into `ps`; only for a mesh with area.
    void sample_point(Point2f u, PositionSample &ps) const;

    /// Per face when the mesh is flat (else empty): geometric normal, shading normal and the
    /// shading frame's s, 9 floats (the frame's t is cross(ns, s)).
    std::vector<float> m_face_table;
    std::vector<Attribute> m_attributes;
    std::vector<float> m_area_cdf; ///< cumulative triangle areas, normalised
    /// sample_point()'s out-of-line parts: the face of u_x in m_area_cdf by a binary search, the
    /// unit normal of face f (flip_normals applied) and the uv at barycentrics b of face f.
    size_t find_area_face(float u_x) const;
    Normal3f face_normal(size_t f) const;
    Point2f face_uv(size_t f, const Point2f &b) const;
    float m_area = 0.f;
    BoundingBox3f m_bbox;
};

} // namespace facet
