#pragma once

#include <facet/object.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace facet {

struct LoadOptions {
    /// `$name` values (the -D options); they override <default> entries.
    std::map<std::string, std::string> params;
    /// Unused properties and parameters become warnings instead of errors.
    bool lenient = false;
    /// Extra folders for relative file names (after the scene's own folder).
    std::vector<std::string> search_path;
    /// The colour mode every object is built for (facet/mode.h), by any name resolve_mode()
    /// accepts; empty: default_mode().
    std::string mode;
};

/// Loads a Mitsuba 3 XML file (the whole grammar: objects, properties, transforms, ref, default,
/// include, alias, path). The root may be a <scene> or any object tag. Errors are facet::Error with
/// file:line:col.
std::shared_ptr<Object> load_file(const std::string &path, const LoadOptions &opts = {});
/// The same for XML text; locations read "string:line:col".
std::shared_ptr<Object> load_string(const std::string &xml, const LoadOptions &opts = {});
/// load_file() that requires a <scene> root.
std::shared_ptr<Scene> load_scene(const std::string &path, const LoadOptions &opts = {});

/// What a scene file declares, read by parsing it (with its includes, defaults and `$name`
/// values) without creating any plugin: no mesh or texture is read, no BVH built.
struct SceneInfo {
    struct SensorInfo {
        std::string plugin, film, sampler;
        int width = 768, height = 576; ///< the film's full size (its defaults when not given)
        int spp = 4;                   ///< the sampler's sample_count
    };
    std::vector<SensorInfo> sensors; ///< in declaration order; a default one when none is declared
    std::string integrator = "path";
    /// Every plugin the scene names, by kind ("bsdf", "shape", ...), sorted, each once.
    std::map<std::string, std::vector<std::string>> plugins;
};
/// Throws the errors load_scene() would give for the file's XML itself (not those of plugins).
SceneInfo scene_info(const std::string &path, const LoadOptions &opts = {});

} // namespace facet
