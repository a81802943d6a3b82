#include <facet/assert.h>

#include <cstdio>
#include <cstdlib>

namespace facet::detail {

void assertion_failed(const char *expr, const char *file, int line) {
    std::fprintf(stderr, "%s:%d: assertion failed: %s\n", file, line, expr);
    std::fflush(stderr);
    std::abort();
}

} // namespace facet::detail
