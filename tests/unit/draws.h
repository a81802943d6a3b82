// Random draws for tests, in a set order. In `Point2f(rng.next_float(), rng.next_float())` the
// order of the two draws is unspecified (g++ evaluates arguments right to left, clang left to
// right), so a test written that way sees other numbers with each compiler: one draw per
// statement, or these helpers.
#pragma once

#include <facet/random.h>
#include <facet/vector.h>

namespace facet {

/// Two draws as a point, x first.
inline Point2f next_point2f(PCG32 &rng) {
    float x = rng.next_float();
    float y = rng.next_float();
    return Point2f(x, y);
}

/// Three draws as a vector, x first.
inline Vector3f next_vector3f(PCG32 &rng) {
    float x = rng.next_float();
    float y = rng.next_float();
    float z = rng.next_float();
    return Vector3f(x, y, z);
}

} // namespace facet
