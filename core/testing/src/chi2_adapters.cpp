// What the chi-square test drives: BSDFs, emitters, sensors and microfacet distributions, plus the
// XML text of an object given as key=value entries (the `facet chi2` command line).

#include <facet/chi2.h>
#include <facet/emitter.h>
#include <facet/logger.h>
#include <facet/microfacet.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/shape.h>
#include <facet/xml.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace facet {

// -- Object XML from key=value entries --------------------------------------------------------

namespace {

/// The wavelengths (nm) the adapters evaluate spectral-mode plugins at.
const Wavelengths ChiSquareWavelengths(450.f, 550.f, 650.f, 500.f);

std::string xml_escape(const std::string &s) {
    std::string out;
    for (char c : s) {
        switch (c) {
        case '&':
            out += "&amp;";
            break;
        case '<':
            out += "&lt;";
            break;
        case '>':
            out += "&gt;";
            break;
        case '"':
            out += "&quot;";
            break;
        default:
            out += c;
        }
    }
    return out;
}

bool is_number(const std::string &s) {
    if (s.empty()) return false;
    char *end = nullptr;
    std::strtod(s.c_str(), &end);
    return end == s.c_str() + s.size();
}

std::vector<std::string> split_commas(const std::string &s) {
    std::vector<std::string> parts;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ',')) {
        size_t a = item.find_first_not_of(" \t"), b = item.find_last_not_of(" \t");
        parts.push_back(a == std::string::npos ? std::string() : item.substr(a, b - a + 1));
    }
    return parts;
}

bool is_triple(const std::string &s) {
    auto parts = split_commas(s);
    return parts.size() == 3 && is_number(parts[0]) && is_number(parts[1]) && is_number(parts[2]);
}

std::string entry_xml(const std::string &entry) {
    size_t eq = entry.find('=');
    if (eq == std::string::npos || eq == 0)
        FACET_THROW("parameter \"{}\": expected key=value or type:key=value", entry);
    std::string key = entry.substr(0, eq), value = entry.substr(eq + 1), tag;
    size_t colon = key.find(':');
    if (colon != std::string::npos) {
        tag = key.substr(0, colon);
        key = key.substr(colon + 1);
    } else if (is_number(value)) {
        tag = "float";
    } else if (value == "true" || value == "false") {
        tag = "boolean";
    } else if (is_triple(value)) {
        tag = "rgb";
    } else {
        tag = "string";
    }
    if (key.empty()) FACET_THROW("parameter \"{}\": empty name", entry);
    if (tag == "vector" || tag == "point") {
        auto parts = split_commas(value);
        if (parts.size() != 3)
            FACET_THROW("parameter \"{}\": a {} needs three comma-separated values", entry, tag);
        return fmt::format("<{} name=\"{}\" x=\"{}\" y=\"{}\" z=\"{}\"/>", tag, xml_escape(key),
                           xml_escape(parts[0]), xml_escape(parts[1]), xml_escape(parts[2]));
    }
    static const char *tags[] = {"float", "integer", "boolean", "string", "rgb", "spectrum"};
    if (std::find(std::begin(tags), std::end(tags), tag) == std::end(tags))
        FACET_THROW("parameter \"{}\": unknown type \"{}\" (expected float, integer, boolean, "
                    "string, rgb, spectrum, vector or point)",
                    entry, tag);
    return fmt::format("<{} name=\"{}\" value=\"{}\"/>", tag, xml_escape(key), xml_escape(value));
}

} // namespace

std::string chi2_object_xml(ObjectType kind, const std::string &plugin,
                            const std::vector<std::string> &entries, const std::string &children,
                            bool with_version) {
    std::string tag = object_type_name(kind);
    std::string xml = fmt::format("<{}{} type=\"{}\">", tag,
                                  with_version ? " version=\"3.0.0\"" : "", xml_escape(plugin));
    for (const std::string &e : entries) xml += entry_xml(e);
    xml += children;
    xml += fmt::format("</{}>", tag);
    return xml;
}

Vector3f direction_from_angles(float theta_deg, float phi_deg) {
    double t = double(theta_deg) * 3.14159265358979323846 / 180.0;
    double p = double(phi_deg) * 3.14159265358979323846 / 180.0;
    return Vector3f(float(std::sin(t) * std::cos(p)), float(std::sin(t) * std::sin(p)),
                    float(std::cos(t)));
}

namespace {

std::string vec_str(const Vector3f &v) {
    return fmt::format("[{:.6g}, {:.6g}, {:.6g}]", v.x, v.y, v.z);
}

template <typename T>
std::shared_ptr<T> load_as(const std::string &xml, ObjectType kind, const std::string &mode = "") {
    LoadOptions opts;
    opts.mode = mode;
    std::shared_ptr<Object> obj = load_string(xml, opts);
    if (!obj || obj->type() != kind)
        FACET_THROW("expected a {} but the XML describes a {}", object_type_name(kind),
                    obj ? object_type_name(obj->type()) : "nothing");
    return std::static_pointer_cast<T>(obj);
}

} // namespace

// -- BSDFs ------------------------------------------------------------------------------------

BSDFAdapter::BSDFAdapter(std::shared_ptr<BSDF> bsdf, const Vector3f &wi, const BSDFContext &ctx)
    : m_bsdf(std::move(bsdf)), m_ctx(ctx) {
    m_si.wi = wi;
    init();
}

BSDFAdapter::BSDFAdapter(const Properties &props, const Vector3f &wi, const BSDFContext &ctx)
    : m_ctx(ctx) {
    m_bsdf = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, props);
    m_bsdf->parameters_changed();
    m_si.wi = wi;
    init();
}

BSDFAdapter::BSDFAdapter(const std::string &xml, const Vector3f &wi, const BSDFContext &ctx,
                         const std::string &mode)
    : m_bsdf(load_as<BSDF>(xml, ObjectType::BSDF, mode)), m_ctx(ctx) {
    m_si.wi = wi;
    init();
}

void BSDFAdapter::init() {
    if (!m_bsdf) FACET_THROW("BSDFAdapter: no BSDF");
    float len = norm(m_si.wi);
    if (!(len > 0.f) || !std::isfinite(len))
        FACET_THROW("BSDFAdapter: the incident direction {} is not a direction", vec_str(m_si.wi));
    m_si.wi /= len;
    m_si.p = Point3f(0.f);
    m_si.n = Normal3f(0.f, 0.f, 1.f);
    m_si.t = 1.f;
    m_si.uv = Point2f(0.5f, 0.5f);
    m_si.dp_du = Vector3f(1.f, 0.f, 0.f);
    m_si.dp_dv = Vector3f(0.f, 1.f, 0.f);
    // Wavelengths of a spectral-mode path (the other modes ignore them): four distinct ones,
    // so that the weight check sees spectral values that differ by channel.
    m_si.wavelengths = ChiSquareWavelengths;
    if (m_ctx.component != uint32_t(-1) && m_ctx.component >= m_bsdf->component_count())
        FACET_THROW("BSDFAdapter: component {} requested but the BSDF has {}", m_ctx.component,
                    m_bsdf->component_count());
}

Chi2Sample BSDFAdapter::sample(const float *u) const {
    Chi2Sample s;
    auto [bs, weight] = m_bsdf->sample(m_ctx, m_si, u[0], Point2f(u[1], u[2]));
    if (weight.is_black()) return s; // a failed sample
    s.has_weight = true;
    s.weight = weight;
    s.d = bs.wo;
    // Radiance-mode refraction carries a 1/η² radiance scale; η² undoes it for the energy check.
    s.energy_scale = m_ctx.mode == TransportMode::Radiance ? bs.eta * bs.eta : 1.f;
    if (has_flag(bs.sampled_type, BSDFFlags::Delta | BSDFFlags::Delta1D)) {
        s.kind = Chi2Sample::Kind::Delta;
        return s;
    }
    s.kind = Chi2Sample::Kind::Smooth;
    s.has_value = true;
    s.sampled_pdf = bs.pdf;
    s.value = m_bsdf->eval(m_ctx, m_si, bs.wo);
    s.pdf = m_bsdf->pdf(m_ctx, m_si, bs.wo);
    auto [value2, pdf2] = m_bsdf->eval_pdf(m_ctx, m_si, bs.wo);
    auto differs = [](float a, float b) {
        float m = std::max(std::abs(a), std::abs(b));
        return !(m == 0.f || std::abs(a - b) <= 1e-4f * m);
    };
    bool value_differs = false;
    for (int c = 0; c < Color3f::Channels; ++c)
        value_differs = value_differs || differs(value2[c], s.value[c]);
    if (differs(pdf2, s.pdf) || value_differs)
        s.problem =
            fmt::format("eval_pdf() = ({}, {}, {}, {}; {}) but eval() = ({}, {}, {}, {}), pdf() "
                        "= {} at {}",
                        value2.r, value2.g, value2.b, value2.w, pdf2, s.value.r, s.value.g,
                        s.value.b, s.value.w, s.pdf, vec_str(bs.wo));
    return s;
}

double BSDFAdapter::pdf(const Vector3f &d) const { return m_bsdf->pdf(m_ctx, m_si, d); }

double BSDFAdapter::plot_phi_center() const {
    return std::atan2(double(m_si.wi.y), double(m_si.wi.x)) + 3.14159265358979323846;
}

std::string BSDFAdapter::to_string() const {
    std::string comp =
        m_ctx.component == uint32_t(-1) ? std::string("all") : std::to_string(m_ctx.component);
    return fmt::format("{}, wi = {}, component {}{}", m_bsdf->to_string(), vec_str(m_si.wi), comp,
                       m_ctx.mode == TransportMode::Importance ? ", importance mode" : "");
}

// -- Emitters ---------------------------------------------------------------------------------

EmitterAdapter::EmitterAdapter(const std::string &scene_xml, const Point3f &ref, size_t index,
                               const std::string &mode) {
    m_scene = load_as<Scene>(scene_xml, ObjectType::Scene, mode);
    const auto &emitters = m_scene->emitters();
    if (index >= emitters.size())
        FACET_THROW("EmitterAdapter: the scene has {} emitters, no emitter {}", emitters.size(),
                    index);
    m_emitter = emitters[index];
    m_ref.p = ref;
    init();
}

EmitterAdapter::EmitterAdapter(std::shared_ptr<Scene> scene, std::shared_ptr<Emitter> emitter,
                               const Point3f &ref)
    : m_scene(std::move(scene)), m_emitter(std::move(emitter)) {
    m_ref.p = ref;
    init();
}

EmitterAdapter::~EmitterAdapter() = default;

void EmitterAdapter::init() {
    if (!m_scene || !m_emitter) FACET_THROW("EmitterAdapter: no scene or no emitter");
    m_ref.wavelengths = ChiSquareWavelengths;
    if (has_flag(m_emitter->flags(), EmitterFlags::Delta))
        FACET_THROW("{}: a delta emitter (point-like or one direction) has no direction density "
                    "to test",
                    m_emitter->to_string());
    m_ref.n = Normal3f(0.f); // a point in space
    m_ref.t = 0.f;
}

std::string EmitterAdapter::scene_xml(const std::string &plugin,
                                      const std::vector<std::string> &entries,
                                      const std::string &shape) {
    std::string emitter = chi2_object_xml(ObjectType::Emitter, plugin, entries, "", false);
    std::string body;
    if (plugin == "area")
        body = fmt::format("<shape type=\"{}\">{}</shape>", xml_escape(shape), emitter);
    else
        body = emitter;
    return "<scene version=\"3.0.0\">" + body + "</scene>";
}

Chi2Sample EmitterAdapter::sample(const float *u) const {
    Chi2Sample s;
    const Point2f u2(u[0], u[1]);
    auto [ds, weight] = m_sampling == LightSampling::MIS
                            ? m_emitter->sample_direction_mis(m_ref, u2, m_side)
                            : m_emitter->sample_direction(m_ref, u2);
    if (weight.is_black() || ds.pdf == 0.f) return s;
    s.has_weight = true;
    s.weight = weight;
    s.d = ds.d;
    if (ds.delta) {
        s.kind = Chi2Sample::Kind::Delta;
        return s;
    }
    s.kind = Chi2Sample::Kind::Smooth;
    s.sampled_pdf = ds.pdf;
    // The record's own point: a traced ray could miss the shape's edge by rounding.
    s.pdf = emitter_pdf(ds);
    return s;
}

float EmitterAdapter::emitter_pdf(const DirectionSample &ds) const {
    return m_sampling == LightSampling::MIS ? m_emitter->pdf_direction_mis(m_ref, ds, m_side)
                                            : m_emitter->pdf_direction(m_ref, ds);
}

double EmitterAdapter::pdf(const Vector3f &d) const {
    DirectionSample ds;
    ds.d = d;
    ds.emitter = m_emitter.get();
    if (m_emitter->is_infinite()) {
        float radius = std::max(1.f, m_scene->bbox().bounding_sphere_radius());
        ds.dist = 2.f * (radius + norm(m_ref.p));
        ds.p = m_ref.p + d * ds.dist;
        ds.n = -d;
        return emitter_pdf(ds);
    }
    SurfaceInteraction si;
    if (!m_scene->ray_intersect(Ray(m_ref.p, d), si) || !si.shape ||
        si.shape->emitter() != m_emitter.get())
        return 0.0;
    ds.p = si.p;
    ds.n = si.n;
    ds.uv = si.uv;
    ds.dist = si.t;
    return emitter_pdf(ds);
}

std::string EmitterAdapter::to_string() const {
    return fmt::format("{}, reference point {}{}", m_emitter->to_string(), vec_str(m_ref.p),
                       m_sampling == LightSampling::MIS ? ", light samples for MIS" : "");
}

// -- Emission directions ----------------------------------------------------------------------

EmissionAdapter::EmissionAdapter(const std::string &scene_xml, size_t index,
                                 const std::string &mode) {
    m_scene = load_as<Scene>(scene_xml, ObjectType::Scene, mode);
    const auto &emitters = m_scene->emitters();
    if (index >= emitters.size())
        FACET_THROW("EmissionAdapter: the scene has {} emitters, no emitter {}", emitters.size(),
                    index);
    m_emitter = emitters[index];
}

EmissionAdapter::EmissionAdapter(std::shared_ptr<Emitter> emitter) : m_emitter(std::move(emitter)) {
    if (!m_emitter) FACET_THROW("EmissionAdapter: no emitter");
}

Chi2Sample EmissionAdapter::sample(const float *u) const {
    // One origin: the position sample does not matter.
    auto [ray, weight] =
        m_emitter->sample_ray(Point2f(0.5f, 0.5f), Point2f(u[0], u[1]), ChiSquareWavelengths);
    Chi2Sample s;
    s.kind = weight.is_black() ? Chi2Sample::Kind::Failed : Chi2Sample::Kind::Smooth;
    s.d = ray.d;
    s.pdf = m_emitter->pdf_ray_direction(ray.d);
    s.has_weight = true;
    s.weight = weight;
    return s;
}

double EmissionAdapter::pdf(const Vector3f &d) const { return m_emitter->pdf_ray_direction(d); }

std::string EmissionAdapter::to_string() const {
    return fmt::format("{}, emitted ray directions", m_emitter->to_string());
}

// -- Sensors ----------------------------------------------------------------------------------

namespace {

Interaction point_at(const Point3f &p) {
    Interaction it;
    it.p = p;
    it.n = Normal3f(0.f); // a point in space
    it.t = 0.f;
    return it;
}

} // namespace

std::shared_ptr<Sensor> SensorAdapter::load(const std::string &xml) {
    std::shared_ptr<Object> obj = load_string(xml);
    if (obj && obj->type() == ObjectType::Scene) {
        const auto &sensors = std::static_pointer_cast<Scene>(obj)->sensors();
        if (sensors.empty()) FACET_THROW("SensorAdapter: the scene has no sensor");
        return sensors.front();
    }
    return load_as<Sensor>(xml, ObjectType::Sensor);
}

std::string SensorAdapter::sensor_xml(const std::string &plugin,
                                      const std::vector<std::string> &entries,
                                      const Point2i &film_size) {
    std::string film;
    if (film_size.x > 0 && film_size.y > 0)
        film = fmt::format("<film type=\"hdrfilm\"><integer name=\"width\" value=\"{}\"/>"
                           "<integer name=\"height\" value=\"{}\"/></film>",
                           film_size.x, film_size.y);
    return chi2_object_xml(ObjectType::Sensor, plugin, entries, film);
}

SensorAdapter::SensorAdapter(std::shared_ptr<Sensor> sensor, const Point2f &aperture_sample)
    : m_sensor(std::move(sensor)), m_mode(Mode::RayDirections), m_aperture(aperture_sample) {
    if (!m_sensor) FACET_THROW("SensorAdapter: no sensor");
    if (!m_sensor->supports_direction_sampling())
        FACET_THROW("{}: the sensor does not support sampling a direction towards it",
                    m_sensor->to_string());
    if (!(m_aperture.x >= 0.f && m_aperture.x < 1.f && m_aperture.y >= 0.f && m_aperture.y < 1.f))
        FACET_THROW("SensorAdapter: the aperture sample ({}, {}) must lie in [0, 1)²", m_aperture.x,
                    m_aperture.y);
    m_world_to_local = m_sensor->to_world().inverse();
    // Rays through three film positions: one origin (pinhole, a lens point) or one direction.
    const Ray a = m_sensor->sample_ray(0.f, Point2f(0.5f, 0.5f), m_aperture).first;
    const Ray b = m_sensor->sample_ray(0.f, Point2f(0.f, 0.5f), m_aperture).first;
    const Ray c = m_sensor->sample_ray(0.f, Point2f(0.5f, 0.f), m_aperture).first;
    const float extent = std::max(norm(b.o - a.o), norm(c.o - a.o));
    const float scale = std::max({1.f, std::abs(a.o.x), std::abs(a.o.y), std::abs(a.o.z)});
    // Importance is evaluated at a point well inside the clipping range of the centre ray.
    m_dist = std::isfinite(a.maxt) && a.mint > 0.f ? std::sqrt(a.mint * a.maxt)
                                                   : std::max(1.f, 10.f * a.mint);
    if (extent <= 1e-5f * scale) {
        m_origin = a.o;
    } else if (dot(a.d, b.d) > 1.f - 1e-6f && dot(a.d, c.d) > 1.f - 1e-6f) {
        // Parallel rays: their origins seen from behind the film, which then spans about
        // ±45° horizontally.
        m_mode = Mode::RayOrigins;
        m_origin = a.o;
        m_dir = a.d;
        m_view = a.o - a.d * norm(b.o - a.o);
    } else {
        FACET_THROW("{}: its camera rays have neither one origin nor one direction (for a given "
                    "aperture sample), which this test does not cover",
                    m_sensor->to_string());
    }
}

SensorAdapter::SensorAdapter(std::shared_ptr<Sensor> sensor, const Point3f &ref)
    : m_sensor(std::move(sensor)), m_mode(Mode::Aperture), m_ref(ref) {
    if (!m_sensor) FACET_THROW("SensorAdapter: no sensor");
    if (!m_sensor->supports_direction_sampling())
        FACET_THROW("{}: the sensor does not support sampling a direction towards it",
                    m_sensor->to_string());
    m_world_to_local = m_sensor->to_world().inverse();
    auto [ds, weight] = m_sensor->sample_direction(point_at(m_ref), Point2f(0.5f, 0.5f));
    if (ds.delta)
        FACET_THROW("{}: seen from a point the sensor is a delta (a pinhole or parallel rays), "
                    "which has no direction density: test its camera rays instead (no reference "
                    "point)",
                    m_sensor->to_string());
}

std::pair<DirectionSample, float> SensorAdapter::importance(const Point3f &p) const {
    auto [ds, weight] = m_sensor->sample_direction(point_at(p), m_aperture);
    return {ds, weight.g};
}

std::string SensorAdapter::check_round_trip(const Point3f &p, const Point2f &film) const {
    auto [ds, weight] = importance(p);
    if (!(weight > 0.f))
        return fmt::format("sample_direction() gives no importance to {}, on the camera ray "
                           "through film position ({}, {})",
                           vec_str(Vector3f(p)), film.x, film.y);
    const Point2i size = m_sensor->film().size();
    const float du = ds.uv.x - film.x * float(size.x), dv = ds.uv.y - film.y * float(size.y);
    const float tol = 1e-3f * float(std::max(size.x, size.y));
    if (!(std::abs(du) <= tol && std::abs(dv) <= tol))
        return fmt::format("sample_direction() towards {} finds film position ({}, {}) px, but "
                           "the camera ray was traced through ({}, {}) px",
                           vec_str(Vector3f(p)), ds.uv.x, ds.uv.y, film.x * float(size.x),
                           film.y * float(size.y));
    return {};
}

Chi2Sample SensorAdapter::sample(const float *u) const {
    Chi2Sample s;
    if (m_mode == Mode::Aperture) {
        auto [ds, weight] = m_sensor->sample_direction(point_at(m_ref), Point2f(u[0], u[1]));
        if (weight.is_black() || !(ds.pdf > 0.f)) return s;
        s.kind = Chi2Sample::Kind::Smooth;
        s.has_weight = true;
        s.weight = weight;
        s.d = ds.d;
        s.sampled_pdf = ds.pdf;
        s.pdf = m_sensor->pdf_direction(point_at(m_ref), ds);
        return s;
    }
    const Point2f film(u[0], u[1]);
    auto [ray, weight] = m_sensor->sample_ray(0.f, film, m_aperture);
    if (weight.is_black()) return s;
    s.kind = Chi2Sample::Kind::Smooth;
    s.has_weight = true;
    s.weight = weight;
    Point3f on_ray;
    if (m_mode == Mode::RayDirections) {
        if (norm(ray.o - m_origin) > 1e-4f * std::max(1.f, norm(Vector3f(m_origin))))
            s.problem =
                fmt::format("the camera ray through ({}, {}) starts at {}, not at {}", film.x,
                            film.y, vec_str(Vector3f(ray.o)), vec_str(Vector3f(m_origin)));
        s.d = ray.d;
        on_ray = ray.o + ray.d * m_dist;
    } else {
        if (dot(ray.d, m_dir) < 1.f - 1e-5f)
            s.problem = fmt::format("the camera ray through ({}, {}) has direction {}, not {}",
                                    film.x, film.y, vec_str(ray.d), vec_str(m_dir));
        s.d = normalize(ray.o - m_view);
        on_ray = ray.o + ray.d * m_dist;
    }
    s.pdf = float(pdf(s.d));
    if (s.problem.empty()) s.problem = check_round_trip(on_ray, film);
    return s;
}

double SensorAdapter::pdf(const Vector3f &d) const {
    switch (m_mode) {
    case Mode::Aperture: {
        // The point of the aperture plane (local z = 0) that d from the reference point reaches.
        const Point3f o = m_world_to_local.apply_point(m_ref);
        const Vector3f ld = m_world_to_local.apply_vector(d);
        if (!(o.z * ld.z < 0.f)) return 0.0;
        DirectionSample ds;
        ds.p = m_sensor->to_world().apply_point(o + ld * (-o.z / ld.z));
        ds.d = d;
        ds.dist = norm(ds.p - m_ref);
        return m_sensor->pdf_direction(point_at(m_ref), ds);
    }
    case Mode::RayDirections: {
        auto [ds, weight] = importance(m_origin + d * m_dist);
        return double(weight) * double(ds.dist) * double(ds.dist);
    }
    case Mode::RayOrigins: {
        const float cos_plane = dot(d, m_dir);
        if (!(cos_plane > 0.f)) return 0.0;
        const float t = dot(m_origin - m_view, m_dir) / cos_plane;
        const Point3f o = m_view + d * t;
        auto [ds, weight] = importance(o + m_dir * m_dist);
        return double(weight) * double(t) * double(t) / double(cos_plane);
    }
    }
    return 0.0;
}

std::string SensorAdapter::to_string() const {
    switch (m_mode) {
    case Mode::Aperture:
        return fmt::format("{}, aperture seen from {}", m_sensor->to_string(),
                           vec_str(Vector3f(m_ref)));
    case Mode::RayDirections:
        return fmt::format("{}, camera ray directions from {} (aperture sample {}, {})",
                           m_sensor->to_string(), vec_str(Vector3f(m_origin)), m_aperture.x,
                           m_aperture.y);
    case Mode::RayOrigins:
        return fmt::format("{}, camera ray origins seen from {}", m_sensor->to_string(),
                           vec_str(Vector3f(m_view)));
    }
    return m_sensor->to_string();
}

// -- Microfacet distributions -----------------------------------------------------------------

struct MicrofacetAdapter::Impl {
    MicrofacetDistribution distr;
    Vector3f wi;
};

MicrofacetAdapter::MicrofacetAdapter(const std::string &type, float alpha_u, float alpha_v,
                                     bool sample_visible, const Vector3f &wi) {
    MicrofacetType t;
    if (type == "beckmann")
        t = MicrofacetType::Beckmann;
    else if (type == "ggx")
        t = MicrofacetType::GGX;
    else
        FACET_THROW("microfacet distribution \"{}\": expected beckmann or ggx", type);
    if (!(alpha_u > 0.f) || !(alpha_v > 0.f))
        FACET_THROW("microfacet roughness must be positive (got {}, {})", alpha_u, alpha_v);
    float len = norm(wi);
    if (!(len > 0.f) || wi.z <= 0.f)
        FACET_THROW("microfacet incident direction {} must point into the upper hemisphere",
                    vec_str(wi));
    m_impl = std::make_unique<Impl>(
        Impl{MicrofacetDistribution(t, alpha_u, alpha_v, sample_visible), wi / len});
}

MicrofacetAdapter::~MicrofacetAdapter() = default;

Chi2Sample MicrofacetAdapter::sample(const float *u) const {
    Chi2Sample s;
    auto [m, pdf] = m_impl->distr.sample(m_impl->wi, Point2f(u[0], u[1]));
    if (!(pdf > 0.f)) {
        if (!std::isfinite(pdf)) s.problem = fmt::format("sample() returned pdf {}", pdf);
        return s;
    }
    s.kind = Chi2Sample::Kind::Smooth;
    s.d = m;
    s.sampled_pdf = pdf;
    s.pdf = m_impl->distr.pdf(m_impl->wi, m);
    return s;
}

double MicrofacetAdapter::pdf(const Vector3f &d) const { return m_impl->distr.pdf(m_impl->wi, d); }

double MicrofacetAdapter::plot_phi_center() const {
    return std::atan2(double(m_impl->wi.y), double(m_impl->wi.x));
}

std::string MicrofacetAdapter::to_string() const {
    return fmt::format("{}, wi = {}", m_impl->distr.to_string(), vec_str(m_impl->wi));
}

} // namespace facet
