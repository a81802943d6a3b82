#include "direction_cone.h"
#include "mesh_inline.h"

#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/logger.h>
#include <facet/mesh.h>
#include <facet/warp.h>

#include <algorithm>
#include <cstring>

namespace facet {

Mesh::Mesh(const Properties &props) : Shape(props) {
    m_name = props.id().empty() ? props.plugin_name() : props.id();
}

void Mesh::initialize(const Transform &to_world, bool face_normals, bool flip_normals) {
    m_flip_normals = flip_normals;
    if (m_positions.size() % 3 != 0)
        FACET_THROW("{}: position array of {} floats is not a list of 3D points", m_name,
                    m_positions.size());
    size_t nv = m_positions.size() / 3;
    if (m_faces.empty()) FACET_THROW("{}: the mesh has no triangles", m_name);
    if (m_faces.size() % 3 != 0)
        FACET_THROW("{}: index array of {} entries is not a list of triangles", m_name,
                    m_faces.size());
    if (nv >= size_t(std::numeric_limits<uint32_t>::max()))
        FACET_THROW("{}: too many vertices ({})", m_name, nv);
    if (!m_normals.empty() && m_normals.size() != 3 * nv)
        FACET_THROW("{}: {} normal floats for {} vertices", m_name, m_normals.size(), nv);
    if (!m_uvs.empty() && m_uvs.size() != 2 * nv)
        FACET_THROW("{}: {} texture coordinate floats for {} vertices", m_name, m_uvs.size(), nv);
    if (!m_colors.empty()) {
        if (m_colors.size() != 3 * nv)
            FACET_THROW("{}: {} colour floats for {} vertices", m_name, m_colors.size(), nv);
        add_attribute("vertex_color", 3, std::move(m_colors));
        m_colors = {};
    }
    for (const Attribute &a : m_attributes) {
        size_t count = a.per_face ? m_faces.size() / 3 : nv;
        if (a.data.size() / a.channels != count || a.data.size() % a.channels != 0)
            FACET_THROW("{}: attribute \"{}\" has {} values, expected {} ({} per {})", m_name,
                        a.name, a.data.size(), count * a.channels, a.channels,
                        a.per_face ? "face" : "vertex");
    }
    for (size_t i = 0; i < m_faces.size(); ++i)
        if (m_faces[i] >= nv)
            FACET_THROW("{}: triangle {} uses vertex {}, but the mesh has only {} vertices", m_name,
                        i / 3, m_faces[i], nv);
    for (size_t i = 0; i < nv; ++i)
        if (!is_finite(vertex_position(i)))
            FACET_THROW("{}: vertex {} has a non-finite position", m_name, i);

    if (!to_world.is_identity()) {
        for (size_t i = 0; i < nv; ++i) {
            Point3f p = to_world.apply_point(vertex_position(i));
            m_positions[3 * i] = p.x;
            m_positions[3 * i + 1] = p.y;
            m_positions[3 * i + 2] = p.z;
        }
        // A mirroring transform reverses the winding; reverse it back so the face normals keep
        // pointing where the (inverse-transpose transformed) normals of the object point.
        const auto &m = to_world.matrix.m;
        double det = double(m[0][0]) * (double(m[1][1]) * m[2][2] - double(m[1][2]) * m[2][1]) -
                     double(m[0][1]) * (double(m[1][0]) * m[2][2] - double(m[1][2]) * m[2][0]) +
                     double(m[0][2]) * (double(m[1][0]) * m[2][1] - double(m[1][1]) * m[2][0]);
        if (det < 0.0)
            for (size_t f = 0; f < m_faces.size(); f += 3)
                std::swap(m_faces[f + 1], m_faces[f + 2]);
    }
    if (face_normals) {
        m_normals.clear();
        m_normals.shrink_to_fit();
    }
    for (size_t i = 0; i < m_normals.size(); i += 3) {
        Normal3f n(m_normals[i], m_normals[i + 1], m_normals[i + 2]);
        if (!to_world.is_identity()) n = to_world.apply_normal(n);
        float len = norm(n);
        // A zero or broken normal stays zero: shading then falls back to the face normal.
        n = (len > 0.f && std::isfinite(len)) ? n / len : Normal3f(0.f);
        m_normals[i] = n.x;
        m_normals[i + 1] = n.y;
        m_normals[i + 2] = n.z;
    }

    m_bbox = BoundingBox3f();
    for (size_t i = 0; i < nv; ++i) m_bbox.expand(vertex_position(i));

    size_t nf = face_count();
    m_area_cdf.resize(nf);
    double total = 0.0;
    for (size_t f = 0; f < nf; ++f) {
        Point3f p0 = vertex_position(m_faces[3 * f]), p1 = vertex_position(m_faces[3 * f + 1]),
                p2 = vertex_position(m_faces[3 * f + 2]);
        total += 0.5 * double(norm(cross(p1 - p0, p2 - p0)));
        m_area_cdf[f] = float(total);
    }
    m_area = float(total);
    if (total > 0.0) {
        for (float &c : m_area_cdf) c = float(double(c) / total);
        m_area_cdf.back() = 1.f;
    } else {
        FACET_LOG(Warn, "{}: all {} triangles are degenerate (zero area)", m_name, nf);
    }

    // Embree reads vertices with 16-byte loads: keep one float of padding after the last one.
    m_positions.push_back(0.f);
    build_face_table();
}

namespace {

/// Tangent vectors of a face in the (u, v) parametrisation: from the texture coordinates when
/// they give a regular map, else (dp_du, dp_dv) completing n (uvs without area), or the two edges
/// (no uvs: the barycentrics are the parametrisation). Returns false when it fell back to n.
inline void face_tangents(const Vector3f &dp0, const Vector3f &dp1, const Point2f *uv,
                          const Normal3f &n, Vector3f &dp_du, Vector3f &dp_dv) {
    if (!uv) {
        dp_du = dp0;
        dp_dv = dp1;
        return;
    }
    const Vector2f duv0 = uv[1] - uv[0], duv1 = uv[2] - uv[0];
    float det = duv0.x * duv1.y - duv0.y * duv1.x;
    if (det != 0.f) {
        float inv = 1.f / det;
        dp_du = (dp0 * duv1.y - dp1 * duv0.y) * inv;
        dp_dv = (dp1 * duv0.x - dp0 * duv1.x) * inv;
        if (is_finite(dp_du) && is_finite(dp_dv)) return;
    }
    coordinate_system(n, dp_du, dp_dv);
}

/// Shading frame: the shading normal and dp_du made orthogonal to it (Gram-Schmidt).
inline Frame shading_frame(const Normal3f &ns, const Vector3f &dp_du) {
    Vector3f s = dp_du - ns * dot(ns, dp_du);
    float s_len = norm(s);
    if (s_len > 1e-6f * norm(dp_du) && std::isfinite(s_len)) {
        s /= s_len;
        return Frame(s, cross(ns, s), ns);
    }
    return Frame(ns);
}

} // namespace

void Mesh::build_face_table() {
    m_face_table.clear();
    m_face_table.shrink_to_fit();
    const size_t nf = face_count();
    auto vn = [&](uint32_t i) {
        return Normal3f(m_normals[3 * i], m_normals[3 * i + 1], m_normals[3 * i + 2]);
    };
    if (has_vertex_normals())
        for (size_t f = 0; f < nf; ++f) {
            Normal3f a = vn(m_faces[3 * f]), b = vn(m_faces[3 * f + 1]), c = vn(m_faces[3 * f + 2]);
            // Equal up to the rounding of normals computed per vertex (recomputed normals of a
            // planar polygon differ in the last bits): interpolating them changes nothing.
            if (!(max_component(abs(a - b)) <= 1e-6f && max_component(abs(a - c)) <= 1e-6f) ||
                !(norm(a) > 0.f))
                return; // smooth (or broken): per hit
        }
    m_face_table.resize(9 * nf);
    for (size_t f = 0; f < nf; ++f) {
        const uint32_t i0 = m_faces[3 * f], i1 = m_faces[3 * f + 1], i2 = m_faces[3 * f + 2];
        const Point3f p0 = vertex_position(i0), p1 = vertex_position(i1), p2 = vertex_position(i2);
        const Vector3f dp0 = p1 - p0, dp1 = p2 - p0;
        Normal3f n = cross(dp0, dp1);
        float n_len = norm(n);
        if (!std::isfinite(n_len)) {
            // The cross product of a huge face overflows in float: take it in double.
            const Vector3d nd = cross(Vector3d(dp0), Vector3d(dp1));
            n = Normal3f(nd / norm(nd));
            n_len = 1.f;
        }
        if (!(n_len > 0.f)) { // a degenerate face has no normal of its own: per hit
            m_face_table.clear();
            return;
        }
        n = n / n_len;
        if (m_flip_normals) n = -n;
        Normal3f ns = n;
        if (has_vertex_normals()) {
            Normal3f v = normalize(vn(i0) + vn(i1) + vn(i2));
            ns = m_flip_normals ? -v : v;
        }
        Point2f uv[3];
        if (has_uvs())
            for (int k = 0; k < 3; ++k) {
                uint32_t i = m_faces[3 * f + k];
                uv[k] = Point2f(m_uvs[2 * i], m_uvs[2 * i + 1]);
            }
        Vector3f dp_du, dp_dv;
        face_tangents(dp0, dp1, has_uvs() ? uv : nullptr, n, dp_du, dp_dv);
        Frame frame = shading_frame(ns, dp_du);
        float *out = &m_face_table[9 * f];
        for (int k = 0; k < 3; ++k) {
            out[k] = n[k];
            out[3 + k] = frame.n[k];
            out[6 + k] = frame.s[k];
        }
    }
}

void Mesh::recompute_vertex_normals() {
    size_t nv = vertex_count();
    m_normals.assign(3 * nv, 0.f);
    std::vector<Vector3d> acc(nv, Vector3d(0.0));
    for (size_t f = 0; f < face_count(); ++f) {
        uint32_t idx[3] = {m_faces[3 * f], m_faces[3 * f + 1], m_faces[3 * f + 2]};
        Vector3d p[3];
        for (int k = 0; k < 3; ++k) p[k] = Vector3d(vertex_position(idx[k]));
        Vector3d n = cross(p[1] - p[0], p[2] - p[0]);
        double len = norm(n);
        if (!(len > 0.0)) continue;
        n /= len;
        // Each face contributes its normal weighted by its angle at the vertex
        // (Thürmer and Wüthrich 1998), which makes the result independent of the tessellation.
        for (int k = 0; k < 3; ++k) {
            Vector3d e1 = p[(k + 1) % 3] - p[k], e2 = p[(k + 2) % 3] - p[k];
            double l1 = norm(e1), l2 = norm(e2);
            if (!(l1 > 0.0 && l2 > 0.0)) continue;
            double angle = std::acos(clamp(dot(e1, e2) / (l1 * l2), -1.0, 1.0));
            acc[idx[k]] += n * angle;
        }
    }
    for (size_t i = 0; i < nv; ++i) {
        double len = norm(acc[i]);
        if (len > 0.0) {
            Vector3d n = acc[i] / len;
            m_normals[3 * i] = float(n.x);
            m_normals[3 * i + 1] = float(n.y);
            m_normals[3 * i + 2] = float(n.z);
        }
    }
    build_face_table();
}

void Mesh::add_attribute(std::string name, uint32_t channels, std::vector<float> data) {
    bool per_face = name.rfind("face_", 0) == 0;
    if (!per_face && name.rfind("vertex_", 0) != 0)
        FACET_THROW("{}: mesh attribute \"{}\" must start with vertex_ or face_", m_name, name);
    if (channels < 1 || channels > 4)
        FACET_THROW("{}: mesh attribute \"{}\" has {} channels (1 to 4 supported)", m_name, name,
                    channels);
    if (attribute(name)) FACET_THROW("{}: mesh attribute \"{}\" is defined twice", m_name, name);
    m_attributes.push_back(Attribute{std::move(name), channels, per_face, std::move(data)});
}

const Mesh::Attribute *Mesh::attribute(const std::string &name) const {
    for (const Attribute &a : m_attributes)
        if (a.name == name) return &a;
    return nullptr;
}

std::string Mesh::attribute_names() const {
    if (m_attributes.empty()) return "none";
    std::string out;
    for (const Attribute &a : m_attributes) out += (out.empty() ? "" : ", ") + a.name;
    return out;
}

void Mesh::eval_attribute(const Attribute &a, const SurfaceInteraction &si, float *out) const {
    const uint32_t f = si.prim_index, c = a.channels;
    if (a.per_face) {
        for (uint32_t k = 0; k < c; ++k) out[k] = a.data[size_t(f) * c + k];
        return;
    }
    const uint32_t i0 = m_faces[3 * f], i1 = m_faces[3 * f + 1], i2 = m_faces[3 * f + 2];
    // Barycentric coordinates of si.p: the least-squares solution in the triangle's plane.
    const Point3f p0 = vertex_position(i0);
    const Vector3f e1 = vertex_position(i1) - p0, e2 = vertex_position(i2) - p0, r = si.p - p0;
    float a11 = dot(e1, e1), a12 = dot(e1, e2), a22 = dot(e2, e2), r1 = dot(r, e1), r2 = dot(r, e2);
    float det = a11 * a22 - a12 * a12;
    float b1 = 0.f, b2 = 0.f;
    if (det != 0.f) {
        b1 = (a22 * r1 - a12 * r2) / det;
        b2 = (a11 * r2 - a12 * r1) / det;
    }
    float b0 = 1.f - b1 - b2;
    const float *d0 = &a.data[size_t(i0) * c], *d1 = &a.data[size_t(i1) * c],
                *d2 = &a.data[size_t(i2) * c];
    for (uint32_t k = 0; k < c; ++k) out[k] = d0[k] * b0 + d1[k] * b1 + d2[k] * b2;
}

RTCGeometry Mesh::embree_geometry(RTCDevice device) const {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                               m_positions.data(), 0, 3 * sizeof(float), vertex_count());
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m_faces.data(), 0,
                               3 * sizeof(uint32_t), face_count());
    rtcCommitGeometry(geom);
    return geom;
}

void Mesh::compute_surface_interaction(const Ray &ray, float /*t*/, uint32_t prim_index,
                                       const Point2f &uv, SurfaceInteraction &si) const {
    // Geometry only: the scene sets t, shape, prim_index and wi (an instance sets them for its
    // members).
    if (has_flat_hit()) { // the common case, taken first
        flat_hit(prim_index, uv, si);
        return;
    }
    const uint32_t *face = &m_faces[3 * size_t(prim_index)];
    const uint32_t i0 = face[0], i1 = face[1], i2 = face[2];
    const Point3f p0 = vertex_position(i0), p1 = vertex_position(i1), p2 = vertex_position(i2);
    // Embree's (u, v) weight vertices 1 and 2.
    const float b1 = uv.x, b2 = uv.y, b0 = 1.f - b1 - b2;

    si.shape = this;
    si.prim_index = prim_index;
    // Interpolating the vertices is more accurate than ray(t) far from the ray origin.
    si.p = p0 * b0 + p1 * b1 + p2 * b2;
    const Vector3f dp0 = p1 - p0, dp1 = p2 - p0;

    const Point2f *uvs = nullptr;
    Point2f uv_corner[3];
    if (has_uvs()) {
        uv_corner[0] = Point2f(m_uvs[2 * i0], m_uvs[2 * i0 + 1]);
        uv_corner[1] = Point2f(m_uvs[2 * i1], m_uvs[2 * i1 + 1]);
        uv_corner[2] = Point2f(m_uvs[2 * i2], m_uvs[2 * i2 + 1]);
        si.uv = uv_corner[0] * b0 + uv_corner[1] * b1 + uv_corner[2] * b2;
        uvs = uv_corner;
    } else {
        // Without texture coordinates the barycentrics serve as (u, v).
        si.uv = Point2f(b1, b2);
    }

    if (!m_face_table.empty()) {
        // A flat mesh: normals and frame of the face were computed at load.
        // Copied as whole vectors from the table: built from single floats, the vectors were
        // packed through the stack and reloaded whole before the stores had landed (a failed
        // store forwarding; perf put 2% of the Veach scene's CPU on those reloads).
        static_assert(sizeof(Normal3f) == 3 * sizeof(float) &&
                      sizeof(Vector3f) == sizeof(Normal3f));
        const float *f = &m_face_table[9 * size_t(prim_index)];
        std::memcpy(static_cast<void *>(&si.n), f, sizeof(Normal3f));
        std::memcpy(static_cast<void *>(&si.sh_frame.n), f + 3, sizeof(Normal3f));
        std::memcpy(static_cast<void *>(&si.sh_frame.s), f + 6, sizeof(Vector3f));
        si.sh_frame.t = cross(si.sh_frame.n, si.sh_frame.s);
        face_tangents(dp0, dp1, uvs, si.n, si.dp_du, si.dp_dv);
        return;
    }

    Normal3f n = cross(dp0, dp1);
    float n_len = norm(n);
    n = n_len > 0.f ? n / n_len : -ray.d;
    if (m_flip_normals) n = -n;
    si.n = n;
    face_tangents(dp0, dp1, uvs, n, si.dp_du, si.dp_dv);

    Normal3f ns = n;
    if (has_vertex_normals()) {
        auto vn = [&](uint32_t i) {
            return Normal3f(m_normals[3 * i], m_normals[3 * i + 1], m_normals[3 * i + 2]);
        };
        Normal3f interp = vn(i0) * b0 + vn(i1) * b1 + vn(i2) * b2;
        float len = norm(interp);
        if (len > 0.f && std::isfinite(len)) ns = m_flip_normals ? -interp / len : interp / len;
    }
    si.sh_frame = shading_frame(ns, si.dp_du);
}

size_t Mesh::find_area_face(float u_x) const {
    size_t f =
        size_t(std::upper_bound(m_area_cdf.begin(), m_area_cdf.end(), u_x) - m_area_cdf.begin());
    return std::min(f, m_area_cdf.size() - 1);
}

std::pair<Vector3f, float> Mesh::normal_cone() const {
    detail::DirectionCone cone;
    auto add = [&](const Vector3f &n) {
        if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z)) return;
        if (!cone.empty() && dot(cone.axis, n) >= std::cos(cone.theta)) return; // inside
        cone = detail::merge(cone, detail::DirectionCone{n, 0.f});
    };
    for (size_t f = 0; f < face_count(); ++f) add(Vector3f(face_normal(f)));
    if (has_vertex_normals())
        for (size_t i = 0; i + 2 < m_normals.size(); i += 3) {
            const Vector3f n =
                normalize(Vector3f(m_normals[i], m_normals[i + 1], m_normals[i + 2]));
            add(m_flip_normals ? -n : n);
        }
    if (cone.empty()) return Shape::normal_cone();
    // A margin for the rounding of the normals.
    return {cone.axis, std::cos(std::min(cone.theta + 1e-3f, Pi))};
}

Normal3f Mesh::face_normal(size_t f) const {
    const Point3f p0 = vertex_position(m_faces[3 * f]), p1 = vertex_position(m_faces[3 * f + 1]),
                  p2 = vertex_position(m_faces[3 * f + 2]);
    Normal3f n = normalize(cross(p1 - p0, p2 - p0));
    return m_flip_normals ? -n : n;
}

Point2f Mesh::face_uv(size_t f, const Point2f &b) const {
    const uint32_t i0 = m_faces[3 * f], i1 = m_faces[3 * f + 1], i2 = m_faces[3 * f + 2];
    const float b0 = 1.f - b.x - b.y;
    return Point2f(m_uvs[2 * i0], m_uvs[2 * i0 + 1]) * b0 +
           Point2f(m_uvs[2 * i1], m_uvs[2 * i1 + 1]) * b.x +
           Point2f(m_uvs[2 * i2], m_uvs[2 * i2 + 1]) * b.y;
}

PositionSample Mesh::sample_position(const Point2f &u) const {
    PositionSample ps;
    if (m_area_cdf.empty() || !(m_area > 0.f)) return ps;
    sample_point(u, ps);
    return ps;
}

std::string Mesh::to_string() const {
    return fmt::format("Mesh[name=\"{}\", vertices={}, triangles={}, normals={}, uvs={}, "
                       "attributes=[{}], area={}, flip_normals={}, bsdf={}, emitter={}]",
                       m_name, vertex_count(), face_count(), has_vertex_normals(), has_uvs(),
                       m_attributes.empty() ? std::string() : attribute_names(), m_area,
                       m_flip_normals, m_bsdf ? m_bsdf->to_string() : "none", emitter_label());
}

} // namespace facet
