static const char *DOC = R"DOC(
# envmap: environment map

Light from infinitely far away, given by a latitude-longitude image (EXR, HDR, PNG, ... any
format the bitmap texture reads; 8-bit images are decoded from sRGB), with Mitsuba 3's
conventions. A direction d (in the map's frame, after the inverse of `to_world`) has u = atan2(d.x, -d.z)/2π
(wrapped to [0, 1); the u = 0 seam lies towards -Z, u = 1/4 towards +X) and v = acos(d.y)/π.
Longitude is texel-centred and wraps: column i sits at u = (i + ½)/W and the lookup blends
across the seam. Latitude is corner-aligned: row j sits at v = j/(H - 1), so the first row is
exactly the +Y pole and the last row the -Y pole. An image needs at least 2x3 pixels.
Negative pixel values are kept.

Directions are sampled in proportion to the luminance times sin θ on the same grid,
interpolated bilinearly between grid points. With `mis_compensation` true the map's mean
luminance is subtracted first (clamped at zero; Karlík et al. 2019) for every sample, which
helps when the emitter is combined with BSDF sampling by MIS; it is skipped for near-constant
maps. false samples the plain luminance. Unset (facet's default; Mitsuba's is false): the light
samples an integrator weights by MIS against BSDF samples (the path tracer's; the direct
integrator's when it takes BSDF samples) follow a mix, 90% of them the compensated table and 10%
the plain one (one table, their weighted sum), so that most go where the map is brighter than
its mean while some still reach every direction with light; every other use (emitted rays,
light samples that stand alone) follows the plain luminance, that table built on first use. The
expected image is the same in all three. Emitted rays (for the
particle tracer) come from a direction drawn the same way and a uniform point of the disk of the
scene's bounding-sphere radius facing it, just outside the sphere, as in Mitsuba.

| Parameter           | Type      | Default  | Description                                                        |
|---------------------|-----------|----------|--------------------------------------------------------------------|
| filename            | string    | —        | Latitude-longitude image (required)                                |
| scale               | float     | 1        | Multiplies the radiance                                            |
| to_world            | transform | identity | Orientation of the map (rotation only)                             |
| mis_compensation    | boolean   | unset    | true: sample only where the map is brighter than its mean luminance; false: the plain luminance; unset: MIS's light samples a 90/10 mix of the two, the others plain |
| filter_type         | string    | bilinear | Lookup filter: bilinear or nearest (facet extension)               |
| importance_sampling | boolean   | true     | false: sample directions uniformly (facet extension, for testing)  |
| sampling_weight | float | — | How often light samples pick this emitter, relative to the others (Mitsuba 3's; unset: facet's choice, see README) |

```xml
<emitter type="envmap">
    <string name="filename" value="sky.exr"/>
    <float name="scale" value="1.5"/>
    <transform name="to_world">
        <rotate y="1" angle="70"/>
    </transform>
</emitter>
```
)DOC";

#include <facet/distribution.h>
#include <facet/emitter.h>
#include <facet/frame.h>
#include <facet/image.h>
#include <facet/plugin.h>
#include <facet/resolver.h>
#include <facet/scene.h>
#include <facet/spectral_upsampling.h>
#include <facet/texture_image.h>
#include <facet/transform.h>
#include <facet/warp.h>

#include <algorithm>
#include <cctype>
#include <memory>
#include <mutex>

namespace facet {

namespace {
float srgb_to_linear(float v) {
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}
/// Floor of sin θ in the density (Mitsuba's float epsilon), so the poles keep a finite pdf.
constexpr float SinThetaFloor = 0x1p-24f;

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
        const Transform to_world = props.get_transform("to_world", Transform());
        for (int r = 0; r < 3; ++r) {
            const auto &m = to_world.matrix.m, &inv = to_world.inverse_matrix.m;
            m_world_rows[r] = Vector3f(m[r][0], m[r][1], m[r][2]);
            m_local_rows[r] = Vector3f(inv[r][0], inv[r][1], inv[r][2]);
        }
        // Unset: facet's mix of the compensated and the plain tables (see the DOC).
        m_mis_given = props.has("mis_compensation");
        m_mis_compensation = props.get_bool("mis_compensation", false);
        std::string filter = props.get_string("filter_type", "bilinear");
        if (filter != "bilinear" && filter != "nearest")
            FACET_THROW_AT(props.location("filter_type"),
                           "envmap: filter_type must be bilinear or nearest, got \"{}\"", filter);
        m_bilinear = filter == "bilinear";
        m_importance = props.get_bool("importance_sampling", true);

        // Read through the process's image cache: its memory budget is checked before the
        // pixels are read, and a file another reference holds is not read again.
        std::shared_ptr<const Image> shared;
        try {
            shared = read_shared_image(m_path);
        } catch (const Error &e) {
            FACET_THROW_AT(props.location("filename"), "envmap: {}", e.what());
        }
        const Image &img = *shared;
        if (img.width < 2 || img.height < 3)
            FACET_THROW_AT(props.location("filename"),
                           "envmap: \"{}\" is {}x{} pixels; an environment map needs at least 2x3 "
                           "(width x height)",
                           m_path, img.width, img.height);
        bool decode = is_display_encoded(m_path);
        m_width = img.width;
        m_height = img.height;
        // Grey (and grey + alpha) images are grey; an alpha channel is ignored.
        int colour_channels = img.channels >= 3 ? 3 : 1;
        // Written once, in order (no zero-filled array written over).
        m_texels.clear();
        m_texels.reserve(size_t(m_width + 1) * m_height);
        for (int y = 0; y < m_height; ++y) {
            for (int x = 0; x < m_width; ++x) {
                auto channel = [&](int ch) {
                    float v = img.at(x, y, std::min(ch, colour_channels - 1));
                    return (decode ? srgb_to_linear(v) : v) * m_scale;
                };
                Color3f c(channel(0), channel(1), channel(2));
                if (!c.is_finite())
                    FACET_THROW_AT(props.location("filename"),
                                   "envmap: \"{}\" has a non-finite pixel at ({}, {})", m_path, x,
                                   y);
                // Negative values are kept, as Mitsuba keeps them; only the sampling table
                // clamps at zero. The mono mode renders the luminance.
                c = in_mode(c, props.mode());
                Texel t{};
                t.set_radiance(c);
                m_texels.push_back(t);
            }
            m_texels.push_back(texel(0, y)); // column W is column 0 again
        }
        build_distribution();
        if (is_spectral(props.mode())) {
            m_luminance.resize(m_texels.size());
            for (int j = 0; j < m_height; ++j)
                for (int i = 0; i <= m_width; ++i)
                    m_luminance[grid_index(i, j)] = luminance_at(i, j);
            // Each pixel's spectrum, RGBSpectrum's scaled form: the curve of c / (2 max c)
            // and the scale 2 max c, blended separately between pixels; radiance() multiplies
            // by D65, the spectrum of an RGB white light. The curve's coefficients replace the
            // texel's colour (the sampling table's values were copied from the colours above,
            // as luminances to m_luminance, read beside the texels as the scales are).
            m_spectral = true;
            m_scales.resize(m_texels.size());
            for (size_t i = 0; i < m_texels.size(); ++i) {
                const RGBSpectrum rs = RGBSpectrum::scaled(m_texels[i].radiance());
                m_scales[i] = rs.scale;
                m_texels[i].curve = rs.poly;
            }
        }
        m_flags = EmitterFlags::Infinite | EmitterFlags::SpatiallyVarying;
    }

    void set_scene(const Scene &scene) override {
        m_center = scene.bbox().valid() ? scene.bbox().center() : Point3f(0.f);
        m_radius = std::max(scene.bbox().bounding_sphere_radius(), 1e-3f);
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &u) const override {
        return sample_with(ref, u, alone_sampling());
    }
    std::pair<DirectionSample, Color3f> sample_direction_mis(const Interaction &ref,
                                                             const Point2f &u,
                                                             const Vector3f &side) const override {
        return sample_with(ref, u, m_sampling, side_bin(side));
    }

    float pdf_direction(const Interaction &, const DirectionSample &ds) const override {
        return pdf_with(ds, alone_sampling());
    }
    float pdf_direction_mis(const Interaction &, const DirectionSample &ds,
                            const Vector3f &side) const override {
        return pdf_with(ds, m_sampling, side_bin(side));
    }

    /// A ray entering the bounding sphere (the particle tracer): the direction it comes from is
    /// drawn as sample_direction() draws it, the origin uniformly on the disk of the sphere's
    /// radius facing that direction, just outside the sphere. Power per ray: L / pdf · π r².
    std::pair<Ray, Color3f> sample_ray(const Point2f &u_pos, const Point2f &u_dir,
                                       const Wavelengths &wavelengths) const override {
        // Light leaves towards every direction it has (unless the scene asked for compensation
        // throughout): the rays follow the plain luminance, as light samples that stand alone.
        const Sampling &sampling = alone_sampling();
        Vector3f local = sampling_enabled() ? uv_to_direction(sample_uv(u_dir, sampling, NoSide))
                                            : warp::square_to_uniform_sphere(u_dir);
        const Vector3f from = to_world(local);
        local = to_local(from);
        const GridPoint g = grid_point(local);
        const float pdf = pdf_local(local, g, sampling, NoSide);
        if (!(pdf > 0.f)) return {Ray(), Color3f(0.f)};
        const float radius = m_radius * (1.f + RayEpsilon);
        const Point2f disk = warp::square_to_uniform_disk_concentric(u_pos);
        const Frame frame(from);
        const Point3f o = m_center + (frame.s * disk.x + frame.t * disk.y + from) * radius;
        Ray ray(o, -from);
        ray.wavelengths = wavelengths;
        return {ray, radiance(g, wavelengths) * (Pi * radius * radius / pdf)};
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        // si is the record of a ray that left the scene: wi points back along it (local frame).
        const Vector3f local = to_local(-si.to_world(si.wi));
        return radiance(grid_point(local), si.wavelengths);
    }

    /// The map's mean radiance (over the sphere of directions) arriving from every direction
    /// at the scene's bounding sphere.
    float power() const override { return 4.f * Pi * Pi * m_radius * m_radius * m_mean_luminance; }

    std::string to_string() const override {
        return fmt::format("EnvironmentMap[\"{}\", {}x{}, scale={}, mis_compensation={}]", m_path,
                           m_width, m_height, m_scale,
                           m_mis_given ? (m_mis_compensation ? "true" : "false") : "mix");
    }

private:
    /// A sampling table and the distribution of its cells. The table's value at grid point
    /// (i, j) is (compensated_weight · max(L - offset, 0) + plain_weight · max(L, 0)) ·
    /// row_weight[j] for the pixel's luminance L: (0, 1) is the plain table, (1, 0) Mitsuba's
    /// compensation, both positive the mix.
    struct Sampling {
        float offset = 0.f, compensated_weight = 0.f, plain_weight = 1.f;
        std::vector<float> row_weight; ///< per row: sin θ times the table's power-of-two scale
        DiscreteDistribution cells;    ///< in the blocks' order (see block_count())
        double total = 0.0;
        float density_scale = 0.f; ///< density over the unit square = value · density_scale
        /// Per block: where its cells start in the CDF of `cells` (blocks + 1 values) and the
        /// inverse of its share of the table's total (0 for an empty block). Only for a table
        /// light samples with a side follow.
        std::vector<double> block_start;
        std::vector<float> block_inv_share;
        /// Per bin of sides, the CDF over the blocks in units of 1 / SideQuanta (block_count()
        /// values each; all zero for a bin whose every block lies behind its sides).
        std::vector<uint16_t> side_cdf;
        /// Per bin, SideGuides + 1 entries: entry g is the block for u = g / SideGuides (the
        /// first whose CDF exceeds it), so that the block of any u in [g, g + 1) / SideGuides
        /// lies between entries g and g + 1.
        std::vector<uint16_t> side_guide;
    };

    /// sample_direction() with the table `sampling`, for sides in bin `bin` (or NoSide).
    std::pair<DirectionSample, Color3f> sample_with(const Interaction &ref, const Point2f &u,
                                                    const Sampling &sampling,
                                                    int bin = NoSide) const {
        DirectionSample ds;
        if (bin != NoSide && !sampling_enabled()) bin = NoSide;
        Vector3f local;
        if (sampling_enabled()) {
            const Point2f uv = sample_uv(u, sampling, bin);
            if (!(uv.y >= 0.f)) return {ds, Color3f(0.f)}; // every block behind the side
            local = uv_to_direction(uv);
        } else {
            local = warp::square_to_uniform_sphere(u);
        }
        ds.d = to_world(local);
        ds.dist = Infinity;
        ds.p = ref.p + ds.d * (2.f * m_radius + norm(ref.p - m_center));
        ds.n = -ds.d;
        ds.emitter = this;
        // Density and radiance of the direction as pdf_direction() and eval() will see it, so
        // the three agree to the last bit even where rounding moves it across a cell border.
        local = to_local(ds.d);
        const GridPoint g = grid_point(local); // one atan2 and acos for both
        ds.pdf = pdf_local(local, g, sampling, bin);
        if (!(ds.pdf > 0.f)) return {ds, Color3f(0.f)};
        return {ds, radiance(g, ref.wavelengths) / ds.pdf};
    }
    /// pdf_direction() with the table `sampling`, for sides in bin `bin` (or NoSide).
    float pdf_with(const DirectionSample &ds, const Sampling &sampling, int bin = NoSide) const {
        if (!sampling_enabled()) return InvFourPi;
        const Vector3f local = to_local(ds.d);
        return pdf_local(local, grid_point(local), sampling, bin);
    }

    /// The map's frame (to_world's rotation), applied inline: every direction of a sample, a
    /// density and a lookup passes through it, with the arithmetic of Transform::apply_vector().
    static Vector3f rotate(const Vector3f (&rows)[3], const Vector3f &v) {
        return normalize(Vector3f(dot(rows[0], v), dot(rows[1], v), dot(rows[2], v)));
    }
    Vector3f to_world(const Vector3f &local) const { return rotate(m_world_rows, local); }
    Vector3f to_local(const Vector3f &world) const { return rotate(m_local_rows, world); }

    /// acos(clamp(c, -1, 1)) within 5.2e-7 (acosf: 2.1e-7; a thousandth of a row of a map 2000
    /// rows high): Abramowitz and Stegun's 4.4.46, √(1 - x) times a polynomial of degree 7 in
    /// x = |c| (in pairs of terms), π less it for a negative c. The library's acosf takes a
    /// branch on |c| and more dependent steps, and every lookup and density waits for it.
    static float polar_angle(float c) {
        const float x = std::min(std::abs(c), 1.f), x2 = x * x, x4 = x2 * x2;
        const float p =
            (1.5707963050f - 0.2145988016f * x) + x2 * (0.0889789874f - 0.0501743046f * x) +
            x4 * ((0.0308918810f - 0.0170881256f * x) + x2 * (0.0066700901f - 0.0012624911f * x));
        const float r = std::sqrt(1.f - x) * p;
        return std::signbit(c) ? Pi - r : r;
    }
    static Vector3f uv_to_direction(const Point2f &uv) {
        float phi = uv.x * 2.f * Pi, theta = uv.y * Pi;
        float st = std::sin(theta);
        return {std::sin(phi) * st, std::cos(theta), -std::cos(phi) * st};
    }

    /// Where a direction falls on the grid: the lower grid indices (i ≤ W-1, j ≤ H-2) and the
    /// fractions (s, t) towards the next ones.
    struct GridPoint {
        int i, j;
        float s, t;
    };

    /// Grid position of a local direction: longitude texel-centred (column i at u = (i + ½)/W,
    /// wrapping), latitude corner-aligned (row j at v = j/(H-1), the poles on the first and
    /// last rows). The radiance and the density of a direction share it.
    GridPoint grid_point(const Vector3f &local) const {
        // u = atan2(x, -z) / 2π (around +Y from -Z towards +X) in [-½, ½], v = θ / π from +Y;
        // x = u W - ½ wrapped into [0, W).
        float x = fast_atan2(local.x, -local.z) * (InvTwoPi * float(m_width)) - 0.5f;
        if (x < 0.f) x += float(m_width);
        // A direction that is not finite (no valid one gives it) still reads inside the grid.
        if (!(x >= 0.f)) x = 0.f;
        float y = polar_angle(local.y) * (InvPi * float(m_height - 1));
        y = y > 0.f ? std::min(y, float(m_height - 1)) : 0.f;
        GridPoint g;
        g.i = std::min(int(x), m_width - 1);
        g.j = std::min(int(y), m_height - 2);
        g.s = x - float(g.i);
        g.t = y - float(g.j);
        return g;
    }

    // The radiance of a grid point and its sampling table's value come from one texel, so that
    // a lookup and the density of the same direction (eval() and pdf_direction(), or the two
    // halves of sample_direction()) read the same cache lines: in a map larger than the cache
    // each texel row read is a miss, and separate arrays took twice as many. In rgb and mono the
    // table's value is computed from the pixel (table()), so a texel is the pixel's 12 bytes.
    struct Texel {
        union {
            float rgb[3] = {0.f, 0.f, 0.f}; ///< the pixel, times `scale`
            SigmoidPolynomial curve;        ///< the spectral mode: the pixel's curve
        };
        Color3f radiance() const { return {rgb[0], rgb[1], rgb[2]}; }
        void set_radiance(const Color3f &c) {
            rgb[0] = c.r;
            rgb[1] = c.g;
            rgb[2] = c.b;
        }
    };
    /// Where grid point (x, y), x in [0, W], lies in the (W + 1) x H arrays (texels, scales,
    /// weights).
    size_t grid_index(int x, int y) const { return size_t(y) * size_t(m_width + 1) + size_t(x); }
    Texel &texel(int x, int y) { return m_texels[grid_index(x, y)]; }
    const Texel &texel(int x, int y) const { return m_texels[grid_index(x, y)]; }

    /// Pixel (x, y) for x in [0, W]: column W is column 0 again.
    Color3f pixel(int x, int y) const { return texel(x, y).radiance(); }

    Color3f lookup(const GridPoint &g) const {
        const int i = g.i, j = g.j;
        const float s = g.s, t = g.t;
        if (!m_bilinear) return pixel(s < 0.5f ? i : i + 1, t < 0.5f ? j : j + 1);
        return (pixel(i, j) * (1.f - s) + pixel(i + 1, j) * s) * (1.f - t) +
               (pixel(i, j + 1) * (1.f - s) + pixel(i + 1, j + 1) * s) * t;
    }

    /// The radiance at a grid point: lookup() in rgb and mono; in the spectral mode at the
    /// path's wavelengths `lambda`.
    Color3f radiance(const GridPoint &g, const Wavelengths &lambda) const {
        if (!m_spectral) return lookup(g);
        Color3f curve(0.f);
        float scale = 0.f;
        auto add = [&](int x, int y, float w) {
            const size_t i = grid_index(x, y);
            const SigmoidPolynomial &c = m_texels[i].curve;
            curve += c(lambda) * w;
            scale += m_scales[i] * w;
        };
        const int i = g.i, j = g.j;
        const float s = g.s, t = g.t;
        if (!m_bilinear) {
            add(s < 0.5f ? i : i + 1, t < 0.5f ? j : j + 1, 1.f);
        } else {
            add(i, j, (1.f - s) * (1.f - t));
            add(i + 1, j, s * (1.f - t));
            add(i, j + 1, (1.f - s) * t);
            add(i + 1, j + 1, s * t);
        }
        return curve * cie_d65(lambda) * scale;
    }

    // -- Importance sampling ------------------------------------------------------------------
    // The table lives on the lookup's grid: (W + 1) × H values, column W repeating column 0,
    // value (i, j) = max(luminance - offset, 0) · sin(π j / (H - 1)) (offset: the MIS
    // compensation, else 0). The density over the shifted square (u - ½/W, v) is the bilinear
    // interpolation of the table between grid points: a cell (i, j) of the W × (H - 1) grid is
    // picked in proportion to the mean of its four corners and a point inside it in proportion
    // to the bilinear patch. In solid angle, dω = 2π² sin θ du dv. With nearest lookups the
    // same density still covers every direction whose radiance is not zero.

    bool sampling_enabled() const { return m_importance && m_sampling.total > 0.0; }

    /// The luminance of grid point (i, j), i in [0, W]: from the pixel, or in the spectral mode
    /// (whose texels hold curves) a stored copy.
    float luminance_at(int i, int j) const {
        if (m_spectral) return m_luminance[grid_index(i, j)];
        return texel(i, j).radiance().luminance();
    }
    /// The table's value at grid point (i, j): see Sampling.
    float table(int i, int j, const Sampling &sampling) const {
        return table_from_luminance(luminance_at(i, j), j, sampling);
    }
    static float table_from_luminance(float luminance, int j, const Sampling &sampling) {
        return (sampling.compensated_weight * std::max(luminance - sampling.offset, 0.f) +
                sampling.plain_weight * std::max(luminance, 0.f)) *
               sampling.row_weight[size_t(j)];
    }

    /// A point of the map's square drawn from the table (restricted to what sides in `bin`
    /// see, unless NoSide); v < 0 when the bin sees no light.
    Point2f sample_uv(Point2f u, const Sampling &sampling, int bin) const {
        float uc = u.x;
        size_t block;
        if (bin == NoSide) {
            block = 0;
        } else {
            // The block, by the bin's CDF; then u is rescaled into the block's range of the
            // table's own CDF, whose sample is the cell.
            const size_t blocks = block_count();
            const uint16_t *cdf = sampling.side_cdf.data() + size_t(bin) * blocks;
            if (cdf[blocks - 1] == 0) return {0.f, -1.f};
            const float x = uc * float(SideQuanta); // below SideQuanta
            // The first block whose CDF exceeds x, from the guide's entry below x on (its CDF
            // is an integer: it exceeds x exactly when it exceeds floor(x)).
            const uint32_t below = uint32_t(x);
            const uint16_t *guide =
                sampling.side_guide.data() + size_t(bin) * size_t(SideGuides + 1);
            block = guide[std::min(size_t(uc * float(SideGuides)), size_t(SideGuides) - 1)];
            while (block + 1 < blocks && cdf[block] <= below) ++block;
            const float c0 = block > 0 ? float(cdf[block - 1]) : 0.f;
            const double v = std::clamp(double(x - c0) / double(float(cdf[block]) - c0), 0.0, 1.0);
            const double b0 = sampling.block_start[block], b1 = sampling.block_start[block + 1];
            uc = std::min(float(b0 + v * (b1 - b0)), OneMinusEpsilon);
        }
        // While the distribution reads the block its cell comes from, the texels of that
        // block's cells are fetched.
        size_t index = sampling.cells.sample_reuse(uc, [&](size_t first, size_t last) {
            prefetch_cells(first, last, bin == NoSide ? block_of_index(first) : block);
        });
        if (bin == NoSide) {
            block = block_of_index(index);
        } else if (index < m_block_first[block] || index >= m_block_first[block + 1]) {
            // The rescaled u rounded into a neighbouring block: its nearest cell instead.
            index = std::clamp(index, size_t(m_block_first[block]),
                               size_t(m_block_first[block + 1]) - 1);
        }
        const int bx = int(block % size_t(m_blocks_x)), by = int(block / size_t(m_blocks_x));
        const int x0 = m_block_x[size_t(bx)], w = m_block_x[size_t(bx) + 1] - x0;
        const size_t local = index - m_block_first[block];
        int i = x0 + int(local % size_t(w)), j = m_block_y[size_t(by)] + int(local / size_t(w));
        float a = table(i, j, sampling), b = table(i + 1, j, sampling),
              c = table(i, j + 1, sampling), d = table(i + 1, j + 1, sampling);
        // A cell next to a pole has a zero row (sin θ = 0): at t = 0 both ends of the s line
        // are zero, and interval_to_linear() samples it uniformly.
        float t = warp::interval_to_linear(0.5f * (a + b), 0.5f * (c + d), u.y);
        float s = warp::interval_to_linear(lerp(t, a, c), lerp(t, b, d), uc);
        float uu = (float(i) + s + 0.5f) / float(m_width);
        uu -= std::floor(uu);
        return {std::min(uu, OneMinusEpsilon), (float(j) + t) / float(m_height - 1)};
    }

    /// Starts fetching every cache line of [begin, end).
    static void prefetch_range(const void *begin, const void *end) {
        const char *b = static_cast<const char *>(begin), *e = static_cast<const char *>(end);
        for (const char *p = b; p < e; p += 64) prefetch_line(p);
        prefetch_line(e - 1);
    }

    /// Starts fetching the texel rows that sampling cells first..last (in the blocks' order)
    /// reads: the rows of their blocks' cells, from the first cell's column to the last's (the
    /// lines of a block's row, for a range across rows).
    void prefetch_cells(size_t first, size_t last, size_t block) const {
        const size_t W = size_t(m_width);
        first = std::max(first, size_t(m_block_first[block]));
        if (first > last || first >= m_block_first[block + 1]) return;
        const size_t bx = block % size_t(m_blocks_x), by = block / size_t(m_blocks_x);
        const size_t x0 = size_t(m_block_x[bx]), w = size_t(m_block_x[bx + 1]) - x0;
        const size_t y0 = size_t(m_block_y[by]), y_end = size_t(m_block_y[by + 1]);
        const size_t f = first - m_block_first[block];
        const size_t l =
            std::min(last, size_t(m_block_first[block + 1]) - 1) - m_block_first[block];
        for (size_t j = y0 + f / w; j <= std::min(y0 + l / w, y_end - 1); ++j) {
            const size_t i0 = j == y0 + f / w ? x0 + f % w : x0;
            const size_t i1 = j == y0 + l / w ? x0 + l % w + 1 : x0 + w;
            for (size_t row = j; row <= j + 1; ++row) {
                prefetch_range(&texel(int(i0), int(row)), &texel(int(i1), int(row)) + 1);
                if (m_spectral) {
                    const float *scales = m_scales.data() + row * (W + 1);
                    prefetch_range(scales + i0, scales + i1 + 1);
                    const float *luminance = m_luminance.data() + row * (W + 1);
                    prefetch_range(luminance + i0, luminance + i1 + 1);
                }
            }
        }
    }

    /// Density of the local direction `local`, whose grid point is g, for sides in bin `bin`
    /// (or NoSide).
    float pdf_local(const Vector3f &local, const GridPoint &g, const Sampling &sampling,
                    int bin) const {
        if (!sampling_enabled()) return InvFourPi;
        const int i = g.i, j = g.j;
        const float s = g.s, t = g.t;
        float value =
            (table(i, j, sampling) * (1.f - s) + table(i + 1, j, sampling) * s) * (1.f - t) +
            (table(i, j + 1, sampling) * (1.f - s) + table(i + 1, j + 1, sampling) * s) * t;
        // sin θ straight from the direction (acos near the poles would lose precision),
        // floored as in Mitsuba so that the poles keep a finite density.
        float sin_theta = std::max(std::sqrt(local.x * local.x + local.z * local.z), SinThetaFloor);
        const float pdf = value * sampling.density_scale / (2.f * Pi * Pi * sin_theta);
        if (bin == NoSide) return pdf;
        // The block's probability for the bin over its share of the table.
        const size_t blocks = block_count();
        const size_t block =
            size_t(m_row_block[size_t(j)]) * size_t(m_blocks_x) + size_t(m_column_block[size_t(i)]);
        const uint16_t *cdf = sampling.side_cdf.data() + size_t(bin) * blocks;
        const int quanta = int(cdf[block]) - (block > 0 ? int(cdf[block - 1]) : 0);
        return pdf * (float(quanta) * (1.f / float(SideQuanta))) * sampling.block_inv_share[block];
    }

    void build_distribution() {
        build_blocks();
        const int W = m_width, H = m_height;
        // Each pixel's luminance, computed once: the table's values below come from it.
        std::vector<float> lum(size_t(W) * H);
        double sum = 0.0, sphere_sum = 0.0, sphere_weight = 0.0;
        float min_lum = Infinity;
        for (int j = 0; j < H; ++j) {
            // The mean over the sphere (for power()): each pixel weighted by its row's sin θ.
            const double sin_theta = std::sin(double(j) * Pi / double(H - 1));
            for (int i = 0; i < W; ++i) {
                const size_t k = size_t(j) * size_t(W) + size_t(i);
                lum[k] = luminance_at(i, j);
                sum += double(lum[k]);
                min_lum = std::min(min_lum, lum[k]);
                sphere_sum += std::max(double(lum[k]), 0.0) * sin_theta;
                sphere_weight += sin_theta;
            }
        }
        m_mean_luminance = sphere_weight > 0.0 ? float(sphere_sum / sphere_weight) : 0.f;
        // MIS compensation (Karlík et al. 2019): sample only where the map is brighter than its
        // mean; skipped for near-constant maps, where it would leave (almost) nothing.
        Sampling &sampling = m_sampling;
        if (m_mis_compensation || !m_mis_given) {
            const float mean = float(sum / double(lum.size()));
            if (mean - min_lum > 0.01f * mean) sampling.offset = mean;
        }
        if (sampling.offset > 0.f && m_mis_compensation) {
            sampling.compensated_weight = 1.f;
            sampling.plain_weight = 0.f;
        } else if (sampling.offset > 0.f) {
            // The mix: each table scaled to its own total (rows weighted by sin θ), then
            // MixedShare of the samples from the compensated one and the rest from the plain
            // one, which keeps every direction with light sampled.
            double compensated = 0.0, plain = 0.0;
            for (int j = 0; j < H; ++j) {
                const double sin_theta = std::sin(double(j) * Pi / double(H - 1));
                for (int i = 0; i < W; ++i) {
                    const float l = lum[size_t(j) * size_t(W) + size_t(i)];
                    compensated += double(std::max(l - sampling.offset, 0.f)) * sin_theta;
                    plain += double(std::max(l, 0.f)) * sin_theta;
                }
            }
            const float compensated_weight =
                compensated > 0.0 ? float(MixedShare / compensated) : 0.f;
            const float plain_weight = plain > 0.0 ? float((1.0 - MixedShare) / plain) : 0.f;
            // Not where either total is zero or a weight leaves the floats (a map too dark or
            // too bright for them): the plain table then.
            if (compensated_weight > 0.f && plain_weight > 0.f &&
                std::isfinite(compensated_weight) && std::isfinite(plain_weight)) {
                sampling.compensated_weight = compensated_weight;
                sampling.plain_weight = plain_weight;
            } else {
                sampling.offset = 0.f;
            }
        }
        build_cells(sampling, lum, true);
    }

    /// The row weights, the cells' distribution and the density's scale of `sampling`, whose
    /// offset and weights are set, from the pixels' luminances `lum` (W x H).
    void build_cells(Sampling &sampling, const std::vector<float> &lum, bool with_sides) const {
        const int W = m_width, H = m_height;
        // Row j's factor: sin θ (zero on the pole rows: sin of a float π is slightly negative)
        // times a power of two that puts the largest entry in [1, 2): the density is unchanged
        // to the last bit (every operation on the table scales exactly), and the sampling's
        // squares neither underflow for a very dark map nor overflow for a very bright one, nor
        // does the density's normalisation (cells / total) overflow.
        sampling.row_weight.assign(size_t(H), 0.f);
        float max_entry = 0.f;
        for (int j = 0; j < H; ++j) {
            sampling.row_weight[size_t(j)] = std::max(std::sin(float(j) * Pi / float(H - 1)), 0.f);
            if (j == H - 1) sampling.row_weight[size_t(j)] = 0.f;
            for (int i = 0; i < W; ++i)
                max_entry =
                    std::max(max_entry, table_from_luminance(lum[size_t(j) * W + i], j, sampling));
        }
        if (max_entry > 0.f && std::isfinite(max_entry)) {
            const float to_unit = std::ldexp(1.f, -std::ilogb(max_entry));
            for (float &w : sampling.row_weight) w *= to_unit;
        }
        // The table's rows j and j + 1 (W + 1 values each: column W is column 0), as table()
        // gives them.
        std::vector<float> row0(size_t(W) + 1), row1(size_t(W) + 1);
        auto table_row = [&](int j, std::vector<float> &row) {
            for (int i = 0; i <= W; ++i)
                row[size_t(i)] =
                    table_from_luminance(lum[size_t(j) * W + size_t(i % W)], j, sampling);
        };
        // Stored block by block (each block's cells row by row): a block is one range.
        std::vector<float> ordered(size_t(W) * size_t(H - 1));
        table_row(0, row1);
        for (int j = 0; j + 1 < H; ++j) {
            std::swap(row0, row1);
            table_row(j + 1, row1);
            const size_t by = m_row_block[size_t(j)];
            const size_t y0 = size_t(m_block_y[by]);
            for (int i = 0; i < W; ++i) {
                const size_t bx = m_column_block[size_t(i)];
                const size_t x0 = size_t(m_block_x[bx]), w = size_t(m_block_x[bx + 1]) - x0;
                const size_t at = m_block_first[by * size_t(m_blocks_x) + bx] +
                                  (size_t(j) - y0) * w + (size_t(i) - x0);
                ordered[at] = 0.25f * (row0[size_t(i)] + row0[size_t(i) + 1] + row1[size_t(i)] +
                                       row1[size_t(i) + 1]);
            }
        }
        sampling.cells.build(ordered.data(), ordered.size());
        sampling.total = sampling.cells.sum();
        // Density over the unit square = table value / (mean cell value).
        sampling.density_scale =
            sampling.total > 0.0 ? float(double(ordered.size()) / sampling.total) : 0.f;
        if (with_sides && sampling.total > 0.0) build_side_tables(sampling, ordered);
    }

    // -- Light samples with a side (sample_direction_mis()) -----------------------------------
    // The cells are grouped in blocks of the grid, at most BlocksX x BlocksY (about 11° square),
    // stored block by block in the table's distribution, so that a block's cells are one range
    // of its CDF. Sides are binned on the faces of a cube (SideBinsPerEdge² bins per face). For
    // each bin a CDF over the blocks picks a block in proportion to its share of the table
    // times the largest cosine a side of the bin can have with a direction of the block, but
    // none that lies wholly behind every side of the bin (the cone of the bin's sides against
    // the cone of the block's directions, both bounded from above, with a margin); the table's
    // own CDF then picks the cell within the block (u rescaled into its range). The density of
    // a direction of block k is the table's times pmf_bin(k) / share(k): the light behind a
    // side is never sampled, the rest in proportion to the table within each block.
    static constexpr int BlocksX = 32, BlocksY = 16, SideBinsPerEdge = 6;
    static constexpr int SideBins = 6 * SideBinsPerEdge * SideBinsPerEdge;
    static constexpr double MinSideCosine = 0.05;
    /// The bins' CDFs count in these units (so that a bin's row of 512 blocks takes 1 KiB).
    static constexpr uint32_t SideQuanta = 65535;
    static_assert(uint32_t(BlocksX) * BlocksY < SideQuanta, "a quantum for every block");
    static constexpr uint32_t SideGuides = 64; ///< guide entries per bin (Sampling::side_guide)
    static constexpr int NoSide = -1;

    size_t block_count() const { return size_t(m_blocks_x) * size_t(m_blocks_y); }

    /// The block that holds cell `index` of the table's (blocks') order. A row of blocks holds
    /// whole rows of cells; within it, block column a starts at index h · x_a (h its height).
    size_t block_of_index(size_t index) const {
        const size_t W = size_t(m_width);
        const size_t by = size_t(m_row_block[std::min(index / W, m_row_block.size() - 1)]);
        const size_t y0 = size_t(m_block_y[by]), h = size_t(m_block_y[by + 1]) - y0;
        const size_t column = std::min((index - y0 * W) / h, W - 1);
        return by * size_t(m_blocks_x) + size_t(m_column_block[column]);
    }

    /// The blocks' bounds on the grid of cells (W x (H - 1)) and each cell's block.
    void build_blocks() {
        const int W = m_width, rows = m_height - 1;
        m_blocks_x = std::min(W, BlocksX);
        m_blocks_y = std::min(rows, BlocksY);
        m_block_x.resize(size_t(m_blocks_x) + 1);
        m_block_y.resize(size_t(m_blocks_y) + 1);
        for (int a = 0; a <= m_blocks_x; ++a)
            m_block_x[size_t(a)] = int(int64_t(a) * W / m_blocks_x);
        for (int b = 0; b <= m_blocks_y; ++b)
            m_block_y[size_t(b)] = int(int64_t(b) * rows / m_blocks_y);
        m_column_block.resize(size_t(W));
        for (int a = 0; a < m_blocks_x; ++a)
            for (int i = m_block_x[size_t(a)]; i < m_block_x[size_t(a) + 1]; ++i)
                m_column_block[size_t(i)] = uint16_t(a);
        m_row_block.resize(size_t(rows));
        for (int b = 0; b < m_blocks_y; ++b)
            for (int j = m_block_y[size_t(b)]; j < m_block_y[size_t(b) + 1]; ++j)
                m_row_block[size_t(j)] = uint16_t(b);
        m_block_first.assign(block_count() + 1, 0);
        for (size_t k = 0; k < block_count(); ++k) {
            const size_t bx = k % size_t(m_blocks_x), by = k / size_t(m_blocks_x);
            m_block_first[k + 1] = m_block_first[k] + uint32_t((m_block_x[bx + 1] - m_block_x[bx]) *
                                                               (m_block_y[by + 1] - m_block_y[by]));
        }
    }

    /// A cone of directions: its axis and an upper bound of the angle from it.
    struct Cone {
        Vector3f axis;
        float angle;
    };

    /// The cone around the directions of block k (its cells' part of the map's square).
    Cone block_cone(size_t k) const {
        const size_t bx = k % size_t(m_blocks_x), by = k / size_t(m_blocks_x);
        // Cell i spans u in [(i + ½)/W, (i + 3/2)/W]; row j spans v in [j, j + 1]/(H - 1).
        const double u0 = (m_block_x[bx] + 0.5) / m_width, u1 = (m_block_x[bx + 1] + 0.5) / m_width;
        const double v0 = double(m_block_y[by]) / (m_height - 1),
                     v1 = double(m_block_y[by + 1]) / (m_height - 1);
        // (The map's own mapping, in float: its rounding is far below the margins below.)
        auto direction = [](double u, double v) {
            return uv_to_direction(Point2f(float(u), float(v)));
        };
        Cone cone{normalize(direction(0.5 * (u0 + u1), 0.5 * (v0 + v1))), float(Pi)};
        // Half a turn or more around the axis (a map a few pixels wide): every direction.
        if (u1 - u0 >= 0.5) return cone;
        // The farthest point from the axis lies on the block's border (the antipode, the only
        // other maximum, is far outside): the border at Steps points per edge, plus the arc
        // between two of them (a bound of how much farther a point between them can be).
        constexpr int Steps = 32;
        double widest = 0.0;
        for (int s = 0; s <= Steps; ++s) {
            const double f = double(s) / Steps;
            const Vector3f points[4] = {
                direction(u0 + f * (u1 - u0), v0), direction(u0 + f * (u1 - u0), v1),
                direction(u0, v0 + f * (v1 - v0)), direction(u1, v0 + f * (v1 - v0))};
            for (const Vector3f &p : points)
                widest =
                    std::max(widest, std::acos(std::clamp(double(dot(cone.axis, p)), -1.0, 1.0)));
        }
        const double step = std::max((u1 - u0) * 2.0 * double(Pi), (v1 - v0) * double(Pi)) / Steps;
        cone.angle = float(widest + step);
        return cone;
    }

    /// The cube face and cell of a side: face f holds the sides whose largest component is
    /// axis f / 2 (positive for even f); the cell comes from the other two components over it.
    static void side_face_axes(int face, int &major, int &a, int &b) {
        major = face / 2;
        a = major == 0 ? 1 : 0;
        b = major == 2 ? 1 : 2;
    }

    /// The cone of sides in bin `bin` (a geodesic quad of the cube's face: its corners bound it).
    static Cone side_cone(int bin) {
        const int face = bin / (SideBinsPerEdge * SideBinsPerEdge);
        const int cell = bin % (SideBinsPerEdge * SideBinsPerEdge);
        const int p = cell % SideBinsPerEdge, q = cell / SideBinsPerEdge;
        int major, a, b;
        side_face_axes(face, major, a, b);
        auto point = [&](double x, double y) {
            double c[3] = {0.0, 0.0, 0.0};
            c[major] = face % 2 == 0 ? 1.0 : -1.0;
            c[a] = x;
            c[b] = y;
            return normalize(Vector3f(float(c[0]), float(c[1]), float(c[2])));
        };
        auto edge = [](int k) { return -1.0 + 2.0 * k / SideBinsPerEdge; };
        Cone cone{point(0.5 * (edge(p) + edge(p + 1)), 0.5 * (edge(q) + edge(q + 1))), 0.f};
        double widest = 0.0;
        for (int corner = 0; corner < 4; ++corner) {
            const Vector3f c = point(edge(p + corner % 2), edge(q + corner / 2));
            widest = std::max(widest, std::acos(std::clamp(double(dot(cone.axis, c)), -1.0, 1.0)));
        }
        cone.angle = float(widest + 1e-4);
        return cone;
    }

    /// The bin of a world-space side (zero: none, NoSide).
    int side_bin(const Vector3f &side) const {
        if (!(dot(side, side) > 0.f)) return NoSide;
        // The map's frame without normalising: the bin depends on the direction alone.
        const Vector3f s(dot(m_local_rows[0], side), dot(m_local_rows[1], side),
                         dot(m_local_rows[2], side));
        const float c[3] = {s.x, s.y, s.z};
        int major = 0;
        for (int k = 1; k < 3; ++k)
            if (std::abs(c[k]) > std::abs(c[major])) major = k;
        const float m = std::abs(c[major]);
        if (!(m > 0.f)) return NoSide; // not finite
        int face = 2 * major + (c[major] > 0.f ? 0 : 1), f_major, a, b;
        side_face_axes(face, f_major, a, b);
        auto cell = [](float x) {
            return std::clamp(int((x + 1.f) * 0.5f * float(SideBinsPerEdge)), 0,
                              SideBinsPerEdge - 1);
        };
        return (face * SideBinsPerEdge + cell(c[b] / m)) * SideBinsPerEdge + cell(c[a] / m);
    }

    /// The blocks' starts and shares and each bin's CDF over them, for `sampling`, whose cells
    /// (in the blocks' order: `ordered`) are built.
    void build_side_tables(Sampling &sampling, const std::vector<float> &ordered) const {
        const size_t blocks = block_count();
        sampling.block_start.resize(blocks + 1);
        sampling.block_inv_share.resize(blocks);
        std::vector<double> share(blocks);
        std::vector<Cone> cones(blocks);
        for (size_t k = 0; k <= blocks; ++k) {
            sampling.block_start[k] = m_block_first[k] < ordered.size()
                                          ? sampling.cells.cdf_before(m_block_first[k])
                                          : 1.0;
            if (k == blocks) break;
            double sum = 0.0;
            for (uint32_t c = m_block_first[k]; c < m_block_first[k + 1]; ++c)
                sum += double(std::max(ordered[c], 0.f));
            share[k] = sum / sampling.total;
            sampling.block_inv_share[k] = sum > 0.0 ? float(sampling.total / sum) : 0.f;
            cones[k] = block_cone(k);
        }
        sampling.side_cdf.assign(size_t(SideBins) * blocks, 0);
        sampling.side_guide.assign(size_t(SideBins) * size_t(SideGuides + 1), 0);
        std::vector<double> weight(blocks);
        for (int bin = 0; bin < SideBins; ++bin) {
            const Cone side = side_cone(bin);
            double sum = 0.0;
            for (size_t k = 0; k < blocks; ++k) {
                // The least angle between a side of the bin and a direction of the block.
                const double apart =
                    std::acos(std::clamp(double(dot(side.axis, cones[k].axis)), -1.0, 1.0)) -
                    double(side.angle) - double(cones[k].angle);
                const bool behind = apart > 0.5 * double(Pi) + 1e-3;
                // In front: weighted by the largest cosine a side of the bin can have with a
                // direction of the block (the cosine of the surfaces the light falls on), at
                // least MinSideCosine.
                const double cosine = std::max(std::cos(std::max(apart, 0.0)), MinSideCosine);
                weight[k] = behind ? 0.0 : share[k] * cosine;
                sum += weight[k];
            }
            if (!(sum > 0.0)) continue;
            // Every block in front gets one quantum, the others' in proportion to the weights:
            // none with light is left out by rounding, and the CDF ends at SideQuanta.
            size_t in_front = 0;
            for (size_t k = 0; k < blocks; ++k) in_front += weight[k] > 0.0 ? 1 : 0;
            const double rest = double(SideQuanta - in_front);
            uint16_t *cdf = sampling.side_cdf.data() + size_t(bin) * blocks;
            double running = 0.0;
            size_t counted = 0;
            for (size_t k = 0; k < blocks; ++k) {
                running += weight[k];
                counted += weight[k] > 0.0 ? 1 : 0;
                cdf[k] =
                    uint16_t(counted + size_t(std::llround(std::min(running / sum, 1.0) * rest)));
            }
            uint16_t *guide = sampling.side_guide.data() + size_t(bin) * size_t(SideGuides + 1);
            size_t k = 0;
            for (uint32_t g = 0; g <= SideGuides; ++g) {
                // The block sample_uv() picks for u = g / SideGuides (x as it computes it).
                const float u = float(g) / float(SideGuides);
                const uint32_t below = uint32_t(u * float(SideQuanta));
                while (k + 1 < blocks && cdf[k] <= below) ++k;
                guide[g] = uint16_t(k);
            }
        }
    }

    /// What light samples that stand alone and emitted rays follow: m_sampling, or, when that
    /// is the mix, the plain table, built on first use (most renders never ask for it and keep
    /// the memory).
    const Sampling &alone_sampling() const {
        if (!(m_sampling.compensated_weight > 0.f && m_sampling.plain_weight > 0.f))
            return m_sampling;
        std::call_once(m_plain_once, [this] {
            std::vector<float> lum(size_t(m_width) * size_t(m_height));
            for (int j = 0; j < m_height; ++j)
                for (int i = 0; i < m_width; ++i)
                    lum[size_t(j) * size_t(m_width) + size_t(i)] = luminance_at(i, j);
            auto plain = std::make_unique<Sampling>();
            build_cells(*plain, lum, false);
            m_plain = std::move(plain);
        });
        return *m_plain;
    }

    std::string m_path;
    float m_scale = 1.f;
    Vector3f m_world_rows[3], m_local_rows[3]; ///< to_world's 3x3 part and its inverse's, by rows
    bool m_bilinear = true, m_importance = true, m_mis_compensation = false;
    bool m_mis_given = false; ///< the scene set mis_compensation (else: the mix)
    /// The mix's share of light samples from the compensated table.
    static constexpr double MixedShare = 0.9;
    int m_width = 0, m_height = 0;
    std::vector<Texel> m_texels;    ///< (W + 1) x H: the pixels (the table's values come from them)
    bool m_spectral = false;        ///< the texels hold curves (the spectral mode)
    std::vector<float> m_scales;    ///< the spectral mode's pixel scales, laid out as m_texels
    std::vector<float> m_luminance; ///< the spectral mode's pixel luminances, laid out as m_texels
    Sampling m_sampling; ///< what light samples for MIS follow (and, but for the mix, all)
    mutable std::once_flag m_plain_once;
    mutable std::unique_ptr<Sampling> m_plain; ///< see alone_sampling()
    // The blocks of cells (see block_count()): their bounds in cells (m_blocks_x + 1 and
    // m_blocks_y + 1 values), each cell column's and row's block, each block's first cell.
    int m_blocks_x = 1, m_blocks_y = 1;
    std::vector<int> m_block_x, m_block_y;
    std::vector<uint16_t> m_column_block, m_row_block;
    std::vector<uint32_t> m_block_first;
    float m_mean_luminance = 0.f; ///< over the sphere of directions, for power()
    Point3f m_center;
    float m_radius = 1.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::EnvironmentMap, Emitter, "envmap",
                          "Latitude-longitude environment map with luminance importance sampling",
                          DOC, ::facet::AllModes)
