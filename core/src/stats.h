#pragma once

// Statistics counters (private to libfacet, not installed; the facet command reads them): named
// event counts such as the rays Scene traces, kept per thread and summed when read, as pbrt's
// STAT_COUNTER does. Counting is a thread-local increment, no lock and no read-modify-write on
// the hot path; reading is for reports between renders (`facet bench` takes the difference of
// two readings around a render).

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace facet::stats {

/// How many counters the process may define (the size of each thread's block).
constexpr uint32_t MaxCounters = 8;

/// One thread's value of every counter. Written only by its thread, with a relaxed load and a
/// relaxed store (plain moves), read by any thread. A thread gets its block when it first
/// counts; blocks are never freed, so nothing needs destroying when threads or the process end
/// (TBB workers can outlive static destructors).
struct alignas(64) ThreadCounters {
    std::atomic<uint64_t> values[MaxCounters] = {};
};

/// The calling thread's block, null until it first counts. initial-exec: a plain
/// thread-pointer-relative load instead of a __tls_get_addr call per count (libfacet is loaded
/// with the program, or early enough that its few bytes of static TLS fit).
inline thread_local ThreadCounters *t_thread_counters __attribute__((tls_model("initial-exec"))) =
    nullptr;

/// Gives the calling thread its block (once per thread, out of line).
ThreadCounters *register_thread();

/// A named counter, defined at namespace scope in the file that counts:
///     const stats::Counter g_rays("scene.ray_intersect");
///     ... g_rays.add();
class Counter {
public:
    /// Registers the counter under `name`, which must outlive it (a string literal).
    explicit Counter(const char *name);
    Counter(const Counter &) = delete;
    Counter &operator=(const Counter &) = delete;

    void add(uint64_t n = 1) const {
        ThreadCounters *block = t_thread_counters;
        if (__builtin_expect(block == nullptr, 0)) block = register_thread();
        std::atomic<uint64_t> &v = block->values[m_index];
        v.store(v.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
    }
    /// The count so far, all threads together.
    uint64_t total() const;
    const char *name() const { return m_name; }

private:
    const char *m_name;
    uint32_t m_index;
};

struct CounterTotal {
    std::string name;
    uint64_t value = 0;
};
/// Every counter's count so far, all threads together, in the order the counters registered.
std::vector<CounterTotal> totals();
/// The count of the counter named `name`; 0 when no counter has that name.
uint64_t total(std::string_view name);

} // namespace facet::stats
