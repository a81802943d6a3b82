// Test-only plugin: a well-formed BSDF-kind plugin with one parameter.
#include <facet/plugin.h>

namespace {

static const char *DOC = R"DOC(
| Parameter | Type    | Default | Description                               |
|-----------|---------|---------|-------------------------------------------|
| alpha     | float   | 0.5     | Any number in [0, 1]                      |
| fail      | boolean | false   | Throw from the constructor (for tests)    |

```xml
<bsdf type="testgood"><float name="alpha" value="0.2"/></bsdf>
```
)DOC";

class TestGood : public facet::Object {
public:
    explicit TestGood(const facet::Properties &props) {
        m_alpha = props.get_float("alpha", 0.5);
        if (props.get_bool("fail", false))
            FACET_THROW_AT(props.location("fail"), "asked to fail (alpha = {})", m_alpha);
        if (m_alpha < 0 || m_alpha > 1) FACET_THROW("alpha must be in [0, 1], got {}", m_alpha);
    }
    facet::ObjectType type() const override { return facet::ObjectType::BSDF; }
    std::string to_string() const override { return fmt::format("TestGood[alpha={}]", m_alpha); }

private:
    double m_alpha;
};

} // namespace

FACET_EXPORT_PLUGIN(TestGood, BSDF, "testgood", "A well-formed test plugin", DOC)
