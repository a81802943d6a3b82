static const char *DOC = R"DOC(
# envmap: environment map

Light from infinitely far away, given by a latitude-longitude image (EXR, HDR, PNG, ... read
through OpenImageIO; 8-bit images are decoded from sRGB). The image's top row is the +Y
direction (up); u runs around the vertical axis. Directions are sampled in proportion to the
map's luminance times the solid angle of each pixel, so bright skies and suns are found quickly.

| Parameter           | Type      | Default  | Description                                                   |
|---------------------|-----------|----------|---------------------------------------------------------------|
| filename            | string    | —        | Latitude-longitude image (required)                           |
| scale               | float     | 1        | Multiplies the radiance                                       |
| to_world            | transform | identity | Orientation of the map (rotation only)                        |
| filter_type         | string    | bilinear | Lookup filter: bilinear or nearest                            |
| importance_sampling | boolean   | true     | false: sample directions uniformly (facet extension, testing) |

```xml
<emitter type="envmap">
    <string name="filename" value="sky.exr"/>
    <float name="scale" value="1.5"/>
</emitter>
```
)DOC";

#include <facet/distribution.h>
#include <facet/emitter.h>
#include <facet/image.h>
#include <facet/plugin.h>
#include <facet/resolver.h>
#include <facet/scene.h>
#include <facet/transform.h>
#include <facet/warp.h>

#include <algorithm>
#include <cctype>

namespace facet {

namespace {
float srgb_to_linear(float v) {
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}
bool is_display_encoded(const std::string &path) {
    std::string ext = path.substr(path.find_last_of('.') + 1);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext == "png" || ext == "jpg" || ext == "jpeg" || ext == "bmp" || ext == "tga" ||
           ext == "gif";
}
} // namespace

class EnvironmentMap final : public Emitter {
public:
    explicit EnvironmentMap(const Properties &props) {
        std::string filename = props.get_string("filename");
        m_path = file_resolver().resolve(filename);
        m_scale = float(props.get_float("scale", 1.0));
        m_to_world = props.get_transform("to_world", Transform());
        std::string filter = props.get_string("filter_type", "bilinear");
        if (filter != "bilinear" && filter != "nearest")
            FACET_THROW_AT(props.location("filter_type"),
                           "envmap: filter_type must be bilinear or nearest, got \"{}\"", filter);
        m_bilinear = filter == "bilinear";
        m_importance = props.get_bool("importance_sampling", true);

        Image img;
        try {
            img = read_image(m_path);
        } catch (const Error &e) {
            FACET_THROW_AT(props.location("filename"), "envmap: {}", e.what());
        }
        if (img.width < 1 || img.height < 1)
            FACET_THROW_AT(props.location("filename"), "envmap: \"{}\" is empty", m_path);
        bool decode = is_display_encoded(m_path);
        m_width = img.width;
        m_height = img.height;
        m_pixels.resize(size_t(m_width) * m_height);
        for (int y = 0; y < m_height; ++y)
            for (int x = 0; x < m_width; ++x) {
                Color3f c;
                for (int ch = 0; ch < 3; ++ch) {
                    float v = img.at(x, y, std::min(ch, img.channels - 1));
                    c[ch] = (decode ? srgb_to_linear(v) : v) * m_scale;
                }
                if (!c.is_finite())
                    FACET_THROW_AT(props.location("filename"),
                                   "envmap: \"{}\" has a non-finite pixel at ({}, {})", m_path, x,
                                   y);
                m_pixels[size_t(y) * m_width + x] =
                    Color3f(std::max(c.r, 0.f), std::max(c.g, 0.f), std::max(c.b, 0.f));
            }
        build_distribution();
        m_flags = EmitterFlags::Infinite | EmitterFlags::SpatiallyVarying;
    }

    void set_scene(const Scene &scene) override {
        m_center = scene.bbox().valid() ? scene.bbox().center() : Point3f(0.f);
        m_radius = std::max(scene.bbox().bounding_sphere_radius(), 1e-3f);
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &u) const override {
        DirectionSample ds;
        Vector3f local = m_importance && m_cells.sum() > 0.0 ? uv_to_direction(sample_uv(u))
                                                             : warp::square_to_uniform_sphere(u);
        ds.d = normalize(m_to_world.apply_vector(local));
        ds.dist = Infinity;
        ds.p = ref.p + ds.d * (2.f * m_radius + norm(ref.p - m_center));
        ds.n = -ds.d;
        ds.emitter = this;
        // Density and radiance of the direction as pdf_direction() and eval() will see it, so
        // the three agree to the last bit even where rounding moves it across a cell border.
        local = normalize(m_to_world.inverse().apply_vector(ds.d));
        ds.pdf = pdf_local(local);
        if (!(ds.pdf > 0.f)) return {ds, Color3f(0.f)};
        return {ds, lookup(local) / ds.pdf};
    }

    float pdf_direction(const Interaction &, const DirectionSample &ds) const override {
        return pdf_local(normalize(m_to_world.inverse().apply_vector(ds.d)));
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        Vector3f local = normalize(m_to_world.inverse().apply_vector(-si.wi));
        return lookup(local);
    }

    std::string to_string() const override {
        return fmt::format("EnvironmentMap[\"{}\", {}x{}, scale={}]", m_path, m_width, m_height,
                           m_scale);
    }

private:
    /// uv in [0,1]²: u = φ/2π around +Y measured from -Z towards +X, v = θ/π from +Y.
    static Point2f direction_to_uv(const Vector3f &d) {
        float u = std::atan2(d.x, -d.z) * InvTwoPi;
        u -= std::floor(u);
        return {u, safe_acos(d.y) * InvPi};
    }
    static Vector3f uv_to_direction(const Point2f &uv) {
        float phi = uv.x * 2.f * Pi, theta = uv.y * Pi;
        float st = std::sin(theta);
        return {std::sin(phi) * st, std::cos(theta), -std::cos(phi) * st};
    }

    const Color3f &pixel(int x, int y) const {
        x = ((x % m_width) + m_width) % m_width; // wrap around in longitude
        y = std::clamp(y, 0, m_height - 1);
        return m_pixels[size_t(y) * m_width + x];
    }

    Color3f lookup(const Vector3f &local) const {
        Point2f uv = direction_to_uv(local);
        float fx = uv.x * float(m_width), fy = uv.y * float(m_height);
        if (!m_bilinear) return pixel(int(fx), int(fy));
        fx -= 0.5f;
        fy -= 0.5f;
        int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
        float tx = fx - float(x0), ty = fy - float(y0);
        return (pixel(x0, y0) * (1.f - tx) + pixel(x0 + 1, y0) * tx) * (1.f - ty) +
               (pixel(x0, y0 + 1) * (1.f - tx) + pixel(x0 + 1, y0 + 1) * tx) * ty;
    }

    // -- Importance sampling ------------------------------------------------------------------
    // The bilinear lookup is a bilinear patch between each 2×2 group of pixel centres, so the
    // sampling density is built on those patches: cell (i, j) spans u from (i + ½)/W to
    // (i + 1½)/W (wrapping around) and v from (j - ½)/H to (j + ½)/H (clamped to [0, 1]; the
    // half cells at the poles are constant in v). A cell is picked in proportion to its mean
    // luminance times its solid angle, and a point inside it in proportion to the bilinear
    // luminance, so the density is zero exactly where the radiance is. With nearest lookups
    // the cells are the pixels and the density is constant inside each.

    struct Cell {
        float u0, du, v0, dv;
        float a, b, c,
            d; ///< luminance at the corners (u0,v0), (u0+du,v0), (u0,v0+dv), (u0+du,v0+dv)
    };

    Cell cell(int i, int j) const {
        Cell c;
        if (!m_bilinear) {
            c.u0 = float(i) / float(m_width);
            c.du = 1.f / float(m_width);
            c.v0 = float(j) / float(m_height);
            c.dv = 1.f / float(m_height);
            c.a = c.b = c.c = c.d = pixel(i, j).luminance();
            return c;
        }
        c.u0 = (float(i) + 0.5f) / float(m_width);
        c.du = 1.f / float(m_width);
        float v0 = std::max(0.f, (float(j) - 0.5f) / float(m_height));
        float v1 = std::min(1.f, (float(j) + 0.5f) / float(m_height));
        c.v0 = v0;
        c.dv = v1 - v0;
        c.a = pixel(i, j - 1).luminance();
        c.b = pixel(i + 1, j - 1).luminance();
        c.c = pixel(i, j).luminance();
        c.d = pixel(i + 1, j).luminance();
        return c;
    }

    int cells_x() const { return m_width; }
    int cells_y() const { return m_bilinear ? m_height + 1 : m_height; }

    /// Cell holding uv, its index, and uv's position (s, t) inside it.
    Cell locate(const Point2f &uv, size_t &index, float &s, float &t) const {
        int i, j;
        if (m_bilinear) {
            float fx = uv.x * float(m_width) - 0.5f;
            i = int(std::floor(fx));
            j = std::clamp(int(std::floor(uv.y * float(m_height) + 0.5f)), 0, m_height);
        } else {
            i = int(uv.x * float(m_width));
            j = std::clamp(int(uv.y * float(m_height)), 0, m_height - 1);
        }
        i = ((i % m_width) + m_width) % m_width;
        index = size_t(j) * size_t(cells_x()) + size_t(i);
        Cell c = cell(i, j);
        float du = uv.x - c.u0;
        du -= std::floor(du); // wrap across the seam
        s = clamp(du / c.du, 0.f, 1.f);
        t = c.dv > 0.f ? clamp((uv.y - c.v0) / c.dv, 0.f, 1.f) : 0.f;
        return c;
    }

    static float bilinear(const Cell &c, float s, float t) {
        return (1.f - s) * (1.f - t) * c.a + s * (1.f - t) * c.b + (1.f - s) * t * c.c +
               s * t * c.d;
    }

    /// Inverse CDF of the density on [0, 1] proportional to the line from v0 to v1.
    static float sample_linear(float u, float v0, float v1) {
        if (std::abs(v0 - v1) < 1e-6f * std::max(v0, v1)) return u;
        float x = (v0 - safe_sqrt(lerp(u, v0 * v0, v1 * v1))) / (v0 - v1);
        return clamp(x, 0.f, 1.f);
    }

    Point2f sample_uv(Point2f u) const {
        float uc = u.x;
        size_t index = m_cells.sample_reuse(uc);
        Cell c = cell(int(index % size_t(cells_x())), int(index / size_t(cells_x())));
        float t = sample_linear(u.y, 0.5f * (c.a + c.b), 0.5f * (c.c + c.d));
        float s = sample_linear(uc, lerp(t, c.a, c.c), lerp(t, c.b, c.d));
        float uu = c.u0 + s * c.du;
        uu -= std::floor(uu);
        return {std::min(uu, OneMinusEpsilon), c.v0 + t * c.dv};
    }

    /// Density per unit solid angle at uv (local direction `local`): the cell's probability
    /// spread by the bilinear luminance, over the Jacobian dω = 2π² sin θ du dv.
    float pdf_solid_angle(const Point2f &uv, const Vector3f &local) const {
        float s, t;
        size_t index;
        Cell c = locate(uv, index, s, t);
        float mean = 0.25f * (c.a + c.b + c.c + c.d);
        // sin θ straight from the direction: acos near the poles would lose precision.
        float sin_theta = std::sqrt(local.x * local.x + local.z * local.z);
        if (!(mean > 0.f) || !(sin_theta > 0.f)) return 0.f;
        float pdf_uv = m_cells.pmf(index) / (c.du * c.dv) * bilinear(c, s, t) / mean;
        return pdf_uv / (2.f * Pi * Pi * sin_theta);
    }

    float pdf_local(const Vector3f &local) const {
        if (!(m_importance && m_cells.sum() > 0.0)) return InvFourPi;
        return pdf_solid_angle(direction_to_uv(local), local);
    }

    void build_distribution() {
        std::vector<float> weights(size_t(cells_x()) * size_t(cells_y()));
        for (int j = 0; j < cells_y(); ++j)
            for (int i = 0; i < cells_x(); ++i) {
                Cell c = cell(i, j);
                float solid_angle =
                    2.f * Pi * c.du * (std::cos(c.v0 * Pi) - std::cos((c.v0 + c.dv) * Pi));
                weights[size_t(j) * size_t(cells_x()) + size_t(i)] =
                    0.25f * (c.a + c.b + c.c + c.d) * solid_angle;
            }
        m_cells.build(weights.data(), weights.size());
    }

    std::string m_path;
    float m_scale = 1.f;
    Transform m_to_world;
    bool m_bilinear = true, m_importance = true;
    int m_width = 0, m_height = 0;
    std::vector<Color3f> m_pixels;
    DiscreteDistribution m_cells;
    Point3f m_center;
    float m_radius = 1.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::EnvironmentMap, Emitter, "envmap",
                    "Latitude-longitude environment map with luminance importance sampling", DOC)
