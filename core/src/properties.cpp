#include <facet/properties.h>
#include <facet/texture.h>

#include <cmath>
#include <limits>

namespace facet {

namespace {

std::string value_to_string(const Properties::Value &v) {
    struct Visitor {
        std::string operator()(bool b) const { return b ? "true" : "false"; }
        std::string operator()(int64_t i) const { return fmt::format("{}", i); }
        std::string operator()(double d) const { return fmt::format("{}", d); }
        std::string operator()(const std::string &s) const { return fmt::format("\"{}\"", s); }
        std::string operator()(const Vector3f &v) const {
            return fmt::format("[{}, {}, {}]", v.x, v.y, v.z);
        }
        std::string operator()(const Color3f &c) const {
            return fmt::format("[{}, {}, {}]", c.r, c.g, c.b);
        }
        std::string operator()(const SpectrumData &s) const { return s.to_string(); }
        std::string operator()(const Transform &t) const { return t.to_string(); }
        std::string operator()(const std::shared_ptr<Object> &o) const {
            return o ? o->to_string() : std::string("null");
        }
    };
    return std::visit(Visitor{}, v);
}

/// Name of the entry's type as written in a scene file ("float", "rgb", "bsdf", ...).
std::string entry_type_name(const Properties::Value &v) {
    if (auto obj = std::get_if<std::shared_ptr<Object>>(&v))
        return *obj ? object_type_name((*obj)->type()) : "object";
    return Properties::type_name(Properties::Type(v.index()));
}

/// Whether a number survives the conversion to the single precision plugins compute in.
bool finite_float(double v) { return std::abs(v) <= double(std::numeric_limits<float>::max()); }

/// Empty when every number in `v` is finite (as a float); otherwise what is wrong.
std::string non_finite(const Properties::Value &v) {
    auto check = [](std::initializer_list<double> values) {
        for (double x : values)
            if (!finite_float(x))
                return std::string(std::isnan(x) ? "NaN" : "an infinite or out-of-range number");
        return std::string();
    };
    if (auto d = std::get_if<double>(&v)) return check({*d});
    if (auto p = std::get_if<Vector3f>(&v)) return check({p->x, p->y, p->z});
    if (auto c = std::get_if<Color3f>(&v)) return check({c->r, c->g, c->b});
    if (auto s = std::get_if<SpectrumData>(&v)) {
        std::string why = check({s->value});
        for (size_t i = 0; why.empty() && i < s->values.size(); ++i) why = check({s->values[i]});
        for (size_t i = 0; why.empty() && i < s->wavelengths.size(); ++i)
            why = check({s->wavelengths[i]});
        return why;
    }
    if (auto t = std::get_if<Transform>(&v)) {
        for (const auto &row : t->matrix.m)
            for (float x : row)
                if (std::string why = check({x}); !why.empty()) return why;
    }
    return {};
}

} // namespace

const char *Properties::type_name(Type t) {
    switch (t) {
    case Type::Bool:
        return "boolean";
    case Type::Integer:
        return "integer";
    case Type::Float:
        return "float";
    case Type::String:
        return "string";
    case Type::Vector:
        return "vector";
    case Type::Color:
        return "rgb";
    case Type::Spectrum:
        return "spectrum";
    case Type::Transform:
        return "transform";
    case Type::Object:
        return "object";
    }
    return "unknown";
}

void Properties::set(const std::string &name, Value value, const Location &loc, bool overwrite) {
    // Every plugin computes in floats: a NaN or infinite parameter is refused here, where its
    // location is known, rather than rendering black or NaN pixels.
    if (std::string why = non_finite(value); !why.empty())
        FACET_THROW_AT(loc.valid() ? loc : m_location,
                       "{} \"{}\" contains {}: parameters must be finite numbers (got {})",
                       entry_type_name(value), name, why, value_to_string(value));
    if (auto it = m_index.find(name); it != m_index.end()) {
        Entry &e = m_entries[it->second];
        if (!overwrite)
            FACET_THROW_AT(loc.valid() ? loc : m_location,
                           "property \"{}\" was specified multiple times", name);
        e.value = std::move(value);
        e.location = loc;
        e.queried = false;
        return;
    }
    m_index.emplace(name, m_entries.size());
    m_entries.push_back(Entry{name, std::move(value), loc, false});
}

bool Properties::remove(const std::string &name) {
    auto it = m_index.find(name);
    if (it == m_index.end()) return false;
    m_entries.erase(m_entries.begin() + long(it->second));
    m_index.clear();
    for (size_t i = 0; i < m_entries.size(); ++i) m_index.emplace(m_entries[i].name, i);
    return true;
}

const Properties::Entry *Properties::find(const std::string &name) const {
    auto it = m_index.find(name);
    return it == m_index.end() ? nullptr : &m_entries[it->second];
}

void Properties::note_request(const std::string &name) const {
    if (std::find(m_requested.begin(), m_requested.end(), name) == m_requested.end())
        m_requested.push_back(name);
}

const Properties::Entry &Properties::require(const std::string &name) const {
    note_request(name);
    const Entry *e = find(name);
    if (!e) {
        if (m_plugin_name.empty())
            FACET_THROW_AT(m_location, "missing required parameter \"{}\"", name);
        FACET_THROW_AT(m_location, "missing required parameter \"{}\" of plugin \"{}\"", name,
                       m_plugin_name);
    }
    e->queried = true;
    return *e;
}

void Properties::type_error(const std::string &name, const char *expected) const {
    const Entry *e = find(name);
    std::string found = e ? entry_type_name(e->value) : std::string("nothing");
    FACET_THROW_AT(e && e->location.valid() ? e->location : m_location,
                   "parameter \"{}\" has type {}, but {} was expected", name, found, expected);
}

bool Properties::has(const std::string &name) const {
    note_request(name);
    return find(name) != nullptr;
}

Properties::Type Properties::type(const std::string &name) const {
    return Type(require(name).value.index());
}

const Location &Properties::location(const std::string &name) const {
    const Entry *e = find(name);
    return e ? e->location : m_location;
}

bool Properties::get_bool(const std::string &name) const {
    const Entry &e = require(name);
    if (auto v = std::get_if<bool>(&e.value)) return *v;
    type_error(name, "boolean");
}

bool Properties::get_bool(const std::string &name, bool def) const {
    return has(name) ? get_bool(name) : def;
}

int64_t Properties::get_int(const std::string &name) const {
    const Entry &e = require(name);
    if (auto v = std::get_if<int64_t>(&e.value)) return *v;
    type_error(name, "integer");
}

int64_t Properties::get_int(const std::string &name, int64_t def) const {
    return has(name) ? get_int(name) : def;
}

double Properties::get_float(const std::string &name) const {
    const Entry &e = require(name);
    if (auto v = std::get_if<double>(&e.value)) return *v;
    if (auto v = std::get_if<int64_t>(&e.value)) return double(*v);
    type_error(name, "float");
}

double Properties::get_float(const std::string &name, double def) const {
    return has(name) ? get_float(name) : def;
}

std::string Properties::get_string(const std::string &name) const {
    const Entry &e = require(name);
    if (auto v = std::get_if<std::string>(&e.value)) return *v;
    type_error(name, "string");
}

std::string Properties::get_string(const std::string &name, const std::string &def) const {
    return has(name) ? get_string(name) : def;
}

Vector3f Properties::get_vector(const std::string &name) const {
    const Entry &e = require(name);
    if (auto v = std::get_if<Vector3f>(&e.value)) return *v;
    type_error(name, "vector");
}

Vector3f Properties::get_vector(const std::string &name, const Vector3f &def) const {
    return has(name) ? get_vector(name) : def;
}

Transform Properties::get_transform(const std::string &name) const {
    const Entry &e = require(name);
    if (auto v = std::get_if<Transform>(&e.value)) return *v;
    type_error(name, "transform");
}

Transform Properties::get_transform(const std::string &name, const Transform &def) const {
    return has(name) ? get_transform(name) : def;
}

Color3f Properties::spectrum_value(const SpectrumTexture &spectrum, const std::string &name,
                                   const Location &loc, SpectrumKind kind) const {
    try {
        return in_mode(spectrum.value(kind), m_mode);
    } catch (const Error &err) {
        if (err.location().valid()) throw;
        FACET_THROW_AT(loc.valid() ? loc : m_location, "parameter \"{}\": {}", name, err.message());
    }
}

Color3f Properties::get_color(const std::string &name, SpectrumKind kind) const {
    const Entry &e = require(name);
    if (auto v = std::get_if<Color3f>(&e.value)) return in_mode(*v, m_mode);
    if (auto v = std::get_if<double>(&e.value)) return Color3f(float(*v));
    if (auto v = std::get_if<int64_t>(&e.value)) return Color3f(float(*v));
    if (auto v = std::get_if<Vector3f>(&e.value)) return Color3f(v->x, v->y, v->z);
    if (auto v = std::get_if<SpectrumData>(&e.value)) {
        try {
            return in_mode(spectrum_to_rgb(*v, kind), m_mode);
        } catch (const Error &err) {
            FACET_THROW_AT(e.location.valid() ? e.location : m_location, "parameter \"{}\": {}",
                           name, err.message());
        }
    }
    if (auto obj = std::get_if<std::shared_ptr<Object>>(&e.value))
        if (auto spectrum = std::dynamic_pointer_cast<SpectrumTexture>(*obj))
            return spectrum_value(*spectrum, name, e.location, kind);
    type_error(name, "rgb, spectrum or float");
}

Color3f Properties::get_color(const std::string &name, const Color3f &def,
                              SpectrumKind kind) const {
    return has(name) ? get_color(name, kind) : in_mode(def, m_mode);
}

std::shared_ptr<Object> Properties::object_entry(const std::string &name) const {
    const Entry &e = require(name);
    if (auto v = std::get_if<std::shared_ptr<Object>>(&e.value)) return *v;
    type_error(name, "object");
}

std::shared_ptr<Texture> Properties::texture(const std::string &name, SpectrumKind kind) const {
    return entry_texture(require(name), kind);
}

std::vector<std::pair<std::string, std::shared_ptr<Texture>>>
Properties::spectra(SpectrumKind kind) const {
    std::vector<std::pair<std::string, std::shared_ptr<Texture>>> out;
    for (const Entry &e : m_entries) {
        const auto *obj = std::get_if<std::shared_ptr<Object>>(&e.value);
        if (!std::holds_alternative<SpectrumData>(e.value) &&
            !(obj && std::dynamic_pointer_cast<SpectrumTexture>(*obj)))
            continue;
        e.queried = true;
        out.emplace_back(e.name, entry_texture(e, kind));
    }
    return out;
}

std::shared_ptr<Texture> Properties::entry_texture(const Entry &e, SpectrumKind kind) const {
    const std::string &name = e.name;
    if (auto obj = std::get_if<std::shared_ptr<Object>>(&e.value)) {
        // A spectrum plugin becomes the constant its use calls for (reflectance, emission, ...).
        if (auto spectrum = std::dynamic_pointer_cast<SpectrumTexture>(*obj)) {
            if (!is_spectral(m_mode))
                return std::make_shared<ConstantTexture>(
                    spectrum_value(*spectrum, name, e.location, kind));
            try {
                return spectrum->spectral(kind);
            } catch (const Error &err) {
                if (err.location().valid()) throw;
                FACET_THROW_AT(e.location.valid() ? e.location : m_location, "parameter \"{}\": {}",
                               name, err.message());
            }
        }
        if (auto tex = std::dynamic_pointer_cast<Texture>(*obj)) return tex;
        type_error(name, "texture, rgb, spectrum or float");
    }
    if (is_spectral(m_mode)) {
        // Numbers are flat spectra (an emitter's, like its rgb, has D65's colour); colours are
        // upsampled, spectra evaluated per wavelength.
        switch (Type(e.value.index())) {
        case Type::Float:
        case Type::Integer:
            if (kind == SpectrumKind::Emission)
                return rgb_spectrum_texture(get_color(name, kind), kind);
            return std::make_shared<ConstantTexture>(get_color(name, kind));
        case Type::Color: {
            // A grey is a flat spectrum, but for an emitter.
            const Color3f c = get_color(name, kind);
            if ((kind == SpectrumKind::Unbounded || kind == SpectrumKind::Reflectance) &&
                !(std::min(c.r, std::min(c.g, c.b)) >= 0.f && c.max() <= 1.f)) {
                const Location &loc = e.location.valid() ? e.location : m_location;
                FACET_LOG(Warn,
                          "{}{}parameter \"{}\" = [{}, {}, {}]: the spectral mode upsamples an "
                          "rgb clamped to [0, 1], as Mitsuba does; give a spectrum for values "
                          "outside it",
                          loc.to_string(), loc.valid() ? ": " : "", name, c.r, c.g, c.b);
            }
            // (Reflectances and unbounded values clamped to [0, 1], as their curves are.)
            if (c.r == c.g && c.g == c.b && kind != SpectrumKind::Emission)
                return std::make_shared<ConstantTexture>(
                    kind == SpectrumKind::Measured ? c : Color3f(clamp(c.r, 0.f, 1.f)));
            return rgb_spectrum_texture(c, kind);
        }
        case Type::Spectrum:
            return data_spectrum_texture(std::get<SpectrumData>(e.value), kind);
        default:
            break;
        }
    }
    switch (Type(e.value.index())) {
    case Type::Float:
    case Type::Integer:
    case Type::Color:
    case Type::Spectrum:
        return std::make_shared<ConstantTexture>(get_color(name, kind));
    default:
        type_error(name, "texture, rgb, spectrum or float");
    }
}

std::shared_ptr<Texture> Properties::texture(const std::string &name, float def,
                                             SpectrumKind kind) const {
    if (!has(name))
        return is_spectral(m_mode) && kind == SpectrumKind::Emission
                   ? rgb_spectrum_texture(Color3f(def), kind)
                   : std::make_shared<ConstantTexture>(Color3f(def));
    return texture(name, kind);
}

std::shared_ptr<Texture> Properties::texture(const std::string &name, const Color3f &def,
                                             SpectrumKind kind) const {
    if (!has(name)) {
        if (is_spectral(m_mode) &&
            !(def.r == def.g && def.g == def.b && kind != SpectrumKind::Emission))
            return rgb_spectrum_texture(def, kind);
        return std::make_shared<ConstantTexture>(in_mode(def, m_mode));
    }
    return texture(name, kind);
}

std::vector<std::pair<std::string, std::shared_ptr<Object>>> Properties::objects() const {
    std::vector<std::pair<std::string, std::shared_ptr<Object>>> result;
    for (const auto &e : m_entries)
        if (auto obj = std::get_if<std::shared_ptr<Object>>(&e.value))
            result.emplace_back(e.name, *obj);
    return result;
}

std::vector<std::string> Properties::names() const {
    std::vector<std::string> result;
    for (const auto &e : m_entries) result.push_back(e.name);
    return result;
}

void Properties::mark_queried(const std::string &name) const {
    if (const Entry *e = find(name)) e->queried = true;
}

bool Properties::was_queried(const std::string &name) const {
    const Entry *e = find(name);
    return e && e->queried;
}

std::vector<std::string> Properties::unqueried() const {
    std::vector<std::string> result;
    for (const auto &e : m_entries)
        if (!e.queried) result.push_back(e.name);
    return result;
}

std::string Properties::entry_to_string(const std::string &name) const {
    const Entry *e = find(name);
    if (!e) return fmt::format("\"{}\": (absent)", name);
    return fmt::format("{} \"{}\": {}", entry_type_name(e->value), name, value_to_string(e->value));
}

} // namespace facet
