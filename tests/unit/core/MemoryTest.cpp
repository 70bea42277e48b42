#include "core/Memory.h"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

namespace gis {
namespace {

constexpr std::size_t kMiB = 1024 * 1024;

TEST(Memory, ResidentSizeIsReadAndFollowsTouchedPages) {
    const auto before = residentBytes();
    ASSERT_TRUE(before.has_value());
    EXPECT_GT(*before, 1 * kMiB);
    std::vector<char> block(64 * kMiB);
    std::memset(block.data(), 1, block.size());
    const auto after = residentBytes();
    ASSERT_TRUE(after.has_value());
    EXPECT_GE(*after, *before + 48 * kMiB);
}

#if defined(__SANITIZE_ADDRESS__)
TEST(Memory, FreedHeapBelowALiveBlockGoesBackToTheSystem) {
    GTEST_SKIP() << "the address sanitizer's allocator keeps freed memory in quarantine";
}
#else
TEST(Memory, FreedHeapBelowALiveBlockGoesBackToTheSystem) {
    // Many small blocks, then one kept above them: free() alone cannot shrink the heap past the
    // live block, so the pages in between stay resident until they are handed back.
    std::vector<std::unique_ptr<char[]>> blocks;
    blocks.reserve(64 * 1024); // no holes from the vector's own growth for the blocks to land in
    for (int i = 0; i < 64 * 1024; ++i) {
        blocks.emplace_back(new char[1000]);
        std::memset(blocks.back().get(), 1, 1000);
    }
    const std::unique_ptr<char[]> pin = std::move(blocks.back()); // the block at the heap's top
    const auto filled = residentBytes();
    ASSERT_TRUE(filled.has_value());
    blocks.clear();
    blocks.shrink_to_fit();
    releaseFreedMemory();
    const auto released = residentBytes();
    ASSERT_TRUE(released.has_value());
    EXPECT_LT(*released + 40 * kMiB, *filled)
        << "resident " << *filled / kMiB << " MiB filled, " << *released / kMiB << " MiB after release";
    pin[0] = 1;
}
#endif

} // namespace
} // namespace gis
