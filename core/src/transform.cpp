#include <facet/frame.h>
#include <facet/transform.h>

#include <fmt/format.h>

#include <cmath>

namespace facet {

Matrix4f Matrix4f::from_rows(const float (&v)[16]) {
    Matrix4f r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) r.m[i][j] = v[i * 4 + j];
    return r;
}

Matrix4f Matrix4f::operator*(const Matrix4f &o) const {
    Matrix4f r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double s = 0.0;
            for (int k = 0; k < 4; ++k) s += double(m[i][k]) * double(o.m[k][j]);
            r.m[i][j] = float(s);
        }
    return r;
}

bool Matrix4f::operator==(const Matrix4f &o) const {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            if (m[i][j] != o.m[i][j]) return false;
    return true;
}

Matrix4f Matrix4f::transpose() const {
    Matrix4f r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) r.m[i][j] = m[j][i];
    return r;
}

Matrix4f Matrix4f::inverse() const {
    // Cofactor expansion in double precision via 2x2 sub-determinants of row pairs (0,1) and (2,3).
    double a[4][4];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) a[i][j] = m[i][j];
    double s0 = a[0][0] * a[1][1] - a[1][0] * a[0][1];
    double s1 = a[0][0] * a[1][2] - a[1][0] * a[0][2];
    double s2 = a[0][0] * a[1][3] - a[1][0] * a[0][3];
    double s3 = a[0][1] * a[1][2] - a[1][1] * a[0][2];
    double s4 = a[0][1] * a[1][3] - a[1][1] * a[0][3];
    double s5 = a[0][2] * a[1][3] - a[1][2] * a[0][3];
    double c5 = a[2][2] * a[3][3] - a[3][2] * a[2][3];
    double c4 = a[2][1] * a[3][3] - a[3][1] * a[2][3];
    double c3 = a[2][1] * a[3][2] - a[3][1] * a[2][2];
    double c2 = a[2][0] * a[3][3] - a[3][0] * a[2][3];
    double c1 = a[2][0] * a[3][2] - a[3][0] * a[2][2];
    double c0 = a[2][0] * a[3][1] - a[3][0] * a[2][1];
    double det = s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0;
    Matrix4f r;
    if (det == 0.0 || !std::isfinite(det)) {
        for (auto &row : r.m)
            for (float &v : row) v = std::numeric_limits<float>::quiet_NaN();
        return r;
    }
    double inv = 1.0 / det;
    double b[4][4] = {
        {a[1][1] * c5 - a[1][2] * c4 + a[1][3] * c3, -a[0][1] * c5 + a[0][2] * c4 - a[0][3] * c3,
         a[3][1] * s5 - a[3][2] * s4 + a[3][3] * s3, -a[2][1] * s5 + a[2][2] * s4 - a[2][3] * s3},
        {-a[1][0] * c5 + a[1][2] * c2 - a[1][3] * c1, a[0][0] * c5 - a[0][2] * c2 + a[0][3] * c1,
         -a[3][0] * s5 + a[3][2] * s2 - a[3][3] * s1, a[2][0] * s5 - a[2][2] * s2 + a[2][3] * s1},
        {a[1][0] * c4 - a[1][1] * c2 + a[1][3] * c0, -a[0][0] * c4 + a[0][1] * c2 - a[0][3] * c0,
         a[3][0] * s4 - a[3][1] * s2 + a[3][3] * s0, -a[2][0] * s4 + a[2][1] * s2 - a[2][3] * s0},
        {-a[1][0] * c3 + a[1][1] * c1 - a[1][2] * c0, a[0][0] * c3 - a[0][1] * c1 + a[0][2] * c0,
         -a[3][0] * s3 + a[3][1] * s1 - a[3][2] * s0, a[2][0] * s3 - a[2][1] * s1 + a[2][2] * s0}};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) r.m[i][j] = float(b[i][j] * inv);
    return r;
}

Point3f Transform::apply_point(const Point3f &p) const {
    const auto &m = matrix.m;
    float x = m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3];
    float y = m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3];
    float z = m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3];
    float w = m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3];
    if (w == 1.f) return {x, y, z};
    return Point3f(x, y, z) / w;
}

Vector3f Transform::apply_vector(const Vector3f &v) const {
    const auto &m = matrix.m;
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

Normal3f Transform::apply_normal(const Normal3f &n) const {
    // Inverse transpose: column i of the inverse dotted with n.
    const auto &m = inverse_matrix.m;
    return {m[0][0] * n.x + m[1][0] * n.y + m[2][0] * n.z,
            m[0][1] * n.x + m[1][1] * n.y + m[2][1] * n.z,
            m[0][2] * n.x + m[1][2] * n.y + m[2][2] * n.z};
}

Transform Transform::translate(const Vector3f &v) {
    Matrix4f m, inv;
    m.m[0][3] = v.x;
    m.m[1][3] = v.y;
    m.m[2][3] = v.z;
    inv.m[0][3] = -v.x;
    inv.m[1][3] = -v.y;
    inv.m[2][3] = -v.z;
    return Transform(m, inv);
}

Transform Transform::scale(const Vector3f &v) {
    Matrix4f m, inv;
    m.m[0][0] = v.x;
    m.m[1][1] = v.y;
    m.m[2][2] = v.z;
    inv.m[0][0] = 1.f / v.x;
    inv.m[1][1] = 1.f / v.y;
    inv.m[2][2] = 1.f / v.z;
    return Transform(m, inv);
}

Transform Transform::rotate(const Vector3f &axis, float angle_deg) {
    // Rodrigues' rotation formula: R = cos·I + sin·[a]x + (1 - cos)·a aᵀ.
    Vector3d a = normalize(Vector3d(axis));
    double theta = double(angle_deg) * (3.14159265358979323846 / 180.0);
    double s = std::sin(theta), c = std::cos(theta), t = 1.0 - c;
    double r[3][3] = {{c + t * a.x * a.x, t * a.x * a.y - s * a.z, t * a.x * a.z + s * a.y},
                      {t * a.x * a.y + s * a.z, c + t * a.y * a.y, t * a.y * a.z - s * a.x},
                      {t * a.x * a.z - s * a.y, t * a.y * a.z + s * a.x, c + t * a.z * a.z}};
    Matrix4f m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m.m[i][j] = float(r[i][j]);
    // A rotation's inverse is its transpose.
    return Transform(m, m.transpose());
}

Transform Transform::look_at(const Point3f &origin, const Point3f &target, const Vector3f &up) {
    Vector3d o(origin), dir = normalize(Vector3d(target) - o);
    Vector3d up_d(up);
    Vector3d left = cross(up_d, dir);
    double len = norm(left);
    if (!(len > 1e-9 * std::max(1.0, norm(up_d)))) {
        // Up missing or parallel to the view direction: pick one perpendicular to dir.
        Vector3f s, t;
        coordinate_system(Vector3f(dir), s, t);
        up_d = Vector3d(s);
        left = cross(up_d, dir);
        len = norm(left);
    }
    left = left / len;
    Vector3d new_up = cross(dir, left);
    Matrix4f m;
    for (int i = 0; i < 3; ++i) {
        m.m[i][0] = float(left[i]);
        m.m[i][1] = float(new_up[i]);
        m.m[i][2] = float(dir[i]);
        m.m[i][3] = float(o[i]);
    }
    // The inverse of [R | o] is [Rᵀ | -Rᵀ o].
    Matrix4f inv;
    Vector3d cols[3] = {left, new_up, dir};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) inv.m[i][j] = float(cols[i][j]);
        inv.m[i][3] = float(-dot(cols[i], o));
    }
    return Transform(m, inv);
}

Transform Transform::perspective(float fov_deg, float near_clip, float far_clip) {
    double recip = 1.0 / (double(far_clip) - double(near_clip));
    double cot = 1.0 / std::tan(double(fov_deg) * (3.14159265358979323846 / 360.0));
    // z' = far (z - near) / ((far - near) z), so near -> 0 and far -> 1; x' = x cot / z.
    Matrix4f m;
    m.m[0][0] = float(cot);
    m.m[1][1] = float(cot);
    m.m[2][2] = float(far_clip * recip);
    m.m[2][3] = float(-double(near_clip) * far_clip * recip);
    m.m[3][2] = 1.f;
    m.m[3][3] = 0.f;
    return Transform(m);
}

std::string transform_problem(const Transform &t, float max_entry, float max_inverse_entry) {
    const auto &m = t.matrix.m;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            if (std::isnan(m[i][j])) return "has a NaN entry";
            if (!(std::abs(m[i][j]) <= max_entry))
                return fmt::format("has an entry of {} (at most {:g} is supported)", m[i][j],
                                   max_entry);
        }
    if (m[3][0] != 0.f || m[3][1] != 0.f || m[3][2] != 0.f || m[3][3] != 1.f)
        return "is projective (its last row is not 0, 0, 0, 1)";
    const double det = double(m[0][0]) * (double(m[1][1]) * m[2][2] - double(m[1][2]) * m[2][1]) -
                       double(m[0][1]) * (double(m[1][0]) * m[2][2] - double(m[1][2]) * m[2][0]) +
                       double(m[0][2]) * (double(m[1][0]) * m[2][1] - double(m[1][1]) * m[2][0]);
    if (det == 0.0) return "is singular (it scales by zero)";
    // The stored inverse may have been built alongside the matrix; recompute it to be sure.
    const Matrix4f inv = t.matrix.inverse();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (!(std::abs(inv.m[i][j]) <= max_inverse_entry))
                return fmt::format("is nearly singular (it shrinks by a factor of up to {:g}; "
                                   "at most {:g} is supported)",
                                   double(std::abs(inv.m[i][j])), max_inverse_entry);
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(inv.m[i][3])) return "has no finite inverse";
    return {};
}

bool has_scale(const Transform &t) {
    const auto &m = t.matrix.m;
    for (int j = 0; j < 3; ++j) {
        const double len2 =
            double(m[0][j]) * m[0][j] + double(m[1][j]) * m[1][j] + double(m[2][j]) * m[2][j];
        if (!(len2 >= 0.999 && len2 <= 1.001)) return true;
    }
    return false;
}

std::string Transform::to_string() const {
    std::string s = "[";
    for (int i = 0; i < 4; ++i) {
        s += fmt::format("{}[{}, {}, {}, {}]", i == 0 ? "" : ",\n ", matrix.m[i][0], matrix.m[i][1],
                         matrix.m[i][2], matrix.m[i][3]);
    }
    return s + "]";
}

} // namespace facet
