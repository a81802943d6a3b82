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
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == "png" || ext == "jpg" || ext == "jpeg" || ext == "bmp" || ext == "tga" || ext == "gif";
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
            FACET_THROW_AT(props.location("filter_type"), "envmap: filter_type must be bilinear or nearest, got \"{}\"", filter);
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
                    FACET_THROW_AT(props.location("filename"), "envmap: \"{}\" has a non-finite pixel at ({}, {})", m_path, x, y);
                m_pixels[size_t(y) * m_width + x] = Color3f(std::max(c.r, 0.f), std::max(c.g, 0.f), std::max(c.b, 0.f));
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
        Vector3f local;
        float pdf;
        if (m_importance && m_distribution.valid()) {
            float pdf_uv;
            Point2f uv = m_distribution.sample(u, pdf_uv);
            local = uv_to_direction(uv);
            float sin_theta = std::sin(uv.y * Pi);
            pdf = sin_theta > 0.f ? pdf_uv / (2.f * Pi * Pi * sin_theta) : 0.f;
        } else {
            local = warp::square_to_uniform_sphere(u);
            pdf = InvFourPi;
        }
        if (!(pdf > 0.f)) return {ds, Color3f(0.f)};
        ds.d = normalize(m_to_world.apply_vector(local));
        ds.dist = Infinity;
        ds.p = ref.p + ds.d * (2.f * m_radius + norm(ref.p - m_center));
        ds.n = -ds.d;
        ds.pdf = pdf;
        ds.emitter = this;
        return {ds, lookup(local) / pdf};
    }

    float pdf_direction(const Interaction &, const DirectionSample &ds) const override {
        if (!(m_importance && m_distribution.valid())) return InvFourPi;
        Vector3f local = normalize(m_to_world.inverse().apply_vector(ds.d));
        Point2f uv = direction_to_uv(local);
        float sin_theta = std::sin(uv.y * Pi);
        return sin_theta > 0.f ? m_distribution.pdf(uv) / (2.f * Pi * Pi * sin_theta) : 0.f;
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        Vector3f local = normalize(m_to_world.inverse().apply_vector(-si.wi));
        return lookup(local);
    }

    std::string to_string() const override {
        return fmt::format("EnvironmentMap[\"{}\", {}x{}, scale={}]", m_path, m_width, m_height, m_scale);
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

    /// Cell weights: the largest luminance the bilinear lookup can reach inside the cell (its
    /// pixel and the 8 neighbours), times the cell's solid angle, so that every direction with
    /// non-zero radiance has a non-zero density.
    void build_distribution() {
        std::vector<float> weights(size_t(m_width) * m_height);
        for (int y = 0; y < m_height; ++y) {
            float theta0 = float(y) / float(m_height) * Pi, theta1 = float(y + 1) / float(m_height) * Pi;
            float solid_angle = std::cos(theta0) - std::cos(theta1);
            for (int x = 0; x < m_width; ++x) {
                float lum = 0.f;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        if (!m_bilinear && (dx != 0 || dy != 0)) continue;
                        lum = std::max(lum, pixel(x + dx, y + dy).luminance());
                    }
                weights[size_t(y) * m_width + x] = lum * solid_angle;
            }
        }
        m_distribution = Distribution2D(weights, m_width, m_height);
    }

    std::string m_path;
    float m_scale = 1.f;
    Transform m_to_world;
    bool m_bilinear = true, m_importance = true;
    int m_width = 0, m_height = 0;
    std::vector<Color3f> m_pixels;
    Distribution2D m_distribution;
    Point3f m_center;
    float m_radius = 1.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::EnvironmentMap, Emitter, "envmap",
                    "Latitude-longitude environment map with luminance importance sampling", DOC)
