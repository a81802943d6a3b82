#pragma once

#include <facet/color.h>
#include <facet/logger.h>
#include <facet/mode.h>
#include <facet/object.h>
#include <facet/spectrum.h>
#include <facet/transform.h>
#include <facet/vector.h>

#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <variant>
#include <vector>

namespace facet {

/// Parameters of one object as read from a scene: typed, ordered, with the location of each entry
/// and a "queried" flag, so that entries nobody read can be reported after construction.
class Properties {
public:
    enum class Type { Bool, Integer, Float, String, Vector, Color, Spectrum, Transform, Object };
    using Value = std::variant<bool, int64_t, double, std::string, Vector3f, Color3f, SpectrumData,
                               Transform, std::shared_ptr<Object>>;

    Properties() = default;
    explicit Properties(std::string plugin_name) : m_plugin_name(std::move(plugin_name)) {}

    /// The `type` attribute of the object ("diffuse").
    const std::string &plugin_name() const { return m_plugin_name; }
    void set_plugin_name(const std::string &name) { m_plugin_name = name; }
    const std::string &id() const { return m_id; }
    void set_id(const std::string &id) { m_id = id; }
    /// Where the object itself was declared.
    const Location &location() const { return m_location; }
    void set_location(const Location &loc) { m_location = loc; }
    /// The colour mode the object is built for (the scene's, LoadOptions::mode). get_color() and
    /// texture() already give colours as the mode renders them (luminance in Mono); a plugin
    /// that reads colours itself (an image, vertex colours) converts them as the mode says.
    ColourMode mode() const { return m_mode; }
    void set_mode(ColourMode mode) { m_mode = mode; }

    // -- Setters (the loader's side) --------------------------------------------------------
    /// Adds an entry; a second entry of the same name is an error unless `overwrite` is set.
    void set(const std::string &name, Value value, const Location &loc = {},
             bool overwrite = false);
    void set_bool(const std::string &n, bool v) { set(n, v); }
    void set_int(const std::string &n, int64_t v) { set(n, v); }
    void set_float(const std::string &n, double v) { set(n, v); }
    void set_string(const std::string &n, const std::string &v) { set(n, v); }
    void set_vector(const std::string &n, const Vector3f &v) { set(n, v); }
    void set_color(const std::string &n, const Color3f &v) { set(n, v); }
    void set_transform(const std::string &n, const Transform &v) { set(n, v); }
    void set_object(const std::string &n, std::shared_ptr<Object> v) { set(n, std::move(v)); }
    bool remove(const std::string &name);

    // -- Queries (the plugin's side); each marks the entry as queried -------------------------
    bool has(const std::string &name) const;
    Type type(const std::string &name) const;
    const Location &location(const std::string &name) const;

    bool get_bool(const std::string &name) const;
    bool get_bool(const std::string &name, bool def) const;
    int64_t get_int(const std::string &name) const;
    int64_t get_int(const std::string &name, int64_t def) const;
    /// An integer entry is converted.
    double get_float(const std::string &name) const;
    double get_float(const std::string &name, double def) const;
    std::string get_string(const std::string &name) const;
    std::string get_string(const std::string &name, const std::string &def) const;
    Vector3f get_vector(const std::string &name) const;
    Vector3f get_vector(const std::string &name, const Vector3f &def) const;
    Transform get_transform(const std::string &name) const;
    Transform get_transform(const std::string &name, const Transform &def) const;
    /// A float, rgb or spectrum (converted as `kind` says, then to the mode's colour).
    Color3f get_color(const std::string &name, SpectrumKind kind = SpectrumKind::Reflectance) const;
    Color3f get_color(const std::string &name, const Color3f &def,
                      SpectrumKind kind = SpectrumKind::Reflectance) const;

    /// A texture-valued parameter: a number, an rgb, a spectrum or a nested texture (constants in
    /// the mode's colour; a texture plugin converts its own values).
    std::shared_ptr<Texture> texture(const std::string &name,
                                     SpectrumKind kind = SpectrumKind::Reflectance) const;
    std::shared_ptr<Texture> texture(const std::string &name, float def,
                                     SpectrumKind kind = SpectrumKind::Reflectance) const;
    std::shared_ptr<Texture> texture(const std::string &name, const Color3f &def,
                                     SpectrumKind kind = SpectrumKind::Reflectance) const;

    /// Every spectrum among the entries, whatever its name (a `<spectrum>` value or a spectrum
    /// plugin), in declaration order, each as texture(name, kind) gives it: for a plugin that
    /// takes any number of them (specfilm's bands). Marks them queried; their names are not
    /// parameters the plugin asks for by name (requested_names()).
    std::vector<std::pair<std::string, std::shared_ptr<Texture>>> spectra(SpectrumKind kind) const;

    /// A named child object of kind T, or nullptr when absent; wrong kinds are errors.
    template <typename T> std::shared_ptr<T> get_object(const std::string &name) const {
        if (!has(name)) return nullptr;
        auto obj = object_entry(name);
        auto res = std::dynamic_pointer_cast<T>(obj);
        if (!res) type_error(name, "object of a different kind");
        return res;
    }

    /// All child objects (named or `_arg_N`) in declaration order; does not mark them queried.
    std::vector<std::pair<std::string, std::shared_ptr<Object>>> objects() const;
    /// Names of all entries in declaration order.
    std::vector<std::string> names() const;

    void mark_queried(const std::string &name) const;
    bool was_queried(const std::string &name) const;
    /// Entries that no query touched, in declaration order.
    std::vector<std::string> unqueried() const;
    /// Every name a plugin asked for, present or not (used to check the parameter tables).
    const std::vector<std::string> &requested_names() const { return m_requested; }

    /// "float \"alpha\": 0.1" style description of an entry.
    std::string entry_to_string(const std::string &name) const;
    static const char *type_name(Type t);

private:
    struct Entry {
        std::string name;
        Value value;
        Location location;
        mutable bool queried = false;
    };
    const Entry *find(const std::string &name) const;
    const Entry &require(const std::string &name) const;
    std::shared_ptr<Texture> entry_texture(const Entry &e, SpectrumKind kind) const;
    std::shared_ptr<Object> object_entry(const std::string &name) const;
    [[noreturn]] void type_error(const std::string &name, const char *expected) const;
    /// A spectrum plugin's value for a parameter of kind `kind`; errors name the parameter.
    Color3f spectrum_value(const SpectrumTexture &spectrum, const std::string &name,
                           const Location &loc, SpectrumKind kind) const;
    void note_request(const std::string &name) const;

    std::string m_plugin_name, m_id;
    Location m_location;
    ColourMode m_mode = ColourMode::RGB;
    std::vector<Entry> m_entries;
    std::unordered_map<std::string, size_t> m_index; ///< name -> position in m_entries
    mutable std::vector<std::string> m_requested;
};

} // namespace facet
