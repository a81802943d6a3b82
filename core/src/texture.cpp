#include <facet/logger.h>
#include <facet/spectral_upsampling.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

Vector2f Texture::eval_1_grad(const SurfaceInteraction &) const {
    FACET_THROW("{} provides no (u, v) gradient of its value (needed by bumpmap)", to_string());
}

std::string ConstantTexture::to_string() const {
    return fmt::format("ConstantTexture[value=[{}, {}, {}]]", m_value.r, m_value.g, m_value.b);
}

namespace {

class RGBSpectrumTexture final : public SpectralTexture {
public:
    RGBSpectrumTexture(const Color3f &rgb, SpectrumKind kind)
        : SpectralTexture(rgb), m_spectrum(RGBSpectrum::from_rgb(rgb, kind)) {}
    Color3f eval_wavelengths(const Wavelengths &lambda) const override {
        return m_spectrum.eval(lambda);
    }
    std::string to_string() const override {
        return fmt::format("RGBSpectrumTexture[rgb=[{}, {}, {}], scale={}, illuminant={}]", m_rgb.r,
                           m_rgb.g, m_rgb.b, m_spectrum.scale, m_spectrum.illuminant);
    }

private:
    RGBSpectrum m_spectrum;
};

class DataSpectrumTexture final : public SpectralTexture {
public:
    DataSpectrumTexture(SpectrumData data, SpectrumKind kind)
        : SpectralTexture(spectrum_to_rgb(data, kind)), m_data(std::move(data)) {}
    Color3f eval_wavelengths(const Wavelengths &lambda) const override {
        return map(lambda, [this](float l) { return float(m_data.eval(l)); });
    }
    std::string to_string() const override {
        return fmt::format("DataSpectrumTexture[{}]", m_data.to_string());
    }
    const SpectrumData &data() const { return m_data; }

private:
    SpectrumData m_data;
};

} // namespace

std::shared_ptr<Texture> rgb_spectrum_texture(const Color3f &rgb, SpectrumKind kind) {
    return std::make_shared<RGBSpectrumTexture>(rgb, kind);
}

std::shared_ptr<Texture> data_spectrum_texture(const SpectrumData &data, SpectrumKind kind) {
    if (data.uniform) return std::make_shared<ConstantTexture>(Color3f(float(data.value)));
    return std::make_shared<DataSpectrumTexture>(data, kind);
}

std::optional<TabulatedRange> tabulated_range(const Texture &texture) {
    const auto *t = dynamic_cast<const DataSpectrumTexture *>(&texture);
    if (!t) return std::nullopt;
    const std::vector<double> &l = t->data().wavelengths;
    if (l.size() < 2) return std::nullopt;
    TabulatedRange r{l.front(), l.back(), l.back() - l.front()};
    for (size_t i = 1; i < l.size(); ++i)
        if (l[i] > l[i - 1]) r.resolution = std::min(r.resolution, l[i] - l[i - 1]);
    return r;
}

} // namespace facet
