static const char *DOC = R"DOC(
# gaussian

Windowed Gaussian reconstruction filter (the default of every film). The Gaussian is cut at
4 standard deviations and shifted down by its value there, so it falls to exactly zero at the
radius.

| Parameter | Type | Default | Description |
|---|---|---|---|
| stddev | float | 0.5 | Standard deviation in pixels (1/256 to 16); the radius is 4·stddev |

```xml
<rfilter type="gaussian">
    <float name="stddev" value="0.25"/>
</rfilter>
```
)DOC";

#include <facet/plugin.h>
#include <facet/rfilter.h>

namespace facet {

class GaussianFilter final : public ReconstructionFilter {
public:
    explicit GaussianFilter(const Properties &props) {
        double stddev = props.get_float("stddev", 0.5);
        // A huge stddev used to overflow the border computation (a float to int conversion), a
        // tiny one gives (almost) every sample the weight 0: a black image.
        if (!(4.0 * stddev >= MinFilterRadius) || !(4.0 * stddev <= MaxFilterRadius))
            FACET_THROW_AT(props.location("stddev"),
                           "stddev must be a number of pixels in [{}, {}] (the radius, 4·stddev, "
                           "in [{}, {}]), got {}",
                           MinFilterRadius / 4.f, MaxFilterRadius / 4.f, MinFilterRadius,
                           MaxFilterRadius, stddev);
        m_stddev = float(stddev);
        m_radius = 4.f * m_stddev;
        m_alpha = -1.f / (2.f * m_stddev * m_stddev);
        m_bias = std::exp(m_alpha * m_radius * m_radius);
        check_weights(props);
    }

    float eval(float x) const override { return std::max(0.f, std::exp(m_alpha * x * x) - m_bias); }

    std::string to_string() const override {
        return fmt::format("GaussianFilter[stddev={}, radius={}]", m_stddev, m_radius);
    }

private:
    float m_stddev = 0.5f, m_alpha = 0.f, m_bias = 0.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::GaussianFilter, ReconstructionFilter, "gaussian",
                          "Windowed Gaussian pixel filter", DOC, ::facet::AllModes)
