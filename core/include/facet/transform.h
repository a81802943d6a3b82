#pragma once

#include <facet/vector.h>

#include <string>

namespace facet {

/// Row-major 4x4 matrix.
struct Matrix4f {
    float m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};

    static Matrix4f identity() { return Matrix4f(); }
    static Matrix4f from_rows(const float (&v)[16]);
    Matrix4f operator*(const Matrix4f &o) const;
    bool operator==(const Matrix4f &o) const;
    Matrix4f transpose() const;
    /// Inverse by cofactors; a singular matrix gives a matrix of NaNs.
    Matrix4f inverse() const;
    bool is_identity() const { return *this == Matrix4f(); }
};

/// Affine or projective transform with its inverse.
struct Transform {
    Matrix4f matrix, inverse_matrix;

    Transform() = default;
    explicit Transform(const Matrix4f &m) : matrix(m), inverse_matrix(m.inverse()) {}
    Transform(const Matrix4f &m, const Matrix4f &inv) : matrix(m), inverse_matrix(inv) {}

    Transform operator*(const Transform &o) const {
        return Transform(matrix * o.matrix, o.inverse_matrix * inverse_matrix);
    }
    Transform inverse() const { return Transform(inverse_matrix, matrix); }
    bool is_identity() const { return matrix.is_identity(); }
    bool operator==(const Transform &o) const { return matrix == o.matrix; }

    Point3f apply_point(const Point3f &p) const;
    Vector3f apply_vector(const Vector3f &v) const;
    /// Normals transform with the inverse transpose.
    Normal3f apply_normal(const Normal3f &n) const;

    static Transform translate(const Vector3f &v);
    static Transform scale(const Vector3f &v);
    /// Counter-clockwise rotation by `angle_deg` degrees about `axis`.
    static Transform rotate(const Vector3f &axis, float angle_deg);
    /// Camera-to-world: columns [left, up', dir, origin] as in Mitsuba (camera looks down +Z).
    static Transform look_at(const Point3f &origin, const Point3f &target, const Vector3f &up);
    /// Perspective projection (fov in degrees) mapping camera space to [-1,1]² × [0,1].
    static Transform perspective(float fov_deg, float near_clip, float far_clip);

    std::string to_string() const;
};

/// Largest coordinate of scene geometry and sensor positions, far beyond real scenes (at 1e12
/// a float cannot tell points 1e5 apart). Embree asserts that ray origins stay below 1.8e18:
/// with this bound, hit points and the rays of instances (see transform_problem()) do.
constexpr float MaxSceneCoordinate = 1e12f;

/// Empty when `t` can place a sensor, shape or instance in the scene: its entries finite and at
/// most `max_entry` in magnitude, its linear part invertible and the entries of its inverse at
/// most `max_inverse_entry` (a bound on how much it may shrink). Otherwise a description of
/// what is wrong ("scales by zero", ...), to follow "to_world ".
std::string transform_problem(const Transform &t, float max_entry = MaxSceneCoordinate,
                              float max_inverse_entry = MaxSceneCoordinate);

/// True when the linear part of `t` changes lengths: one of the images of the three axes has a
/// squared length outside [0.999, 1.001] (Mitsuba's test; mirroring, e.g. scale x = -1, is no
/// scale). Mitsuba's perspective and thin-lens cameras refuse such a to_world.
bool has_scale(const Transform &t);

} // namespace facet
