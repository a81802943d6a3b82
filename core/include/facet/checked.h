#pragma once

#include <cstddef>
#include <string>
#include <type_traits>

namespace facet {

/**
 * Checked arithmetic for sizes that come from files (element counts, image dimensions, offsets).
 * A count read from a file is hostile until checked: multiply and add it only through these,
 * and allocate what it implies only after allocation_bytes() has checked it against the limit.
 */

/// `a * b` in `out`; false (and `out` unspecified) when the product does not fit in T.
template <typename T> [[nodiscard]] inline bool checked_mul(T a, T b, T &out) {
    static_assert(std::is_integral_v<T>, "checked_mul is for integers");
    return !__builtin_mul_overflow(a, b, &out);
}

/// `a + b` in `out`; false (and `out` unspecified) when the sum does not fit in T.
template <typename T> [[nodiscard]] inline bool checked_add(T a, T b, T &out) {
    static_assert(std::is_integral_v<T>, "checked_add is for integers");
    return !__builtin_add_overflow(a, b, &out);
}

/// Largest buffer, in bytes, that a reader allocates for sizes taken from a file: 16 GiB, or
/// $FACET_ALLOC_LIMIT_MB (mebibytes) when set; set_allocation_limit() overrides both.
size_t allocation_limit();
void set_allocation_limit(size_t bytes);

/**
 * Bytes of `count` items of `item_size` bytes each. Throws facet::Error
 * "<where>: <what>: <count> items of <item_size> bytes ..." when the product overflows or
 * exceeds allocation_limit(); `where` names the file (and line), `what` the buffer.
 */
size_t allocation_bytes(size_t count, size_t item_size, const std::string &where, const char *what);

} // namespace facet
