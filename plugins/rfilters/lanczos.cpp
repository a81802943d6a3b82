static const char *DOC = R"DOC(
# lanczos

Lanczos-windowed sinc reconstruction filter: sinc(x)·sinc(x / lobes) for |x| < lobes, zero
beyond. The radius equals the number of lobes. Sharp, but it rings around bright edges (a
directly visible light gets dark fringes); the film sums the negative weights with their sign.
Like every filter, the film looks the weight up in a table of 31 values over the radius
(piecewise constant), as Mitsuba 3's scalar renderer does, so images match Mitsuba's at sharp edges.

| Parameter | Type | Default | Description |
|---|---|---|---|
| lobes | integer | 3 | Number of lobes on each side (>= 1), which is also the radius in pixels |

```xml
<rfilter type="lanczos">
    <integer name="lobes" value="2"/>
</rfilter>
```
)DOC";

#include <facet/plugin.h>
#include <facet/rfilter.h>

#include <cmath>

namespace facet {

class LanczosFilter final : public ReconstructionFilter {
public:
    explicit LanczosFilter(const Properties &props) {
        int64_t lobes = props.get_int("lobes", 3);
        if (lobes < 1 || lobes > 64)
            FACET_THROW_AT(props.location("lobes"),
                           "lobes must be a whole number between 1 and 64, got {}", lobes);
        m_lobes = int(lobes);
        m_radius = float(lobes);
        check_weights(props);
    }

    float eval(float x) const override { return exact(x, m_radius); }

    /// sinc(x)·sinc(x / lobes) with sinc(x) = sin(πx)/(πx), zero from |x| = lobes on.
    static float exact(float x, float lobes) {
        x = std::abs(x);
        if (x < 1e-6f) return 1.f; // both sincs tend to 1
        if (x >= lobes) return 0.f;
        const float a = float(M_PI) * x, b = a / lobes;
        return (std::sin(a) * std::sin(b)) / (a * b);
    }

    std::string to_string() const override {
        return fmt::format("LanczosFilter[lobes={}]", m_lobes);
    }

private:
    int m_lobes = 3;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::LanczosFilter, ReconstructionFilter, "lanczos",
                          "Lanczos windowed-sinc pixel filter", DOC, ::facet::AllModes)
