#pragma once

/**
 * FACET_ASSERT(expr): an invariant of hot code, checked in debug builds only (like pbrt-v4's
 * DCHECK). When NDEBUG is not defined (CMAKE_BUILD_TYPE=Debug) a false `expr` prints
 * "file:line: assertion failed: expr" to stderr and aborts, so a debugger or core dump stops at
 * the culprit. In release builds the expression is not evaluated (but still compiled, so it cannot
 * rot, and variables used only in assertions raise no warnings).
 *
 * For invariants only: bad input from a scene or a user is an error with a message
 * (FACET_THROW, facet/logger.h), in every build.
 */
namespace facet::detail {
[[noreturn]] void assertion_failed(const char *expr, const char *file, int line);
} // namespace facet::detail

#ifdef NDEBUG
#define FACET_ASSERT(expr) ((void)sizeof((expr) ? 1 : 0))
#else
#define FACET_ASSERT(expr)                                                                         \
    ((expr) ? (void)0 : ::facet::detail::assertion_failed(#expr, __FILE__, __LINE__))
#endif
