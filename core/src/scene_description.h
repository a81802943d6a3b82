#pragma once

// The descriptions a scene was built from, kept with the scene (Scene::description()) so that
// traverse() (facet/params.h) can change a value and build again exactly the objects that depend
// on it. Written by the XML loader (xml.cpp); private to libfacet.

#include <facet/object.h>
#include <facet/properties.h>
#include <facet/resolver.h>

#include <memory>
#include <string>
#include <vector>

namespace facet {

struct SceneDescription {
    static constexpr size_t NoNode = size_t(-1);

    /// One entry of an object's Properties, in declaration order: a value or a child object.
    struct Entry {
        std::string name;
        Location location;
        Properties::Value value; ///< when child == NoNode
        size_t child = NoNode;   ///< index into `nodes`
    };

    /// One object as the loader instantiated it.
    struct Node {
        ObjectType kind = ObjectType::Unknown;
        std::string plugin; ///< the `type` attribute
        std::string id;
        Location location;
        std::vector<Entry> entries;
        /// Every parameter name the plugin asked for (present or not): the names a value may be
        /// given for.
        std::vector<std::string> requested;
        /// The live object; null for the root (the scene itself, which holds this description).
        std::shared_ptr<Object> instance;
    };

    std::vector<Node> nodes; ///< in creation order: children before the objects holding them
    size_t root = NoNode;    ///< the <scene>
    bool lenient = false;    ///< LoadOptions::lenient of the load
    ColourMode mode = ColourMode::RGB; ///< LoadOptions::mode of the load
    /// The folders the load found files in (the scene's, <path> entries, the search path): the
    /// file resolver of the objects built again.
    FileResolver resolver;
};

} // namespace facet
