// One entry point for the mesh loaders: the input becomes a file that the shape plugin `type`
// loads; a facet::Error is the expected outcome for most inputs, anything else is a finding.
#pragma once

#include "fuzz_common.h"

#include <facet/mesh.h>
#include <facet/plugin.h>

namespace facet::fuzz {

inline int load_mesh(const char *type, const char *ext, const uint8_t *data, size_t size) {
    init();
    std::string path = write_input(data, size, ext);
    try {
        Properties props(type);
        props.set_string("filename", path);
        auto shape = PluginRegistry::instance().create(ObjectType::Shape, props);
        // Touch what the renderer reads: the bounds, the area table, the arrays.
        if (auto mesh = std::dynamic_pointer_cast<Mesh>(shape)) {
            volatile float sink = mesh->bbox().min.x + mesh->surface_area();
            if (mesh->face_count() > 0) sink = sink + mesh->sample_position(Point2f(0.5f)).p.x;
            (void)sink;
        }
    } catch (const Error &) {}
    return 0;
}

} // namespace facet::fuzz
