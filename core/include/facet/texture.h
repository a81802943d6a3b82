#pragma once

#include <facet/assert.h>
#include <facet/color.h>
#include <facet/interaction.h>
#include <facet/logger.h>
#include <facet/object.h>
#include <facet/spectrum.h>

#include <memory>
#include <optional>
#include <utility>

namespace facet {

/// A spatially varying quantity, evaluated at a surface interaction (usually by its uv).
class Texture : public Object {
public:
    ObjectType type() const override { return ObjectType::Texture; }
    virtual Color3f eval(const SurfaceInteraction &si) const = 0;
    /// Scalar value (the mean of the channels unless the texture knows better).
    virtual float eval_1(const SurfaceInteraction &si) const { return eval(si).mean(); }
    /// Gradient of eval_1 with respect to the surface's (u, v) (a height field's slope, for bump
    /// mapping). Textures without one throw facet::Error; piecewise constant ones return zero.
    virtual Vector2f eval_1_grad(const SurfaceInteraction &si) const;
    /// Average over the texture's domain.
    virtual Color3f mean() const = 0;
    virtual float max() const { return mean().max(); }
    /// False promises that eval(si) is mean() at every point: BSDFs and emitters may then take
    /// mean() once instead of calling eval() (see BakedTexture).
    virtual bool is_spatially_varying() const { return true; }
    /// Called by the scene loader for every shape whose BSDF or emitter uses this texture
    /// (directly or nested); throws facet::Error when the texture cannot be evaluated on it
    /// (a `mesh_attribute` naming an attribute the shape lacks).
    virtual void check_shape(const Shape &) const {}
    /// Pixel resolution of a texture backed by an image ((1, 1) otherwise); the projector takes
    /// its aspect ratio from it, as in Mitsuba 3.
    virtual Point2i resolution() const { return {1, 1}; }
    /// A hint that eval() is coming at `si` (BSDF::prefetch()): a texture that reads memory the
    /// cache may not hold may start loading it, and returns true when it did. It must not change
    /// any result; the default loads nothing and returns false.
    virtual bool prefetch(const SurfaceInteraction &) const { return false; }

    /// Importance sampling of the texture's domain, uv in [0, 1]², for an area light whose shape
    /// maps [0, 1]² onto its surface (Shape::eval_parameterization). A texture that can sample
    /// builds what it needs here and returns true; the call comes from the emitter before any
    /// render, so textures that only reflect hold nothing for it. The default cannot.
    virtual bool prepare_position_sampling() { return false; }
    /// A uv in [0, 1]² drawn from `u`, with a density over [0, 1]² that is positive wherever
    /// eval() is not zero, and that density (0: no sample). Only after prepare_position_sampling()
    /// returned true.
    virtual std::pair<Point2f, float> sample_position(const Point2f &u) const { return {u, 1.f}; }
    /// The density sample_position() draws `uv` with (0 outside [0, 1]²).
    virtual float pdf_position(const Point2f &uv) const {
        return uv.x >= 0.f && uv.x <= 1.f && uv.y >= 0.f && uv.y <= 1.f ? 1.f : 0.f;
    }
};

/// True for a texture that is present and varies over the surface (sets
/// BSDFFlags::SpatiallyVarying).
inline bool varies(const std::shared_ptr<Texture> &t) { return t && t->is_spatially_varying(); }

/// Texture::prefetch() of `t`, where it is present (false where not).
inline bool prefetch(const std::shared_ptr<Texture> &t, const SurfaceInteraction &si) {
    return t && t->prefetch(si);
}

/// The texture behind a plain number, rgb or spectrum parameter.
class ConstantTexture final : public Texture {
public:
    explicit ConstantTexture(const Color3f &value) : m_value(value) {}
    Color3f eval(const SurfaceInteraction &) const override { return m_value; }
    float eval_1(const SurfaceInteraction &) const override { return m_value.mean(); }
    Vector2f eval_1_grad(const SurfaceInteraction &) const override { return Vector2f(0.f); }
    Color3f mean() const override { return m_value; }
    float max() const override { return m_value.max(); }
    bool is_spatially_varying() const override { return false; }
    std::string to_string() const override;

private:
    Color3f m_value;
};

/// A texture parameter of a BSDF with its constant value baked in: eval() of a texture that is
/// not spatially varying (a plain number or rgb, the common case) is a load and a branch, not a
/// virtual call. The texture itself stays reachable (to_string, mean, gradients).
class BakedTexture {
public:
    BakedTexture() = default;
    explicit BakedTexture(std::shared_ptr<Texture> texture) { *this = std::move(texture); }
    BakedTexture &operator=(std::shared_ptr<Texture> texture) {
        m_texture = std::move(texture);
        m_constant = m_texture && !m_texture->is_spatially_varying();
        if (m_constant) m_value = m_texture->mean();
        return *this;
    }
    Color3f eval(const SurfaceInteraction &si) const {
        return m_constant ? m_value : m_texture->eval(si);
    }
    bool prefetch(const SurfaceInteraction &si) const {
        return !m_constant && m_texture && m_texture->prefetch(si);
    }
    const std::shared_ptr<Texture> &texture() const { return m_texture; }
    const Texture *operator->() const { return m_texture.get(); }
    explicit operator bool() const { return bool(m_texture); }

private:
    std::shared_ptr<Texture> m_texture;
    Color3f m_value;
    bool m_constant = false;
};

/**
 * A constant of the spectral mode: a value that does not vary over the surface but with the
 * wavelength (an rgb or a spectrum a scene gives, upsampled or tabulated). eval() gives it at the
 * interaction's wavelengths. mean() is the colour the rgb mode would use, for heuristics that
 * want one colour (sampling weights, power estimates). is_spatially_varying() is true: eval()
 * depends on the interaction, so BSDFs and emitters must call it.
 */
class SpectralTexture : public Texture {
public:
    explicit SpectralTexture(const Color3f &rgb) : m_rgb(rgb) {}
    /// The value at each of `lambda`'s wavelengths (nm).
    virtual Color3f eval_wavelengths(const Wavelengths &lambda) const = 0;
    Color3f eval(const SurfaceInteraction &si) const final {
        // Wavelengths outside the visible range are ones a caller lost (zero).
        FACET_ASSERT(std::min(std::min(si.wavelengths.r, si.wavelengths.g),
                              std::min(si.wavelengths.b, si.wavelengths.w)) >= 360.f &&
                     si.wavelengths.max() <= 830.f);
        return eval_wavelengths(si.wavelengths);
    }
    /// A scalar parameter given as a colour or spectrum (a weight, an opacity, a roughness)
    /// stays one number: the rgb mode's mean, whatever the path's wavelengths.
    float eval_1(const SurfaceInteraction &) const override { return m_rgb.mean(); }
    Vector2f eval_1_grad(const SurfaceInteraction &) const override { return Vector2f(0.f); }
    Color3f mean() const override { return m_rgb; }
    bool is_spatially_varying() const override { return true; }

protected:
    Color3f m_rgb;
};

/**
 * A parameter that may vary with the wavelength but not over a surface (a point light's
 * intensity), read once from its texture: at(lambda) is a load in rgb and mono, and the value
 * at the path's wavelengths in the spectral mode. Throws facet::Error for a texture that varies
 * over the surface.
 */
class SpectralValue {
public:
    SpectralValue() = default;
    explicit SpectralValue(std::shared_ptr<Texture> texture) {
        m_spectral = std::dynamic_pointer_cast<SpectralTexture>(texture);
        if (!m_spectral && texture->is_spatially_varying())
            FACET_THROW("{} varies over the surface; a constant or a spectrum is needed here",
                        texture->to_string());
        m_value = texture->mean();
    }
    Color3f at(const Wavelengths &lambda) const {
        return m_spectral ? m_spectral->eval_wavelengths(lambda) : m_value;
    }
    /// The rgb mode's colour (exact in rgb and mono).
    const Color3f &mean() const { return m_value; }

private:
    std::shared_ptr<SpectralTexture> m_spectral;
    Color3f m_value;
};

/// The spectral mode's form of an rgb a scene gives for a parameter of kind `kind`
/// (RGBSpectrum::from_rgb).
std::shared_ptr<Texture> rgb_spectrum_texture(const Color3f &rgb, SpectrumKind kind);
/// The spectral mode's form of a spectrum written in a scene: its values per wavelength (linear
/// between the pairs, 0 outside them); a uniform spectrum is a ConstantTexture. `kind` only
/// chooses mean()'s colour.
std::shared_ptr<Texture> data_spectrum_texture(const SpectrumData &data, SpectrumKind kind);

/// The wavelengths (nm) a tabulated spectrum is given at: its first and last, and the smallest
/// spacing between two of them.
struct TabulatedRange {
    double min = 0.0, max = 0.0, resolution = 0.0;
};
/// The range of a texture of the spectral modes made from (wavelength, value) pairs (a value
/// list, an .spd file, `regular`, `irregular`); none for any other texture.
std::optional<TabulatedRange> tabulated_range(const Texture &texture);

/**
 * A spectrum plugin (`<spectrum type="d65">`, uniform, regular, irregular, srgb, blackbody): a
 * constant whose RGB value depends on what it describes, as in Mitsuba's RGB variants (a
 * reflectance is D65-weighted and clamped to [0, 1], an emission only clamped at 0). The
 * parameter that reads it asks for its kind: Properties::texture() and get_color() replace it
 * by a ConstantTexture of value(kind).
 */
class SpectrumTexture : public Texture {
public:
    /// The RGB value for a parameter of kind `kind`; throws facet::Error when the spectrum
    /// cannot describe such a quantity (an srgb reflectance outside [0, 1]).
    virtual Color3f value(SpectrumKind kind) const = 0;
    /// The spectral mode's form for a parameter of kind `kind` (Properties::texture() asks for
    /// it): by default the upsampled value(kind) (rgb_spectrum_texture). Spectra defined per
    /// wavelength (d65, blackbody, regular, ...) return their values at the wavelengths.
    virtual std::shared_ptr<Texture> spectral(SpectrumKind kind) const {
        return rgb_spectrum_texture(value(kind), kind);
    }
    /// Used only where no parameter kind is known: the reflectance conversion.
    Color3f eval(const SurfaceInteraction &) const override {
        return value(SpectrumKind::Reflectance);
    }
    Vector2f eval_1_grad(const SurfaceInteraction &) const override { return Vector2f(0.f); }
    Color3f mean() const override { return value(SpectrumKind::Reflectance); }
    bool is_spatially_varying() const override { return false; }
};

} // namespace facet
