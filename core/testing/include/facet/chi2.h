#pragma once

#include <facet/bsdf.h>
#include <facet/color.h>
#include <facet/emitter.h>
#include <facet/sensor.h>
#include <facet/vector.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

/**
 * Chi-square goodness-of-fit test of a sampling routine over the sphere of directions.
 *
 * The domain is parameterised by (φ, cos θ) ∈ [-π, π] × [-1, 1]; this map preserves area
 * (dω = dφ dcos θ), so the expected count of a cell is N times the pdf integrated over the cell in
 * these coordinates, with no Jacobian. `res` cells split cos θ and 2·res cells split φ.
 *
 * One run draws N samples (sample i uses a PCG32 seeded from tea_hash(i, seed), so any failure
 * reproduces), bins the directions, integrates the pdf over every cell (a fixed composite Simpson
 * rule on ires × ires points, or adaptive Simpson), pools cells expecting fewer than
 * `min_expected` samples, and compares Pearson's statistic with the chi-square distribution.
 * The significance level is Šidák-corrected for the number of tests run together.
 *
 * Outright failures, whatever the statistic says: a sample in a cell whose expected count is
 * zero, a non-finite or negative pdf, a non-finite weight, a sampled direction that is not a unit
 * vector. On the same samples the test also checks that each smooth sample's weight equals
 * eval/pdf and that its reported pdf equals pdf() (relative 1e-3; a fraction 1e-4 of the samples
 * may miss by float rounding, none by more than 5 %), that the pdf integrates to at
 * most one and to the fraction of samples that produced a smooth direction, and (for BSDFs) that
 * the mean weight does not exceed one beyond its statistical noise.
 */
namespace facet {

/// One draw of the routine under test, as the test sees it.
struct Chi2Sample {
    enum class Kind {
        Failed, ///< no direction (zero weight)
        Smooth, ///< a direction with a density: goes into the histogram
        Delta,  ///< a direction of a delta lobe: only its weight is checked
    };
    Kind kind = Kind::Failed;
    Vector3f d;              ///< sampled unit direction
    bool has_weight = false; ///< `weight` is meaningful (checked for finiteness, summed)
    bool has_value = false;  ///< `value` is meaningful: check weight == value / pdf
    Color3f weight;          ///< what the routine returned
    /// Factor that turns `weight` into the fraction of energy carried (η² for radiance-mode
    /// refraction, whose weight carries the 1/η² radiance scaling).
    float energy_scale = 1.f;
    Color3f value; ///< eval(d), for the weight == value / pdf check (Smooth)
    float sampled_pdf = std::numeric_limits<float>::quiet_NaN(); ///< density the routine reported
    float pdf = std::numeric_limits<float>::quiet_NaN();         ///< pdf(d) from the pdf function
    /// Set by an adapter that found its routine inconsistent (e.g. eval_pdf != (eval, pdf)).
    std::string problem;
};

/// What the test drives: a sampler of directions and the density of what it samples.
class Chi2Adapter {
public:
    virtual ~Chi2Adapter() = default;
    /// Uniform numbers one sample consumes (at most 8).
    virtual int sample_dim() const = 0;
    /// Draws one sample from the uniform numbers u[0 .. sample_dim()).
    virtual Chi2Sample sample(const float *u) const = 0;
    /// Solid-angle density of sample() at the unit direction d (zero for delta lobes).
    virtual double pdf(const Vector3f &d) const = 0;
    /// True when the mean of the weights may not exceed one (BSDFs: energy conservation).
    virtual bool bounded_weights() const { return false; }
    /// Azimuth (radians) the heat map puts at the centre of its panels, for display only (the
    /// statistics never depend on it): 0 by default, so the panels span φ = -π .. π.
    virtual double plot_phi_center() const { return 0.0; }
    virtual std::string to_string() const = 0;
};

struct Chi2Options {
    int res = 32;               ///< cos θ cells (made even); φ gets 2·res cells
    uint64_t samples = 1000000; ///< N
    uint32_t seed = 0;
    /// Adaptive Simpson (the default) or the fixed composite Simpson rule on ires × ires points.
    /// The fixed rule is cheaper per cell but misses lobes narrower than its spacing (α = 0.05
    /// near the normal, say), which then reads as a wrong pdf.
    bool adaptive = true;
    int ires = 7;                   ///< points per axis and cell of the fixed rule (made odd)
    double tolerance = 1e-5;        ///< relative tolerance of the adaptive rule
    int max_depth = 8;              ///< bisections per axis of the adaptive rule
    double min_expected = 5.0;      ///< cells expecting less are pooled
    double significance = 0.01;     ///< before the Šidák correction
    uint32_t test_count = 1;        ///< number of tests of the family (Šidák)
    double weight_tolerance = 1e-3; ///< relative, weight vs eval/pdf and sampled vs pdf()
    /// Float rounding allowance: up to this fraction of the samples may exceed weight_tolerance
    /// (rounding near singular configurations), but none may be off by more than gross_tolerance.
    double mismatch_fraction = 1e-4;
    double gross_tolerance = 0.05;
};

struct Chi2Result {
    bool passed = false;
    double statistic = 0.0;
    int dof = 0;
    double p_value = 0.0;
    double significance = 0.0; ///< after the Šidák correction
    /// Why the test failed (empty when it passed) and notes worth reading either way.
    std::vector<std::string> failures, notes;

    int phi_res = 0, cos_res = 0;
    /// Counts per cell, row-major: index = cos_bin · phi_res + phi_bin, cos θ = -1 in row 0.
    std::vector<double> observed, expected;

    uint64_t samples = 0, smooth = 0, delta = 0, failed = 0;
    double pdf_integral = 0.0; ///< ∫ pdf over the sphere
    Color3f mean_weight;       ///< energy-scaled, over all samples (failures count as 0)
    Color3f weight_stddev;
    uint64_t weight_mismatches = 0, pdf_mismatches = 0;
    double max_weight_error = 0.0, max_pdf_error = 0.0; ///< largest relative differences seen
    std::string description;                            ///< the adapter's to_string()
    double phi_center = 0.0; ///< the adapter's plot_phi_center(), for the heat map only

    /// Several lines: what was tested, the statistic, dof, p-value and the verdict.
    std::string summary() const;
};

/// Runs the whole test.
Chi2Result run_chi2(const Chi2Adapter &adapter, const Chi2Options &opts = {});

/// Writes observed | expected | difference side by side as a PNG, under a title (what was tested,
/// the statistic, dof, p-value and verdict), with axes (φ in degrees below the panels, θ in
/// degrees on the left and cos θ on the right: rows are uniform in cos θ, 1 at the top) and a
/// colour scale with values under each panel. The panels span 2π of φ centred on
/// result.phi_center (rounded to a cell edge; for BSDFs the mirror azimuth φ_i + π, so that a
/// reflection lobe is not split across the edges): a rotation of the columns for display only.
/// Counts on a logarithmic scale; difference = (o - e)/√e, red above and blue below expectation
/// (full colour at 5), near black where both are zero, green where samples fell into a cell
/// expecting none. Text uses a built-in bitmap font (ASCII; other characters show as '?').
void write_chi2_heatmap(const std::string &path, const Chi2Result &result);

/// Where write_chi2_heatmap() puts the panels, in pixels (for tests and for tools that crop).
struct Chi2HeatmapLayout {
    int width = 0, height = 0;
    int panel_x[3] = {0, 0, 0}; ///< left edges of the observed, expected, difference panels
    int panel_y = 0, panel_width = 0, panel_height = 0;
    int cell = 0; ///< pixels per side of one histogram cell
    /// Display column c of a panel shows histogram column (c + column_shift) mod phi_res.
    int column_shift = 0;
    int title_lines = 0; ///< lines of text above the panel captions
    int bar_y = 0;       ///< top of the colour scales
};
Chi2HeatmapLayout chi2_heatmap_layout(const Chi2Result &result);
/// Writes the observed and expected tables as text (one line per cell).
void write_chi2_tables(const std::string &path, const Chi2Result &result);

// -- The statistics, exposed for tests ------------------------------------------------------------

/// Regularised lower incomplete gamma function P(a, x) (series or continued fraction).
double regularized_gamma_p(double a, double x);
/// Q(a, x) = 1 - P(a, x), computed without cancellation.
double regularized_gamma_q(double a, double x);
/// P(X ≥ x) for X chi-square distributed with `dof` degrees of freedom.
double chi2_survival(double x, double dof);
/// Per-test level that keeps the family-wise level at `alpha` over `test_count` tests.
double sidak_correction(double alpha, uint32_t test_count);

struct PearsonResult {
    double statistic = 0.0;
    int dof = 0;                    ///< number of terms - 1
    int pooled_cells = 0;           ///< cells that went into pools
    bool zero_expected_hit = false; ///< a cell expecting nothing received samples
    size_t zero_expected_cell = 0;
};
/// Pearson's statistic after sorting cells by expected count and pooling those expecting less
/// than `min_expected`: a pool becomes one term once it reaches min_expected, and a last pool that
/// never does joins the smallest cell above the threshold (or is a term of its own when there is
/// none). Cells expecting zero are skipped; samples in them set `zero_expected_hit`.
PearsonResult pearson_chi2(const std::vector<double> &observed, const std::vector<double> &expected,
                           double min_expected = 5.0);

// -- Adapters -------------------------------------------------------------------------------------

/// XML text of one object: `<kind version="3.0.0" type="plugin"> entries children </kind>`.
/// Each entry is `key=value` with the type inferred (a number: float, true/false: boolean,
/// "r,g,b": rgb, anything else: string) or `type:key=value` with the tag given
/// (float, integer, boolean, string, rgb, spectrum, vector, point).
std::string chi2_object_xml(ObjectType kind, const std::string &plugin,
                            const std::vector<std::string> &entries,
                            const std::string &children = "", bool with_version = true);

/// A BSDF seen from the incident direction wi (local frame), in context ctx.
class BSDFAdapter : public Chi2Adapter {
public:
    BSDFAdapter(std::shared_ptr<BSDF> bsdf, const Vector3f &wi, const BSDFContext &ctx = {});
    /// Creates the plugin from properties through the registry.
    BSDFAdapter(const Properties &props, const Vector3f &wi, const BSDFContext &ctx = {});
    /// Loads `<bsdf version="3.0.0" type="...">...</bsdf>` with load_string, in colour mode
    /// `mode` (LoadOptions::mode: empty is the default).
    BSDFAdapter(const std::string &xml, const Vector3f &wi, const BSDFContext &ctx = {},
                const std::string &mode = "");

    int sample_dim() const override { return 3; }
    Chi2Sample sample(const float *u) const override;
    double pdf(const Vector3f &d) const override;
    bool bounded_weights() const override { return true; }
    /// The mirror azimuth φ_i + π, where reflection lobes peak.
    double plot_phi_center() const override;
    std::string to_string() const override;
    const BSDF &bsdf() const { return *m_bsdf; }

private:
    void init();
    std::shared_ptr<BSDF> m_bsdf;
    BSDFContext m_ctx;
    SurfaceInteraction m_si;
};

/// An emitter's direction sampling seen from a reference point. The emitter lives in a small
/// scene (so infinite emitters know the scene bounds and area emitters have their shape);
/// pdf() of a direction traces a ray in that scene to find the point it reaches.
class EmitterAdapter : public Chi2Adapter {
public:
    /// `scene_xml` is a whole <scene> with at least one emitter; `index` picks it. The scene is
    /// loaded in colour mode `mode` (LoadOptions::mode: empty is the default).
    EmitterAdapter(const std::string &scene_xml, const Point3f &ref, size_t index = 0,
                   const std::string &mode = "");
    EmitterAdapter(std::shared_ptr<Scene> scene, std::shared_ptr<Emitter> emitter,
                   const Point3f &ref);
    ~EmitterAdapter() override;

    /// The scene for plugin `plugin` with `entries` (see chi2_object_xml): an `area` emitter is
    /// put on a shape of type `shape` (a 2×2 rectangle at z = 0 facing +z by default).
    static std::string scene_xml(const std::string &plugin, const std::vector<std::string> &entries,
                                 const std::string &shape = "rectangle");

    /// Which of the emitter's samplings to test: sample_direction() and pdf_direction()
    /// (LightSampling::Alone, the default) or sample_direction_mis() and pdf_direction_mis().
    void set_light_sampling(LightSampling sampling) { m_sampling = sampling; }
    /// The side given to sample_direction_mis() and pdf_direction_mis() (zero: none; normalised
    /// here).
    void set_side(const Vector3f &side) {
        m_side = dot(side, side) > 0.f ? normalize(side) : Vector3f(0.f);
    }

    int sample_dim() const override { return 2; }
    Chi2Sample sample(const float *u) const override;
    double pdf(const Vector3f &d) const override;
    std::string to_string() const override;

private:
    void init();
    float emitter_pdf(const DirectionSample &ds) const;
    std::shared_ptr<Scene> m_scene;
    std::shared_ptr<Emitter> m_emitter;
    Interaction m_ref;
    LightSampling m_sampling = LightSampling::Alone;
    Vector3f m_side = Vector3f(0.f);
};

/// The directions of an emitter's emitted rays (sample_ray()) against pdf_ray_direction(), for
/// emitters with one origin (point-like lights such as spot): what a light tracer draws.
class EmissionAdapter : public Chi2Adapter {
public:
    /// `scene_xml` is a whole <scene> with at least one emitter; `index` picks it; `mode` as for
    /// EmitterAdapter.
    explicit EmissionAdapter(const std::string &scene_xml, size_t index = 0,
                             const std::string &mode = "");
    explicit EmissionAdapter(std::shared_ptr<Emitter> emitter);

    int sample_dim() const override { return 2; }
    Chi2Sample sample(const float *u) const override;
    double pdf(const Vector3f &d) const override;
    std::string to_string() const override;

private:
    std::shared_ptr<Scene> m_scene;
    std::shared_ptr<Emitter> m_emitter;
};

/// A sensor's importance as the light tracer uses it (sample_direction(), pdf_direction()).
///
/// Camera rays (the first constructor): the directions of sample_ray() for uniform film
/// positions and one fixed aperture sample, so that every ray leaves the same lens point,
/// against the density that sample_direction()'s weight implies there. The weight is the
/// importance towards a point with the 1/dist² of the connection, and for a light path to
/// estimate what camera rays estimate it must equal the camera rays' solid-angle density over
/// dist²: pdf(d) = weight · dist² for the point at distance dist along d. For a sensor whose rays
/// are parallel (orthographic) the rays' origins on the film plane are seen from a point behind
/// the film instead, and the weight (the importance per unit film area) times dist²/cos is
/// their density. Each sample also checks that sample_direction() finds the film position the
/// ray was traced through.
///
/// From a reference point (the second constructor): the aperture points that sample_direction()
/// draws, seen from `ref`, against pdf_direction() (the thin lens; a pinhole or orthographic
/// sensor is a delta seen from a point and has no density to test). The aperture is taken to lie
/// in the camera's local z = 0 plane, and `ref` should be seen from every aperture point (on the
/// plane in focus, say): a sample that misses the film fails and breaks the pdf's integral check.
class SensorAdapter : public Chi2Adapter {
public:
    explicit SensorAdapter(std::shared_ptr<Sensor> sensor,
                           const Point2f &aperture_sample = Point2f(0.5f, 0.5f));
    SensorAdapter(std::shared_ptr<Sensor> sensor, const Point3f &ref);

    /// Loads `<sensor version="3.0.0" type="...">...</sensor>` (or the first sensor of a
    /// `<scene>`) with load_string.
    static std::shared_ptr<Sensor> load(const std::string &xml);
    /// The XML text of sensor `plugin` with `entries` (see chi2_object_xml) and an hdrfilm of
    /// `film_size` pixels (the plugin's default film when either is zero).
    static std::string sensor_xml(const std::string &plugin,
                                  const std::vector<std::string> &entries,
                                  const Point2i &film_size = Point2i(0, 0));

    int sample_dim() const override { return 2; }
    Chi2Sample sample(const float *u) const override;
    double pdf(const Vector3f &d) const override;
    std::string to_string() const override;

private:
    enum class Mode { RayDirections, RayOrigins, Aperture };
    /// The importance weight towards world point p (aperture sample m_aperture) and the record.
    std::pair<DirectionSample, float> importance(const Point3f &p) const;
    /// "" when sample_direction() towards a point on the ray finds film position `film`.
    std::string check_round_trip(const Point3f &p, const Point2f &film) const;
    std::shared_ptr<Sensor> m_sensor;
    Mode m_mode;
    Point2f m_aperture;
    Point3f m_ref;      ///< Aperture: the reference point
    Point3f m_origin;   ///< RayDirections: the rays' origin; RayOrigins: the film centre
    Point3f m_view;     ///< RayOrigins: the point behind the film the origins are seen from
    Vector3f m_dir;     ///< RayOrigins: the rays' direction
    float m_dist = 1.f; ///< distance along a ray of the point importance is evaluated at
    Transform m_world_to_local;
};

/// A microfacet distribution's normal sampling (facet/microfacet.h) for incident direction wi.
class MicrofacetAdapter : public Chi2Adapter {
public:
    /// `type` is "beckmann" or "ggx".
    MicrofacetAdapter(const std::string &type, float alpha_u, float alpha_v, bool sample_visible,
                      const Vector3f &wi);
    ~MicrofacetAdapter() override;

    int sample_dim() const override { return 2; }
    Chi2Sample sample(const float *u) const override;
    double pdf(const Vector3f &d) const override;
    /// φ_i: visible normals lean towards the incident direction.
    double plot_phi_center() const override;
    std::string to_string() const override;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

/// Direction at polar angle θ and azimuth φ (degrees) in the local frame.
Vector3f direction_from_angles(float theta_deg, float phi_deg);

} // namespace facet
