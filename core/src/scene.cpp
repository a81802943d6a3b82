#include <facet/assert.h>
#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/integrator.h>
#include <facet/logger.h>
#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/shape.h>
#include <facet/shapegroup.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <pmmintrin.h>
#include <vector>
#include <xmmintrin.h>

namespace facet {

SceneSensor::~SceneSensor() = default;

namespace {

/// Per-thread count of ray_intersect() and ray_test() calls, summed by Scene::ray_count() for
/// `facet bench`. The hot path only does a relaxed load and store on its own thread's slot (plain
/// moves: no lock, no read-modify-write). A thread registers its slot on its first ray. Slots and
/// their list are never freed, so nothing needs destroying when threads or the process end (TBB
/// workers can outlive static destructors).
struct alignas(64) RayCounter {
    std::atomic<uint64_t> count{0};
};
std::mutex g_ray_counter_mutex;
std::vector<RayCounter *> *g_ray_counters = new std::vector<RayCounter *>();
// initial-exec: a plain thread-pointer-relative load instead of a __tls_get_addr call per ray
// (libfacet is loaded with the program, or early enough that its few bytes of static TLS fit).
thread_local RayCounter *t_ray_counter __attribute__((tls_model("initial-exec"))) = nullptr;

inline void count_ray() {
    RayCounter *c = t_ray_counter;
    if (!c) {
        c = t_ray_counter = new RayCounter();
        std::lock_guard<std::mutex> lock(g_ray_counter_mutex);
        g_ray_counters->push_back(c);
    }
    c->count.store(c->count.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
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
inline bool embree_can_trace(const Ray &ray) {
    constexpr float Large = 1.8e18f;
    return std::abs(ray.o.x) <= Large && std::abs(ray.o.y) <= Large && std::abs(ray.o.z) <= Large &&
           std::abs(ray.d.x) <= Large && std::abs(ray.d.y) <= Large && std::abs(ray.d.z) <= Large &&
           !std::isnan(ray.mint) && !std::isnan(ray.maxt);
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

Scene::Scene(const Properties &props) {
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
        Color3f radiance;
        if (shape && shape->is_mesh() && emitter->uniform_area_radiance(radiance) &&
            shape->surface_area() > 0.f) {
            entry.mesh = static_cast<const Mesh *>(shape);
            entry.radiance = radiance;
            entry.inv_area = 1.f / shape->surface_area();
        }
        emitter->set_scene_index(uint32_t(m_emitter_table.size()));
        m_emitter_table.push_back(entry);
    }

    m_device = facet::embree_device(); // the free function, not the accessor of the same name
    rtcRetainDevice(m_device);
    const auto accel_start = std::chrono::steady_clock::now();
    m_rtc_scene = rtcNewScene(m_device);
    // As in Mitsuba 3: Embree's fast triangle test unless the scene asks for the robust
    // (watertight, slower) one.
    m_robust = props.get_bool("embree_use_robust_intersections", false);
    rtcSetSceneFlags(m_rtc_scene, m_robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(m_rtc_scene, RTC_BUILD_QUALITY_HIGH);
    try {
        // Shape groups first, with the scene's triangle test: their instances (attached below)
        // only fetch the group's scene.
        for (auto &shape : m_shapes)
            if (auto group = dynamic_cast<const ShapeGroup *>(shape.get()))
                group->group_scene(m_device, m_robust);
        for (auto &shape : m_shapes) {
            RTCGeometry geom = shape->embree_geometry(m_device);
            if (!geom) continue; // a shape group: only visible through its instances
            unsigned id = rtcAttachGeometry(m_rtc_scene, geom);
            rtcReleaseGeometry(geom); // the scene holds it now
            if (id >= m_geometries.size()) m_geometries.resize(id + 1);
            m_geometries[id].shape = shape.get();
            if (shape->is_mesh() && static_cast<const Mesh &>(*shape).has_flat_hit())
                m_geometries[id].flat_mesh = static_cast<const Mesh *>(shape.get());
            m_bbox.expand(shape->bbox());
        }
        rtcCommitScene(m_rtc_scene);
        m_accel_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - accel_start).count();
        RTCError err = rtcGetDeviceError(m_device);
        if (err != RTC_ERROR_NONE)
            FACET_THROW("building the Embree scene failed: {}", embree_error_name(err));

        for (auto &emitter : m_emitters) emitter->set_scene(*this);
        for (auto &sensor : m_sensors)
            if (auto *needs_scene = dynamic_cast<SceneSensor *>(sensor.get()))
                needs_scene->set_scene(*this);
    } catch (...) {
        // The destructor does not run for a half-built object.
        rtcReleaseScene(m_rtc_scene);
        rtcReleaseDevice(m_device);
        throw;
    }
}

Scene::~Scene() {
    if (m_rtc_scene) rtcReleaseScene(m_rtc_scene);
    if (m_device) rtcReleaseDevice(m_device);
}

uint64_t Scene::ray_count() {
    std::lock_guard<std::mutex> lock(g_ray_counter_mutex);
    uint64_t total = 0;
    for (const RayCounter *c : *g_ray_counters) total += c->count.load(std::memory_order_relaxed);
    return total;
}

bool Scene::ray_intersect(const Ray &ray, SurfaceInteraction &si) const {
    count_ray();
    if (!embree_can_trace(ray)) {
        escaped(ray, si); // a NaN direction, say: Embree would abort the process
        return false;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = ray.o.x;
    rh.ray.org_y = ray.o.y;
    rh.ray.org_z = ray.o.z;
    rh.ray.tnear = ray.mint;
    rh.ray.dir_x = ray.d.x;
    rh.ray.dir_y = ray.d.y;
    rh.ray.dir_z = ray.d.z;
    rh.ray.time = 0.f;
    rh.ray.tfar = ray.maxt;
    rh.ray.mask = 0xFFFFFFFFu; // the Debian build has ray masks on: any other value can miss
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m_rtc_scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
        escaped(ray, si);
        return false;
    }
    const Point2f uv(rh.hit.u, rh.hit.v);
    if (rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID) {
        // A hit inside an instanced group: geomID is the member of the group.
        FACET_ASSERT(rh.hit.instID[0] < m_geometries.size());
        m_geometries[rh.hit.instID[0]].shape->compute_instance_interaction(
            ray, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, uv, si);
        si.instance_index = rh.hit.instID[0];
    } else {
        FACET_ASSERT(rh.hit.geomID < m_geometries.size());
        const GeometryEntry &geometry = m_geometries[rh.hit.geomID];
        const Shape *shape = geometry.shape;
        // The shape fills in its geometry (a flat mesh inline); the hit is finished here, once
        // for every shape.
        if (geometry.flat_mesh)
            geometry.flat_mesh->flat_hit(rh.hit.primID, uv, si);
        else
            shape->compute_surface_interaction(ray, rh.ray.tfar, rh.hit.primID, uv, si);
        si.t = rh.ray.tfar;
        si.shape = shape;
        si.prim_index = rh.hit.primID;
        si.instance_index = uint32_t(-1);
        si.wi = si.to_local(-ray.d);
    }
    return true;
}

bool Scene::ray_test(const Ray &ray) const { return occluded(ray); }

inline bool Scene::occluded(const Ray &ray) const {
    count_ray();
    if (!embree_can_trace(ray)) return false;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay r;
    r.org_x = ray.o.x;
    r.org_y = ray.o.y;
    r.org_z = ray.o.z;
    r.tnear = ray.mint;
    r.dir_x = ray.d.x;
    r.dir_y = ray.d.y;
    r.dir_z = ray.d.z;
    r.time = 0.f;
    r.tfar = ray.maxt;
    r.mask = 0xFFFFFFFFu;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(m_rtc_scene, &context, &r);
    // Embree sets tfar to -inf when something was hit.
    return r.tfar == -Infinity;
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

std::pair<DirectionSample, Color3f>
Scene::sample_emitter_direction(const Interaction &ref, Point2f u, bool test_visibility) const {
    // The result is built in place (one copy of the sample less on every return).
    std::pair<DirectionSample, Color3f> result{DirectionSample(), Color3f(0.f)};
    DirectionSample &ds = result.first;
    Color3f &weight = result.second;
    const size_t count = m_emitter_table.size();
    if (count == 0) return result;
    // Uniform emitter selection; the sample is stretched back to [0, 1) for the emitter.
    float scaled = u.x * float(count);
    size_t index = std::min(size_t(scaled), count - 1);
    u.x = std::min(scaled - float(index), OneMinusEpsilon);
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
    } else {
        std::tie(ds, weight) = entry.emitter->sample_direction(ref, u);
    }
    ds.emitter = entry.emitter;
    if (!(ds.pdf > 0.f) || weight.is_black()) {
        weight = Color3f(0.f);
        return result;
    }
    // Delta emitters report pdf 1 (not a density): it is left as returned, as in
    // pdf_emitter_direction() which gives them 0. The weight always carries the selection.
    if (!ds.delta) ds.pdf /= float(count);
    weight *= float(count);

    if (test_visibility) {
        Ray shadow = std::isfinite(ds.dist) ? ref.spawn_ray_to(ds.p) : ref.spawn_ray(ds.d);
        if (occluded(shadow)) weight = Color3f(0.f);
    }
    return result;
}

float Scene::pdf_emitter_direction(const Interaction &ref, const DirectionSample &ds) const {
    if (!ds.emitter || m_emitter_table.empty()) return 0.f;
    const float count = float(m_emitter_table.size());
    const uint32_t index = ds.emitter->scene_index();
    if (index < m_emitter_table.size() && m_emitter_table[index].emitter == ds.emitter &&
        m_emitter_table[index].mesh)
        return triangle_light_pdf(m_emitter_table[index].inv_area, ds) / count;
    return ds.emitter->pdf_direction(ref, ds) / count;
}

void Scene::escaped(const Ray &ray, SurfaceInteraction &si) {
    si.p = ray.o;
    si.n = Normal3f(0.f);
    si.t = Infinity;
    si.sh_frame = Frame();
    si.uv = Point2f(0.f, 0.f);
    si.dp_du = si.dp_dv = Vector3f(0.f);
    si.wi = -ray.d; // local: the frame is the identity
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
