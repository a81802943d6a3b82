static const char *DOC = R"DOC(
# sphere

An exact sphere, intersected analytically (an Embree user geometry), not tessellated.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| center | point | (0, 0, 0) | Centre of the sphere (before `to_world`) |
| radius | float | 1 | Radius (before `to_world`); must be positive |
| flip_normals | boolean | false | Make the normals point inwards (an emitter then lights the inside) |
| to_world | transform | identity | Object-to-world transform: rotation, uniform scale and translation only |

Texture coordinates are spherical: u = φ/2π (longitude around the object-space z axis),
v = θ/π (from the +z pole). Seen from outside, an area emitter on a sphere is sampled by the
cone of directions it subtends, so its light is sampled without waste at any distance.

```xml
<shape type="sphere">
    <point name="center" x="0" y="1" z="0"/>
    <float name="radius" value="0.5"/>
    <bsdf type="diffuse"/>
</shape>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/shape.h>
#include <facet/transform.h>
#include <facet/user_geometry.h>
#include <facet/warp.h>

namespace facet {

class Sphere final : public Shape {
public:
    explicit Sphere(const Properties &props) : Shape(props) {
        Vector3f center = props.get_vector("center", Vector3f(0.f));
        float radius = float(props.get_float("radius", 1.0));
        m_flip_normals = props.get_bool("flip_normals", false);
        Transform to_world = props.get_transform("to_world", Transform());
        if (!(radius > 0.f) || !std::isfinite(radius))
            FACET_THROW_AT(props.location(), "sphere: radius must be positive, got {}", radius);
        check_similarity(to_world, props);

        m_to_world = to_world * Transform::translate(center) *
                     Transform::scale(Vector3f(radius, radius, radius));
        m_center = m_to_world.apply_point(Point3f(0.f));
        m_radius = norm(m_to_world.apply_vector(Vector3f(1.f, 0.f, 0.f)));
        if (!(m_radius > 0.f) || !std::isfinite(m_radius) || !is_finite(m_center))
            FACET_THROW_AT(props.location(), "sphere: to_world gives a degenerate sphere");
        m_to_object = m_to_world.inverse();
        m_inv_radius = 1.0 / double(m_radius);
    }

    BoundingBox3f bbox() const override {
        Vector3f r(m_radius);
        return BoundingBox3f(m_center - r, m_center + r);
    }

    float surface_area() const override { return 4.f * Pi * m_radius * m_radius; }

    RTCGeometry embree_geometry(RTCDevice device) const override {
        return make_user_geometry(device, this);
    }

    /// Embree callback (facet/user_geometry.h): nearest hit in [tnear, tfar].
    bool intersect_user(const Point3f &o, const Vector3f &d, float tnear, float tfar,
                        UserHit &hit) const {
        if (!nearest_hit(o.x, o.y, o.z, d.x, d.y, d.z, tnear, tfar, hit.t)) return false;
        hit.ng = o + d * hit.t - m_center;
        hit.uv = Point2f(0.f);
        return true;
    }

    void compute_surface_interaction(const Ray &ray, float t, uint32_t prim_index, const Point2f &,
                                     SurfaceInteraction &si) const override {
        Vector3f dir = normalize(ray(t) - m_center);
        si.t = t;
        si.shape = this;
        si.prim_index = prim_index;
        // Project the hit back onto the sphere: ray(t) carries the rounding of t.
        si.p = m_center + dir * m_radius;
        si.n = m_flip_normals ? -dir : dir;

        Vector3f q = object_direction(dir);
        float cos_theta = clamp(q.z, -1.f, 1.f);
        float sin_theta = safe_sqrt(1.f - cos_theta * cos_theta);
        float phi = fast_atan2(q.y, q.x);
        if (phi < 0.f) phi += 2.f * Pi;
        si.uv = Point2f(phi * InvTwoPi, safe_acos(cos_theta) * InvPi);
        float cos_phi = std::cos(phi), sin_phi = std::sin(phi);
        si.dp_du = m_to_world.apply_vector(Vector3f(-q.y, q.x, 0.f) * (2.f * Pi));
        si.dp_dv = m_to_world.apply_vector(
            Vector3f(cos_theta * cos_phi, cos_theta * sin_phi, -sin_theta) * Pi);

        Vector3f s = si.dp_du - si.n * dot(si.n, si.dp_du);
        float s_len = norm(s);
        if (s_len > 1e-6f * norm(si.dp_du)) {
            s /= s_len;
            si.sh_frame = Frame(s, cross(si.n, s), si.n);
        } else {
            si.sh_frame = Frame(si.n); // at the poles
        }
        si.wi = si.to_local(-ray.d);
    }

    PositionSample sample_position(const Point2f &u) const override {
        Vector3f q = warp::square_to_uniform_sphere(u);
        Vector3f dir = normalize(m_to_world.apply_vector(q));
        PositionSample ps;
        ps.p = m_center + dir * m_radius;
        ps.n = m_flip_normals ? -dir : dir;
        ps.uv = spherical_uv(q);
        ps.pdf = 1.f / surface_area();
        return ps;
    }

    DirectionSample sample_direction(const Interaction &ref, const Point2f &u) const override {
        double one_minus_cos_max, dist2, dist;
        if (!sees_cone(ref, one_minus_cos_max, dist2, dist))
            return Shape::sample_direction(ref, u); // inside: every point is visible

        // Uniform direction in the cone around the axis towards the centre, in double so that
        // small distant spheres keep their precision. The angle around the axis needs no more
        // than float: its rounding moves the point by a float's part of the cone's width.
        const Vector3d axis = (Vector3d(m_center) - Vector3d(ref.p)) * (1.0 / dist);
        const double x = double(u.x) * one_minus_cos_max;
        const double cos_theta = 1.0 - x, sin2_theta = x * (2.0 - x);
        const double sin_theta = std::sqrt(std::max(sin2_theta, 0.0));
        const float phi = 2.f * Pi * u.y;
        const double cos_phi = double(std::cos(phi)), sin_phi = double(std::sin(phi));
        Vector3d s, t;
        build_basis(axis, s, t);
        const Vector3d d = s * (sin_theta * cos_phi) + t * (sin_theta * sin_phi) + axis * cos_theta;
        // Nearest intersection of ref + τ·d with the sphere.
        const double r = double(m_radius);
        const double disc = std::max(r * r - dist2 * sin2_theta, 0.0);
        const double tau = dist * cos_theta - std::sqrt(disc);

        DirectionSample ds;
        ds.emitter = m_emitter.get();
        if (!(tau > 0.0)) return ds;
        // The point lies on the sphere to double rounding, an error of about 1e-16 d: its offset
        // over the radius is the unit normal to float precision while d/r < 1e8 (beyond, off by
        // (d/r)·1e-16, e.g. 1e-6 of the radius for a sphere 1e10 radii away).
        const Vector3f dir =
            Vector3f((Vector3d(ref.p) + d * tau - Vector3d(m_center)) * m_inv_radius);
        ds.p = m_center + dir * m_radius;
        ds.n = m_flip_normals ? -dir : dir;
        // The uv only for whom reads it: a light whose radiance varies over the surface (a
        // uniform one, the common case, ignores it), or a caller without a light.
        if (!m_emitter || has_flag(m_emitter->flags(), EmitterFlags::SpatiallyVarying))
            ds.uv = spherical_uv(object_direction(dir));
        // The direction and distance of the double computation (d is a unit vector to its
        // rounding): the point is within its rounding of ref + d·τ, and the float point's
        // difference and its norm would put a square root and a division on the chain.
        ds.d = Vector3f(d);
        ds.dist = float(tau);
        if (!(ds.dist > 0.f)) return ds;
        ds.pdf = cone_pdf(one_minus_cos_max);
        return ds;
    }

    float pdf_direction(const Interaction &ref, const DirectionSample &ds) const override {
        double one_minus_cos_max, dist2, dist;
        if (!sees_cone(ref, one_minus_cos_max, dist2, dist)) return Shape::pdf_direction(ref, ds);
        return cone_pdf(one_minus_cos_max);
    }

    std::string to_string() const override {
        return fmt::format("Sphere[center=[{}, {}, {}], radius={}, flip_normals={}, bsdf={}, "
                           "emitter={}]",
                           m_center.x, m_center.y, m_center.z, m_radius, m_flip_normals,
                           m_bsdf ? m_bsdf->to_string() : "none", emitter_label());
    }

private:
    /// Rejects transforms that would turn the sphere into an ellipsoid.
    static void check_similarity(const Transform &tr, const Properties &props) {
        const auto &m = tr.matrix.m;
        if (m[3][0] != 0.f || m[3][1] != 0.f || m[3][2] != 0.f || m[3][3] != 1.f)
            FACET_THROW_AT(
                props.location("to_world"),
                "sphere: to_world must be affine (rotation, uniform scale, translation)");
        Vector3d c[3];
        for (int j = 0; j < 3; ++j) c[j] = Vector3d(m[0][j], m[1][j], m[2][j]);
        double s2 = squared_norm(c[0]);
        double tol = 1e-4 * s2;
        bool ok = s2 > 0.0 && std::abs(squared_norm(c[1]) - s2) <= tol &&
                  std::abs(squared_norm(c[2]) - s2) <= tol && std::abs(dot(c[0], c[1])) <= tol &&
                  std::abs(dot(c[0], c[2])) <= tol && std::abs(dot(c[1], c[2])) <= tol;
        if (!ok)
            FACET_THROW_AT(props.location("to_world"),
                           "sphere: to_world may only rotate, scale uniformly and translate "
                           "(a non-uniform scale or shear would make an ellipsoid): {}",
                           tr.to_string());
    }

    static void build_basis(const Vector3d &n, Vector3d &s, Vector3d &t) {
        double sgn = std::copysign(1.0, n.z);
        double a = -1.0 / (sgn + n.z);
        double b = n.x * n.y * a;
        s = Vector3d(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
        t = Vector3d(b, sgn + n.y * n.y * a, -n.y);
    }

    /// Unit direction in object space for a world-space direction from the centre.
    Vector3f object_direction(const Vector3f &dir) const {
        return normalize(m_to_object.apply_vector(dir));
    }

    static Point2f spherical_uv(const Vector3f &q) {
        float phi = fast_atan2(q.y, q.x);
        if (phi < 0.f) phi += 2.f * Pi;
        return Point2f(phi * InvTwoPi, safe_acos(q.z) * InvPi);
    }

    /// Whether `ref` samples the sphere by its cone of directions (it lies outside), and the
    /// cone's 1 - cos θmax, the squared distance to the centre and the distance. Points on the
    /// surface count as outside unless the normals are flipped.
    bool sees_cone(const Interaction &ref, double &one_minus_cos_max, double &dist2,
                   double &dist) const {
        dist2 = squared_norm(Vector3d(m_center) - Vector3d(ref.p));
        const double r2 = double(m_radius) * double(m_radius);
        const double threshold = r2 * (m_flip_normals ? 1.0 + 2e-4 : 1.0 - 2e-4);
        if (!(dist2 > threshold)) return false;
        dist = std::sqrt(dist2);
        // 1 - sqrt(1 - r²/d²) = r² / (d² + d·sqrt(d² - r²)): no cancellation for small cones,
        // one division (a point on the surface, d² a rounding below r², gets the hemisphere).
        one_minus_cos_max =
            std::min(r2 / (dist2 + dist * std::sqrt(std::max(dist2 - r2, 0.0))), 1.0);
        return true;
    }

    static float cone_pdf(double one_minus_cos_max) {
        const float pdf = 1.f / (2.f * Pi * float(one_minus_cos_max));
        return std::isfinite(pdf) ? pdf : 0.f;
    }

    /// Both roots of |o + t·d - c|² = r², nearest first. Returns false when the ray misses, or
    /// when it ends (at tfar) before it reaches the sphere from outside: f(t) = a t² + 2 b t + c
    /// then still falls at tfar (its least lies beyond) and is positive there, so no root lies
    /// on it. A light sample's shadow ray, which stops short of the light's sphere, is told so
    /// without the divisions and the square root. f(tfar) must exceed a margin far above the
    /// rounding of either computation (1e-10 of its terms' size, against doubles' 1e-16), so
    /// that it only says what the roots would say too; a ray ending closer finds them.
    bool solve(double ox, double oy, double oz, double dx, double dy, double dz, double tfar,
               double &t0, double &t1) const {
        ox -= m_center.x;
        oy -= m_center.y;
        oz -= m_center.z;
        double a = dx * dx + dy * dy + dz * dz;
        if (!(a > 0.0)) return false;
        double b = ox * dx + oy * dy + oz * dz; // half of the usual linear coefficient
        const double r2 = double(m_radius) * double(m_radius);
        double c = ox * ox + oy * oy + oz * oz - r2;
        if (c > 0.0 && -b > a * tfar &&
            (a * tfar + 2.0 * b) * tfar + c > 1e-10 * (c + 2.0 * r2 + a * tfar * tfar))
            return false;
        // Discriminant from the distance between the centre and the line (Haines et al.,
        // "Precision improvements for ray/sphere intersection", Ray Tracing Gems 2019).
        double k = b / a;
        double lx = ox - dx * k, ly = oy - dy * k, lz = oz - dz * k;
        double disc = a * (r2 - (lx * lx + ly * ly + lz * lz));
        if (disc < 0.0) return false;
        double q = -b - std::copysign(std::sqrt(disc), b);
        if (q == 0.0) {
            t0 = t1 = 0.0;
            return true;
        }
        t0 = q / a;
        t1 = c / q;
        if (t0 > t1) std::swap(t0, t1);
        return true;
    }

    /// Nearest root inside [tnear, tfar], or a negative value.
    bool nearest_hit(float ox, float oy, float oz, float dx, float dy, float dz, float tnear,
                     float tfar, float &t_hit) const {
        double t0, t1;
        if (!solve(ox, oy, oz, dx, dy, dz, tfar, t0, t1)) return false;
        if (t0 >= tnear && t0 <= tfar) {
            t_hit = float(t0);
            return true;
        }
        if (t1 >= tnear && t1 <= tfar) {
            t_hit = float(t1);
            return true;
        }
        return false;
    }

    Transform m_to_world, m_to_object;
    Point3f m_center;
    float m_radius = 1.f;
    double m_inv_radius = 1.0;
    bool m_flip_normals = false;
};

} // namespace facet

using facet::Sphere;
FACET_EXPORT_PLUGIN_MODES(Sphere, Shape, "sphere", "Exact sphere (analytic intersection)", DOC,
                          ::facet::AllModes)
