#pragma once

#include <facet/bbox.h>
#include <facet/color.h>
#include <facet/distribution.h>
#include <facet/emitter.h>
#include <facet/interaction.h>
#include <facet/object.h>
#include <facet/properties.h>

#include <embree3/rtcore.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace facet {

/// A sensor that needs the finished scene (its bounds), such as `distant`: the scene calls
/// set_scene() once it is built, as it does for emitters.
class SceneSensor {
public:
    virtual ~SceneSensor();
    virtual void set_scene(const Scene &scene) = 0;
};

struct SceneDescription;
namespace detail {
class SceneQueries;
class LightBVH;
class LightGuide;
} // namespace detail

/// The scene: shapes in one Embree scene, emitters, sensors and the integrator.
/// Immutable while it renders; every query is thread-safe. Only traverse() (facet/params.h)
/// changes a built scene, between renders.
class Scene : public Object {
public:
    /// Collects the children of a <scene> and builds the Embree scene. Missing pieces get
    /// Mitsuba's defaults (a perspective sensor, the path integrator, diffuse BSDFs).
    explicit Scene(const Properties &props);
    ~Scene() override;
    ObjectType type() const override { return ObjectType::Scene; }

    /// Closest hit: fills si and returns true. On a miss returns false and makes si the record
    /// of a ray that left the scene (escaped()), which environment emitters' eval() reads.
    bool ray_intersect(const Ray &ray, SurfaceInteraction &si) const;
    /// ray_intersect() for `count` rays (1 to PacketSize) at once, as one Embree packet: rays
    /// that travel together (the camera rays of neighbouring pixels) cost a fraction of their
    /// separate queries. hits[k] and sis[k] are what ray_intersect(rays[k], sis[k]) gives,
    /// except that Embree's packet arithmetic may settle a ray that grazes the edge between two
    /// triangles the other way (rarely: 6 of 57,600 camera rays of a staircase scene, in packets
    /// of 4x2 pixels). The answers can depend on the packet's other rays: the same rays in the
    /// same lanes give the same answers.
    static constexpr int PacketSize = 8;
    void ray_intersect_packet(const Ray *rays, int count, SurfaceInteraction *sis,
                              bool *hits) const;
    /// The record of a ray that left the scene, the one route to the environment emitters: t =
    /// Infinity, no shape, p = the ray's origin, the identity shading frame and wi = -ray.d in it
    /// (local, like every wi; the world direction towards the origin is si.to_world(si.wi)), and
    /// the ray's wavelengths.
    static void escaped(const Ray &ray, SurfaceInteraction &si);
    /// Any hit in [ray.mint, ray.maxt] (rtcOccluded1).
    bool ray_test(const Ray &ray) const;
    /// Picks an emitter (sample_emitter()) and samples a direction to it from ref. The weight
    /// includes the selection probability; with `test_visibility` an occluded sample gets weight
    /// zero. Once prepare_light_sampling() has run, a point where the scene's survey found few
    /// light samples useful takes one only with a probability q below 1 (else: no sample, pdf
    /// 0); the weight is divided by q and the density multiplied by it, as in
    /// pdf_emitter_direction(), so estimates keep their expectation. `sampling` says how the
    /// caller uses the sample (LightSampling: alone, or weighted by MIS against BSDF samples with
    /// the densities of pdf_emitter_direction() in the same mode); emitters may sample
    /// differently for each (Emitter::sample_direction_mis()). `side` (the MIS mode only): zero,
    /// or a unit vector such that no light counts from directions d with dot(d, side) <= 0 (a
    /// BSDF with BSDFFlags::WiSideOnly), which emitters may then leave unsampled; the densities
    /// of pdf_emitter_direction() must be asked with the same side.
    std::pair<DirectionSample, Color3f>
    sample_emitter_direction(const Interaction &ref, Point2f u, bool test_visibility,
                             LightSampling sampling, const Vector3f &side = Vector3f(0.f)) const;
    /// The visibility test of sample_emitter_direction() on its own: true when nothing blocks
    /// the segment from ref to the emitter sample ds (or the ray towards it, for an emitter at
    /// infinity). For callers that test later, once the BSDF has given the sample a weight.
    bool emitter_visible(const Interaction &ref, const DirectionSample &ds) const;
    /// Density of sample_emitter_direction() in the mode `sampling` for ds (selection
    /// probability and q included).
    float pdf_emitter_direction(const Interaction &ref, const DirectionSample &ds,
                                LightSampling sampling, const Vector3f &side = Vector3f(0.f)) const;
    /// Surveys, once per scene (and again after rebuild()), where light samples are worth
    /// taking: a few thousand paths from the scene's sensors, a light sample at each vertex,
    /// counted per cell of a grid over the scene as useful (the emitter gives light, the BSDF
    /// reflects it, nothing blocks it) or not. Sets sample_emitter_direction()'s q per cell
    /// (1 where at least a quarter were useful, in proportion below that, at least 0.1) and,
    /// for scenes of 2 to 32 emitters without sampling weights, the choice of emitters per
    /// cell of a coarser grid (sample_emitter()). The
    /// result depends on the scene alone, never on a render's threads, seed or split. Renders
    /// call it; the scene option `light_guide` false (a facet extension) turns it off.
    void prepare_light_sampling() const;
    /// sample_emitter_direction()'s probability of a light sample at p: 1 until
    /// prepare_light_sampling() has run, and wherever the survey found them worth it.
    float light_sample_probability(const Point3f &p) const;
    /// Picks the emitter of a light sample for the point `ref` (sample_emitter_direction()'s
    /// choice, before its q). Where the scene gives emitters a `sampling_weight`: in proportion to
    /// it (1 for the others), as Mitsuba 3 does, whatever the point. Otherwise the emitters with
    /// light_bounds() (eight or more) share the samples the uniform choice would give them
    /// through the light hierarchy, in proportion to a bound of their importance at ref.p
    /// (power, distance, orientation, ref.n); the others keep their uniform share. Once
    /// prepare_light_sampling() has run (scenes without weights, 2 to 32 emitters), half of the
    /// picks follow that rule and half what the survey learned near ref (the emitters at
    /// infinity keep their share; the others in proportion to the root mean square of the light
    /// their samples brought there), and the probability is that mixture's. Returns the
    /// emitter and the probability it had (null and 0 when none can reach ref); `u` becomes a
    /// fresh uniform variate for the emitter's own sample.
    std::pair<const Emitter *, float> sample_emitter(const Interaction &ref, float &u) const;
    /// The probability that sample_emitter(ref, ...) picks `emitter` (0 for one not in the
    /// scene).
    float emitter_pmf(const Interaction &ref, const Emitter &emitter) const;
    /// The choice without a point (light tracing): by `sampling_weight` as above, else the
    /// emitters at infinity keep their uniform share and the others share the rest half in
    /// proportion to their power() and half uniformly (all uniformly when a power is unknown).
    std::pair<const Emitter *, float> sample_emitter(float &u) const;
    /// The probability that sample_emitter(u) picks `emitter` (0 for one not in the scene).
    float emitter_pmf(const Emitter &emitter) const;

    const std::vector<std::shared_ptr<Shape>> &shapes() const { return m_shapes; }
    const std::vector<std::shared_ptr<Emitter>> &emitters() const { return m_emitters; }
    /// The infinite emitters, the ones a ray that left the scene sees (facet/mis.h).
    const std::vector<std::shared_ptr<Emitter>> &environment_emitters() const {
        return m_environment;
    }
    const std::vector<std::shared_ptr<Sensor>> &sensors() const { return m_sensors; }
    std::shared_ptr<Integrator> integrator() const { return m_integrator; }
    const BoundingBox3f &bbox() const { return m_bbox; }
    /// Seconds the acceleration structure (the Embree scene) took to build.
    double accel_build_seconds() const { return m_accel_seconds; }
    RTCDevice embree_device() const { return m_device; }
    /// The scene option `embree_two_level` (default false): the Embree scene holds a structure
    /// per geometry and one over them, so that an edit of a shape rebuilds its structure alone
    /// (rebuild()). Renders take up to 3% more time than with the one-level structure.
    bool two_level() const { return m_two_level; }
    /// The scene option `embree_use_robust_intersections` (default false, as in Mitsuba 3):
    /// Embree's robust (watertight) triangle test instead of its fast one.
    bool robust_intersections() const { return m_robust; }
    /// The colour mode the scene's objects were built for (LoadOptions::mode); a render of the
    /// scene renders in it.
    ColourMode mode() const { return m_mode; }
    std::string to_string() const override;

    /// The object descriptions the loader built the scene from (for traverse()); null for a
    /// scene built otherwise.
    const std::shared_ptr<SceneDescription> &description() const { return m_description; }
    void set_description(std::shared_ptr<SceneDescription> d) { m_description = std::move(d); }

    /// Held by every render of the scene (facet::render takes one): while any is alive, rebuild()
    /// refuses to run, and while rebuild() runs, taking one fails. Both are clear errors.
    class RenderLock {
    public:
        explicit RenderLock(const Scene &scene);
        ~RenderLock();
        RenderLock(const RenderLock &) = delete;
        RenderLock &operator=(const RenderLock &) = delete;

    private:
        const Scene &m_scene;
    };

    /// Rebuilds the scene in place from the children in `props` (the same properties as the
    /// constructor's; unchanged objects are the same pointers). The Embree scene is kept when the
    /// shapes are the same objects in the same order. In a two-level scene (two_level()), shapes
    /// that are new objects in the places of old ones (an edited transform) have their
    /// structures built again, and the top level; the others keep theirs. Otherwise the Embree
    /// scene is built again. On an error the scene is left as it was.
    /// Fails when a render of the scene is running. Returns how many geometries had their
    /// acceleration structure built (0: the Embree scene was kept).
    size_t rebuild(const Properties &props);

private:
    friend class detail::SceneQueries; ///< `facet bench`'s replay of Embree queries (private)

    Scene() = default;
    /// The constructor's body; with `previous`, takes over its Embree scene when the shapes
    /// are the same, or replaces the geometries of the shapes that changed places in it.
    void build(const Properties &props, Scene *previous);
    /// build()'s Embree part when some shapes of `previous` were replaced one for one; false
    /// (nothing changed) when the shape lists do not allow it.
    bool replace_geometries(Scene &previous);
    /// ray_test()'s body, inlined into the shadow ray of sample_emitter_direction().
    bool occluded(const Ray &ray) const;
    /// The record of Embree's hit of `ray` (at distance t, geometry `geom`, primitive `prim`,
    /// instance `inst`, barycentrics uv) in si: ray_intersect()'s, and its packet's, last step.
    void complete_hit(const Ray &ray, float t, unsigned geom, unsigned prim, unsigned inst,
                      const Point2f &uv, SurfaceInteraction &si) const;

    std::vector<std::shared_ptr<Shape>> m_shapes;
    std::vector<std::shared_ptr<Emitter>> m_emitters;
    std::vector<std::shared_ptr<Emitter>> m_environment;
    std::vector<std::shared_ptr<Sensor>> m_sensors;
    std::shared_ptr<Integrator> m_integrator;
    /// One entry per emitter of m_emitters, in the same order: for an emitter with a
    /// constant_radiance() on a mesh, that radiance and the mesh's area density (without this
    /// table the real-scene bench ran 5.4% slower on its 13-light scene); on another shape,
    /// that radiance and the shape (Veach's four sphere lights: 3.1% slower without it).
    struct EmitterEntry {
        const Emitter *emitter = nullptr;
        const Mesh *mesh = nullptr; ///< set for a triangle light
        /// Set for another shape's light of constant radiance: sampled through the shape's own
        /// sample_direction() (constant_radiance()'s promise), without the emitter's call.
        const Shape *shape = nullptr;
        Color3f radiance;          ///< of a triangle light or a shape's constant light
        float inv_area = 0.f;      ///< of a triangle light: its area density
        float pmf = 0.f;           ///< the probability that sample_emitter(u) picks it
        bool in_hierarchy = false; ///< in m_light_bvh
    };
    std::vector<EmitterEntry> m_emitter_table;
    /// The emitters' selection (sample_emitter()): uniform, or by m_emitter_distr.
    bool m_emitter_uniform = true;
    DiscreteDistribution m_emitter_distr;
    /// The choice for a point: the light hierarchy, which gets m_hierarchy_share of the
    /// samples, and the emitters outside it, each with probability m_outside_pmf. Null: the
    /// choice without a point serves for every point.
    std::unique_ptr<detail::LightBVH> m_light_bvh;
    float m_hierarchy_share = 0.f, m_outside_pmf = 0.f;
    std::vector<uint32_t> m_outside_hierarchy;
    /// The scene gives emitters a `sampling_weight`: its choice is kept everywhere (the light
    /// guide learns none).
    bool m_emitter_weights_given = false;
    /// Sets the entries' pmf, the distribution and the hierarchy once the emitters know the
    /// scene: build_light_hierarchy() (unless the scene gives sampling weights) and
    /// build_emitter_distribution().
    void build_emitter_selection();
    void build_light_hierarchy();
    void build_emitter_distribution(bool weights_given);
    /// The emitter (its index) for a light sample from `ref` (null: the choice without a point)
    /// and its probability (0: none).
    std::pair<size_t, float> pick_emitter(const Interaction *ref, float &u) const;
    float pick_pmf(const Interaction *ref, size_t index) const;
    /// pick_emitter() and pick_pmf() without the light guide's learned choice.
    std::pair<size_t, float> own_pick(const Interaction *ref, float &u) const;
    float own_pmf(const Interaction *ref, size_t index) const;
    /// The selection keeps the uniform choice's arithmetic (no distribution, hierarchy or
    /// learned choice).
    bool uniform_selection() const;
    /// The solid-angle density of emitter `entry`'s own sample for ds seen from ref (without
    /// the selection): computed inline for triangle lights and shapes' constant lights.
    float light_pdf(const EmitterEntry &entry, const Interaction &ref, const DirectionSample &ds,
                    const Vector3f &side, LightSampling sampling) const;
    /// Per Embree geometry id: its shape, and the same shape as a Mesh when the scene computes
    /// the hits on it itself (without this the real-scene bench ran matpreview 2.2% to 8.1%
    /// slower in three of four paired measurements).
    struct GeometryEntry {
        const Shape *shape = nullptr;
        const Mesh *flat_mesh = nullptr;
    };
    std::vector<GeometryEntry> m_geometries;
    BoundingBox3f m_bbox;
    double m_accel_seconds = 0.0;
    RTCDevice m_device = nullptr;
    RTCScene m_rtc_scene = nullptr;
    bool m_robust = false;
    std::shared_ptr<SceneDescription> m_description;
    /// Renders running (> 0), or -1 while rebuild() runs.
    mutable std::atomic<int> m_renders{0};
    /// Set by build(): geometries whose acceleration structure was built (0: the Embree
    /// scene came from `previous` as it was).
    size_t m_geometries_built = 0;
    bool m_two_level = false; ///< the scene option `embree_two_level`
    ColourMode m_mode = ColourMode::RGB;
    /// The light-sample guide (prepare_light_sampling()): null until it has run, or when it
    /// found every cell worth a light sample at every vertex. Set before any render's threads
    /// start, read by them.
    mutable std::unique_ptr<detail::LightGuide> m_light_guide;
    mutable bool m_light_guide_ready = false;
    mutable std::mutex m_light_guide_mutex;
    bool m_light_guide_enabled = true; ///< the scene option `light_guide`
    /// pdf_emitter_direction() before the guide's q.
    float unguided_emitter_pdf(const Interaction &ref, const DirectionSample &ds,
                               const Vector3f &side, LightSampling sampling) const;
    /// prepare_light_sampling()'s survey into `guide`.
    void survey_light_samples(detail::LightGuide &guide) const;
};

/// Embree device shared by all scenes of the process; `threads` = 0 lets Embree decide.
/// The first call fixes the configuration.
RTCDevice embree_device(int threads = 0);

} // namespace facet
