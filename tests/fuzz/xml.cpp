// libFuzzer target: the XML scene loader, and a 1-spp render of scenes with a tiny film.
// Inputs whose integer width/height/crop sizes exceed 64 (also through $parameters) are skipped
// before loading: a huge film is a scene-level limit of its own, not this target's subject, and
// would only exhaust the fuzzer's memory. Films above 32 x 32 pixels load but are not rendered.
#include "fuzz_common.h"

#include <facet/film.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <cstdlib>
#include <cstring>
#include <map>
#include <pugixml.hpp>
#include <string>

namespace {

/// The <default> values of the document (name -> value), for $name references.
void collect_defaults(const pugi::xml_node &node, std::map<std::string, std::string> &out) {
    for (pugi::xml_node child : node.children()) {
        if (std::strcmp(child.name(), "default") == 0)
            out[child.attribute("name").value()] = child.attribute("value").value();
        collect_defaults(child, out);
    }
}

/// False when an <integer> named like a film or block size holds a value above 64 (directly or
/// through a $name of a <default>), or a reference that is not a plain $name of a default.
bool sizes_are_small(const pugi::xml_node &node, const std::map<std::string, std::string> &defs) {
    static const char *const sized[] = {"width", "height", "crop_width", "crop_height",
                                        "block_size"};
    for (pugi::xml_node child : node.children()) {
        if (std::strcmp(child.name(), "integer") == 0) {
            const char *name = child.attribute("name").value();
            for (const char *s : sized) {
                if (std::strcmp(name, s) != 0) continue;
                std::string value = child.attribute("value").value();
                if (!value.empty() && value[0] == '$') {
                    auto it = defs.find(value.substr(1));
                    if (it == defs.end()) return false;
                    value = it->second;
                }
                if (value.find('$') != std::string::npos) return false;
                long v = std::strtol(value.c_str(), nullptr, 10);
                if (v > 64 || v < -64) return false;
            }
        }
        if (!sizes_are_small(child, defs)) return false;
    }
    return true;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    facet::fuzz::init();
    std::string xml(reinterpret_cast<const char *>(data), size);
    pugi::xml_document doc;
    if (!doc.load_buffer(xml.data(), xml.size())) return 0;
    std::map<std::string, std::string> defaults;
    collect_defaults(doc, defaults);
    if (!sizes_are_small(doc, defaults)) return 0;
    try {
        facet::LoadOptions opts;
        opts.lenient = true;
        std::shared_ptr<facet::Object> obj = facet::load_string(xml, opts);
        auto scene = std::dynamic_pointer_cast<facet::Scene>(obj);
        if (!scene || scene->sensors().empty()) return 0;
        const facet::Sensor &sensor = *scene->sensors()[0];
        facet::Point2i crop = sensor.film().crop_size();
        if (crop.x <= 0 || crop.y <= 0 || crop.x * crop.y > 32 * 32) return 0;
        facet::RenderOptions ro;
        ro.threads = 1;
        ro.spp = 1;
        ro.progress = false;
        facet::render(*scene, sensor, ro);
    } catch (const facet::Error &) {}
    return 0;
}
