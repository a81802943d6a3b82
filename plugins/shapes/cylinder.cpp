static const char *DOC = R"DOC(
# cylinder

An exact open cylinder (a tube without end caps), intersected analytically as an Embree user
geometry. The axis runs from `p0` to `p1`; `to_world` is applied afterwards. The normals point
outwards, so with a one-sided BSDF the inside is black: use `twosided`, or `flip_normals` to make
the inside the front (an area emitter then lights the inside).

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| p0 | point | (0, 0, 0) | Start of the axis (object space) |
| p1 | point | (0, 0, 1) | End of the axis (object space); must differ from p0 |
| radius | float | 1 | Radius (object space); must be positive |
| flip_normals | boolean | false | Make the normals point inwards |
| to_world | transform | identity | Object-to-world transform applied after p0/p1/radius |

As in Mitsuba 3, `to_world` should be a rotation, translation and a scale that is uniform across
the axis (a different scale along the axis is fine). A shear or a non-uniform scale across the
axis logs a warning: the surface is then the exactly transformed (elliptic) tube, but its area,
and so the density of area-light sampling, uses the radius along the first cross-section axis.

Texture coordinates: u = φ/2π around the axis (φ measured in the frame Mitsuba builds from the
axis direction), v = 0 at p0 to 1 at p1. dp/du is the tangent around the axis (length 2π·radius)
and dp/dv = p1 - p0.

```xml
<shape type="cylinder">
    <point name="p0" value="0, -1, 0"/>
    <point name="p1" value="0, 1, 0"/>
    <float name="radius" value="0.3"/>
    <bsdf type="twosided">
        <bsdf type="diffuse"/>
    </bsdf>
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

#include <cmath>

namespace facet {

class Cylinder final : public Shape {
public:
    explicit Cylinder(const Properties &props) : Shape(props) {
        m_flip_normals = props.get_bool("flip_normals", false);
        const double radius = props.get_float("radius", 1.0);
        const Vector3f p0 = props.get_vector("p0", Vector3f(0.f, 0.f, 0.f));
        const Vector3f p1 = props.get_vector("p1", Vector3f(0.f, 0.f, 1.f));
        const Transform to_world = props.get_transform("to_world", Transform());
        if (!(radius > 0.0) || !std::isfinite(radius))
            FACET_THROW_AT(props.location("radius"),
                           "cylinder: radius must be a positive number, got {}", radius);
        const Vector3f axis = p1 - p0;
        const float length = norm(axis);
        if (!(length > 0.f) || !std::isfinite(length))
            FACET_THROW_AT(props.location(), "cylinder: p0 and p1 must be distinct finite points");
        const auto &m = to_world.matrix.m;
        if (m[3][0] != 0.f || m[3][1] != 0.f || m[3][2] != 0.f || m[3][3] != 1.f)
            FACET_THROW_AT(props.location("to_world"), "cylinder: to_world must be affine");

        // Object space is the unit tube x² + y² = 1, 0 <= z <= 1. The frame around the axis is
        // the one Mitsuba's Frame(axis) builds, so u = 0 lies where it does there.
        Frame frame(axis / length);
        Matrix4f to_frame;
        for (int r = 0; r < 3; ++r) {
            to_frame.m[r][0] = frame.s[r];
            to_frame.m[r][1] = frame.t[r];
            to_frame.m[r][2] = frame.n[r];
        }
        const float rad = float(radius);
        m_to_world = to_world * Transform::translate(p0) * Transform(to_frame) *
                     Transform::scale(Vector3f(rad, rad, length));
        m_to_object = m_to_world.inverse();

        const Vector3f ex = m_to_world.apply_vector(Vector3f(1.f, 0.f, 0.f));
        const Vector3f ey = m_to_world.apply_vector(Vector3f(0.f, 1.f, 0.f));
        const Vector3f ez = m_to_world.apply_vector(Vector3f(0.f, 0.f, 1.f));
        m_radius = norm(ex);
        m_length = norm(ez);
        m_area = 2.f * Pi * m_radius * m_length;
        const float det = dot(cross(ex, ey), ez);
        if (!std::isfinite(m_radius) || !std::isfinite(m_length) || !std::isfinite(m_area) ||
            !std::isfinite(det))
            FACET_THROW_AT(props.has("radius") ? props.location("radius") : props.location(),
                           "cylinder: too large for single precision (radius {}, length {}, "
                           "then to_world: its world-space size or area overflows)",
                           radius, length);
        if (!(m_area > 0.f) || !(std::abs(det) > 0.f))
            FACET_THROW_AT(props.location("to_world"),
                           "cylinder: to_world collapses the cylinder ({})", to_world.to_string());
        // The tolerances of Mitsuba's check on the polar decomposition, relative here.
        const float ry = norm(ey);
        const float tol = 1e-5f;
        if (std::abs(dot(ex, ey)) > tol * m_radius * ry ||
            std::abs(dot(ex, ez)) > tol * m_radius * m_length ||
            std::abs(dot(ey, ez)) > tol * ry * m_length)
            FACET_LOG(Warn, "cylinder: to_world should not contain a shear; the area (and the "
                            "density of area-light sampling) will be approximate");
        else if (std::abs(m_radius - ry) > tol * m_radius)
            FACET_LOG(Warn,
                      "cylinder: to_world should not scale the two directions across the axis "
                      "differently (radii {} and {}); the area (and the density of area-light "
                      "sampling) uses {}",
                      m_radius, ry, m_radius);

        // The two end circles bound the tube: per world axis, centre ± |(ex_i, ey_i)|.
        const Point3f c0 = m_to_world.apply_point(Point3f(0.f, 0.f, 0.f));
        const Point3f c1 = m_to_world.apply_point(Point3f(0.f, 0.f, 1.f));
        Vector3f ext;
        for (int i = 0; i < 3; ++i) ext[i] = std::sqrt(ex[i] * ex[i] + ey[i] * ey[i]);
        m_bbox.expand(c0 - ext);
        m_bbox.expand(c0 + ext);
        m_bbox.expand(c1 - ext);
        m_bbox.expand(c1 + ext);

        const auto &w = m_to_object.matrix.m;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) m_inv[r][c] = w[r][c];
    }

    BoundingBox3f bbox() const override { return m_bbox; }
    float surface_area() const override { return m_area; }

    RTCGeometry embree_geometry(RTCDevice device) const override {
        return make_user_geometry(device, this);
    }

    /// Embree callback (facet/user_geometry.h): the nearest hit in [tnear, tfar]; keeps the
    /// surface coordinates (u = φ/2π, v = z) as the hit's uv.
    bool intersect_user(const Point3f &o, const Vector3f &d, float tnear, float tfar,
                        UserHit &h) const {
        double t, x, y, z;
        if (!hit(o, d, tnear, tfar, t, x, y, z)) return false;
        double phi = std::atan2(y, x);
        if (phi < 0.0) phi += 2.0 * M_PI;
        h.t = float(t);
        h.uv = Point2f(float(phi * (0.5 / M_PI)), float(z));
        h.ng = normal_at(float(x), float(y));
        return true;
    }

    /// `uv` holds (φ/2π, z) of the hit in object space, stored by the intersection callback.
    void compute_surface_interaction(const Ray &ray, float t, uint32_t prim_index,
                                     const Point2f &uv, SurfaceInteraction &si) const override {
        si.t = t;
        si.shape = this;
        si.prim_index = prim_index;
        const float phi = 2.f * Pi * uv.x;
        const float c = std::cos(phi), s = std::sin(phi);
        si.p = m_to_world.apply_point(Point3f(c, s, uv.y));
        si.n = normal_at(c, s);
        si.uv = uv;
        si.dp_du = m_to_world.apply_vector(Vector3f(-s, c, 0.f) * (2.f * Pi));
        si.dp_dv = m_to_world.apply_vector(Vector3f(0.f, 0.f, 1.f));
        Vector3f tangent = si.dp_du - si.n * dot(si.n, si.dp_du);
        const Vector3f ts = normalize(tangent);
        si.sh_frame = Frame(ts, cross(si.n, ts), si.n);
        si.wi = si.to_local(-ray.d);
    }

    /// Uniform in (φ, z) of the object-space tube, which is uniform in area when the tube is
    /// circular (see the note on to_world above). uv = (u.y, u.x) as in Mitsuba.
    PositionSample sample_position(const Point2f &u) const override {
        const float phi = 2.f * Pi * u.y;
        const float c = std::cos(phi), s = std::sin(phi);
        PositionSample ps;
        ps.p = m_to_world.apply_point(Point3f(c, s, u.x));
        ps.n = normal_at(c, s);
        ps.uv = Point2f(u.y, u.x);
        ps.pdf = 1.f / m_area;
        return ps;
    }

    std::string to_string() const override {
        return fmt::format(
            "Cylinder[to_world={}, radius={}, length={}, area={}, flip_normals={}, bsdf={}, "
            "emitter={}]",
            m_to_world.to_string(), m_radius, m_length, m_area, m_flip_normals,
            m_bsdf ? m_bsdf->to_string() : "none", emitter_label());
    }

private:
    /// Unit world-space normal at the object-space point (x, y, ·) of the tube.
    Normal3f normal_at(float x, float y) const {
        Normal3f n = normalize(m_to_world.apply_normal(Normal3f(x, y, 0.f)));
        return m_flip_normals ? -n : n;
    }

    /// Ray-tube intersection in object space (double precision). An affine map keeps the ray
    /// parameter, so the object-space t is the world-space t. Takes the nearer root when it lies
    /// on the finite tube, else the farther one (looking into the open end).
    bool hit(const Point3f &o_, const Vector3f &d_, float tnear, float tfar, double &t_hit,
             double &x, double &y, double &z) const {
        const double o[3] = {o_.x, o_.y, o_.z}, d[3] = {d_.x, d_.y, d_.z};
        double lo[3], ld[3];
        for (int r = 0; r < 3; ++r) {
            lo[r] = m_inv[r][0] * o[0] + m_inv[r][1] * o[1] + m_inv[r][2] * o[2] + m_inv[r][3];
            ld[r] = m_inv[r][0] * d[0] + m_inv[r][1] * d[1] + m_inv[r][2] * d[2];
        }
        const double a = ld[0] * ld[0] + ld[1] * ld[1];
        const double b = 2.0 * (ld[0] * lo[0] + ld[1] * lo[1]);
        const double c = lo[0] * lo[0] + lo[1] * lo[1] - 1.0;
        if (!(a > 0.0)) return false; // parallel to the axis: never on the tube
        const double disc = b * b - 4.0 * a * c;
        if (!(disc >= 0.0)) return false;
        // Numerically stable roots (no cancellation between -b and the square root).
        const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
        double t0 = q / a, t1 = q != 0.0 ? c / q : t0;
        if (t0 > t1) std::swap(t0, t1);
        for (double tc : {t0, t1}) {
            if (!(tc >= double(tnear) && tc <= double(tfar))) continue;
            const double zc = lo[2] + tc * ld[2];
            if (!(zc >= 0.0 && zc <= 1.0)) continue;
            t_hit = tc;
            x = lo[0] + tc * ld[0];
            y = lo[1] + tc * ld[1];
            z = zc;
            return true;
        }
        return false;
    }

    Transform m_to_world, m_to_object;
    double m_inv[3][4];
    BoundingBox3f m_bbox;
    float m_radius = 1.f, m_length = 1.f, m_area = 0.f;
    bool m_flip_normals = false;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Cylinder, Shape, "cylinder",
                          "Exact open cylinder (analytic intersection)", DOC, ::facet::AllModes)
