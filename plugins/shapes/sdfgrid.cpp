static const char *DOC = R"DOC(
# sdfgrid

A signed distance function sampled on a regular 3D grid, intersected exactly: the surface is the
zero set of the trilinear interpolant of the samples. As in Mitsuba 3, the grid fills the unit
cube [0, 1]³ of object space (sample (i, j, k) of an nx × ny × nz grid sits at
(i/(nx−1), j/(ny−1), k/(nz−1))), and `to_world` places it. Negative values are inside.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| filename | string | — | Grid file in Mitsuba's `.vol` format with one float32 channel (required) |
| normals | string | smooth | Shading normals: `smooth` (gradients of the 8 voxels around the nearest grid vertex, blended trilinearly; Hansson-Söderlund et al. 2022) or `analytic` (the gradient of the interpolant in the hit voxel) |
| to_world | transform | identity | Object-to-world transform (affine, invertible) |

The `.vol` file is little-endian: the bytes `VOL`, the version byte 3, the encoding (int32, 1 =
float32), the resolution xres, yres, zres (int32), the channel count (int32, must be 1), a
bounding box of 6 float32 (read but not used: Mitsuba's sdfgrid always maps the grid to [0, 1]³)
and xres·yres·zres float32 values, x fastest: value (x, y, z) at index (z·yres + y)·xres + x.
Every axis needs at least 2 samples and the values must be finite.

Each voxel whose corner values are not all of one sign is an Embree primitive with a tight
bounding box (so empty space costs nothing); a ray is clipped to the voxel and the cubic of the
interpolant along it is split at the roots of its derivative and solved by safeguarded Newton
iterations, in double precision. The geometric normal is always the analytic one. As in
Mitsuba 3, the shape has no texture coordinates (uv = 0, dp/du = dp/dv = 0) and cannot be an area
emitter or carry a sensor (both are refused). The `grid` tensor parameter of Mitsuba exists only
in its Python and C++ API and is not read from XML.

```xml
<shape type="sdfgrid">
    <string name="filename" value="bunny_sdf.vol"/>
    <string name="normals" value="analytic"/>
    <bsdf type="diffuse"/>
</shape>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/resolver.h>
#include <facet/shape.h>
#include <facet/transform.h>
#include <facet/user_geometry.h>

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace facet {

namespace {

/// The samples of a one-channel .vol file.
struct GridSamples {
    int n[3] = {0, 0, 0}; ///< resolution along x, y, z
    std::vector<float> values;
};

int32_t read_i32(const std::string &bytes, size_t offset) {
    int32_t v;
    std::memcpy(&v, bytes.data() + offset, sizeof v);
    return v;
}

/// Reads and checks a .vol file for an SDF grid (see the table above for the layout).
GridSamples read_vol(const std::string &path, const Location &loc) {
    struct stat st;
    if (::stat(path.c_str(), &st) != 0)
        FACET_THROW_AT(loc, "sdfgrid: cannot open \"{}\": {}", path, std::strerror(errno));
    if (!S_ISREG(st.st_mode)) FACET_THROW_AT(loc, "sdfgrid: \"{}\" is not a regular file", path);
    const std::string bytes = read_file(path, "sdfgrid");
    const size_t header = 48;
    if (bytes.size() < header)
        FACET_THROW_AT(loc, "sdfgrid: \"{}\" has {} bytes, less than the 48-byte .vol header", path,
                       bytes.size());
    if (bytes.compare(0, 3, "VOL") != 0)
        FACET_THROW_AT(loc, "sdfgrid: \"{}\" is not a .vol grid (it does not start with \"VOL\")",
                       path);
    if (uint8_t(bytes[3]) != 3)
        FACET_THROW_AT(loc, "sdfgrid: \"{}\" is a .vol file of version {}, expected version 3",
                       path, int(uint8_t(bytes[3])));
    int32_t encoding = read_i32(bytes, 4);
    if (encoding != 1)
        FACET_THROW_AT(loc,
                       "sdfgrid: \"{}\" uses encoding {}, but only encoding 1 (float32) is "
                       "supported",
                       path, encoding);
    GridSamples g;
    const char *axes = "xyz";
    for (int a = 0; a < 3; ++a) {
        int32_t res = read_i32(bytes, 8 + 4 * size_t(a));
        if (res < 2)
            FACET_THROW_AT(loc,
                           "sdfgrid: \"{}\" has {}res = {}, but an SDF grid needs at least 2 "
                           "samples along each axis",
                           path, axes[a], res);
        g.n[a] = res;
    }
    int32_t channels = read_i32(bytes, 20);
    if (channels != 1)
        FACET_THROW_AT(loc, "sdfgrid: \"{}\" has {} channels, expected 1 (one distance per sample)",
                       path, channels);
    // xres·yres·zres·channels·4 bytes must follow the header exactly; checked arithmetic, as
    // the resolutions come from the file.
    uint64_t count = 1, data_bytes = 0;
    bool overflow = __builtin_mul_overflow(count, uint64_t(g.n[0]), &count) ||
                    __builtin_mul_overflow(count, uint64_t(g.n[1]), &count) ||
                    __builtin_mul_overflow(count, uint64_t(g.n[2]), &count) ||
                    __builtin_mul_overflow(count, uint64_t(channels) * 4u, &data_bytes);
    if (overflow || data_bytes != bytes.size() - header)
        FACET_THROW_AT(loc,
                       "sdfgrid: \"{}\" declares {} x {} x {} samples ({} bytes of data), but "
                       "{} bytes follow its header",
                       path, g.n[0], g.n[1], g.n[2],
                       overflow ? std::string("more than 2^64") : std::to_string(data_bytes),
                       bytes.size() - header);
    if (count > uint64_t(UINT32_MAX))
        FACET_THROW_AT(loc, "sdfgrid: \"{}\" has {} samples, more than the 2^32 - 1 supported",
                       path, count);
    g.values.resize(size_t(count));
    std::memcpy(g.values.data(), bytes.data() + header, size_t(data_bytes));
    for (size_t i = 0; i < g.values.size(); ++i)
        if (!std::isfinite(g.values[i])) {
            size_t x = i % size_t(g.n[0]), y = (i / size_t(g.n[0])) % size_t(g.n[1]),
                   z = i / (size_t(g.n[0]) * size_t(g.n[1]));
            FACET_THROW_AT(loc, "sdfgrid: \"{}\" has a non-finite value at sample ({}, {}, {})",
                           path, x, y, z);
        }
    return g;
}

/// An affine map in double precision (3 rows of a 4x4 matrix).
struct Affine {
    double m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

    Vector3d point(const Vector3d &p) const {
        return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
                m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
                m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
    }
    Vector3d vector(const Vector3d &v) const {
        return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
                m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    }
    /// The transpose of the linear part applied to v: how a gradient taken in this map's
    /// target space becomes one in its source space.
    Vector3d transpose_vector(const Vector3d &v) const {
        return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z,
                m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
                m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
    }
    double determinant() const {
        return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
               m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    }
    Affine inverse() const {
        double det = determinant();
        Affine r;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                // Cofactor of (j, i) over the determinant.
                int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
                r.m[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
            }
        for (int i = 0; i < 3; ++i)
            r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
        return r;
    }
};

/// Roots of a u² + b u + c in increasing order; returns their number (0 to 2).
int solve_quadratic(double a, double b, double c, double roots[2]) {
    if (a == 0.0) {
        if (b == 0.0) return 0;
        roots[0] = -c / b;
        return 1;
    }
    double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) return 0;
    // The form without cancellation (Numerical Recipes §5.6).
    double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    if (q == 0.0) {
        roots[0] = 0.0;
        return 1;
    }
    roots[0] = q / a;
    roots[1] = c / q;
    if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
    return 2;
}

double eval_cubic(const double c[4], double u) { return ((c[3] * u + c[2]) * u + c[1]) * u + c[0]; }
double eval_cubic_derivative(const double c[4], double u) {
    return (3.0 * c[3] * u + 2.0 * c[2]) * u + c[1];
}

/// Smallest root of the cubic c in [0, len]. The interval is split at the roots of the
/// derivative into pieces on which the cubic is monotonic; the first piece whose ends differ in
/// sign holds the root, found by Newton steps kept inside the shrinking bracket (bisection
/// otherwise).
bool first_root(const double c[4], double len, double &root) {
    double splits[4];
    int count = 0;
    splits[count++] = 0.0;
    double r[2];
    int nr = solve_quadratic(3.0 * c[3], 2.0 * c[2], c[1], r);
    for (int i = 0; i < nr; ++i)
        if (r[i] > 0.0 && r[i] < len) splits[count++] = r[i];
    splits[count++] = len;

    for (int piece = 0; piece + 1 < count; ++piece) {
        double lo = splits[piece], hi = splits[piece + 1];
        double f_lo = eval_cubic(c, lo), f_hi = eval_cubic(c, hi);
        if (f_lo == 0.0) {
            root = lo;
            return true;
        }
        if (!((f_lo < 0.0 && f_hi > 0.0) || (f_lo > 0.0 && f_hi < 0.0))) continue;
        const bool lo_negative = f_lo < 0.0;
        // Start from the secant estimate.
        double u = lo + (hi - lo) * (f_lo / (f_lo - f_hi));
        if (!(u > lo && u < hi)) u = 0.5 * (lo + hi);
        for (int it = 0; it < 100; ++it) {
            double f = eval_cubic(c, u);
            if (f == 0.0) break;
            if ((f < 0.0) == lo_negative)
                lo = u;
            else
                hi = u;
            double next = u - f / eval_cubic_derivative(c, u);
            if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
            bool converged = std::abs(next - u) <= 1e-15 * std::max(std::abs(u), len) ||
                             hi - lo <= 1e-15 * std::max(std::abs(lo), len);
            u = next;
            if (converged) break;
        }
        root = u;
        return true;
    }
    if (eval_cubic(c, len) == 0.0) {
        root = len;
        return true;
    }
    return false;
}

/// Gradient of the trilinear interpolant of the corner values f (indexed x + 2y + 4z) at w in
/// [0, 1]³, in voxel units: each partial derivative is the bilinear interpolation of the
/// differences along the four edges parallel to its axis.
Vector3d trilerp_gradient(const double f[8], const Vector3d &w) {
    auto bilerp = [](double a, double b, double c, double d, double s, double t) {
        return (a + (b - a) * s) * (1.0 - t) + (c + (d - c) * s) * t;
    };
    return {bilerp(f[1] - f[0], f[3] - f[2], f[5] - f[4], f[7] - f[6], w.y, w.z),
            bilerp(f[2] - f[0], f[3] - f[1], f[6] - f[4], f[7] - f[5], w.x, w.z),
            bilerp(f[4] - f[0], f[5] - f[1], f[6] - f[2], f[7] - f[3], w.x, w.y)};
}

} // namespace

class SDFGrid final : public Shape {
public:
    explicit SDFGrid(const Properties &props) : Shape(props) {
        std::string normals = props.get_string("normals", "smooth");
        if (normals == "smooth")
            m_smooth = true;
        else if (normals == "analytic")
            m_smooth = false;
        else
            FACET_THROW_AT(props.location("normals"),
                           "sdfgrid: normals must be \"smooth\" or \"analytic\", got \"{}\"",
                           normals);
        if (!props.has("filename"))
            FACET_THROW_AT(props.location(),
                           "sdfgrid: the grid must be given with \"filename\" (a .vol file)");
        m_filename = props.get_string("filename");
        Transform to_world = props.get_transform("to_world", Transform());
        if (m_emitter)
            FACET_THROW_AT(props.location(),
                           "sdfgrid: an SDF grid cannot be an area emitter (as in Mitsuba 3, it "
                           "has no surface sampling)");
        if (m_sensor)
            FACET_THROW_AT(props.location(),
                           "sdfgrid: an SDF grid cannot carry a sensor (it has no surface "
                           "sampling)");

        const auto &m = to_world.matrix.m;
        if (m[3][0] != 0.f || m[3][1] != 0.f || m[3][2] != 0.f || m[3][3] != 1.f)
            FACET_THROW_AT(props.location("to_world"),
                           "sdfgrid: to_world must be affine (no projection): {}",
                           to_world.to_string());
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j) m_to_world.m[i][j] = double(m[i][j]);
        double det = m_to_world.determinant();
        if (!(std::abs(det) > 0.0) || !std::isfinite(det))
            FACET_THROW_AT(props.location("to_world"), "sdfgrid: to_world is singular: {}",
                           to_world.to_string());
        m_to_object = m_to_world.inverse();

        GridSamples grid =
            read_vol(file_resolver().resolve(m_filename), props.location("filename"));
        for (int a = 0; a < 3; ++a) {
            m_n[a] = grid.n[a];
            m_scale[a] = double(grid.n[a] - 1);
        }
        m_values = std::move(grid.values);
        // World to grid coordinates: object space [0,1]³ scaled to [0, n-1] per axis.
        m_to_grid = m_to_object;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j) m_to_grid.m[i][j] *= m_scale[i];

        build_voxels();
        if (m_voxels.empty())
            FACET_THROW_AT(props.location("filename"),
                           "sdfgrid: \"{}\" has no surface: no voxel has corner values of both "
                           "signs (or zero)",
                           m_filename);

        for (int k = 0; k < 8; ++k)
            m_bbox.expand(Point3f(
                m_to_world.point(Vector3d(double(k & 1), double((k >> 1) & 1), double(k >> 2)))));
    }

    BoundingBox3f bbox() const override { return m_bbox; }
    /// As in Mitsuba 3: the area of the level set is not computed.
    float surface_area() const override { return 0.f; }

    RTCGeometry embree_geometry(RTCDevice device) const override {
        RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(geom, unsigned(m_voxels.size()));
        rtcSetGeometryUserData(geom, const_cast<SDFGrid *>(this));
        rtcSetGeometryBoundsFunction(geom, &SDFGrid::embree_bounds, nullptr);
        rtcSetGeometryIntersectFunction(geom, &SDFGrid::embree_intersect);
        rtcSetGeometryOccludedFunction(geom, &SDFGrid::embree_occluded);
        rtcCommitGeometry(geom);
        return geom;
    }

    void compute_surface_interaction(const Ray &ray, float t, uint32_t prim_index, const Point2f &,
                                     SurfaceInteraction &si) const override {
        const Point3f p = ray(t);
        const Vector3d g = m_to_grid.point(Vector3d(p));
        double f[8];
        int v[3];
        corners(m_voxels[prim_index], f, v);
        Vector3d w(std::clamp(g.x - v[0], 0.0, 1.0), std::clamp(g.y - v[1], 0.0, 1.0),
                   std::clamp(g.z - v[2], 0.0, 1.0));
        // The gradient in grid units becomes one in world units through the transpose of the
        // world-to-grid map (normals transform with the inverse transpose of to_world).
        Vector3d n_world = m_to_grid.transpose_vector(trilerp_gradient(f, w));
        double len = norm(n_world);
        Normal3f n = len > 0.0 && std::isfinite(len) ? Normal3f(n_world / len) : -ray.d;

        si.t = t;
        si.p = p;
        si.n = n;
        si.shape = this;
        si.prim_index = prim_index;
        si.uv = Point2f(0.f);
        si.dp_du = si.dp_dv = Vector3f(0.f);
        Normal3f ns = n;
        if (m_smooth) {
            Vector3d s = smooth_normal(g);
            double s_len = norm(s);
            if (s_len > 0.0 && std::isfinite(s_len)) ns = Normal3f(s / s_len);
        }
        si.sh_frame = Frame(ns);
        si.wi = si.to_local(-ray.d);
    }

    /// As in Mitsuba 3, the surface is not sampled: an empty sample of density zero.
    PositionSample sample_position(const Point2f &) const override { return PositionSample(); }
    float pdf_position(const PositionSample &) const override { return 0.f; }

    /// Exact hit with voxel `prim` in [tnear, tfar] (public for the Embree callbacks).
    bool intersect_voxel(uint32_t prim, const Point3f &o, const Vector3f &d, float tnear,
                         float tfar, float &t_hit) const {
        double f[8];
        int v[3];
        corners(m_voxels[prim], f, v);
        const Vector3d og = m_to_grid.point(Vector3d(o)), dg = m_to_grid.vector(Vector3d(d));
        const double q0[3] = {og.x - v[0], og.y - v[1], og.z - v[2]}, dq[3] = {dg.x, dg.y, dg.z};

        // Slab test against the voxel [0,1]³ in its own coordinates.
        double t_enter = -Infinity, t_exit = Infinity, d_max = 0.0;
        for (int a = 0; a < 3; ++a) {
            if (dq[a] == 0.0) {
                if (q0[a] < 0.0 || q0[a] > 1.0) return false;
                continue;
            }
            double ta = -q0[a] / dq[a], tb = (1.0 - q0[a]) / dq[a];
            if (ta > tb) std::swap(ta, tb);
            t_enter = std::max(t_enter, ta);
            t_exit = std::min(t_exit, tb);
            d_max = std::max(d_max, std::abs(dq[a]));
        }
        if (d_max == 0.0) return false;
        // The ends are pushed a millionth of a voxel beyond the faces: neighbours agree on a
        // shared face only up to rounding, and a root right on it must not slip between them.
        const double margin = 1e-6 / d_max;
        double t0 = std::max(double(tnear), t_enter - margin),
               t1 = std::min(double(tfar), t_exit + margin);
        if (!(t0 <= t1)) return false;

        // f along the ray as a cubic in u = t - t0: every corner weight is a product of three
        // linear factors (w or 1 - w per axis).
        double c[4] = {0.0, 0.0, 0.0, 0.0};
        for (int i = 0; i < 8; ++i) {
            double a0[3], a1[3];
            for (int a = 0; a < 3; ++a) {
                double w0 = q0[a] + dq[a] * t0;
                bool upper = (i >> a) & 1;
                a0[a] = upper ? w0 : 1.0 - w0;
                a1[a] = upper ? dq[a] : -dq[a];
            }
            c[0] += f[i] * (a0[0] * a0[1] * a0[2]);
            c[1] += f[i] * (a1[0] * a0[1] * a0[2] + a0[0] * a1[1] * a0[2] + a0[0] * a0[1] * a1[2]);
            c[2] += f[i] * (a1[0] * a1[1] * a0[2] + a1[0] * a0[1] * a1[2] + a0[0] * a1[1] * a1[2]);
            c[3] += f[i] * (a1[0] * a1[1] * a1[2]);
        }
        double u;
        if (!first_root(c, t1 - t0, u)) return false;
        float t = float(t0 + u);
        t_hit = std::clamp(t, tnear, tfar);
        return true;
    }

    std::string to_string() const override {
        return fmt::format("SDFGrid[filename=\"{}\", resolution=[{}, {}, {}], voxels with "
                           "surface={}, normals={}, bsdf={}]",
                           m_filename, m_n[0], m_n[1], m_n[2], m_voxels.size(),
                           m_smooth ? "smooth" : "analytic", m_bsdf ? m_bsdf->to_string() : "none");
    }

private:
    float sample(int x, int y, int z) const {
        return m_values[(size_t(z) * size_t(m_n[1]) + size_t(y)) * size_t(m_n[0]) + size_t(x)];
    }
    float sample_clamped(int x, int y, int z) const {
        return sample(std::clamp(x, 0, m_n[0] - 1), std::clamp(y, 0, m_n[1] - 1),
                      std::clamp(z, 0, m_n[2] - 1));
    }

    /// The corner values of the voxel whose lower corner has sample index `base` (indexed
    /// x + 2y + 4z) and that corner's grid position.
    void corners(uint32_t base, double f[8], int v[3]) const {
        const uint32_t nx = uint32_t(m_n[0]), ny = uint32_t(m_n[1]);
        v[0] = int(base % nx);
        v[1] = int((base / nx) % ny);
        v[2] = int(base / (nx * ny));
        for (int i = 0; i < 8; ++i)
            f[i] = double(m_values[base + (i & 1) + nx * (((i >> 1) & 1) + ny * (i >> 2))]);
    }

    /// The voxels with corner values of both signs (a zero counts as both), with boxes around
    /// the part of the surface inside them: the box of the corners that are zero and of the
    /// points where the surface crosses an edge, which bounds the zero set of the trilinear
    /// interpolant (Hansson-Söderlund and Akenine-Möller 2023).
    void build_voxels() {
        const int nx = m_n[0], ny = m_n[1], nz = m_n[2];
        const Vector3d world_voxel = abs(m_to_world.vector(Vector3d(1.0 / m_scale[0], 0, 0))) +
                                     abs(m_to_world.vector(Vector3d(0, 1.0 / m_scale[1], 0))) +
                                     abs(m_to_world.vector(Vector3d(0, 0, 1.0 / m_scale[2])));
        for (int z = 0; z + 1 < nz; ++z)
            for (int y = 0; y + 1 < ny; ++y)
                for (int x = 0; x + 1 < nx; ++x) {
                    uint32_t base =
                        uint32_t((size_t(z) * size_t(ny) + size_t(y)) * size_t(nx) + size_t(x));
                    double f[8];
                    int v[3];
                    corners(base, f, v);
                    bool nonneg = false, nonpos = false;
                    for (double fi : f) {
                        nonneg |= fi >= 0.0;
                        nonpos |= fi <= 0.0;
                    }
                    if (!(nonneg && nonpos)) continue;
                    Vector3d lo(Infinity), hi(-Infinity);
                    auto include = [&](const Vector3d &p) {
                        lo = min(lo, p);
                        hi = max(hi, p);
                    };
                    for (int i = 0; i < 8; ++i) {
                        Vector3d corner(i & 1, (i >> 1) & 1, i >> 2);
                        if (f[i] == 0.0) include(corner);
                        for (int a = 0; a < 3; ++a) {
                            if (i & (1 << a)) continue;
                            int j = i | (1 << a);
                            if (f[i] * f[j] <= 0.0 && f[i] != f[j]) {
                                Vector3d p = corner;
                                p[a] = f[i] / (f[i] - f[j]);
                                include(p);
                            }
                        }
                    }
                    BoundingBox3f box;
                    for (int k = 0; k < 8; ++k) {
                        Vector3d g((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y,
                                   (k & 4) ? hi.z : lo.z);
                        Vector3d obj((g.x + v[0]) / m_scale[0], (g.y + v[1]) / m_scale[1],
                                     (g.z + v[2]) / m_scale[2]);
                        box.expand(Point3f(m_to_world.point(obj)));
                    }
                    // Padding for the rounding of the box and of Embree's ray-box tests, and
                    // for the margin of intersect_voxel().
                    Vector3f pad = Vector3f(world_voxel * 1e-3) +
                                   Vector3f(max_component(max(abs(box.min), abs(box.max))) * 1e-6f);
                    m_voxels.push_back(base);
                    m_boxes.emplace_back(box.min - pad, box.max + pad);
                }
    }

    /// Smooth shading normal (Hansson-Söderlund, Evans and Akenine-Möller 2022, "Ray Tracing of
    /// Signed Distance Function Grids", JCGT 11(3)), in Mitsuba 3's form: the gradients of the
    /// 2×2×2 voxels around the grid vertex nearest to the point, each normalised, blended
    /// trilinearly by the point's position relative to the voxel centres. Along each axis a
    /// voxel's gradient component is the difference of the interpolant across the voxel,
    /// evaluated at the point's other two coordinates. Voxels below the grid get no weight;
    /// above it, the clamped samples make that component zero. Returns the world-space normal
    /// (not normalised), or zero.
    Vector3d smooth_normal(const Vector3d &s) const {
        int v[3], cell[3];
        double u[3], w[3];
        bool inside[3];
        for (int a = 0; a < 3; ++a) {
            int nearest = int(std::nearbyint(s[a]));
            v[a] = nearest - 1;
            u[a] = s[a] - double(v[a]) - 0.5;
            cell[a] = std::clamp(int(std::floor(s[a])), 0, m_n[a] - 2);
            w[a] = s[a] - double(cell[a]);
            inside[a] = v[a] >= 0;
            if (!inside[a]) u[a] = 1.0;
        }
        // Interpolant on sample plane q of axis a, at the point's other coordinates.
        auto plane = [&](int a, int q) {
            int b = (a + 1) % 3, c = (a + 2) % 3;
            double f[2][2];
            for (int i = 0; i < 2; ++i)
                for (int j = 0; j < 2; ++j) {
                    int idx[3];
                    idx[a] = q;
                    idx[b] = cell[b] + i;
                    idx[c] = cell[c] + j;
                    f[i][j] = double(sample_clamped(idx[0], idx[1], idx[2]));
                }
            double lo = f[0][0] + (f[1][0] - f[0][0]) * w[b];
            double hi = f[0][1] + (f[1][1] - f[0][1]) * w[b];
            return lo + (hi - lo) * w[c];
        };
        // diff[a][h]: the gradient component along a of the voxels with index v[a] + h.
        double diff[3][2];
        for (int a = 0; a < 3; ++a)
            for (int h = 0; h < 2; ++h) {
                int j = v[a] + h;
                diff[a][h] = (plane(a, j + 1) - plane(a, j)) * m_scale[a];
            }
        Vector3d blended(0.0);
        for (int i = 0; i < 8; ++i) {
            int h[3] = {i & 1, (i >> 1) & 1, (i >> 2) & 1};
            bool used = true;
            double weight = 1.0;
            Vector3d g;
            for (int a = 0; a < 3; ++a) {
                used &= h[a] == 1 || inside[a];
                weight *= h[a] ? u[a] : 1.0 - u[a];
                g[a] = diff[a][h[a]];
            }
            double len = norm(g);
            if (!used || !(len > 0.0)) continue;
            blended = blended + g * (weight / len);
        }
        // An object-space gradient: to world with the transpose of to_object.
        return m_to_object.transpose_vector(blended);
    }

    static void embree_bounds(const RTCBoundsFunctionArguments *args) {
        const auto *shape = static_cast<const SDFGrid *>(args->geometryUserPtr);
        const BoundingBox3f &box = shape->m_boxes[args->primID];
        RTCBounds *b = args->bounds_o;
        b->lower_x = box.min.x;
        b->lower_y = box.min.y;
        b->lower_z = box.min.z;
        b->upper_x = box.max.x;
        b->upper_y = box.max.y;
        b->upper_z = box.max.z;
    }

    static void embree_intersect(const RTCIntersectFunctionNArguments *args) {
        const auto *shape = static_cast<const SDFGrid *>(args->geometryUserPtr);
        const unsigned n = args->N;
        RTCRayN *ray = RTCRayHitN_RayN(args->rayhit, n);
        RTCHitN *hit = RTCRayHitN_HitN(args->rayhit, n);
        for (unsigned i = 0; i < n; ++i) {
            if (!args->valid[i]) continue;
            float t;
            if (!shape->intersect_voxel(args->primID, detail::ray_origin(ray, n, i),
                                        detail::ray_direction(ray, n, i), RTCRayN_tnear(ray, n, i),
                                        RTCRayN_tfar(ray, n, i), t))
                continue;
            RTCRayN_tfar(ray, n, i) = t;
            // facet computes the normal in compute_surface_interaction(); Embree only keeps it.
            RTCHitN_Ng_x(hit, n, i) = 0.f;
            RTCHitN_Ng_y(hit, n, i) = 0.f;
            RTCHitN_Ng_z(hit, n, i) = 1.f;
            RTCHitN_u(hit, n, i) = 0.f;
            RTCHitN_v(hit, n, i) = 0.f;
            RTCHitN_primID(hit, n, i) = args->primID;
            RTCHitN_geomID(hit, n, i) = args->geomID;
            RTCHitN_instID(hit, n, i, 0) = args->context->instID[0];
        }
    }

    static void embree_occluded(const RTCOccludedFunctionNArguments *args) {
        const auto *shape = static_cast<const SDFGrid *>(args->geometryUserPtr);
        const unsigned n = args->N;
        RTCRayN *ray = args->ray;
        for (unsigned i = 0; i < n; ++i) {
            if (!args->valid[i]) continue;
            float t;
            if (shape->intersect_voxel(args->primID, detail::ray_origin(ray, n, i),
                                       detail::ray_direction(ray, n, i), RTCRayN_tnear(ray, n, i),
                                       RTCRayN_tfar(ray, n, i), t))
                RTCRayN_tfar(ray, n, i) = -Infinity; // Embree's mark for "occluded"
        }
    }

    std::string m_filename;
    int m_n[3] = {0, 0, 0};
    double m_scale[3] = {1, 1, 1};  ///< n - 1 per axis: object [0,1] to grid [0, n-1]
    std::vector<float> m_values;    ///< x fastest
    std::vector<uint32_t> m_voxels; ///< sample index of the lower corner of each primitive
    std::vector<BoundingBox3f> m_boxes;
    Affine m_to_world, m_to_object, m_to_grid;
    BoundingBox3f m_bbox;
    bool m_smooth = true;
};

} // namespace facet

using facet::SDFGrid;
FACET_EXPORT_PLUGIN_MODES(
    SDFGrid, Shape, "sdfgrid",
    "Signed distance grid (.vol), intersected exactly by its trilinear interpolant", DOC,
    ::facet::AllModes)
