// `facet new-plugin bsdf|emitter|texture|integrator <name> [dir]`: writes an out-of-tree plugin
// project (CMakeLists.txt, the plugin's .cpp, a scene.xml using it) that builds against the
// installed facet package and loads with -a.

#include "commands.h"

#include <facet/logger.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace {

const char *CMAKE_TEMPLATE = R"CMAKE(# The @NAME@ plugin (@KIND@) for facet, built out of tree:
#   cmake -S . -B build -DCMAKE_PREFIX_PATH=<facet's install prefix>
#   cmake --build build
#   facet plugins @NAME@ -a build            # its parameter table
@CHECK_LINE@#   facet render scene.xml -a build          # or: export FACET_PLUGIN_PATH=$PWD/build
cmake_minimum_required(VERSION 3.20)
project(@NAME@ LANGUAGES CXX)

# A plugin built without optimisation renders many times slower: Release unless asked otherwise.
if(NOT CMAKE_BUILD_TYPE AND NOT CMAKE_CONFIGURATION_TYPES)
    set(CMAKE_BUILD_TYPE Release CACHE STRING "Build type (Debug, Release, RelWithDebInfo)" FORCE)
endif()

find_package(facet REQUIRED)
facet_add_plugin(@NAME@ @NAME@.cpp)
)CMAKE";

// The scene every template comes with: the plugin in use, rendered by
// `facet render scene.xml -a build`. @OBJECTS@ is the template's part.
const char *SCENE_TEMPLATE =
    R"XML(<!-- A small scene that uses the @NAME@ plugin: facet render scene.xml -a build -->
<scene version="3.0.0">
    <default name="spp" value="16"/>
    <default name="res" value="64"/>

@INTEGRATOR@
    <sensor type="@SENSOR@">
        <float name="fov" value="40"/>
        <transform name="to_world">
            <lookat origin="0, 1.5, 4" target="0, 0.5, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="@SAMPLER@">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="@FILM@">
            <integer name="width" value="$res"/>
            <integer name="height" value="$res"/>
@FILM_LINES@        </film>
    </sensor>

    <shape type="sphere">
        <point name="center" x="0" y="0.6" z="0"/>
        <float name="radius" value="0.6"/>
@SPHERE_BSDF@
    </shape>

    <shape type="rectangle">
        <transform name="to_world">
            <rotate x="1" angle="-90"/>
            <scale value="5"/>
        </transform>
@FLOOR_BSDF@
    </shape>
@SHAPE@
@EMITTER@
</scene>
)XML";

const char *PATH_INTEGRATOR = R"(    <integrator type="path">
        <integer name="max_depth" value="4"/>
    </integrator>
)";
const char *DIFFUSE_BSDF = R"(        <bsdf type="diffuse"/>)";
const char *SKY = R"(    <emitter type="constant">
        <rgb name="radiance" value="0.8, 0.85, 1.0"/>
    </emitter>)";

// The plugins: each complete and correct, to be turned into something else. The doc block is
// what `facet plugins @NAME@` prints; keep its table in step with the constructor (every name the
// constructor reads must be a row of the table).
const char *BSDF_TEMPLATE = R"CPP(static const char *DOC = R"DOC(
# @NAME@: a BSDF plugin (so far a Lambertian reflector)

Describe the model here. Until you change it this is ideal diffuse reflection on the front side:
f = ρ/π, sampled cosine-weighted, so the sample weight is ρ.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| reflectance | spectrum or texture | 0.5 | Diffuse albedo ρ |

```xml
<bsdf type="@NAME@">
    <rgb name="reflectance" value="0.6, 0.4, 0.2"/>
</bsdf>
```
)DOC";

// Conventions (facet/bsdf.h): directions are in the local shading frame (normal +Z,
// cos θ = v.z); si.wi points away from the surface; eval() returns f·|cos θo|; sample() returns
// the weight f·|cos θo|/pdf (zero when it fails); pdf() is the density of exactly what sample()
// does. `facet chi2 bsdf @NAME@ -a <build dir>` checks all of this statistically.

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class @CLASS@ final : public BSDF {
public:
    explicit @CLASS@(const Properties &props) {
        // Read every parameter of the table, with its default; unread ones are reported.
        m_reflectance = props.texture("reflectance", 0.5f);
        BSDFFlags flags = BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide;
        if (m_reflectance->is_spatially_varying()) flags |= BSDFFlags::SpatiallyVarying;
        set_components({flags});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float /*sample1*/, const Point2f &sample2) const override {
        BSDFSample bs;
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || Frame::cos_theta(si.wi) <= 0.f)
            return {bs, Color3f(0.f)};
        bs.wo = warp::square_to_cosine_hemisphere(sample2);
        bs.pdf = warp::square_to_cosine_hemisphere_pdf(bs.wo);
        bs.eta = 1.f;
        bs.sampled_type = BSDFFlags::DiffuseReflection;
        bs.sampled_component = 0;
        if (!(bs.pdf > 0.f) || Frame::cos_theta(bs.wo) <= 0.f) return {bs, Color3f(0.f)};
        return {bs, eval(ctx, si, bs.wo) / bs.pdf};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || Frame::cos_theta(si.wi) <= 0.f ||
            Frame::cos_theta(wo) <= 0.f)
            return Color3f(0.f);
        return m_reflectance->eval(si) * (InvPi * Frame::cos_theta(wo));
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || Frame::cos_theta(si.wi) <= 0.f ||
            Frame::cos_theta(wo) <= 0.f)
            return 0.f;
        return warp::square_to_cosine_hemisphere_pdf(wo);
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_reflectance->eval(si);
    }

    std::string to_string() const override {
        return fmt::format("@CLASS@[reflectance = {}]", m_reflectance->to_string());
    }

private:
    std::shared_ptr<Texture> m_reflectance;
};

} // namespace facet

// Name = the XML type = the library's file name (@NAME@.so).
// Every mode: the reflectance comes from Properties::texture() and is evaluated at the
// interaction (in scalar_spectral at its wavelengths). A plugin that reads its own colours
// declares ::facet::RGBAndMono (or uses FACET_EXPORT_PLUGIN) until it evaluates them there.
FACET_EXPORT_PLUGIN_MODES(facet::@CLASS@, BSDF, "@NAME@",
                          "A BSDF plugin (so far a Lambertian reflector)", DOC, ::facet::AllModes)
)CPP";

const char *EMITTER_TEMPLATE = R"CPP(static const char *DOC = R"DOC(
# @NAME@: an emitter plugin (so far a two-colour sky)

Describe the light here. Until you change it this is an environment that surrounds the scene and
sends radiance blended linearly from `bottom` (light travelling upwards, from straight below) to
`top` (from straight above) with the height of the direction it comes from; +y is up, as in most
Mitsuba scenes. Directions are sampled uniformly over the sphere (pdf 1/4π): correct for any
radiance, and the first thing to improve (sample the brighter half more often) once the model is
right. With `top` = `bottom` it is the `constant` emitter.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| top | spectrum | 1 | Radiance arriving from straight above (+y) |
| bottom | spectrum | 0.25 | Radiance arriving from straight below (-y) |

```xml
<emitter type="@NAME@">
    <rgb name="top" value="0.6, 0.7, 1.0"/>
    <rgb name="bottom" value="0.2, 0.15, 0.1"/>
</emitter>
```
)DOC";

// Conventions (facet/emitter.h): sample_direction() picks a point of the emitter seen from
// ref.p and returns the record (unit direction towards it, distance, solid-angle pdf) and the
// weight radiance/pdf, without testing visibility; pdf_direction() is the density of exactly
// what sample_direction() does; eval() is the radiance along a ray that reached the emitter (for
// an environment: a miss record whose si.wi = -ray.d in world space). sample_ray() is what the
// light tracer (ptracer) draws. `facet chi2 emitter @NAME@ -a <build dir>` checks the sampling
// against the pdf statistically.

#include <facet/emitter.h>
#include <facet/frame.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/scene.h>
#include <facet/warp.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace facet {

class @CLASS@ final : public Emitter {
public:
    explicit @CLASS@(const Properties &props) {
        // Read every parameter of the table, with its default; unread ones are reported.
        m_top = props.get_color("top", Color3f(1.f), SpectrumKind::Emission);
        m_bottom = props.get_color("bottom", Color3f(0.25f), SpectrumKind::Emission);
        m_flags = EmitterFlags::Infinite;
    }

    /// The environment surrounds the scene: remember its bounding sphere.
    void set_scene(const Scene &scene) override {
        const BoundingBox3f &bbox = scene.bbox();
        float radius = bbox.bounding_sphere_radius();
        if (bbox.valid() && std::isfinite(radius) && radius > 0.f) {
            m_center = bbox.center();
            m_radius = radius * (1.f + RayEpsilon); // the sampled points lie outside it
        }
    }

    std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                         const Point2f &u) const override {
        DirectionSample ds;
        ds.d = warp::square_to_uniform_sphere(u);
        // A point beyond the bounding sphere for every reference point inside it.
        ds.dist = 2.f * m_radius;
        ds.p = ref.p + ds.d * ds.dist;
        ds.n = -ds.d;
        ds.uv = u;
        ds.pdf = InvFourPi;
        ds.delta = false;
        ds.emitter = this;
        return {ds, radiance_from(ds.d) / ds.pdf};
    }

    float pdf_direction(const Interaction &, const DirectionSample &) const override {
        return InvFourPi;
    }

    Color3f eval(const SurfaceInteraction &si) const override { return radiance_from(-si.wi); }

    /// A ray entering the bounding sphere: direction w uniform over the sphere (pdf 1/4π), origin
    /// uniform on the disk of radius r facing it (pdf 1/(π r²)); weight = radiance / both pdfs.
    /// (The colours are RGB: the plugin renders in scalar_rgb and scalar_mono, where the path's
    /// wavelengths are unused; the ray carries them on all the same.)
    std::pair<Ray, Color3f> sample_ray(const Point2f &u_pos, const Point2f &u_dir,
                                       const Wavelengths &wavelengths) const override {
        const Vector3f w = warp::square_to_uniform_sphere(u_dir);
        const Point2f disk = warp::square_to_uniform_disk_concentric(u_pos);
        const Frame frame(w);
        const Point3f o = m_center + (frame.s * disk.x + frame.t * disk.y - w) * m_radius;
        Ray ray(o, w);
        ray.wavelengths = wavelengths;
        return {ray, radiance_from(-w) * (4.f * Pi * Pi * m_radius * m_radius)};
    }

    std::string to_string() const override {
        return fmt::format("@CLASS@[top = ({}, {}, {}), bottom = ({}, {}, {})]", m_top.r, m_top.g,
                           m_top.b, m_bottom.r, m_bottom.g, m_bottom.b);
    }

private:
    /// Radiance arriving from the unit world direction d (pointing away from the scene).
    Color3f radiance_from(const Vector3f &d) const {
        float t = std::clamp(0.5f * (d.y + 1.f), 0.f, 1.f);
        return lerp(t, m_bottom, m_top);
    }

    Color3f m_top, m_bottom;
    Point3f m_center{0.f, 0.f, 0.f};
    float m_radius = 1.f;
};

} // namespace facet

// Name = the XML type = the library's file name (@NAME@.so).
FACET_EXPORT_PLUGIN(facet::@CLASS@, Emitter, "@NAME@", "An emitter plugin (so far a two-colour sky)", DOC)
)CPP";

const char *TEXTURE_TEMPLATE = R"CPP(static const char *DOC = R"DOC(
# @NAME@: a texture plugin (so far a colour ramp)

Describe the pattern here. Until you change it this is a linear ramp along the surface's u
coordinate from `color0` (at u = 0) to `color1` (at u = 1), repeated `scale` times over the unit
square of texture coordinates.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| color0 | spectrum | 0 | Colour at the start of each ramp |
| color1 | spectrum | 1 | Colour at the end of each ramp |
| scale | float | 1 | Number of ramps over u ∈ [0, 1] (> 0) |

```xml
<bsdf type="diffuse">
    <texture type="@NAME@" name="reflectance">
        <rgb name="color0" value="0.1, 0.1, 0.4"/>
        <rgb name="color1" value="0.9, 0.8, 0.2"/>
        <float name="scale" value="4"/>
    </texture>
</bsdf>
```
)DOC";

// Conventions (facet/texture.h): eval() is the colour at a surface point (si.uv are its texture
// coordinates), eval_1() its scalar value (for roughness, blend weights: by default the mean of
// the channels), eval_1_grad() the gradient of eval_1 over (u, v) (for bump mapping), mean() the
// average over the texture's domain and max() an upper bound of eval_1 over all points.

#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace facet {

class @CLASS@ final : public Texture {
public:
    explicit @CLASS@(const Properties &props) {
        // Read every parameter of the table, with its default; unread ones are reported.
        m_color0 = props.get_color("color0", Color3f(0.f));
        m_color1 = props.get_color("color1", Color3f(1.f));
        m_scale = float(props.get_float("scale", 1.0));
        if (!(m_scale > 0.f) || !std::isfinite(m_scale))
            FACET_THROW_AT(props.location("scale"), "@NAME@: scale must be positive, got {}",
                           m_scale);
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        return lerp(ramp(si), m_color0, m_color1);
    }

    /// d/du of the mean of the channels along the ramp (the steps between ramps have none).
    Vector2f eval_1_grad(const SurfaceInteraction &) const override {
        return Vector2f((m_color1.mean() - m_color0.mean()) * m_scale, 0.f);
    }

    /// A linear ramp averages to the middle of its ends.
    Color3f mean() const override { return (m_color0 + m_color1) * 0.5f; }
    float max() const override { return std::max(m_color0.max(), m_color1.max()); }

    std::string to_string() const override {
        return fmt::format("@CLASS@[color0 = ({}, {}, {}), color1 = ({}, {}, {}), scale = {}]",
                           m_color0.r, m_color0.g, m_color0.b, m_color1.r, m_color1.g, m_color1.b,
                           m_scale);
    }

private:
    /// Position in [0, 1) along the ramp the point lies on.
    float ramp(const SurfaceInteraction &si) const {
        float x = si.uv.x * m_scale;
        return x - std::floor(x);
    }

    Color3f m_color0, m_color1;
    float m_scale = 1.f;
};

} // namespace facet

// Name = the XML type = the library's file name (@NAME@.so).
FACET_EXPORT_PLUGIN(facet::@CLASS@, Texture, "@NAME@", "A texture plugin (so far a colour ramp)", DOC)
)CPP";

const char *INTEGRATOR_TEMPLATE = R"CPP(static const char *DOC = R"DOC(
# @NAME@: an integrator plugin (so far ambient occlusion)

Describe the estimator here. Until you change it this is ambient occlusion: at the first surface
a camera ray hits, the fraction of the hemisphere around the shading normal (on the side the ray
came from), weighted by the cosine, that is not blocked within `max_distance`. It takes
`shading_samples` cosine-distributed directions per camera sample, so each counts 0 or 1 and
their mean is the estimate. Rays that hit nothing give 0. The value goes to all three channels.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| shading_samples | integer | 1 | Occlusion rays per camera sample (≥ 1) |
| max_distance | float | -1 | Occluders further away than this are ignored; ≤ 0: no limit |
| timeout | float | -1 | Stop after this many seconds and develop what is done (like Ctrl-C); <= 0: no limit |
| samples_per_pass | integer | (all) | Render in passes over the image of this many samples per pixel (must divide the sample count) |
| block_size | integer | 0 | Side of the square image blocks, in pixels; 0 chooses 32 |

```xml
<integrator type="@NAME@">
    <integer name="shading_samples" value="4"/>
    <float name="max_distance" value="0.5"/>
</integrator>
```
)DOC";

// Conventions (facet/integrator.h): a SamplingIntegrator estimates the radiance along one camera
// ray in sample(); facet's render loop takes the image in blocks and passes on all threads around
// it (an integrator implements no loop of its own). The estimate may use only the sampler for
// randomness (so the image is the same for any number of threads), and sample() runs on many
// threads at once: it must not modify the integrator.
// The base class reads timeout, samples_per_pass and block_size (rows of the table above).

#include <facet/frame.h>
#include <facet/integrator.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class @CLASS@ final : public SamplingIntegrator {
public:
    explicit @CLASS@(const Properties &props) : SamplingIntegrator(props) {
        // Read every parameter of the table, with its default; unread ones are reported.
        int64_t samples = props.get_int("shading_samples", 1);
        if (samples < 1 || samples > 0xffff)
            FACET_THROW_AT(props.location("shading_samples"),
                           "@NAME@: shading_samples must be in [1, 65535], got {}", samples);
        m_samples = uint32_t(samples);
        m_max_distance = float(props.get_float("max_distance", -1.0));
    }

    Color3f sample(const Scene &scene, Sampler &sampler, const Ray &ray,
                   float * /*aovs*/) const override {
        SurfaceInteraction si;
        if (!scene.ray_intersect(ray, si)) return Color3f(0.f);
        // The hemisphere on the side the camera ray arrived from (si.wi is in the local frame).
        float side = Frame::cos_theta(si.wi) < 0.f ? -1.f : 1.f;
        uint32_t unoccluded = 0;
        for (uint32_t i = 0; i < m_samples; ++i) {
            Vector3f local = warp::square_to_cosine_hemisphere(sampler.next_2d());
            local.z *= side;
            Ray shadow = si.spawn_ray(si.to_world(local));
            if (m_max_distance > 0.f) shadow.maxt = m_max_distance;
            if (!scene.ray_test(shadow)) ++unoccluded;
        }
        return Color3f(float(unoccluded) / float(m_samples));
    }

    std::string to_string() const override {
        return fmt::format("@CLASS@[shading_samples = {}, max_distance = {}]", m_samples,
                           m_max_distance);
    }

private:
    uint32_t m_samples = 1;
    float m_max_distance = -1.f;
};

} // namespace facet

// Name = the XML type = the library's file name (@NAME@.so).
FACET_EXPORT_PLUGIN(facet::@CLASS@, Integrator, "@NAME@", "An integrator plugin (so far ambient occlusion)", DOC)
)CPP";

const char *RFILTER_TEMPLATE = R"CPP(static const char *DOC = R"DOC(
# @NAME@: a reconstruction filter plugin (so far a Hann window)

Describe the filter here. Until you change it this is a Hann (raised cosine) window: the weight
of a sample at distance x from a pixel centre is (1 + cos(π x / radius)) / 2 inside `radius`
and 0 beyond. The film weighs a sample by w(x) · w(y), where w is eval() tabulated once over the
radius (as for every filter), and divides each pixel by the sum of the weights it received.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| radius | float | 1.5 | Radius in pixels (1/64 to 64) |

```xml
<film type="hdrfilm">
    <rfilter type="@NAME@">
        <float name="radius" value="2"/>
    </rfilter>
</film>
```
)DOC";

// Conventions (facet/rfilter.h): the filter is separable, eval(x) is the weight at distance x
// (in pixels, either sign) from a pixel centre, the same at -x and x, and must be 0 beyond
// m_radius; the film tabulates it once (ReconstructionFilter::weight()). Weights may be
// negative (a sharpening filter) but must stay finite and sum to a positive number over the
// radius: check_weights() at the end of the constructor checks that, at the filter's place in
// the scene.

#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/rfilter.h>

#include <fmt/format.h>

#include <cmath>

namespace facet {

class @CLASS@ final : public ReconstructionFilter {
public:
    explicit @CLASS@(const Properties &props) {
        // Read every parameter of the table, with its default; unread ones are reported.
        const double radius = props.get_float("radius", 1.5);
        if (!(radius >= MinFilterRadius && radius <= MaxFilterRadius))
            FACET_THROW_AT(props.location("radius"),
                           "@NAME@: radius must be a number of pixels in [{}, {}], got {}",
                           MinFilterRadius, MaxFilterRadius, radius);
        m_radius = float(radius);
        check_weights(props);
    }

    float eval(float x) const override {
        if (std::abs(x) >= m_radius) return 0.f;
        return 0.5f * (1.f + std::cos(3.14159265358979f * x / m_radius));
    }

    std::string to_string() const override { return fmt::format("@CLASS@[radius = {}]", m_radius); }
};

} // namespace facet

// Name = the XML type = the library's file name (@NAME@.so).
// Every mode: a filter has no colours.
FACET_EXPORT_PLUGIN_MODES(facet::@CLASS@, ReconstructionFilter, "@NAME@",
                          "A reconstruction filter plugin (so far a Hann window)", DOC,
                          ::facet::AllModes)
)CPP";

const char *SAMPLER_TEMPLATE = R"CPP(static const char *DOC = R"DOC(
# @NAME@: a sampler plugin (so far independent random numbers)

Describe the sample values here. Until you change it every sample of every pixel draws
independent uniform numbers from its own PCG32 stream, seeded from the pixel, the sample index
and `seed`.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| sample_count | integer | 4 | Samples per pixel |
| seed | integer | 0 | Base seed: other seeds give statistically independent images |

```xml
<sampler type="@NAME@">
    <integer name="sample_count" value="64"/>
</sampler>
```
)DOC";

// Conventions (facet/sampler.h): the render clones the sampler per thread, calls seed() once
// per pixel and set_sample_index() for each sample it takes. The values of sample i of a pixel
// must depend only on (the pixel's seed, i, sample_count, the base seed), never on the samples
// taken before: renders split into passes, crops and threads then give the same image. The base
// class reads sample_count and seed; clone() must copy everything a sample's values depend on.
// A sampler whose pattern needs a particular count (a square, a power of two) overrides
// set_sample_count() to round it and returns the count it takes; the render reports it.

#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/sampler.h>

#include <fmt/format.h>

#include <memory>

namespace facet {

class @CLASS@ final : public Sampler {
public:
    explicit @CLASS@(const Properties &props) : Sampler(props) {}

    std::unique_ptr<Sampler> clone() const override { return std::make_unique<@CLASS@>(*this); }

    void seed(uint64_t seed_value) override {
        m_pixel_seed = seed_value;
        set_sample_index(0);
    }

    void set_sample_index(uint32_t index) override {
        Sampler::set_sample_index(index);
        // One stream per (pixel, sample, base seed): hash them into PCG32's state and stream.
        const uint64_t v = m_pixel_seed ^ (uint64_t(index) * 0x9e3779b97f4a7c15ull) ^
                           (m_base_seed * 0xd1b54a32d192ed03ull);
        m_rng.seed(mix64(v), mix64(v ^ 0x6a09e667f3bcc908ull));
    }

    float next_1d() override {
        ++m_dimension;
        return m_rng.next_float();
    }

    Point2f next_2d() override {
        m_dimension += 2;
        const float x = m_rng.next_float();
        return {x, m_rng.next_float()};
    }

    std::string to_string() const override {
        return fmt::format("@CLASS@[sample_count = {}, seed = {}]", m_sample_count, m_base_seed);
    }

private:
    PCG32 m_rng;
    uint64_t m_pixel_seed = 0;
};

} // namespace facet

// Name = the XML type = the library's file name (@NAME@.so).
// Every mode: a sampler has no colours.
FACET_EXPORT_PLUGIN_MODES(facet::@CLASS@, Sampler, "@NAME@",
                          "A sampler plugin (so far independent random numbers)", DOC,
                          ::facet::AllModes)
)CPP";

const char *FILM_TEMPLATE = R"CPP(static const char *DOC = R"DOC(
# @NAME@: a film plugin (so far an exposure control)

Describe what the film does to the image here. Until you change it this film develops like
facet's base film and scales the colour by 2^`exposure` (photographic stops) before writing.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| width | integer | 768 | Image width in pixels |
| height | integer | 576 | Image height in pixels |
| crop_offset_x | integer | 0 | Left column of the crop window |
| crop_offset_y | integer | 0 | Top row of the crop window |
| crop_width | integer | width - crop_offset_x | Width of the crop window |
| crop_height | integer | height - crop_offset_y | Height of the crop window |
| component_format | string | float16 | float16 or float32 (EXR sample type; read by the base class) |
| exposure | float | 0 | Exposure in stops: the colour is multiplied by 2^exposure |
| (rfilter) | rfilter | gaussian | Nested reconstruction filter |

```xml
<film type="@NAME@">
    <integer name="width" value="640"/>
    <integer name="height" value="480"/>
    <float name="exposure" value="1"/>
</film>
```
)DOC";

// Conventions (facet/film.h): the base class reads the size, the crop window, the component
// format and the nested rfilter, and develops a render's pixel sums (a FilmBuffer the render owns: the film is only
// read, by any number of renders at once) into linear RGB, alpha, then the AOVs of the render. A
// film changes what develop() returns or how write() stores it. A render of several passes in
// one process or a merge develops the pass sums with the base class's Film::develop(), not this
// override: keep changes of the image to what a merge may skip, or render such films in one pass.

#include <facet/film.h>
#include <facet/image.h>
#include <facet/logger.h>
#include <facet/plugin.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace facet {

class @CLASS@ final : public Film {
public:
    explicit @CLASS@(const Properties &props) : Film(props) {
        // Read every parameter of the table, with its default; unread ones are reported.
        const double exposure = props.get_float("exposure", 0.0);
        if (!(std::abs(exposure) <= 64.0))
            FACET_THROW_AT(props.location("exposure"),
                           "@NAME@: exposure must be a number of stops in [-64, 64], got {}",
                           exposure);
        m_gain = float(std::exp2(exposure));
    }

    Image develop(const FilmBuffer &buffer) const override {
        Image image = Film::develop(buffer);
        // The colour channels (R, G, B) come first; alpha and the AOVs keep their values.
        const int colour = std::min(image.channels, 3);
        for (size_t i = 0; i < image.data.size(); i += size_t(image.channels))
            for (int c = 0; c < colour; ++c) image.data[i + size_t(c)] *= m_gain;
        return image;
    }

    std::string to_string() const override {
        return fmt::format("@CLASS@[{}x{}, gain = {}]", size().x, size().y, m_gain);
    }

private:
    float m_gain = 1.f;
};

} // namespace facet

// Name = the XML type = the library's file name (@NAME@.so).
// Every mode: a film has no colours (the render loop develops spectra before the film).
FACET_EXPORT_PLUGIN_MODES(facet::@CLASS@, Film, "@NAME@",
                          "A film plugin (so far an exposure control)", DOC, ::facet::AllModes)
)CPP";

const char *SENSOR_TEMPLATE = R"CPP(static const char *DOC = R"DOC(
# @NAME@: a sensor plugin (so far a pinhole camera)

Describe the camera here. Until you change it this is a pinhole camera at the origin of its
`to_world` frame looking down +Z, with `fov` degrees across the film's width.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| fov | float | 40 | Horizontal field of view in degrees (0 to 180, exclusive) |
| to_world | transform | identity | Camera-to-world transform |
| shutter_open | float | 0 | Accepted for compatibility (still images) |
| shutter_close | float | 0 | Accepted for compatibility (>= shutter_open) |
| srf | spectrum | none | Spectral response (spectral modes; read by the Sensor base class) |
| (film) | film | hdrfilm | Nested film |
| (sampler) | sampler | independent | Nested sampler |

```xml
<sensor type="@NAME@">
    <float name="fov" value="45"/>
    <transform name="to_world">
        <lookat origin="0, 1, 4" target="0, 0, 0" up="0, 1, 0"/>
    </transform>
    <film type="hdrfilm"/>
</sensor>
```
)DOC";

// Conventions (facet/sensor.h): the base class reads to_world, the shutter and the nested film
// and sampler. sample_ray() turns a position on the full film (x right, y down, in [0, 1]²)
// into a world-space ray with a unit direction and its weight. The camera looks down its local
// +Z with +Y up, so film x growing to the right is local -X (Mitsuba's convention). A sensor that
// implements sample_direction() and pdf_direction() can also be used by the light tracer.

#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/ray.h>
#include <facet/sensor.h>
#include <facet/film.h>

#include <fmt/format.h>

#include <cmath>

namespace facet {

class @CLASS@ final : public Sensor {
public:
    explicit @CLASS@(const Properties &props) : Sensor(props) {
        // Read every parameter of the table, with its default; unread ones are reported.
        const double fov = props.get_float("fov", 40.0);
        if (!(fov > 0.0 && fov < 180.0))
            FACET_THROW_AT(props.location("fov"), "@NAME@: fov must be in (0, 180) degrees, got {}",
                           fov);
        const Point2i size = film().size();
        m_tan_x = float(std::tan(fov * 0.5 * 3.14159265358979 / 180.0));
        m_tan_y = m_tan_x * float(size.y) / float(size.x);
    }

    std::pair<Ray, Color3f> sample_ray(float time, const Point2f &film_pos,
                                       const Point2f &) const override {
        const Vector3f local((1.f - 2.f * film_pos.x) * m_tan_x,
                             (1.f - 2.f * film_pos.y) * m_tan_y, 1.f);
        Ray ray(m_to_world.apply_point(Point3f(0.f)),
                normalize(m_to_world.apply_vector(normalize(local))), 0.f, Infinity);
        ray.time = time;
        return {ray, Color3f(1.f)};
    }

    std::string to_string() const override {
        return fmt::format("@CLASS@[tan_x = {}, tan_y = {}]", m_tan_x, m_tan_y);
    }

private:
    float m_tan_x = 1.f, m_tan_y = 1.f;
};

} // namespace facet

// Name = the XML type = the library's file name (@NAME@.so).
// Every mode: a sensor has no colours (the render loop develops spectra before the film).
FACET_EXPORT_PLUGIN_MODES(facet::@CLASS@, Sensor, "@NAME@",
                          "A sensor plugin (so far a pinhole camera)", DOC, ::facet::AllModes)
)CPP";

const char *SHAPE_TEMPLATE = R"CPP(static const char *DOC = R"DOC(
# @NAME@: a shape plugin (so far a square pyramid)

Describe the shape here. Until you change it this is a pyramid over the square [-1, 1]² of the
plane y = 0 with its apex at (0, `height`, 0), as 6 triangles whose normals point outwards,
placed by `to_world`.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| height | float | 1 | Height of the apex above the base (> 0) |
| flip_normals | boolean | false | Make the normals point inwards |
| to_world | transform | identity | Object-to-world transform |

```xml
<shape type="@NAME@">
    <float name="height" value="1.5"/>
    <bsdf type="diffuse"/>
</shape>
```
)DOC";

// Conventions (facet/mesh.h, facet/shape.h): a shape made of triangles derives from Mesh, fills
// m_positions (3 floats per vertex), m_faces (3 indices per triangle, counter-clockwise around
// the outward normal) and optionally m_normals and m_uvs, then calls initialize(), which checks
// the arrays, applies to_world and prepares sampling. Embree, area lights and instancing then work
// as for facet's own meshes. A shape that is not made of triangles derives from Shape and gives
// Embree a user geometry (facet/user_geometry.h).

#include <facet/logger.h>
#include <facet/mesh.h>
#include <facet/plugin.h>

#include <cmath>

namespace facet {

class @CLASS@ final : public Mesh {
public:
    explicit @CLASS@(const Properties &props) : Mesh(props) {
        // Read every parameter of the table, with its default; unread ones are reported.
        const double height = props.get_float("height", 1.0);
        if (!(height > 0.0) || !std::isfinite(height))
            FACET_THROW_AT(props.location("height"), "@NAME@: height must be positive, got {}",
                           height);
        const bool flip_normals = props.get_bool("flip_normals", false);
        const Transform to_world = props.get_transform("to_world", Transform());
        const float h = float(height);
        // The base corners 0..3, the apex 4 (no vertex normals: each face is flat).
        m_positions = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1, 0, h, 0};
        m_faces = {0, 1, 2, 0, 2, 3,                     // the base, facing down
                   0, 4, 1, 1, 4, 2, 2, 4, 3, 3, 4, 0}; // the sides
        initialize(to_world, /*face_normals=*/true, flip_normals);
    }
};

} // namespace facet

// Name = the XML type = the library's file name (@NAME@.so).
// Every mode: a shape has no colours.
FACET_EXPORT_PLUGIN_MODES(facet::@CLASS@, Shape, "@NAME@",
                          "A shape plugin (so far a square pyramid)", DOC, ::facet::AllModes)
)CPP";

/// One kind of plugin `facet new-plugin` can write.
struct Template {
    const char *kind;
    const char *source;
    const char *check; ///< the CMakeLists line of the chi2 command, if the kind has one
    // The scene's parts: the integrator, the sphere's and the floor's BSDF, the emitters, and
    // (for the kinds that take their place) the sensor, sampler and film types, more lines
    // inside the film (its rfilter) and one more shape.
    const char *integrator, *sphere_bsdf, *floor_bsdf, *emitter;
    const char *sensor = "perspective", *sampler = "independent", *film = "hdrfilm";
    const char *film_lines = "", *shape = "";
};

const Template TEMPLATES[] = {
    {"bsdf", BSDF_TEMPLATE,
     "#   facet chi2 bsdf @NAME@ -a build          # checks its sampling against its pdf\n",
     PATH_INTEGRATOR, R"(        <bsdf type="@NAME@">
            <rgb name="reflectance" value="0.6, 0.4, 0.2"/>
        </bsdf>)",
     DIFFUSE_BSDF, SKY},
    {"emitter", EMITTER_TEMPLATE,
     "#   facet chi2 emitter @NAME@ -a build       # checks its sampling against its pdf\n",
     PATH_INTEGRATOR, DIFFUSE_BSDF, DIFFUSE_BSDF, R"(    <emitter type="@NAME@">
        <rgb name="top" value="0.6, 0.7, 1.0"/>
        <rgb name="bottom" value="0.2, 0.15, 0.1"/>
    </emitter>)"},
    {"texture", TEXTURE_TEMPLATE, "", PATH_INTEGRATOR, R"(        <bsdf type="diffuse">
            <texture type="@NAME@" name="reflectance">
                <rgb name="color0" value="0.1, 0.1, 0.4"/>
                <rgb name="color1" value="0.9, 0.8, 0.2"/>
                <float name="scale" value="4"/>
            </texture>
        </bsdf>)",
     DIFFUSE_BSDF, SKY},
    {"integrator", INTEGRATOR_TEMPLATE, "", R"(    <integrator type="@NAME@">
        <integer name="shading_samples" value="4"/>
    </integrator>
)",
     DIFFUSE_BSDF, DIFFUSE_BSDF, SKY},
    {"shape", SHAPE_TEMPLATE, "", PATH_INTEGRATOR, DIFFUSE_BSDF, DIFFUSE_BSDF, SKY, "perspective",
     "independent", "hdrfilm", "", R"(
    <shape type="@NAME@">
        <float name="height" value="1.2"/>
        <transform name="to_world">
            <scale value="0.5"/>
            <translate x="1.3" z="-0.5"/>
        </transform>
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.7, 0.3, 0.2"/>
        </bsdf>
    </shape>
)"},
    {"sensor", SENSOR_TEMPLATE, "", PATH_INTEGRATOR, DIFFUSE_BSDF, DIFFUSE_BSDF, SKY, "@NAME@"},
    {"sampler", SAMPLER_TEMPLATE, "", PATH_INTEGRATOR, DIFFUSE_BSDF, DIFFUSE_BSDF, SKY,
     "perspective", "@NAME@"},
    {"film", FILM_TEMPLATE, "", PATH_INTEGRATOR, DIFFUSE_BSDF, DIFFUSE_BSDF, SKY, "perspective",
     "independent", "@NAME@", R"(            <float name="exposure" value="0.5"/>
)"},
    {"rfilter", RFILTER_TEMPLATE, "", PATH_INTEGRATOR, DIFFUSE_BSDF, DIFFUSE_BSDF, SKY,
     "perspective", "independent", "hdrfilm", R"(            <rfilter type="@NAME@"/>
)"},
};

std::string substitute(std::string text, const std::string &key, const std::string &value) {
    for (size_t at = text.find(key); at != std::string::npos;
         at = text.find(key, at + value.size()))
        text.replace(at, key.size(), value);
    return text;
}

/// "my_phong" -> "MyPhong".
std::string class_name(const std::string &name) {
    std::string out;
    bool upper = true;
    for (char c : name) {
        if (c == '_') {
            upper = true;
            continue;
        }
        out += upper ? char(std::toupper((unsigned char)c)) : c;
        upper = false;
    }
    return out;
}

void write_file(const fs::path &path, const std::string &text) {
    std::ofstream out(path);
    out << text;
    if (!out) FACET_THROW("cannot write \"{}\"", path.string());
}

} // namespace

int new_plugin_main(int argc, char **argv) {
    std::string kind, name, dir;
    bool force = false;
    std::string kinds;
    for (const Template &t : TEMPLATES) kinds += std::string(kinds.empty() ? "" : ", ") + t.kind;
    CLI::App app("Write a new plugin project that builds out of tree against the installed facet "
                 "(CMakeLists.txt, one .cpp with a working plugin to start from and a scene.xml "
                 "that uses it)",
                 "facet new-plugin");
    app.add_option("kind", kind, "Kind of plugin (" + kinds + ")")->required();
    app.add_option("name", name, "Plugin name: the XML type and the library file name")->required();
    app.add_option("dir", dir, "Folder to write (default: ./<name>)");
    app.add_flag("-f,--force", force, "Overwrite the files if they exist");
    if (int code = facet::cli::parse(app, argc, argv); code >= 0) return code;

    const Template *tpl = nullptr;
    for (const Template &t : TEMPLATES)
        if (kind == t.kind) tpl = &t;
    if (!tpl)
        FACET_THROW("facet new-plugin: no template for \"{}\" plugins (templates: {})", kind,
                    kinds);
    bool valid = !name.empty() && std::islower((unsigned char)name[0]);
    for (char c : name)
        valid =
            valid && (std::islower((unsigned char)c) || std::isdigit((unsigned char)c) || c == '_');
    if (!valid)
        FACET_THROW("plugin name \"{}\": use lower-case letters, digits and '_', starting with a "
                    "letter (it is the XML type and the file name)",
                    name);

    fs::path folder = dir.empty() ? fs::path(name) : fs::path(dir);
    fs::path cmake_file = folder / "CMakeLists.txt", source_file = folder / (name + ".cpp"),
             scene_file = folder / "scene.xml";
    for (const fs::path &p : {cmake_file, source_file, scene_file})
        if (fs::exists(p) && !force)
            FACET_THROW("\"{}\" exists (use --force to overwrite it)", p.string());
    fs::create_directories(folder);

    std::string cmake = substitute(CMAKE_TEMPLATE, "@CHECK_LINE@", tpl->check);
    cmake = substitute(substitute(cmake, "@KIND@", tpl->kind), "@NAME@", name);
    std::string source =
        substitute(substitute(tpl->source, "@NAME@", name), "@CLASS@", class_name(name));
    std::string scene = SCENE_TEMPLATE;
    scene = substitute(scene, "@INTEGRATOR@", tpl->integrator);
    scene = substitute(scene, "@SPHERE_BSDF@", tpl->sphere_bsdf);
    scene = substitute(scene, "@FLOOR_BSDF@", tpl->floor_bsdf);
    scene = substitute(scene, "@EMITTER@", tpl->emitter);
    scene = substitute(scene, "@SENSOR@", tpl->sensor);
    scene = substitute(scene, "@SAMPLER@", tpl->sampler);
    scene = substitute(scene, "@FILM@", tpl->film);
    scene = substitute(scene, "@FILM_LINES@", tpl->film_lines);
    scene = substitute(scene, "@SHAPE@", tpl->shape);
    scene = substitute(scene, "@NAME@", name);
    write_file(cmake_file, cmake);
    write_file(source_file, source);
    write_file(scene_file, scene);

    fmt::print("Wrote {}, {} and {}. Build and try it with:\n"
               "  cmake -S {} -B {}/build -DCMAKE_PREFIX_PATH=<facet's install prefix>\n"
               "  cmake --build {}/build\n"
               "  facet plugins {} -a {}/build\n"
               "  facet render {} -a {}/build\n",
               cmake_file.string(), source_file.string(), scene_file.string(), folder.string(),
               folder.string(), folder.string(), name, folder.string(), scene_file.string(),
               folder.string());
    if (std::string(tpl->kind) == "bsdf" || std::string(tpl->kind) == "emitter")
        fmt::print("  facet chi2 {} {} -a {}/build\n", tpl->kind, name, folder.string());
    return 0;
}
