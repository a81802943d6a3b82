static const char *DOC = R"DOC(
# catmullrom

Catmull–Rom reconstruction filter: the Mitchell–Netravali cubic with B = 0, C = 1/2. Sharper
than `mitchell`, with more ringing. The radius is 2 pixels; the negative lobes between 1 and 2
pixels are summed with their sign by the film.
Like every filter, the film looks the weight up in a table of 31 values over the radius
(piecewise constant), as Mitsuba 3's scalar renderer does, so images match Mitsuba's at sharp edges.

| Parameter | Type | Default | Description |
|---|---|---|---|
| (none) | | | The filter has no parameters; its radius is 2 pixels |

```xml
<rfilter type="catmullrom"/>
```
)DOC";

#include <facet/plugin.h>
#include <facet/rfilter.h>

#include <cmath>

namespace facet {

class CatmullRomFilter final : public ReconstructionFilter {
public:
    explicit CatmullRomFilter(const Properties &props) {
        m_radius = 2.f;
        check_weights(props);
    }

    float eval(float x) const override { return exact(x); }

    /// The Mitchell–Netravali cubic with B = 0, C = 1/2, written out.
    static float exact(float x) {
        x = std::abs(x);
        const float x2 = x * x, x3 = x2 * x;
        if (x < 1.f) return 1.5f * x3 - 2.5f * x2 + 1.f;
        if (x < 2.f) return -0.5f * x3 + 2.5f * x2 - 4.f * x + 2.f;
        return 0.f;
    }

    std::string to_string() const override { return "CatmullRomFilter[radius=2]"; }
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::CatmullRomFilter, ReconstructionFilter, "catmullrom",
                          "Catmull-Rom cubic pixel filter", DOC, ::facet::AllModes)
