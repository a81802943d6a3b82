#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/logger.h>
#include <facet/sensor.h>
#include <facet/shape.h>

#include <tuple>

namespace facet {

ShapeSensor::~ShapeSensor() = default;

Shape::Shape(const Properties &props) {
    for (const auto &[name, obj] : props.objects()) {
        if (!obj) continue;
        const Location &loc = props.location(name);
        switch (obj->type()) {
        case ObjectType::BSDF:
            if (m_bsdf)
                FACET_THROW_AT(loc, "shape \"{}\" has more than one bsdf (\"{}\" is the second)",
                               props.plugin_name(), name);
            m_bsdf = std::static_pointer_cast<BSDF>(obj);
            break;
        case ObjectType::Emitter: {
            if (m_emitter)
                FACET_THROW_AT(loc, "shape \"{}\" has more than one emitter (\"{}\" is the second)",
                               props.plugin_name(), name);
            auto emitter = std::static_pointer_cast<Emitter>(obj);
            if (emitter->shape() && emitter->shape() != this)
                FACET_THROW_AT(loc, "emitter {}is already attached to another shape",
                               emitter->id().empty() ? "" : "\"" + emitter->id() + "\" ");
            m_emitter = std::move(emitter);
            m_emitter->set_shape(this);
            break;
        }
        case ObjectType::Sensor: {
            auto *on_shape = dynamic_cast<ShapeSensor *>(obj.get());
            if (!on_shape)
                FACET_THROW_AT(loc,
                               "shape \"{}\": a nested sensor must measure on the shape (e.g. "
                               "irradiancemeter); \"{}\" is a sensor of its own",
                               props.plugin_name(), name);
            if (m_sensor)
                FACET_THROW_AT(loc, "shape \"{}\" has more than one sensor (\"{}\" is the second)",
                               props.plugin_name(), name);
            m_sensor = std::static_pointer_cast<Sensor>(obj);
            on_shape->attach_shape(this);
            break;
        }
        default:
            FACET_THROW_AT(loc,
                           "shape \"{}\" cannot hold a nested {} (\"{}\"): only a bsdf, an "
                           "emitter and a sensor that measures on it are accepted",
                           props.plugin_name(), object_type_name(obj->type()), name);
        }
        props.mark_queried(name);
    }
}

DirectionSample Shape::sample_direction(const Interaction &ref, const Point2f &u) const {
    PositionSample ps = sample_position(u);
    DirectionSample ds;
    static_cast<PositionSample &>(ds) = ps;
    ds.emitter = m_emitter.get();
    ds.d = ps.p - ref.p;
    float dist2 = squared_norm(ds.d);
    ds.dist = std::sqrt(dist2);
    if (!(ds.dist > 0.f)) {
        ds.pdf = 0.f;
        return ds;
    }
    ds.d /= ds.dist;
    // Area density to solid angle: dA = r² / |cos θ| dω, computed as pdf_direction() does, so
    // that it gives back exactly this pdf for the sample.
    float cos_theta = absdot(ds.n, ds.d);
    ds.pdf = cos_theta > 0.f ? ps.pdf * (ds.dist * ds.dist) / cos_theta : 0.f;
    return ds;
}

float Shape::pdf_direction(const Interaction &ref, const DirectionSample &ds) const {
    float cos_theta = absdot(ds.n, ds.d);
    if (!(cos_theta > 0.f)) return 0.f;
    return pdf_position(ds) * (ds.dist * ds.dist) / cos_theta;
}

void Shape::set_emitter(std::shared_ptr<Emitter> emitter) {
    m_emitter = std::move(emitter);
    if (m_emitter) m_emitter->set_shape(this);
}

std::string Shape::emitter_label() const {
    if (!m_emitter) return "none";
    return m_emitter->id().empty() ? "attached" : "\"" + m_emitter->id() + "\"";
}

std::string Shape::to_string() const {
    return fmt::format("Shape[bbox=[{}, {}, {}]-[{}, {}, {}], area={}, bsdf={}, emitter={}]",
                       bbox().min.x, bbox().min.y, bbox().min.z, bbox().max.x, bbox().max.y,
                       bbox().max.z, surface_area(), m_bsdf ? m_bsdf->to_string() : "none",
                       emitter_label());
}

std::optional<LightBounds> Emitter::surface_light_bounds() const {
    if (!m_shape) return std::nullopt;
    LightBounds b;
    b.bbox = m_shape->bbox();
    std::tie(b.axis, b.cos_normals) = m_shape->normal_cone();
    b.cos_emission = 0.f;
    b.power = power();
    return b;
}

} // namespace facet
