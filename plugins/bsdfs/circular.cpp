static const char *DOC = R"DOC(
# circular: ideal circular polarizer

A thin sheet that passes right-circularly polarised light (S3 > 0) and absorbs left-circular
light, or the reverse with `left_handed`. Light crosses it without changing direction (a Null
lobe, both sides). In the modes without polarisation it passes half of the light, times
`transmittance`.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| left_handed | boolean | false | Pass left-circular light instead |
| transmittance | spectrum or texture | 1 | Scale of the light passed |

```xml
<shape type="rectangle">
    <bsdf type="circular"/>
</shape>
```
)DOC";

#include "optical_element.h"

#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class CircularPolarizer final : public OpticalElement {
public:
    explicit CircularPolarizer(const Properties &props) {
        m_left = props.get_bool("left_handed", false);
        m_transmittance = props.texture("transmittance", 1.f);
    }

    std::string to_string() const override {
        return fmt::format("CircularPolarizer[left_handed = {}, transmittance = {}]", m_left,
                           m_transmittance->to_string());
    }

protected:
    Color3f unpolarized(const SurfaceInteraction &si) const override {
        return m_transmittance->eval(si) * 0.5f;
    }

    /// A circular polariser looks the same in every frame about the direction of travel.
    Mueller polarized(const SurfaceInteraction &si, const Vector3f &) const override {
        return mueller::circular_polarizer(m_left) * m_transmittance->eval(si);
    }

private:
    bool m_left;
    std::shared_ptr<Texture> m_transmittance;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::CircularPolarizer, BSDF, "circular",
                          "Ideal circular polarizer (a thin sheet light crosses)", DOC,
                          ::facet::AllModes)
