// Hostile mesh and image files: sizes taken from headers that wrap around, exceed the file or the
// allocation limit, offsets near 2^64, devices given as file names, non-numbers where counts and
// indices belong. Every one must end in a facet::Error naming the file, never in a crash, a read or
// write outside a buffer, or memory exhaustion.
#include <facet/checked.h>
#include <facet/image.h>
#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/texture.h>

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <unistd.h>
#include <zlib.h>

using namespace facet;
namespace fs = std::filesystem;

#define EXPECT_CONTAINS(text, part)                                                                \
    EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

namespace {

/// Restores the allocation limit when a test that lowers it ends.
struct LimitGuard {
    size_t saved = allocation_limit();
    ~LimitGuard() { set_allocation_limit(saved); }
};

} // namespace

// --- the checked arithmetic itself ---------------------------------------------------------------

TEST(CheckedArithmetic, OverflowIsDetected) {
    size_t r = 0;
    EXPECT_TRUE(checked_mul<size_t>(3, 5, r));
    EXPECT_EQ(r, 15u);
    EXPECT_FALSE(checked_mul<size_t>(6148914691236517206ull, 3, r));
    EXPECT_FALSE(checked_add<size_t>(std::numeric_limits<size_t>::max(), 1, r));
    EXPECT_TRUE(checked_add<size_t>(2, 3, r));
    EXPECT_EQ(r, 5u);
    int32_t i = 0;
    EXPECT_FALSE(checked_mul<int32_t>(65536, 65536, i));
    LimitGuard guard;
    set_allocation_limit(1000);
    EXPECT_EQ(allocation_bytes(10, 100, "f", "x"), 1000u);
    EXPECT_THROW(allocation_bytes(11, 100, "f", "x"), Error);
    EXPECT_THROW(allocation_bytes(size_t(1) << 62, 8, "f", "x"), Error);
    try {
        allocation_bytes(11, 100, "mesh.ply:3", "vertex positions");
    } catch (const Error &e) {
        EXPECT_CONTAINS(e.what(), "mesh.ply:3: vertex positions");
    }
}
