#pragma once

#include <facet/shape.h>
#include <facet/transform.h>
#include <facet/warp.h>

#include <algorithm>
#include <cstring>
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
    /// Final: the scene computes the hits of meshes with has_flat_hit() by flat_hit() directly.
    void compute_surface_interaction(const Ray &ray, float t, uint32_t prim_index,
                                     const Point2f &uv, SurfaceInteraction &si) const final;
    /// True for a flat mesh without texture coordinates (the common case), whose hits
    /// flat_hit() computes.
    bool has_flat_hit() const { return !m_face_table.empty() && m_uvs.empty(); }
    /// compute_surface_interaction() of a mesh with has_flat_hit(), inline for
    /// Scene::ray_intersect() (no virtual call): p, n, sh_frame, uv, dp_du, dp_dv, shape and
    /// prim_index of the hit at Embree's barycentrics `uv` on face `prim_index`.
    void flat_hit(uint32_t prim_index, const Point2f &uv, SurfaceInteraction &si) const;
    PositionSample sample_position(const Point2f &u) const override;
    /// sample_position() written into `ps` (p, n, uv, pdf and delta), inline for the triangle
    /// lights of Scene::sample_emitter_direction(). Only for a mesh with area (surface_area() >
    /// 0): sample_position() checks it.
    void sample_point(Point2f u, PositionSample &ps) const;
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

inline void Mesh::flat_hit(uint32_t prim_index, const Point2f &uv, SurfaceInteraction &si) const {
    FACET_ASSERT(has_flat_hit());
    const uint32_t *face = &m_faces[3 * size_t(prim_index)];
    const Point3f p0 = vertex_position(face[0]), p1 = vertex_position(face[1]),
                  p2 = vertex_position(face[2]);
    // Embree's (u, v) weight vertices 1 and 2; they serve as the texture coordinates too.
    const float b1 = uv.x, b2 = uv.y, b0 = 1.f - b1 - b2;
    si.shape = this;
    si.prim_index = prim_index;
    // Interpolating the vertices is more accurate than ray(t) far from the ray origin.
    si.p = p0 * b0 + p1 * b1 + p2 * b2;
    // Normals and the shading frame of the face were computed at load. They are copied from
    // the table, not from registers: spilled and copied back as 8-byte words, the floats
    // would be read before their 4-byte stores had reached the cache (a stall on every hit).
    const float *f = &m_face_table[9 * size_t(prim_index)];
    std::memcpy(static_cast<void *>(&si.n), f, sizeof(Normal3f));
    std::memcpy(static_cast<void *>(&si.sh_frame.n), f + 3, sizeof(Normal3f));
    std::memcpy(static_cast<void *>(&si.sh_frame.s), f + 6, sizeof(Vector3f));
    si.sh_frame.t = cross(Normal3f(f[3], f[4], f[5]), Vector3f(f[6], f[7], f[8]));
    si.uv = Point2f(b1, b2);
    si.dp_du = p1 - p0;
    si.dp_dv = p2 - p0;
}

inline void Mesh::sample_point(Point2f u, PositionSample &ps) const {
    // Pick a triangle in proportion to its area and reuse the sample within its interval: the
    // first whose cumulative area exceeds u.x (the last one if none does), by a linear scan for
    // the few triangles of a typical light. (The rarer cases are out of line, so that this
    // stays small enough to inline.)
    const size_t count = m_area_cdf.size();
    size_t f = 0;
    if (count <= 8) {
        while (f + 1 < count && !(u.x < m_area_cdf[f])) ++f;
    } else {
        f = find_area_face(u.x);
    }
    const float lo = f > 0 ? m_area_cdf[f - 1] : 0.f, hi = m_area_cdf[f];
    u.x = hi > lo ? clamp((u.x - lo) / (hi - lo), 0.f, OneMinusEpsilon) : 0.f;

    const uint32_t i0 = m_faces[3 * f], i1 = m_faces[3 * f + 1], i2 = m_faces[3 * f + 2];
    const Point3f p0 = vertex_position(i0), p1 = vertex_position(i1), p2 = vertex_position(i2);
    const Point2f b = warp::square_to_uniform_triangle(u);
    const float b0 = 1.f - b.x - b.y;
    ps.p = p0 * b0 + p1 * b.x + p2 * b.y;
    if (!m_face_table.empty()) {
        const float *t = &m_face_table[9 * f];
        ps.n = Normal3f(t[0], t[1], t[2]);
    } else {
        ps.n = face_normal(f);
    }
    // b goes to ps.uv first: kept aside across the face_uv() call instead, it was copied from
    // the stack as one 8-byte word over two fresh 4-byte stores (a store-forwarding stall).
    ps.uv = b;
    if (has_uvs()) ps.uv = face_uv(f, ps.uv);
    ps.pdf = 1.f / m_area;
    ps.delta = false;
}

} // namespace facet
