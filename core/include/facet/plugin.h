#pragma once

#include <facet/object.h>
#include <facet/properties.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace facet {

/// Version of the binary interface between libfacet and plugins. Bump it whenever a public class
/// layout, a virtual table or PluginDescriptor changes; the registry refuses other versions.
constexpr uint32_t FACET_ABI_VERSION = 15;

/// What every plugin library exports through `facet_plugin_descriptor()`.
/// `abi_version` stays the first member in every future version, so it can always be checked.
struct PluginDescriptor {
    uint32_t abi_version;
    ObjectType kind;
    const char *name;        ///< XML `type`, equal to the library's file name
    const char *description; ///< one line
    const char *doc;         ///< Markdown parameter table and an XML example
    Object *(*create)(const Properties &props);
    /// The colour modes the plugin renders in: mode_bit() of each. A scene loaded in any other
    /// mode is refused with the plugin's name and its modes. FACET_EXPORT_PLUGIN declares rgb
    /// and mono (mono reaches a plugin as three equal channels); a plugin that evaluates its
    /// colours at the path's wavelengths (Interaction::wavelengths) adds the spectral mode with
    /// FACET_EXPORT_PLUGIN_MODES.
    uint32_t modes = RGBAndMono;
};

/// The modes of `desc` by name, in modes()'s order ("scalar_rgb, scalar_mono").
std::string plugin_modes(const PluginDescriptor &desc);

using PluginDescriptorFn = const PluginDescriptor *(*)();

/// Finds, loads (dlopen) and checks plugin libraries, and creates objects from them.
/// Search order: add_search_dir() folders (the `-a` option), then $FACET_PLUGIN_PATH, then the
/// build tree's plugin folder (when libfacet runs from its build tree), then the installed folder.
class PluginRegistry {
public:
    static PluginRegistry &instance();

    /// Prepends nothing: folders are searched in the order they were added.
    void add_search_dir(const std::string &dir);
    std::vector<std::string> search_path() const;

    /// Registers a plugin compiled into the calling program (tests use this).
    void register_static(const PluginDescriptor *desc);

    /// Loads the plugin library `<name>.so`; throws facet::Error (listing the known plugins of
    /// `expected` kind and the closest name) when it is missing or invalid.
    const PluginDescriptor &descriptor(const std::string &name,
                                       ObjectType expected = ObjectType::Unknown);
    /// Loads the library at `path` and checks it; returns its descriptor.
    const PluginDescriptor &load_library(const std::string &path,
                                         ObjectType expected = ObjectType::Unknown);

    /// Creates an object and checks its kind. Unqueried properties are reported afterwards:
    /// an error unless `lenient`, in which case a warning.
    std::shared_ptr<Object> create(ObjectType expected, const Properties &props,
                                   bool lenient = false);
    template <typename T> std::shared_ptr<T> create_as(ObjectType expected, const Properties &props,
                                                       bool lenient = false) {
        return std::static_pointer_cast<T>(create(expected, props, lenient));
    }

    /// Names of all plugins found on the search path (of one kind unless Unknown), sorted.
    std::vector<std::string> available(ObjectType kind = ObjectType::Unknown);

private:
    PluginRegistry();
    std::string find_library(const std::string &name) const;

    mutable std::recursive_mutex m_mutex;
    std::vector<std::string> m_dirs;
    std::map<std::string, const PluginDescriptor *> m_loaded;
    std::vector<void *> m_handles;
};

/// Reports the entries of `props` nobody queried (see Properties::unqueried) for an object of
/// `kind`: throws unless `lenient`, then only warns.
void check_unqueried(const Properties &props, ObjectType kind, bool lenient);

/// Levenshtein distance, for "did you mean" suggestions.
size_t edit_distance(const std::string &a, const std::string &b);
/// The candidate closest to `name`, or "" when none is reasonably close.
std::string closest_name(const std::string &name, const std::vector<std::string> &candidates);

} // namespace facet

/// Exports a plugin. Use once at the end of the plugin's .cpp file:
///   FACET_EXPORT_PLUGIN(Diffuse, BSDF, "diffuse", "Smooth diffuse (Lambertian) reflection", DOC)
#define FACET_EXPORT_PLUGIN(Class, Kind, Name, Description, Doc)                                   \
    FACET_EXPORT_PLUGIN_MODES(Class, Kind, Name, Description, Doc, ::facet::RGBAndMono)

/// FACET_EXPORT_PLUGIN for the modes `Modes` (mode_bit()s or'ed, or ::facet::AllModes):
///   FACET_EXPORT_PLUGIN_MODES(Diffuse, BSDF, "diffuse", "...", DOC, ::facet::AllModes)
#define FACET_EXPORT_PLUGIN_MODES(Class, Kind, Name, Description, Doc, Modes)                      \
    extern "C" __attribute__((visibility("default"))) const ::facet::PluginDescriptor *            \
    facet_plugin_descriptor() {                                                                    \
        static const ::facet::PluginDescriptor desc{                                               \
            ::facet::FACET_ABI_VERSION,                                                            \
            ::facet::ObjectType::Kind,                                                             \
            Name,                                                                                  \
            Description,                                                                           \
            Doc,                                                                                   \
            [](const ::facet::Properties &props) -> ::facet::Object * {                            \
                return new Class(props);                                                           \
            },                                                                                     \
            Modes};                                                                                \
        return &desc;                                                                              \
    }
