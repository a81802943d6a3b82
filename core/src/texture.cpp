#include <facet/logger.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

Vector2f Texture::eval_1_grad(const SurfaceInteraction &) const {
    FACET_THROW("{} provides no (u, v) gradient of its value (needed by bumpmap)", to_string());
}

std::string ConstantTexture::to_string() const {
    return fmt::format("ConstantTexture[value=[{}, {}, {}]]", m_value.r, m_value.g, m_value.b);
}

} // namespace facet
