static const char *DOC = R"DOC(
# retarder: linear retarder (wave plate)

A thin sheet that delays the phase of the light polarised along its slow axis by `delta`
degrees against the light along its fast axis: 90 is a quarter-wave plate (light polarised at
45° to the axes leaves circularly polarised), 180 a half-wave plate (it mirrors linear
polarisation about the fast axis). Light crosses it without changing direction (a Null lobe,
both sides). In the modes without polarisation it passes the light, times `transmittance`.

The fast axis lies in the surface: at `theta` = 0 it is the shading frame's first tangent (the u
direction of a rectangle or disk), and `theta` turns it towards the second tangent v
(counter-clockwise seen from the front; note that `polarizer`'s `theta` turns the other way, as
in Mitsuba 3). Light crossing obliquely sees the delay scaled by |cos θ| of its direction, and,
as in Mitsuba 3, the tangent u itself as its reference axis (not projected onto the plane
perpendicular to the light): an approximation for light near the normal.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| theta | float | 0 | Angle of the fast axis, in degrees |
| delta | float | 90 | Phase delay of the slow axis, in degrees |
| transmittance | spectrum or texture | 1 | Scale of the light passed |

```xml
<shape type="rectangle">
    <bsdf type="retarder">
        <float name="theta" value="45"/>
        <float name="delta" value="90"/>
    </bsdf>
</shape>
```
)DOC";

#include "optical_element.h"

#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class Retarder final : public OpticalElement {
public:
    explicit Retarder(const Properties &props) {
        m_theta = deg_to_rad(props.get_float("theta", 0.f));
        m_delta = deg_to_rad(props.get_float("delta", 90.f));
        m_transmittance = props.texture("transmittance", 1.f);
    }

    std::string to_string() const override {
        return fmt::format("Retarder[theta = {} deg, delta = {} deg, transmittance = {}]",
                           m_theta * (180.f / Pi), m_delta * (180.f / Pi),
                           m_transmittance->to_string());
    }

protected:
    Color3f unpolarized(const SurfaceInteraction &si) const override {
        return m_transmittance->eval(si);
    }

    Mueller polarized(const SurfaceInteraction &si, const Vector3f &forward) const override {
        // The axes turn with the frame (x, forward × x) of the light's direction of travel,
        // which is mirrored for light crossing the sheet towards its back.
        Mueller M = mueller::linear_retarder(m_delta * std::abs(Frame::cos_theta(si.wi)));
        M = mueller::rotated_element(forward.z < 0.f ? -m_theta : m_theta, M);
        // The element's frame has the surface's first tangent as its x axis.
        M = mueller::rotate_mueller_basis_collinear(M, forward, Vector3f(1.f, 0.f, 0.f),
                                                    mueller::stokes_basis(forward));
        return M * m_transmittance->eval(si);
    }

private:
    float m_theta, m_delta;
    std::shared_ptr<Texture> m_transmittance;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Retarder, BSDF, "retarder",
                          "Linear retarder, a wave plate (a thin sheet light crosses)", DOC,
                          ::facet::AllModes)
