#pragma once

#include <facet/properties.h>

#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace facet {

/// What SceneParameters::update() rebuilt.
struct SceneUpdate {
    size_t objects_created = 0; ///< objects constructed again (shapes included)
    size_t shapes_created = 0;  ///< shapes constructed again (their geometry loaded again)
    size_t shapes_relinked = 0; ///< shapes given a new BSDF or emitter, their geometry kept
    bool accel_rebuilt = false; ///< the Embree scene was built again
    /// Embree geometries whose acceleration structure was built (those of the shapes built
    /// again, or all of them when the whole Embree scene was).
    size_t geometries_built = 0;
};

/// The parameters of a loaded scene (facet::traverse), keyed by path: the object's id when it
/// has one, else its place ("shape_3": the fourth <shape> of the scene; a nested object
/// adds its property name or its tag: "shape_7.emitter", "sensor.film"), then the parameter's
/// name: "red.reflectance", "sensor.to_world", "sensor.film.width", "integrator.max_depth".
///
/// Values are the ones the scene gives (floats, integers, booleans, strings, points, rgb,
/// spectra, transforms; texture-valued parameters given as constants included). set() stages a
/// change; update() applies the staged changes: it constructs again the objects whose values
/// changed and those that hold them (a shape whose BSDF or emitter changed keeps its geometry
/// and is given the new one), and the scene keeps its Embree scene unless a shape was built
/// again. A render after update() is the render of a fresh load of the edited scene, bit for
/// bit. update() fails (a facet::Error, the scene unchanged) while a render of the scene runs.
class SceneParameters {
public:
    /// Keys of the values the scene gives, in the order of the objects' creation.
    const std::vector<std::string> &keys() const { return m_keys; }
    /// True for a key of keys() and for a parameter an object takes but the scene leaves at
    /// its default (a shape's "to_world", say), which set() may give.
    bool has(const std::string &key) const { return m_slots.count(key) != 0; }
    /// False for a parameter left at the plugin's default.
    bool is_set(const std::string &key) const;
    /// The value's type; an unknown key or a parameter left at its default is an error.
    Properties::Type type(const std::string &key) const;
    /// The current value (a staged change included).
    const Properties::Value &get(const std::string &key) const;
    /// Stages a change. The value must have the parameter's type (an integer is accepted for
    /// a float, a float for an rgb); an unknown key is an error that names the closest key.
    void set(const std::string &key, Properties::Value value);
    /// Number of staged changes.
    size_t pending() const { return m_pending.size(); }
    /// Applies the staged changes (see the class comment). On an error the scene and the
    /// values are as before, and the staged changes are dropped.
    SceneUpdate update();

    const std::shared_ptr<Scene> &scene() const { return m_scene; }

private:
    friend SceneParameters traverse(const std::shared_ptr<Scene> &scene);
    struct Slot {
        size_t node;
        std::string name;
    };
    const Slot &slot(const std::string &key) const;
    [[noreturn]] void unknown_key(const std::string &key) const;

    std::shared_ptr<Scene> m_scene;
    std::vector<std::string> m_keys;
    std::unordered_map<std::string, Slot> m_slots;
    std::vector<std::pair<std::string, Properties::Value>> m_pending;
};

/// The parameters of `scene`, which must have been loaded from a scene description
/// (facet::load_file, load_string, load_scene). Several SceneParameters of one scene see each
/// other's updates.
SceneParameters traverse(const std::shared_ptr<Scene> &scene);

} // namespace facet
