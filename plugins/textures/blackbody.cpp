static const char *DOC = R"DOC(
# blackbody: Planck's black body radiation

The spectral radiance of a black body at `temperature` kelvin, in W·m⁻²·sr⁻¹·nm⁻¹ (so a
scene lit by it is in metres), zero outside [`lambda_min`, `lambda_max`]. Mitsuba's RGB variants
cannot render it; facet integrates Planck's law against the CIE 1931 curves when the scene is
loaded (as for any emission spectrum: unweighted, divided by the integral of ȳ, converted to
linear sRGB and clamped at 0). Meant for emission (an emitter's radiance or intensity).

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| temperature | float | — | Temperature in kelvin (> 0) |
| lambda_min | float | 360 | Lower end of the emitted range (nm) |
| lambda_max | float | 830 | Upper end of the emitted range (nm) |

```xml
<emitter type="area">
    <spectrum type="blackbody" name="radiance">
        <float name="temperature" value="3200"/>
    </spectrum>
</emitter>
```
)DOC";

#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

#include <cmath>

namespace facet {

class BlackBodySpectrum final : public SpectrumTexture {
public:
    explicit BlackBodySpectrum(const Properties &props) {
        if (!props.has("temperature"))
            FACET_THROW_AT(props.location(),
                           "blackbody: the parameter \"temperature\" is required");
        m_temperature = props.get_float("temperature");
        if (!(m_temperature > 0.0) || !std::isfinite(m_temperature))
            FACET_THROW_AT(props.location("temperature"),
                           "blackbody: temperature must be a positive number of kelvin, found {}",
                           m_temperature);
        double lo = props.get_float("lambda_min", 360.0), hi = props.get_float("lambda_max", 830.0);
        if (!(lo < hi) || !(lo >= 0.0) || !std::isfinite(hi))
            FACET_THROW_AT(props.location(),
                           "blackbody: lambda_min ({}) must be below lambda_max ({})", lo, hi);
        // Tabulated finely enough (at most 0.25 nm apart) that the linear interpolation of the
        // CIE integration cannot be told from the exact curve.
        SpectrumData &data = m_data;
        data.uniform = false;
        int n = std::max(2, int(std::ceil((hi - lo) / 0.25)) + 1);
        for (int i = 0; i < n; ++i) {
            double l = lo + (hi - lo) * double(i) / double(n - 1);
            data.wavelengths.push_back(l);
            data.values.push_back(planck(l, m_temperature));
        }
        m_rgb = spectrum_to_rgb(data, SpectrumKind::Emission);
    }

    /// Planck's law: spectral radiance in W·m⁻²·sr⁻¹ per nm at `lambda_nm`.
    static double planck(double lambda_nm, double temperature) {
        constexpr double c = 2.99792458e8, h = 6.62607015e-34, k = 1.380649e-23;
        double l = lambda_nm * 1e-9;
        return 1e-9 * 2.0 * h * c * c /
               (std::pow(l, 5) * std::expm1(h * c / (l * k * temperature)));
    }

    Color3f value(SpectrumKind) const override { return m_rgb; }
    /// Planck's law per wavelength (tabulated every 0.25 nm, linear between), 0 outside
    /// [lambda_min, lambda_max].
    std::shared_ptr<Texture> spectral(SpectrumKind) const override {
        return data_spectrum_texture(m_data, SpectrumKind::Emission);
    }
    std::string to_string() const override {
        return fmt::format("BlackBodySpectrum[temperature = {}, rgb = [{}, {}, {}]]", m_temperature,
                           m_rgb.r, m_rgb.g, m_rgb.b);
    }

private:
    double m_temperature = 0.0;
    SpectrumData m_data;
    Color3f m_rgb;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::BlackBodySpectrum, Texture, "blackbody",
                          "Black body spectrum (Planck's law), converted to RGB at load time", DOC,
                          ::facet::AllModes)
