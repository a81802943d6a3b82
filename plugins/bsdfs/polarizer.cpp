static const char *DOC = R"DOC(
# polarizer: ideal linear polarizer

A thin sheet that passes light polarised along its transmission axis and absorbs the
perpendicular component (Malus's law: a second polarizer at angle θ to the first passes cos²θ of
what the first passed). Light crosses it without changing direction (a Null lobe, both sides).
In the modes without polarisation it passes half of the light, times `transmittance`.

The transmission axis lies in the surface: at `theta` = 0 it is the shading frame's first
tangent (the u direction of a rectangle or disk), and `theta` turns it from there towards the
negative second tangent (−v): clockwise, seen from the front of the surface. The absorbing axis
is perpendicular to it, at (sin θ, cos θ) in (u, v). For light crossing the sheet obliquely, the
absorbing axis is projected onto the plane perpendicular to the direction of travel.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| theta | float | 0 | Angle of the transmission axis, in degrees |
| transmittance | spectrum or texture | 1 | Scale of the light passed |
| polarizing | boolean | true | false: a neutral filter passing half of the light (an absorber), for comparisons |

```xml
<shape type="rectangle">
    <bsdf type="polarizer">
        <float name="theta" value="45"/>
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

class Polarizer final : public OpticalElement {
public:
    explicit Polarizer(const Properties &props) {
        m_theta = deg_to_rad(props.get_float("theta", 0.f));
        m_transmittance = props.texture("transmittance", 1.f);
        m_polarizing = props.get_bool("polarizing", true);
    }

    std::string to_string() const override {
        return fmt::format("Polarizer[theta = {} deg, transmittance = {}, polarizing = {}]",
                           m_theta * (180.f / Pi), m_transmittance->to_string(), m_polarizing);
    }

protected:
    Color3f unpolarized(const SurfaceInteraction &si) const override {
        return m_transmittance->eval(si) * 0.5f;
    }

    Mueller polarized(const SurfaceInteraction &si, const Vector3f &forward) const override {
        const Color3f t = m_transmittance->eval(si);
        if (!m_polarizing) return Mueller::identity(t * 0.5f);
        // The absorbing axis (the tangent v at theta = 0), projected onto the plane
        // perpendicular to the light; the transmission axis is perpendicular to both.
        const Vector3f absorbing(std::sin(m_theta), std::cos(m_theta), 0.f);
        const Vector3f projected = absorbing - forward * dot(absorbing, forward);
        // Light travelling along the absorbing axis itself (grazing the sheet) passes nothing.
        if (!(dot(projected, projected) > 1e-12f)) return Mueller{};
        const Vector3f a = normalize(projected);
        const Vector3f transmitting = cross(forward, a);
        const Mueller M = mueller::rotate_mueller_basis_collinear(
            mueller::linear_polarizer(), forward, transmitting, mueller::stokes_basis(forward));
        return M * t;
    }

private:
    float m_theta;
    std::shared_ptr<Texture> m_transmittance;
    bool m_polarizing;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Polarizer, BSDF, "polarizer",
                          "Ideal linear polarizer (a thin sheet light crosses)", DOC,
                          ::facet::AllModes)
