static const char *DOC = R"DOC(
# disk

The unit disk x² + y² ≤ 1 in the z = 0 plane with its normal along +z, placed by `to_world`
(any affine transform: a non-uniform scale makes an ellipse). Intersected exactly as an Embree
user geometry.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| flip_normals | boolean | false | Make the normal point along -z (object space) |
| to_world | transform | identity | Object-to-world transform |

Texture coordinates are polar: u = r (distance to the centre), v = φ/2π.

```xml
<shape type="disk">
    <transform name="to_world">
        <scale value="0.3"/>
        <rotate x="1" angle="90"/>
        <translate y="2"/>
    </transform>
    <emitter type="area"/>
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

class Disk final : public Shape {
public:
    explicit Disk(const Properties &props) : Shape(props) {
        m_flip_normals = props.get_bool("flip_normals", false);
        m_to_world = props.get_transform("to_world", Transform());
        const auto &m = m_to_world.matrix.m;
        if (m[3][0] != 0.f || m[3][1] != 0.f || m[3][2] != 0.f || m[3][3] != 1.f)
            FACET_THROW_AT(props.location("to_world"), "disk: to_world must be affine");
        m_to_object = m_to_world.inverse();
        Vector3f du = m_to_world.apply_vector(Vector3f(1.f, 0.f, 0.f));
        Vector3f dv = m_to_world.apply_vector(Vector3f(0.f, 1.f, 0.f));
        // An affine map scales every area of the plane by |du × dv|.
        m_area = Pi * norm(cross(du, dv));
        if (!(m_area > 0.f) || !std::isfinite(m_area))
            FACET_THROW_AT(props.location("to_world"), "disk: to_world collapses the disk ({})",
                           m_to_world.to_string());
        Normal3f n = normalize(m_to_world.apply_normal(Normal3f(0.f, 0.f, 1.f)));
        m_normal = m_flip_normals ? -n : n;
        for (int i = 0; i < 4; ++i)
            m_bbox.expand(
                m_to_world.apply_point(Point3f((i & 1) ? 1.f : -1.f, (i & 2) ? 1.f : -1.f, 0.f)));
        // Rows of the world-to-object matrix in double for the intersection test.
        const auto &w = m_to_object.matrix.m;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) m_inv[r][c] = w[r][c];
    }

    BoundingBox3f bbox() const override { return m_bbox; }
    float surface_area() const override { return m_area; }

    RTCGeometry embree_geometry(RTCDevice device) const override {
        return make_user_geometry(device, this);
    }

    /// Embree callback (facet/user_geometry.h): keeps the object-space (x, y) of the hit as uv.
    bool intersect_user(const Point3f &o, const Vector3f &d, float tnear, float tfar,
                        UserHit &h) const {
        if (!hit(o.x, o.y, o.z, d.x, d.y, d.z, tnear, tfar, h.t, h.uv.x, h.uv.y)) return false;
        h.ng = m_normal;
        return true;
    }

    /// `uv` holds the object-space (x, y) of the hit, stored by the intersection callback.
    void compute_surface_interaction(const Ray &ray, float t, uint32_t prim_index,
                                     const Point2f &uv, SurfaceInteraction &si) const override {
        si.t = t;
        si.shape = this;
        si.prim_index = prim_index;
        si.p = m_to_world.apply_point(Point3f(uv.x, uv.y, 0.f));
        si.n = m_normal;
        float r = std::sqrt(uv.x * uv.x + uv.y * uv.y);
        float phi = r > 0.f ? fast_atan2(uv.y, uv.x) : 0.f;
        if (phi < 0.f) phi += 2.f * Pi;
        si.uv = Point2f(r, phi * InvTwoPi);
        float cos_phi = std::cos(phi), sin_phi = std::sin(phi);
        si.dp_du = m_to_world.apply_vector(Vector3f(cos_phi, sin_phi, 0.f));
        si.dp_dv = m_to_world.apply_vector(Vector3f(-sin_phi, cos_phi, 0.f) * (2.f * Pi * r));

        Vector3f s = si.dp_du - si.n * dot(si.n, si.dp_du);
        float s_len = norm(s);
        if (s_len > 1e-6f * norm(si.dp_du)) {
            s /= s_len;
            si.sh_frame = Frame(s, cross(si.n, s), si.n);
        } else {
            si.sh_frame = Frame(si.n);
        }
        si.wi = si.to_local(-ray.d);
    }

    PositionSample sample_position(const Point2f &u) const override {
        Point2f q = warp::square_to_uniform_disk_concentric(u);
        PositionSample ps;
        ps.p = m_to_world.apply_point(Point3f(q.x, q.y, 0.f));
        ps.n = m_normal;
        float r = norm(q);
        float phi = r > 0.f ? fast_atan2(q.y, q.x) : 0.f;
        if (phi < 0.f) phi += 2.f * Pi;
        ps.uv = Point2f(r, phi * InvTwoPi);
        ps.pdf = 1.f / m_area;
        return ps;
    }

    /// One normal (with a margin for its rounding).
    std::pair<Vector3f, float> normal_cone() const override {
        return {Vector3f(m_normal), std::cos(1e-3f)};
    }

    std::string to_string() const override {
        return fmt::format("Disk[to_world={}, area={}, flip_normals={}, bsdf={}, emitter={}]",
                           m_to_world.to_string(), m_area, m_flip_normals,
                           m_bsdf ? m_bsdf->to_string() : "none", emitter_label());
    }

private:
    /// Ray-plane intersection in object space. An affine map keeps the ray parameter, so the
    /// object-space t is the world-space t.
    bool hit(float ox_, float oy_, float oz_, float dx_, float dy_, float dz_, float tnear,
             float tfar, float &t_hit, float &x, float &y) const {
        const double o[3] = {ox_, oy_, oz_}, d[3] = {dx_, dy_, dz_};
        double lo[3], ld[3];
        for (int r = 0; r < 3; ++r) {
            lo[r] = m_inv[r][0] * o[0] + m_inv[r][1] * o[1] + m_inv[r][2] * o[2] + m_inv[r][3];
            ld[r] = m_inv[r][0] * d[0] + m_inv[r][1] * d[1] + m_inv[r][2] * d[2];
        }
        if (ld[2] == 0.0) return false;
        double t = -lo[2] / ld[2];
        if (!(t >= tnear && t <= tfar)) return false;
        double px = lo[0] + t * ld[0], py = lo[1] + t * ld[1];
        if (px * px + py * py > 1.0) return false;
        t_hit = float(t);
        x = float(px);
        y = float(py);
        return true;
    }

    Transform m_to_world, m_to_object;
    double m_inv[3][4];
    Normal3f m_normal;
    BoundingBox3f m_bbox;
    float m_area = 0.f;
    bool m_flip_normals = false;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Disk, Shape, "disk", "Exact disk (analytic intersection)", DOC,
                          ::facet::AllModes)
