// Test-only plugin: a valid emitter plugin, loaded where a BSDF is expected.
#include <facet/plugin.h>

namespace {

static const char *DOC = R"DOC(
Test emitter without parameters.
)DOC";

class WrongKind : public facet::Object {
public:
    explicit WrongKind(const facet::Properties &) {}
    facet::ObjectType type() const override { return facet::ObjectType::Emitter; }
};

} // namespace

FACET_EXPORT_PLUGIN(WrongKind, Emitter, "wrongkind", "An emitter used where a bsdf is expected",
                    DOC)
