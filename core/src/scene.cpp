#include "light_bvh.h"
#include "light_guide.h"
#include "mesh_inline.h"
#include "scene_queries.h"
#include "stats.h"

#include <facet/assert.h>
#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/integrator.h>
#include <facet/logger.h>
#include <facet/mesh.h>
#include <facet/mis.h>
#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/shape.h>
#include <facet/shapegroup.h>
#include <facet/spectrum.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <mutex>
#include <new>
#include <pmmintrin.h>
#include <type_traits>
#include <vector>
#include <xmmintrin.h>

namespace facet {

SceneSensor::~SceneSensor() = default;

namespace {

/// Rays traced, for `facet bench`: every ray_intersect() and ray_test() call, the ones Embree
/// cannot trace included.
const stats::Counter g_intersect_calls("scene.ray_intersect");
const stats::Counter g_test_calls("scene.ray_test");

/// What sees the queries sent to Embree (SceneQueries::set_observer()), null when nothing does:
/// a load that stays in the cache and a branch the predictor always gets right.
std::atomic<detail::RayQueryObserver *> g_query_observer{nullptr};

/// Shows a query Embree has answered to the observer. Out of line: only a recording render
/// comes here.
__attribute__((noinline)) void observe_query(detail::RayQueryObserver &observer, const Ray &ray,
                                             bool occlusion, bool hit) {
    observer.observe({{ray.o.x, ray.o.y, ray.o.z, ray.d.x, ray.d.y, ray.d.z, ray.mint, ray.maxt},
                      occlusion,
                      hit});
}

const char *embree_error_name(RTCError code) {
    switch (code) {
    case RTC_ERROR_NONE:
        return "no error";
    case RTC_ERROR_UNKNOWN:
        return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT:
        return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
        return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
        return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
        return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
        return "cancelled";
    }
    return "unknown error";
}

void embree_error_callback(void *, RTCError code, const char *str) {
    FACET_LOG(Error, "Embree: {}: {}", embree_error_name(code), str ? str : "");
}

/// Embree's own precondition on rays (it asserts it and aborts): origin and direction below
/// 1.8e18 in magnitude (so not NaN), tnear and tfar not NaN. Scenes are validated so that their
/// rays meet it; this catches what a plugin computes from bad data (a NaN normal, say).
/// `a` and `b` are the ray's first eight floats (ray_words()): o, d, mint and maxt.
inline bool embree_can_trace(__m128 a, __m128 b) {
    constexpr float Large = 1.8e18f;
    const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    // |x| <= limit is false for NaN; the limit of mint and maxt is infinity (only NaN fails).
    const __m128 ok_a = _mm_cmple_ps(_mm_and_ps(a, abs_mask), _mm_set1_ps(Large));
    const __m128 ok_b =
        _mm_cmple_ps(_mm_and_ps(b, abs_mask), _mm_setr_ps(Large, Large, Infinity, Infinity));
    return _mm_movemask_ps(_mm_and_ps(ok_a, ok_b)) == 0xF;
}

/// The first eight floats of `ray`, (o.x, o.y, o.z, d.x) and (d.y, d.z, mint, maxt), in two
/// registers: the check and the Embree ray are built from them. Read float by float: the ray
/// was just written float by float (or is still in registers), and a 16-byte load of four
/// separate 4-byte stores cannot be forwarded from the store buffer; it would wait for them to
/// reach the cache, on the critical path of every ray.
inline void ray_words(const Ray &ray, __m128 &a, __m128 &b) {
    a = _mm_setr_ps(ray.o.x, ray.o.y, ray.o.z, ray.d.x);
    b = _mm_setr_ps(ray.d.y, ray.d.z, ray.mint, ray.maxt);
}

/// Fills the ray part of an Embree ray (RTCRay, the first part of RTCRayHit) from ray_words():
/// origin, tnear = mint, direction, time 0, tfar = maxt, all mask bits, id and flags 0.
inline void set_embree_ray(__m128 a, __m128 b, RTCRay &r) {
    static_assert(offsetof(RTCRay, tnear) == 12 && offsetof(RTCRay, time) == 28 &&
                      offsetof(RTCRay, tfar) == 32 && offsetof(RTCRay, flags) == 44 &&
                      alignof(RTCRay) >= 16,
                  "RTCRay: three rows of four words");
    float *out = &r.org_x;
    // Row 0: o.x, o.y, o.z, mint.
    const __m128 z = _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 2, 2, 2)); // o.z o.z mint mint
    _mm_store_ps(out, _mm_shuffle_ps(a, z, _MM_SHUFFLE(2, 0, 1, 0)));
    // Row 1: d.x, d.y, d.z, time = 0.
    const __m128 d = _mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 0, 3, 3)); // d.x d.x d.y d.z
    const __m128 keep3 = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
    _mm_store_ps(out + 4, _mm_and_ps(_mm_shuffle_ps(d, d, _MM_SHUFFLE(3, 3, 2, 0)), keep3));
    // Row 2: tfar = maxt, mask = all bits (the Debian build has ray masks on: any other value
    // can miss), id = 0, flags = 0.
    const __m128 row2 = _mm_castsi128_ps(_mm_setr_epi32(0, -1, 0, 0));
    _mm_store_ps(out + 8, _mm_move_ss(row2, _mm_shuffle_ps(b, b, _MM_SHUFFLE(3, 3, 3, 3))));
}
/// The closest-hit query of ray_intersect(), and of SceneQueries::resend().
inline void embree_intersect(RTCScene scene, __m128 a, __m128 b, RTCRayHit &rh) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    set_embree_ray(a, b, rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
}

/// The any-hit query of occluded(), and of SceneQueries::resend(): true when something blocks
/// the ray.
inline bool embree_occluded(RTCScene scene, __m128 a, __m128 b) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay r;
    set_embree_ray(a, b, r);
    rtcOccluded1(scene, &context, &r);
    // Embree sets tfar to -inf when something was hit.
    return r.tfar == -Infinity;
}

std::string object_label(const Object &obj) {
    return obj.id().empty() ? obj.to_string() : "\"" + obj.id() + "\"";
}

} // namespace

RTCDevice embree_device(int threads) {
    static RTCDevice device = nullptr;
    static std::once_flag once;
    std::call_once(once, [threads] {
        std::string config = threads > 0 ? fmt::format("threads={}", threads) : std::string();
        device = rtcNewDevice(config.empty() ? nullptr : config.c_str());
        if (!device)
            FACET_THROW("could not create the Embree device: {}",
                        embree_error_name(rtcGetDeviceError(nullptr)));
        rtcSetDeviceErrorFunction(device, embree_error_callback, nullptr);
    });
    if (!device) FACET_THROW("the Embree device is not available");
    return device;
}

Scene::Scene(const Properties &props) { build(props, nullptr); }

Scene::RenderLock::RenderLock(const Scene &scene) : m_scene(scene) {
    int n = scene.m_renders.load();
    do {
        if (n < 0) FACET_THROW("the scene is being updated: render it once update() has returned");
    } while (!scene.m_renders.compare_exchange_weak(n, n + 1));
}

Scene::RenderLock::~RenderLock() { m_scene.m_renders.fetch_sub(1); }

size_t Scene::rebuild(const Properties &props) {
    int idle = 0;
    if (!m_renders.compare_exchange_strong(idle, -1)) {
        if (idle < 0) FACET_THROW("cannot update the scene: another update of it is running");
        FACET_THROW("cannot update the scene while a render of it is running: update it "
                    "between renders");
    }
    struct Release {
        std::atomic<int> &state;
        ~Release() { state.store(0); }
    } release{m_renders};
    Scene next;
    next.build(props, this);
    // Everything that can fail has run: the new state becomes this scene's.
    std::swap(m_shapes, next.m_shapes);
    std::swap(m_emitters, next.m_emitters);
    std::swap(m_environment, next.m_environment);
    std::swap(m_sensors, next.m_sensors);
    std::swap(m_integrator, next.m_integrator);
    std::swap(m_emitter_table, next.m_emitter_table);
    std::swap(m_emitter_uniform, next.m_emitter_uniform);
    std::swap(m_emitter_distr, next.m_emitter_distr);
    std::swap(m_light_bvh, next.m_light_bvh);
    std::swap(m_hierarchy_share, next.m_hierarchy_share);
    std::swap(m_emitter_weights_given, next.m_emitter_weights_given);
    std::swap(m_outside_pmf, next.m_outside_pmf);
    std::swap(m_outside_hierarchy, next.m_outside_hierarchy);
    std::swap(m_geometries, next.m_geometries);
    std::swap(m_bbox, next.m_bbox);
    std::swap(m_accel_seconds, next.m_accel_seconds);
    std::swap(m_device, next.m_device);
    std::swap(m_rtc_scene, next.m_rtc_scene); // `next` releases the old one (or null)
    std::swap(m_robust, next.m_robust);
    std::swap(m_two_level, next.m_two_level);
    std::swap(m_mode, next.m_mode);
    std::swap(m_light_guide_enabled, next.m_light_guide_enabled);
    // The guide surveyed the old scene: the next render surveys this one.
    m_light_guide.reset();
    m_light_guide_ready = false;
    return next.m_geometries_built;
}

void Scene::build(const Properties &props, Scene *previous) {
    // Embree asks every thread that builds or traces to flush denormals; the caller's mode is
    // restored afterwards (render threads set their own).
    struct FlushDenormals {
        unsigned csr = _mm_getcsr();
        FlushDenormals() {
            _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
            _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
        }
        ~FlushDenormals() { _mm_setcsr(csr); }
    } flush_denormals;

    m_mode = props.mode();
    for (const auto &[name, obj] : props.objects()) {
        if (!obj) continue;
        const Location &loc = props.location(name);
        switch (obj->type()) {
        case ObjectType::Shape: {
            auto shape = std::static_pointer_cast<Shape>(obj);
            // Embree asserts on rays from hit points beyond its range: refuse such geometry here.
            if (std::string why = bounds_problem(shape->bbox()); !why.empty())
                FACET_THROW_AT(loc, "shape {}: its bounding box {}", object_label(*shape), why);
            for (auto &part : expand_shape(shape)) { // a `merge` stands for its shapes
                m_shapes.push_back(part);
                if (auto emitter = part->emitter_ptr()) m_emitters.push_back(emitter);
                if (auto sensor = part->sensor_ptr()) m_sensors.push_back(sensor);
            }
            break;
        }
        case ObjectType::Emitter: {
            auto emitter = std::static_pointer_cast<Emitter>(obj);
            if (emitter->shape())
                break; // an area emitter referenced by a shape: the shape brings it in
            if (has_flag(emitter->flags(), EmitterFlags::Surface))
                FACET_THROW_AT(loc,
                               "area emitter {} is not attached to any shape: nest it in a "
                               "<shape> (or reference it from one)",
                               object_label(*emitter));
            m_emitters.push_back(emitter);
            break;
        }
        case ObjectType::Sensor:
            m_sensors.push_back(std::static_pointer_cast<Sensor>(obj));
            break;
        case ObjectType::Integrator:
            if (m_integrator)
                FACET_THROW_AT(loc, "the scene has more than one integrator ({} and {})",
                               object_label(*m_integrator), object_label(*obj));
            m_integrator = std::static_pointer_cast<Integrator>(obj);
            break;
        case ObjectType::BSDF:
        case ObjectType::Texture:
            break; // declared at the top level to be referenced elsewhere
        default:
            FACET_THROW_AT(loc, "a scene cannot hold a top-level {} ({})",
                           object_type_name(obj->type()), object_label(*obj));
        }
        props.mark_queried(name);
    }

    auto &registry = PluginRegistry::instance();
    if (!m_integrator)
        m_integrator = registry.create_as<Integrator>(ObjectType::Integrator, Properties("path"));
    if (m_sensors.empty())
        m_sensors.push_back(
            registry.create_as<Sensor>(ObjectType::Sensor, Properties("perspective")));
    // Shapes without a BSDF (those inside shape groups included) share one default diffuse;
    // as in Mitsuba, an emitting shape's default diffuse is black (it only emits).
    std::shared_ptr<BSDF> default_bsdf, default_emitter_bsdf;
    auto give_default_bsdf = [&](Shape &shape) {
        if (shape.bsdf()) return;
        std::shared_ptr<BSDF> &bsdf = shape.emitter() ? default_emitter_bsdf : default_bsdf;
        if (!bsdf) {
            Properties props("diffuse");
            props.set_mode(m_mode);
            if (shape.emitter()) props.set_float("reflectance", 0.0);
            bsdf = registry.create_as<BSDF>(ObjectType::BSDF, props);
        }
        shape.set_bsdf(bsdf);
    };
    for (auto &shape : m_shapes) {
        if (auto group = dynamic_cast<const ShapeGroup *>(shape.get())) {
            for (auto &member : group->shapes()) give_default_bsdf(*member);
            continue;
        }
        give_default_bsdf(*shape);
    }
    for (auto &emitter : m_emitters)
        if (emitter->is_infinite()) m_environment.push_back(emitter);
    for (auto &emitter : m_emitters) {
        EmitterEntry entry;
        entry.emitter = emitter.get();
        const Shape *shape = emitter->shape();
        const std::optional<Color3f> radiance = emitter->constant_radiance();
        if (shape && shape->is_mesh() && radiance && shape->surface_area() > 0.f) {
            entry.mesh = static_cast<const Mesh *>(shape);
            entry.radiance = *radiance;
            entry.inv_area = 1.f / shape->surface_area();
        } else if (shape && radiance) {
            entry.shape = shape;
            entry.radiance = *radiance;
        }
        emitter->set_scene_index(uint32_t(m_emitter_table.size()));
        m_emitter_table.push_back(entry);
    }
    // Checked before the emitters are given this scene: an update that fails leaves them as
    // they were. (An emitter without a weight counts as 1.)
    if (!m_emitters.empty() &&
        std::all_of(m_emitters.begin(), m_emitters.end(),
                    [](const auto &emitter) { return emitter->sampling_weight() == 0.f; }))
        FACET_THROW("the scene's emitters all have sampling_weight 0: light samples would go "
                    "to none of them");

    m_device = facet::embree_device(); // the free function, not the accessor of the same name
    rtcRetainDevice(m_device);
    // As in Mitsuba 3: Embree's fast triangle test unless the scene asks for the robust
    // (watertight, slower) one.
    m_robust = props.get_bool("embree_use_robust_intersections", false);
    m_two_level = props.get_bool("embree_two_level", false);
    m_light_guide_enabled = props.get_bool("light_guide", true);
    if (previous && previous->m_rtc_scene && previous->m_shapes == m_shapes &&
        previous->m_robust == m_robust && previous->m_two_level == m_two_level) {
        // The same shapes (an update changed no geometry): the Embree scene is theirs.
        m_geometries = previous->m_geometries;
        m_bbox = previous->m_bbox;
        m_accel_seconds = previous->m_accel_seconds;
        for (auto &emitter : m_emitters) emitter->set_scene(*this);
        build_emitter_selection();
        for (auto &sensor : m_sensors)
            if (auto *needs_scene = dynamic_cast<SceneSensor *>(sensor.get()))
                needs_scene->set_scene(*this);
        std::swap(m_rtc_scene, previous->m_rtc_scene); // last: nothing can fail after it
        return;
    }
    if (previous && previous->m_rtc_scene && previous->m_robust == m_robust &&
        previous->m_two_level && m_two_level && replace_geometries(*previous))
        return;
    const auto accel_start = std::chrono::steady_clock::now();
    m_rtc_scene = rtcNewScene(m_device);
    int flags = m_robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE;
    // Two levels: a structure per geometry and one over their boxes, which Embree builds again
    // alone when geometries change (the dynamic flag: without it the top level also splits
    // the geometries' own nodes, and an edit of the Python tests' 200k-triangle scene cost
    // 40 ms instead of 0.3).
    if (m_two_level) flags |= RTC_SCENE_FLAG_DYNAMIC;
    rtcSetSceneFlags(m_rtc_scene, RTCSceneFlags(flags));
    rtcSetSceneBuildQuality(m_rtc_scene,
                            m_two_level ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_HIGH);
    try {
        // Shape groups first, with the scene's triangle test: their instances (attached below)
        // only fetch the group's scene.
        for (auto &shape : m_shapes)
            if (auto group = dynamic_cast<const ShapeGroup *>(shape.get()))
                group->group_scene(m_device, m_robust);
        for (auto &shape : m_shapes) {
            RTCGeometry geom = shape->embree_geometry(m_device);
            if (!geom) continue; // a shape group: only visible through its instances
            if (m_two_level) {
                rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
                rtcCommitGeometry(geom);
            }
            unsigned id = rtcAttachGeometry(m_rtc_scene, geom);
            rtcReleaseGeometry(geom); // the scene holds it now
            if (id >= m_geometries.size()) m_geometries.resize(id + 1);
            m_geometries[id].shape = shape.get();
            if (shape->is_mesh() && static_cast<const Mesh &>(*shape).has_flat_hit())
                m_geometries[id].flat_mesh = static_cast<const Mesh *>(shape.get());
            m_bbox.expand(shape->bbox());
            ++m_geometries_built;
        }
        rtcCommitScene(m_rtc_scene);
        m_accel_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - accel_start).count();
        RTCError err = rtcGetDeviceError(m_device);
        if (err != RTC_ERROR_NONE)
            FACET_THROW("building the Embree scene failed: {}", embree_error_name(err));

        for (auto &emitter : m_emitters) emitter->set_scene(*this);
        build_emitter_selection();
        for (auto &sensor : m_sensors)
            if (auto *needs_scene = dynamic_cast<SceneSensor *>(sensor.get()))
                needs_scene->set_scene(*this);
    } catch (...) {
        // The destructor does not run for a half-built object (nor twice for a rebuilt one).
        rtcReleaseScene(m_rtc_scene);
        rtcReleaseDevice(m_device);
        m_rtc_scene = nullptr;
        m_device = nullptr;
        throw;
    }
}

bool Scene::replace_geometries(Scene &previous) {
    // The shapes that are new objects in old places, as a transform edit leaves them. Shape
    // groups (built into scenes of their own) and changed counts take the full build.
    if (m_shapes.size() != previous.m_shapes.size()) return false;
    std::vector<size_t> changed;
    for (size_t i = 0; i < m_shapes.size(); ++i) {
        if (m_shapes[i] == previous.m_shapes[i]) continue;
        if (dynamic_cast<const ShapeGroup *>(m_shapes[i].get()) ||
            dynamic_cast<const ShapeGroup *>(previous.m_shapes[i].get()))
            return false;
        changed.push_back(i);
    }
    std::vector<unsigned> ids(changed.size(), RTC_INVALID_GEOMETRY_ID);
    for (size_t k = 0; k < changed.size(); ++k)
        for (unsigned id = 0; id < previous.m_geometries.size(); ++id)
            if (previous.m_geometries[id].shape == previous.m_shapes[changed[k]].get()) ids[k] = id;
    if (std::count(ids.begin(), ids.end(), RTC_INVALID_GEOMETRY_ID) != 0) return false;

    const auto accel_start = std::chrono::steady_clock::now();
    m_geometries = previous.m_geometries;
    for (size_t k = 0; k < changed.size(); ++k) {
        const Shape *shape = m_shapes[changed[k]].get();
        m_geometries[ids[k]] = GeometryEntry{shape, nullptr};
        if (shape->is_mesh() && static_cast<const Mesh &>(*shape).has_flat_hit())
            m_geometries[ids[k]].flat_mesh = static_cast<const Mesh *>(shape);
    }
    for (const GeometryEntry &geometry : m_geometries)
        if (geometry.shape) m_bbox.expand(geometry.shape->bbox());

    auto set_scene = [&] {
        for (auto &emitter : m_emitters) emitter->set_scene(*this);
        build_emitter_selection();
        for (auto &sensor : m_sensors)
            if (auto *needs_scene = dynamic_cast<SceneSensor *>(sensor.get()))
                needs_scene->set_scene(*this);
    };
    // The new geometries first (a shape may fail to give one), each to be built as build()
    // builds it; then they take the old ones' ids in the old scene, whose other geometries keep
    // their structures. On a failure the old geometries go back.
    std::vector<RTCGeometry> fresh;
    fresh.reserve(changed.size());
    try {
        for (size_t k = 0; k < changed.size(); ++k) {
            fresh.push_back(m_shapes[changed[k]]->embree_geometry(m_device));
            rtcSetGeometryBuildQuality(fresh.back(), RTC_BUILD_QUALITY_HIGH);
            rtcCommitGeometry(fresh.back());
        }
    } catch (...) {
        for (RTCGeometry geom : fresh) rtcReleaseGeometry(geom);
        throw;
    }
    RTCScene scene = previous.m_rtc_scene;
    std::vector<RTCGeometry> old(changed.size());
    for (size_t k = 0; k < changed.size(); ++k) {
        old[k] = rtcGetGeometry(scene, ids[k]);
        rtcRetainGeometry(old[k]);
        rtcDetachGeometry(scene, ids[k]);
        rtcAttachGeometryByID(scene, fresh[k], ids[k]);
        rtcReleaseGeometry(fresh[k]); // the scene holds it now
    }
    auto restore = [&](bool failed) {
        for (size_t k = 0; k < changed.size(); ++k) {
            if (failed) {
                rtcDetachGeometry(scene, ids[k]);
                rtcAttachGeometryByID(scene, old[k], ids[k]);
            }
            rtcReleaseGeometry(old[k]);
        }
        if (failed) rtcCommitScene(scene);
    };
    try {
        rtcCommitScene(scene);
        if (RTCError err = rtcGetDeviceError(m_device); err != RTC_ERROR_NONE)
            FACET_THROW("updating the Embree scene failed: {}", embree_error_name(err));
        set_scene();
    } catch (...) {
        restore(true);
        throw;
    }
    restore(false);
    std::swap(m_rtc_scene, previous.m_rtc_scene); // last: nothing can fail after it
    m_geometries_built = changed.size();
    m_accel_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - accel_start).count();
    return true;
}

Scene::~Scene() {
    if (m_rtc_scene) rtcReleaseScene(m_rtc_scene);
    if (m_device) rtcReleaseDevice(m_device);
}

detail::RayQueryObserver::~RayQueryObserver() = default;

detail::RayQueryObserver *detail::SceneQueries::set_observer(RayQueryObserver *observer) {
    return g_query_observer.exchange(observer, std::memory_order_relaxed);
}

uint64_t detail::SceneQueries::resend(const Scene &scene, const RayQuery *queries, size_t count) {
    uint64_t differing = 0;
    for (size_t i = 0; i < count; ++i) {
        // The queries of ray_intersect() and occluded(), from the same words.
        const RayQuery &query = queries[i];
        const __m128 a = _mm_loadu_ps(query.words), b = _mm_loadu_ps(query.words + 4);
        bool hit;
        if (query.occlusion) {
            hit = embree_occluded(scene.m_rtc_scene, a, b);
        } else {
            RTCRayHit rh;
            embree_intersect(scene.m_rtc_scene, a, b, rh);
            hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
        differing += hit != query.hit;
    }
    return differing;
}

inline void Scene::complete_hit(const Ray &ray, float t, unsigned geom, unsigned prim,
                                unsigned inst, const Point2f &uv, SurfaceInteraction &si) const {
    if (inst != RTC_INVALID_GEOMETRY_ID) {
        // A hit inside an instanced group: geom is the member of the group.
        FACET_ASSERT(inst < m_geometries.size());
        m_geometries[inst].shape->compute_instance_interaction(ray, t, geom, prim, uv, si);
        si.instance_index = inst;
        return;
    }
    FACET_ASSERT(geom < m_geometries.size());
    const GeometryEntry &geometry = m_geometries[geom];
    const Shape *shape = geometry.shape;
    // The shape fills in its geometry (a flat mesh inline); the hit is finished here, once for
    // every shape.
    if (geometry.flat_mesh)
        geometry.flat_mesh->flat_hit(prim, uv, si);
    else
        shape->compute_surface_interaction(ray, t, prim, uv, si);
    si.t = t;
    si.shape = shape;
    si.prim_index = prim;
    si.instance_index = uint32_t(-1);
    si.wi = si.to_local(-ray.d);
}

bool Scene::ray_intersect(const Ray &ray, SurfaceInteraction &si) const {
    g_intersect_calls.add();
    si.wavelengths = ray.wavelengths;
    __m128 a, b;
    ray_words(ray, a, b);
    if (!embree_can_trace(a, b)) {
        escaped(ray, si); // a NaN direction, say: Embree would abort the process
        return false;
    }
    RTCRayHit rh;
    embree_intersect(m_rtc_scene, a, b, rh);
    if (detail::RayQueryObserver *observer = g_query_observer.load(std::memory_order_relaxed))
        observe_query(*observer, ray, false, rh.hit.geomID != RTC_INVALID_GEOMETRY_ID);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
        escaped(ray, si);
        return false;
    }
    complete_hit(ray, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.instID[0],
                 Point2f(rh.hit.u, rh.hit.v), si);
    return true;
}

void Scene::ray_intersect_packet(const Ray *rays, int count, SurfaceInteraction *sis,
                                 bool *hits) const {
    static_assert(PacketSize == 8, "the packet is Embree's RTCRayHit8");
    FACET_ASSERT(count >= 1 && count <= PacketSize);
    alignas(32) int valid[PacketSize];
    alignas(32) RTCRayHit8 rh;
    for (int k = 0; k < PacketSize; ++k) {
        // A lane without a ray (past `count`, or one Embree cannot trace: a NaN direction, say,
        // escapes) is left out (valid 0) and holds an empty range.
        const Ray *ray = k < count ? &rays[k] : nullptr;
        if (ray) {
            __m128 a, b;
            ray_words(*ray, a, b);
            if (!embree_can_trace(a, b)) ray = nullptr;
        }
        valid[k] = ray ? -1 : 0;
        rh.ray.org_x[k] = ray ? ray->o.x : 0.f;
        rh.ray.org_y[k] = ray ? ray->o.y : 0.f;
        rh.ray.org_z[k] = ray ? ray->o.z : 0.f;
        rh.ray.tnear[k] = ray ? ray->mint : 0.f;
        rh.ray.dir_x[k] = ray ? ray->d.x : 0.f;
        rh.ray.dir_y[k] = ray ? ray->d.y : 0.f;
        rh.ray.dir_z[k] = ray ? ray->d.z : 1.f;
        rh.ray.time[k] = 0.f;
        rh.ray.tfar[k] = ray ? ray->maxt : -Infinity;
        rh.ray.mask[k] = ~0u; // the Debian build has ray masks on: any other value can miss
        rh.ray.id[k] = 0;
        rh.ray.flags[k] = 0;
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect8(valid, m_rtc_scene, &context, &rh);
    detail::RayQueryObserver *observer = g_query_observer.load(std::memory_order_relaxed);
    for (int k = 0; k < count; ++k) {
        g_intersect_calls.add();
        const Ray &ray = rays[k];
        SurfaceInteraction &si = sis[k];
        si.wavelengths = ray.wavelengths;
        const bool hit = valid[k] != 0 && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
        if (observer && valid[k] != 0) observe_query(*observer, ray, false, hit);
        hits[k] = hit;
        if (!hit) {
            escaped(ray, si);
            continue;
        }
        complete_hit(ray, rh.ray.tfar[k], rh.hit.geomID[k], rh.hit.primID[k], rh.hit.instID[0][k],
                     Point2f(rh.hit.u[k], rh.hit.v[k]), si);
    }
}

bool Scene::ray_test(const Ray &ray) const { return occluded(ray); }

inline bool Scene::occluded(const Ray &ray) const {
    g_test_calls.add();
    __m128 a, b;
    ray_words(ray, a, b);
    if (!embree_can_trace(a, b)) return false;
    const bool hit = embree_occluded(m_rtc_scene, a, b);
    if (detail::RayQueryObserver *observer = g_query_observer.load(std::memory_order_relaxed))
        observe_query(*observer, ray, true, hit);
    return hit;
}

namespace {

/// Solid-angle density of a triangle light at the point of `ds` seen along ds.d from ds.dist
/// away: the area density converted (dA = r² / |cos θ| dω), zero from behind (only the front side
/// emits). The one formula for both the sample and pdf_emitter_direction(), so they agree.
inline float triangle_light_pdf(float inv_area, const DirectionSample &ds) {
    float cos_theta = -dot(ds.n, ds.d);
    if (!(cos_theta > 0.f)) return 0.f;
    return inv_area * (ds.dist * ds.dist) / cos_theta;
}

} // namespace

std::pair<DirectionSample, Color3f> Scene::sample_emitter_direction(const Interaction &ref,
                                                                    Point2f u, bool test_visibility,
                                                                    LightSampling sampling,
                                                                    const Vector3f &side) const {
    // The result is built in place (one copy of the sample less on every return).
    std::pair<DirectionSample, Color3f> result{DirectionSample(), Color3f(0.f)};
    DirectionSample &ds = result.first;
    Color3f &weight = result.second;
    const size_t count = m_emitter_table.size();
    if (count == 0) return result;
    // The guide's probability of a light sample here: u.x decides, and is rescaled for the
    // choice of the emitter.
    float take = 1.f;
    if (m_light_guide) {
        take = m_light_guide->probability(ref.p);
        if (take < 1.f) {
            if (!(u.x < take)) return result;
            u.x = std::min(u.x / take, OneMinusEpsilon);
        }
    }
    const auto [index, pmf] = pick_emitter(&ref, u.x);
    // None can reach ref, or sampling_weight 0 (never picked but by rounding).
    if (!(pmf > 0.f)) return result;
    const EmitterEntry &entry = m_emitter_table[index];

    if (entry.mesh) {
        // A triangle light: a point uniform in area on the mesh (inline, no virtual call; the
        // table holds only meshes with area).
        entry.mesh->sample_point(u, ds);
        ds.d = ds.p - ref.p;
        ds.dist = norm(ds.d);
        if (!(ds.dist > 0.f)) return result;
        ds.d /= ds.dist;
        ds.pdf = triangle_light_pdf(entry.inv_area, ds);
        if (!(ds.pdf > 0.f)) return result;
        weight = entry.radiance / ds.pdf;
    } else if (entry.shape) {
        // Another shape's constant light: the shape's own sample, from its front side only,
        // written by the shape straight into the result (an assignment copied it from the
        // stack 16 bytes at a time, reloading what the shape had just stored 4 bytes at a time;
        // perf on the Veach scene: this function's own share 5.9% to 2.8%, with the emitter's
        // pick and the shadow ray's setup 9.1% to 8.4%; 0.987 of its time).
        static_assert(std::is_trivially_destructible_v<DirectionSample>);
        new (&ds) DirectionSample(entry.shape->sample_direction(ref, u));
        if (!(ds.pdf > 0.f) || !(dot(ds.n, ds.d) < 0.f)) return result;
        weight = entry.radiance / ds.pdf;
    } else {
        // The emitter's sample and weight, written straight into the result as above.
        using Result = std::pair<DirectionSample, Color3f>;
        static_assert(std::is_trivially_destructible_v<Result>);
        if (sampling == LightSampling::MIS)
            new (&result) Result(entry.emitter->sample_direction_mis(ref, u, side));
        else
            new (&result) Result(entry.emitter->sample_direction(ref, u));
    }
    ds.emitter = entry.emitter;
    if (!(ds.pdf > 0.f) || weight.is_black()) {
        weight = Color3f(0.f);
        return result;
    }
    // Delta emitters report pdf 1 (not a density): it is left as returned, as in
    // pdf_emitter_direction() which gives them 0. The weight always carries the selection.
    if (uniform_selection()) {
        // The uniform choice keeps its arithmetic (images as before to the last bit).
        if (!ds.delta) ds.pdf /= float(count);
        weight *= float(count);
    } else {
        if (!ds.delta) ds.pdf *= pmf;
        weight /= pmf;
    }

    if (take < 1.f) {
        if (!ds.delta) ds.pdf *= take;
        weight /= take;
    }

    if (test_visibility && !emitter_visible(ref, ds)) weight = Color3f(0.f);
    return result;
}

bool Scene::emitter_visible(const Interaction &ref, const DirectionSample &ds) const {
    return !occluded(std::isfinite(ds.dist) ? ref.spawn_ray_to(ds.p) : ref.spawn_ray(ds.d));
}

float Scene::pdf_emitter_direction(const Interaction &ref, const DirectionSample &ds,
                                   LightSampling sampling, const Vector3f &side) const {
    const float pdf = unguided_emitter_pdf(ref, ds, side, sampling);
    return m_light_guide ? pdf * m_light_guide->probability(ref.p) : pdf;
}

float Scene::unguided_emitter_pdf(const Interaction &ref, const DirectionSample &ds,
                                  const Vector3f &side, LightSampling sampling) const {
    if (!ds.emitter || m_emitter_table.empty()) return 0.f;
    const uint32_t index = ds.emitter->scene_index();
    const bool ours =
        index < m_emitter_table.size() && m_emitter_table[index].emitter == ds.emitter;
    if (uniform_selection()) {
        const float count = float(m_emitter_table.size());
        if (ours) return light_pdf(m_emitter_table[index], ref, ds, side, sampling) / count;
        return (sampling == LightSampling::MIS ? ds.emitter->pdf_direction_mis(ref, ds, side)
                                               : ds.emitter->pdf_direction(ref, ds)) /
               count;
    }
    if (!ours) return 0.f;
    const float pmf = pick_pmf(&ref, index);
    if (!(pmf > 0.f)) return 0.f;
    return light_pdf(m_emitter_table[index], ref, ds, side, sampling) * pmf;
}

void Scene::prepare_light_sampling() const {
    const std::lock_guard<std::mutex> lock(m_light_guide_mutex);
    if (m_light_guide_ready) return;
    if (m_light_guide_enabled && !m_emitter_table.empty() && !m_sensors.empty() && m_bbox.valid()) {
        const auto start = std::chrono::steady_clock::now();
        // The choice of emitters is learned unless the scene gave its own (sampling_weight).
        auto guide = std::make_unique<detail::LightGuide>(
            m_bbox, m_emitter_weights_given ? 0 : m_emitter_table.size());
        survey_light_samples(*guide);
        // The emitters at infinity keep the probability the scene's own rule gives them
        // everywhere (as in the light hierarchy): their light reaches points at scales finer
        // than the guide's cells (a sky seen past a pillar), and a share learned per cell
        // starved such points.
        std::vector<float> fixed(m_emitter_table.size(), -1.f);
        for (size_t i = 0; i < m_emitter_table.size(); ++i)
            if (m_emitter_table[i].emitter->is_infinite())
                fixed[i] = m_light_bvh ? m_outside_pmf : m_emitter_table[i].pmf;
        // The scene's own rule for a cell of the choice: the hierarchy's choice for its box (the
        // emitters outside the hierarchy their constant share), else the constant choice. (The
        // hierarchy's probabilities hold every emitter in it, by scene index.)
        std::vector<float> hierarchy;
        auto own = [this, &hierarchy](const BoundingBox3f &box, float *out) {
            if (m_light_bvh) m_light_bvh->pmf(box, hierarchy);
            for (size_t i = 0; i < m_emitter_table.size(); ++i)
                out[i] = !m_light_bvh                      ? m_emitter_table[i].pmf
                         : m_emitter_table[i].in_hierarchy ? m_hierarchy_share * hierarchy[i]
                                                           : m_outside_pmf;
        };
        const size_t guided = guide->finish(fixed, own);
        const bool chooses = guide->chooses();
        if (guided > 0) m_light_guide = std::move(guide);
        FACET_LOG(
            Debug, "light-sample guide: survey in {:.1f} ms, {} cells with q < 1 or a choice{}",
            1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
            guided, chooses ? " (emitters chosen as learned)" : "");
    }
    m_light_guide_ready = true;
}

float Scene::light_sample_probability(const Point3f &p) const {
    return m_light_guide ? m_light_guide->probability(p) : 1.f;
}

void Scene::survey_light_samples(detail::LightGuide &guide) const {
    // Paths from the sensors in turn, through uniform points of their films, each bounce by
    // its BSDF's own sample, with a light sample at every vertex whose BSDF is not purely
    // specular (the light sample a path tracer takes, for MIS): what a path tracer's vertices
    // see. One thread and a fixed generator: the
    // survey is the same for every render of the scene.
    constexpr uint32_t Paths = 4096, Vertices = 5;
    const BSDFContext ctx;
    const bool spectral = is_spectral(m_mode);
    PCG32 rng;
    // One draw per statement: the order of a call's arguments is the compiler's.
    auto next_2d = [&rng] {
        const float x = rng.next_float();
        return Point2f(x, rng.next_float());
    };
    SurfaceInteraction si;
    for (uint32_t k = 0; k < Paths; ++k) {
        const Sensor &sensor = *m_sensors[k % m_sensors.size()];
        const Point2f film = next_2d();
        const Point2f aperture = next_2d();
        Ray ray = sensor.sample_ray(0.f, film, aperture).first;
        const float u_wavelengths = rng.next_float();
        if (spectral) ray.wavelengths = sample_wavelengths(u_wavelengths).first;
        for (uint32_t depth = 0; depth < Vertices; ++depth) {
            if (!ray_intersect(ray, si) || !si.shape) break;
            const BSDF *bsdf = si.shape->bsdf();
            if (!bsdf) break;
            const Point2f u_light = next_2d();
            const float u1 = rng.next_float();
            const Point2f u2 = next_2d();
            if (has_flag(bsdf->flags(), BSDFFlags::Smooth)) {
                // As the path tracer samples: told the side the BSDF reflects to.
                const auto [ds, weight] = sample_emitter_direction(
                    si, u_light, false, LightSampling::MIS, light_side(*bsdf, si));
                bool useful = false;
                float contribution = 0.f;
                if (ds.pdf > 0.f && !weight.is_black()) {
                    const auto [f, bsdf_pdf] = bsdf->eval_pdf(ctx, si, si.to_local(ds.d));
                    useful = !f.is_black() && emitter_visible(si, ds);
                    if (useful) {
                        // The emitter's light through the BSDF as the path tracer counts it
                        // (times its MIS weight: light a BSDF sample finds better is not the
                        // light sample's to carry), without its choice: X · pmf for the
                        // sample's X = f · weight · w. Its square over pmf estimates the
                        // emitter's second moment at the cell's points, whatever the choice.
                        const float w = ds.delta ? 1.f : mis_weight(ds.pdf, bsdf_pdf);
                        const float pmf = emitter_pmf(si, *ds.emitter);
                        const float y = std::max((f * weight).luminance(), 0.f) * pmf * w;
                        contribution = pmf > 0.f ? y * y / pmf : 0.f;
                    }
                }
                guide.record(si.p, useful, ds.emitter ? ds.emitter->scene_index() : 0,
                             contribution);
            }
            const auto [bs, weight] = bsdf->sample(ctx, si, u1, u2);
            if (weight.is_black() || !(bs.pdf > 0.f)) break;
            ray = si.spawn_ray(si.to_world(bs.wo));
        }
    }
}

float Scene::light_pdf(const EmitterEntry &entry, const Interaction &ref, const DirectionSample &ds,
                       const Vector3f &side, LightSampling sampling) const {
    if (entry.mesh) return triangle_light_pdf(entry.inv_area, ds);
    if (entry.shape) return dot(ds.n, ds.d) < 0.f ? entry.shape->pdf_direction(ref, ds) : 0.f;
    return sampling == LightSampling::MIS ? ds.emitter->pdf_direction_mis(ref, ds, side)
                                          : ds.emitter->pdf_direction(ref, ds);
}

bool Scene::uniform_selection() const {
    return m_emitter_uniform && !m_light_bvh && !(m_light_guide && m_light_guide->chooses());
}

std::pair<size_t, float> Scene::pick_emitter(const Interaction *ref, float &u) const {
    const float *choice = ref && m_light_guide ? m_light_guide->choice(ref->p) : nullptr;
    if (!choice) return own_pick(ref, u);
    // The guide's choice for this cell (its own rule's floor included): probabilities, then
    // running sums.
    const size_t count = m_light_guide->emitters();
    const float *sums = choice + count;
    size_t index = count;
    for (size_t e = 0; e < count; ++e)
        if (u < sums[e]) {
            index = e;
            break;
        }
    if (index == count) // past the last sum by rounding: the last emitter with a share
        for (index = count - 1; index > 0 && !(choice[index] > 0.f); --index) {}
    const float below = index > 0 ? sums[index - 1] : 0.f;
    u = choice[index] > 0.f ? std::clamp((u - below) / choice[index], 0.f, OneMinusEpsilon) : 0.f;
    return {index, choice[index]};
}

float Scene::pick_pmf(const Interaction *ref, size_t index) const {
    const float *choice = ref && m_light_guide ? m_light_guide->choice(ref->p) : nullptr;
    return choice ? choice[index] : own_pmf(ref, index);
}

std::pair<size_t, float> Scene::own_pick(const Interaction *ref, float &u) const {
    const size_t count = m_emitter_table.size();
    if (ref && m_light_bvh) {
        if (u < m_hierarchy_share) {
            u = std::min(u / m_hierarchy_share, OneMinusEpsilon);
            const auto [index, pmf] = m_light_bvh->sample(ref->p, ref->n, u);
            return {size_t(index), pmf * m_hierarchy_share};
        }
        const size_t k = m_outside_hierarchy.size();
        const float scaled = (u - m_hierarchy_share) / (1.f - m_hierarchy_share) * float(k);
        const size_t j = std::min(size_t(scaled), k - 1);
        u = std::clamp(scaled - float(j), 0.f, OneMinusEpsilon);
        return {size_t(m_outside_hierarchy[j]), m_outside_pmf};
    }
    size_t index;
    if (m_emitter_uniform) {
        float scaled = u * float(count);
        index = std::min(size_t(scaled), count - 1);
        u = std::min(scaled - float(index), OneMinusEpsilon);
    } else {
        index = m_emitter_distr.sample_reuse(u);
    }
    return {index, m_emitter_table[index].pmf};
}

float Scene::own_pmf(const Interaction *ref, size_t index) const {
    if (ref && m_light_bvh)
        return m_emitter_table[index].in_hierarchy
                   ? m_hierarchy_share * m_light_bvh->pmf(ref->p, ref->n, uint32_t(index))
                   : m_outside_pmf;
    return m_emitter_table[index].pmf;
}

std::pair<const Emitter *, float> Scene::sample_emitter(float &u) const {
    if (m_emitter_table.empty()) return {nullptr, 0.f};
    const auto [index, pmf] = pick_emitter(nullptr, u);
    return {m_emitter_table[index].emitter, pmf};
}

std::pair<const Emitter *, float> Scene::sample_emitter(const Interaction &ref, float &u) const {
    if (m_emitter_table.empty()) return {nullptr, 0.f};
    const auto [index, pmf] = pick_emitter(&ref, u);
    if (!(pmf > 0.f)) return {nullptr, 0.f};
    return {m_emitter_table[index].emitter, pmf};
}

float Scene::emitter_pmf(const Emitter &emitter) const {
    const uint32_t index = emitter.scene_index();
    if (index >= m_emitter_table.size() || m_emitter_table[index].emitter != &emitter) return 0.f;
    return pick_pmf(nullptr, index);
}

float Scene::emitter_pmf(const Interaction &ref, const Emitter &emitter) const {
    const uint32_t index = emitter.scene_index();
    if (index >= m_emitter_table.size() || m_emitter_table[index].emitter != &emitter) return 0.f;
    return pick_pmf(&ref, index);
}

void Scene::build_emitter_selection() {
    m_emitter_uniform = true;
    m_emitter_distr = DiscreteDistribution();
    m_light_bvh.reset();
    m_outside_hierarchy.clear();
    for (EmitterEntry &entry : m_emitter_table) entry.in_hierarchy = false;
    bool given = false;
    for (const EmitterEntry &entry : m_emitter_table)
        given = given || entry.emitter->sampling_weight() >= 0.f;
    m_emitter_weights_given = given;
    if (!given) build_light_hierarchy();
    build_emitter_distribution(given);
}

void Scene::build_light_hierarchy() {
    // The emitters with bounds and a power that is a number, when there are enough of them for
    // the choice per point to pay for its cost: a pick evaluates the bounds of four children per
    // level, and where a few emitters all matter everywhere it only costs (measured with the
    // earlier tree of two children per node: Veach's scene, 4 lights, 8.5 % more CPU for the
    // same noise; the 13-light staircase, 30 % more samples for an error).
    constexpr size_t MinHierarchy = 8;
    std::vector<std::pair<uint32_t, LightBounds>> items;
    for (uint32_t i = 0; i < m_emitter_table.size(); ++i) {
        std::optional<LightBounds> bounds = m_emitter_table[i].emitter->light_bounds();
        if (!bounds || !bounds->bbox.valid() || !(bounds->power >= 0.f) ||
            !std::isfinite(bounds->power))
            continue;
        items.emplace_back(i, *bounds);
    }
    if (items.size() < MinHierarchy) return;
    m_light_bvh = std::make_unique<detail::LightBVH>();
    m_light_bvh->build(items);
    for (const auto &item : items) m_emitter_table[item.first].in_hierarchy = true;
    for (uint32_t i = 0; i < m_emitter_table.size(); ++i)
        if (!m_emitter_table[i].in_hierarchy) m_outside_hierarchy.push_back(i);
    const size_t n = m_emitter_table.size();
    m_hierarchy_share = items.size() == n ? 1.f : float(double(items.size()) / double(n));
    m_outside_pmf = m_outside_hierarchy.empty()
                        ? 0.f
                        : (1.f - m_hierarchy_share) / float(m_outside_hierarchy.size());
}

void Scene::build_emitter_distribution(bool given) {
    const size_t n = m_emitter_table.size();
    for (EmitterEntry &entry : m_emitter_table) entry.pmf = 1.f / float(n);
    std::vector<float> weights(n);
    if (given) {
        // Mitsuba 3's rule: the weights as given, 1 where none is; all 1 is the uniform choice.
        bool all_one = true;
        for (size_t i = 0; i < n; ++i) {
            const float w = m_emitter_table[i].emitter->sampling_weight();
            weights[i] = w >= 0.f ? w : 1.f;
            all_one = all_one && weights[i] == 1.f;
        }
        if (all_one) return;
        double total = 0.0;
        for (float w : weights) total += double(w);
        if (!(total > 0.0)) return; // (build() refuses all weights 0)
    } else {
        // facet's choice where the scene makes none. The emitters at infinity keep the share
        // the uniform choice gives them (their power, the light crossing the scene's bounding
        // sphere, says little about what reaches the surfaces seen); the others share the rest
        // half in proportion to their power and half uniformly, so that a dim emitter keeps at
        // least half its uniform share. The expected image is the same whatever the choice.
        size_t finite = 0;
        double total = 0.0;
        std::vector<double> power(n, 0.0);
        for (size_t i = 0; i < n; ++i) {
            const Emitter &emitter = *m_emitter_table[i].emitter;
            if (emitter.is_infinite()) continue;
            ++finite;
            power[i] = double(emitter.power());
            if (!(power[i] >= 0.0) || !std::isfinite(power[i])) return; // unknown: uniform
            total += power[i];
        }
        if (finite < 2 || !(total > 0.0) || !std::isfinite(total)) return;
        for (size_t i = 0; i < n; ++i)
            weights[i] = m_emitter_table[i].emitter->is_infinite()
                             ? float(1.0 / double(n))
                             : float(double(finite) / double(n) *
                                     (0.5 * power[i] / total + 0.5 / double(finite)));
        if (std::all_of(weights.begin(), weights.end(), [&](float w) { return w == weights[0]; }))
            return; // equal powers: the uniform choice, exactly
    }
    m_emitter_distr.build(weights.data(), n);
    m_emitter_uniform = false;
    for (size_t i = 0; i < n; ++i) m_emitter_table[i].pmf = m_emitter_distr.pmf(i);
}

void Scene::escaped(const Ray &ray, SurfaceInteraction &si) {
    si.p = ray.o;
    si.n = Normal3f(0.f);
    si.t = Infinity;
    si.sh_frame = Frame();
    si.uv = Point2f(0.f, 0.f);
    si.dp_du = si.dp_dv = Vector3f(0.f);
    si.wi = -ray.d;                   // local: the frame is the identity
    si.wavelengths = ray.wavelengths; // what an environment emitter's eval() reads
    si.shape = nullptr;
    si.prim_index = 0;
    si.instance_index = uint32_t(-1);
}

std::string Scene::to_string() const {
    std::string s =
        fmt::format("Scene[\n  bbox=[{}, {}, {}]-[{}, {}, {}],\n  shapes=[\n", m_bbox.min.x,
                    m_bbox.min.y, m_bbox.min.z, m_bbox.max.x, m_bbox.max.y, m_bbox.max.z);
    for (const auto &shape : m_shapes) s += "    " + shape->to_string() + ",\n";
    s += "  ],\n  emitters=[\n";
    for (const auto &emitter : m_emitters) s += "    " + emitter->to_string() + ",\n";
    s += "  ],\n  sensors=[\n";
    for (const auto &sensor : m_sensors) s += "    " + sensor->to_string() + ",\n";
    s += "  ],\n  integrator=" + (m_integrator ? m_integrator->to_string() : "none") + "\n]";
    return s;
}

} // namespace facet
