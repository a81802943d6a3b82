static const char *DOC = R"DOC(
# mitchell

Mitchell–Netravali separable cubic reconstruction filter (Mitchell & Netravali 1988), a good
compromise between sharpness and ringing. The radius is 2 pixels. With the default B = C = 1/3
the filter has small negative lobes between 1 and 2 pixels; the film sums the weights with their
sign and divides by that sum.
Like every filter, the film looks the weight up in a table of 31 values over the radius
(piecewise constant), as Mitsuba 3's scalar renderer does, so images match Mitsuba's at sharp edges.

| Parameter | Type | Default | Description |
|---|---|---|---|
| B | float | 1/3 | The B parameter of the cubic family (blurring), in [-2, 2] |
| C | float | 1/3 | The C parameter of the cubic family (ringing), in [-2, 2] |

```xml
<rfilter type="mitchell">
    <float name="B" value="0.3333"/>
    <float name="C" value="0.3333"/>
</rfilter>
```
)DOC";

#include <facet/plugin.h>
#include <facet/rfilter.h>

#include <cmath>
#include <utility>

namespace facet {

class MitchellFilter final : public ReconstructionFilter {
public:
    explicit MitchellFilter(const Properties &props) {
        double b = props.get_float("B", 1.0 / 3.0);
        double c = props.get_float("C", 1.0 / 3.0);
        // The paper's filters have B and C in [0, 1]; within [-2, 2] the weight at the centre,
        // 1 - B/3, stays positive and every weight small. B = 1e30 used to give weights whose
        // products overflow: an all-NaN image.
        for (auto [name, v] : {std::pair<const char *, double>{"B", b}, {"C", c}})
            if (!(v >= -2.0 && v <= 2.0))
                FACET_THROW_AT(props.location(name), "{} must be a number in [-2, 2], got {}", name,
                               v);
        m_radius = 2.f;
        m_b = float(b);
        m_c = float(c);
        check_weights(props);
    }

    float eval(float x) const override { return cubic(std::abs(x), m_b, m_c); }

    /// The Mitchell–Netravali cubic k(x) for x = |offset| (paper eq. 8), zero from 2 on.
    static float cubic(float x, float b, float c) {
        const float x2 = x * x, x3 = x2 * x;
        if (x < 1.f)
            return ((12.f - 9.f * b - 6.f * c) * x3 + (-18.f + 12.f * b + 6.f * c) * x2 +
                    (6.f - 2.f * b)) *
                   (1.f / 6.f);
        if (x < 2.f)
            return ((-b - 6.f * c) * x3 + (6.f * b + 30.f * c) * x2 + (-12.f * b - 48.f * c) * x +
                    (8.f * b + 24.f * c)) *
                   (1.f / 6.f);
        return 0.f;
    }

    std::string to_string() const override {
        return fmt::format("MitchellFilter[radius={}, B={}, C={}]", m_radius, m_b, m_c);
    }

private:
    float m_b = 1.f / 3.f, m_c = 1.f / 3.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::MitchellFilter, ReconstructionFilter, "mitchell",
                          "Mitchell-Netravali cubic pixel filter", DOC, ::facet::AllModes)
