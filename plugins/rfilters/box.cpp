static const char *DOC = R"DOC(
# box

Box reconstruction filter: every sample counts fully for the one pixel it falls into. Fast and
sharp, but it aliases.

| Parameter | Type | Default | Description |
|---|---|---|---|
| (none) | | | The box has a fixed radius of half a pixel |

```xml
<rfilter type="box"/>
```
)DOC";

#include <facet/plugin.h>
#include <facet/rfilter.h>

namespace facet {

class BoxFilter final : public ReconstructionFilter {
public:
    explicit BoxFilter(const Properties &props) {
        m_radius = 0.5f;
        check_weights(props);
    }

    /// Half-open [-0.5, 0.5): a sample on a pixel boundary belongs to exactly one pixel.
    float eval(float x) const override { return (x >= -0.5f && x < 0.5f) ? 1.f : 0.f; }

    std::string to_string() const override { return "BoxFilter[radius=0.5]"; }
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::BoxFilter, ReconstructionFilter, "box", "Box pixel filter", DOC,
                          ::facet::AllModes)
