#include "stats.h"

#include <cstdio>
#include <cstdlib>
#include <mutex>

namespace facet::stats {

namespace {

/// The counters' names (by index) and every thread's block. Built on first use, so counters
/// of any file may register during static initialisation; never freed (see ThreadCounters).
struct Registry {
    std::mutex mutex;
    std::vector<const char *> names;
    std::vector<ThreadCounters *> blocks;
};

Registry &registry() {
    static Registry *r = new Registry();
    return *r;
}

uint64_t sum(const Registry &r, uint32_t index) {
    uint64_t total = 0;
    for (const ThreadCounters *block : r.blocks)
        total += block->values[index].load(std::memory_order_relaxed);
    return total;
}

} // namespace

ThreadCounters *register_thread() {
    Registry &r = registry();
    auto *block = new ThreadCounters();
    std::lock_guard<std::mutex> lock(r.mutex);
    r.blocks.push_back(block);
    t_thread_counters = block;
    return block;
}

Counter::Counter(const char *name) : m_name(name) {
    Registry &r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    if (r.names.size() >= MaxCounters) {
        // A programming error found at load time, before any logger exists.
        std::fprintf(stderr, "facet: statistics counter \"%s\": more than %u counters\n", name,
                     unsigned(MaxCounters));
        std::abort();
    }
    m_index = uint32_t(r.names.size());
    r.names.push_back(name);
}

uint64_t Counter::total() const {
    Registry &r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    return sum(r, m_index);
}

std::vector<CounterTotal> totals() {
    Registry &r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    std::vector<CounterTotal> result;
    for (uint32_t i = 0; i < uint32_t(r.names.size()); ++i)
        result.push_back({r.names[i], sum(r, i)});
    return result;
}

uint64_t total(std::string_view name) {
    Registry &r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    for (uint32_t i = 0; i < uint32_t(r.names.size()); ++i)
        if (name == r.names[i]) return sum(r, i);
    return 0;
}

} // namespace facet::stats
