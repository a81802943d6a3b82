#include <facet/sampler.h>

namespace facet {

Sampler::Sampler(const Properties &props) {
    int64_t count = props.get_int("sample_count", 4);
    if (count <= 0 || count > int64_t(UINT32_MAX))
        FACET_THROW_AT(props.location("sample_count"),
                       "sample_count must be a positive number of samples per pixel, got {}",
                       count);
    m_sample_count = uint32_t(count);
    int64_t seed = props.get_int("seed", 0);
    m_base_seed = uint64_t(seed);
}

} // namespace facet
