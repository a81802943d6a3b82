// Test-only plugin: exports a descriptor built for a newer facet ABI; the registry must refuse it.
#include <facet/plugin.h>

namespace {

class BadAbi : public facet::Object {
public:
    explicit BadAbi(const facet::Properties &) {}
    facet::ObjectType type() const override { return facet::ObjectType::BSDF; }
};

facet::Object *create(const facet::Properties &props) { return new BadAbi(props); }

} // namespace

extern "C" __attribute__((visibility("default"))) const facet::PluginDescriptor *
facet_plugin_descriptor() {
    static const facet::PluginDescriptor desc{facet::FACET_ABI_VERSION + 1,
                                              facet::ObjectType::BSDF,
                                              "badabi",
                                              "Built for another ABI",
                                              "",
                                              create};
    return &desc;
}
