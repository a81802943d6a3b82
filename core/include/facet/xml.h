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
};

/// Loads a Mitsuba 3 XML file (the whole grammar: objects, properties, transforms, ref, default,
/// include, alias, path). The root may be a <scene> or any object tag. Errors are facet::Error with
/// file:line:col.
std::shared_ptr<Object> load_file(const std::string &path, const LoadOptions &opts = {});
/// The same for XML text; locations read "string:line:col".
std::shared_ptr<Object> load_string(const std::string &xml, const LoadOptions &opts = {});
/// load_file() that requires a <scene> root.
std::shared_ptr<Scene> load_scene(const std::string &path, const LoadOptions &opts = {});

} // namespace facet
