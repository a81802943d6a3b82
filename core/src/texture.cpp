#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

std::string ConstantTexture::to_string() const {
    return fmt::format("ConstantTexture[value=[{}, {}, {}]]", m_value.r, m_value.g, m_value.b);
}

} // namespace facet
