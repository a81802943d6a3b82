#include <facet/checked.h>
#include <facet/logger.h>

#include <atomic>
#include <cstdlib>

namespace facet {

namespace {

size_t default_limit() {
    constexpr size_t mib = size_t(1) << 20;
    if (const char *env = std::getenv("FACET_ALLOC_LIMIT_MB"); env && *env) {
        char *end = nullptr;
        unsigned long long mb = std::strtoull(env, &end, 10);
        size_t bytes;
        if (end && *end == 0 && mb > 0 && checked_mul(size_t(mb), mib, bytes)) return bytes;
        FACET_LOG(Warn, "FACET_ALLOC_LIMIT_MB=\"{}\" is not a positive number of MiB; ignored",
                  env);
    }
    return size_t(16) << 30;
}

std::atomic<size_t> &limit() {
    static std::atomic<size_t> value{default_limit()};
    return value;
}

} // namespace

size_t allocation_limit() { return limit().load(std::memory_order_relaxed); }

void set_allocation_limit(size_t bytes) { limit().store(bytes, std::memory_order_relaxed); }

size_t allocation_bytes(size_t count, size_t item_size, const std::string &where,
                        const char *what) {
    size_t bytes;
    if (!checked_mul(count, item_size, bytes))
        FACET_THROW("{}: {}: {} items of {} bytes overflow the address space", where, what, count,
                    item_size);
    if (bytes > allocation_limit())
        FACET_THROW("{}: {}: {} items of {} bytes ({:.1f} MiB) exceed the allocation limit of "
                    "{:.1f} MiB (set FACET_ALLOC_LIMIT_MB to raise it)",
                    where, what, count, item_size, double(bytes) / double(1 << 20),
                    double(allocation_limit()) / double(1 << 20));
    return bytes;
}

} // namespace facet
