// The inline bodies of Mesh's hit and area sampling (private to libfacet): mesh.cpp and
// scene.cpp include it, so the scene computes the hits and light samples of every mesh without a
// virtual call, whatever loader filled the mesh.
#pragma once

#include <facet/mesh.h>
#include <facet/warp.h>

#include <cstring>

namespace facet {

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
