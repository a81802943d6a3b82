static const char *DOC = R"DOC(
# tent

Tent (triangle, bilinear) reconstruction filter: the weight falls linearly from 1 at the pixel
centre to 0 at `radius`.

| Parameter | Type | Default | Description |
|---|---|---|---|
| radius | float | 1.0 | Radius of the filter in pixels (1/64 to 64) |

```xml
<rfilter type="tent">
    <float name="radius" value="1.5"/>
</rfilter>
```
)DOC";

#include <facet/plugin.h>
#include <facet/rfilter.h>

namespace facet {

class TentFilter final : public ReconstructionFilter {
public:
    explicit TentFilter(const Properties &props) {
        double radius = props.get_float("radius", 1.0);
        // A tiny radius gives (almost) every sample the weight 0: a black image.
        if (!(radius >= MinFilterRadius) || !(radius <= MaxFilterRadius))
            FACET_THROW_AT(props.location("radius"),
                           "radius must be a number of pixels in [{}, {}], got {}", MinFilterRadius,
                           MaxFilterRadius, radius);
        m_radius = float(radius);
        m_inv_radius = 1.f / m_radius;
        check_weights(props);
    }

    float eval(float x) const override { return std::max(0.f, 1.f - std::abs(x) * m_inv_radius); }

    std::string to_string() const override {
        return fmt::format("TentFilter[radius={}]", m_radius);
    }

private:
    float m_inv_radius = 1.f;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::TentFilter, ReconstructionFilter, "tent",
                          "Tent (triangle) pixel filter", DOC, ::facet::AllModes)
