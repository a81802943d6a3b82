// Test-only plugin: its descriptor names another plugin than its file name says.
#include <facet/plugin.h>

namespace {

static const char *DOC = "Test plugin with a mismatched name.";

class Misnamed : public facet::Object {
public:
    explicit Misnamed(const facet::Properties &) {}
    facet::ObjectType type() const override { return facet::ObjectType::BSDF; }
};

} // namespace

FACET_EXPORT_PLUGIN(Misnamed, BSDF, "othername", "A plugin whose file has another name", DOC)
