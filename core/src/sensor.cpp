#include <facet/plugin.h>
#include <facet/sensor.h>

namespace facet {

Sensor::Sensor(const Properties &props) {
    m_to_world = props.get_transform("to_world", Transform());
    // A camera that scales by zero or sits beyond any scene sends rays Embree cannot take (it
    // asserts on NaN or huge origins and directions).
    if (std::string why = transform_problem(m_to_world); !why.empty())
        FACET_THROW_AT(props.location("to_world"), "the sensor's to_world {}", why);

    // Mitsuba's sensors take a shutter interval; facet renders still scenes, so only check it.
    double open = props.get_float("shutter_open", 0.0);
    double close = props.get_float("shutter_close", 0.0);
    if (close < open)
        FACET_THROW_AT(props.location("shutter_close"),
                       "shutter_close ({}) must not be earlier than shutter_open ({})", close,
                       open);

    for (const auto &[name, obj] : props.objects()) {
        if (!obj) continue;
        if (obj->type() == ObjectType::Film) {
            if (m_film) FACET_THROW_AT(props.location(name), "a sensor takes only one film");
            m_film = std::static_pointer_cast<Film>(obj);
            props.mark_queried(name);
        } else if (obj->type() == ObjectType::Sampler) {
            if (m_sampler) FACET_THROW_AT(props.location(name), "a sensor takes only one sampler");
            m_sampler = std::static_pointer_cast<Sampler>(obj);
            props.mark_queried(name);
        }
    }
    auto &registry = PluginRegistry::instance();
    if (!m_film) m_film = registry.create_as<Film>(ObjectType::Film, Properties("hdrfilm"));
    if (!m_sampler)
        m_sampler = registry.create_as<Sampler>(ObjectType::Sampler, Properties("independent"));

    // A spectral response (Mitsuba's sensor `srf`): the spectral modes only, and not with a
    // film's own bands.
    if (props.has("srf")) {
        const Location &at = props.location("srf");
        if (!is_spectral(props.mode()))
            FACET_THROW_AT(at, "the sensor's srf (a spectral response function) needs a spectral "
                               "mode (scalar_spectral or scalar_spectral_polarized)");
        if (m_film->bands())
            FACET_THROW_AT(at, "the sensor's srf and the film's spectral bands both set the "
                               "spectral response: give only one");
        try {
            m_srf = SpectralBands::fit({{"srf", props.texture("srf", SpectrumKind::Measured)}});
        } catch (const Error &e) {
            if (e.location().valid()) throw;
            FACET_THROW_AT(at, "the sensor's srf: {}", e.message());
        }
    }
}

std::pair<DirectionSample, Color3f> Sensor::sample_direction(const Interaction &,
                                                             const Point2f &) const {
    FACET_THROW("{} does not support sampling a direction towards it (needed by light tracers "
                "such as ptracer); use a perspective, thinlens or orthographic sensor",
                to_string());
}

float Sensor::pdf_direction(const Interaction &, const DirectionSample &) const {
    FACET_THROW("{} does not support sampling a direction towards it (needed by light tracers "
                "such as ptracer); use a perspective, thinlens or orthographic sensor",
                to_string());
}

} // namespace facet
