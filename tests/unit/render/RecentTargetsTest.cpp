// gl/RecentTargets.h: which shapes' targets are kept, and that kept ones are freed when they go.
#include <memory>
#include <utility>

#include <gtest/gtest.h>

#include "gl/RecentTargets.h"

namespace gis {
namespace {

// Counts the live instances, as a GL owner's destructor would free its objects.
struct Counted {
    explicit Counted(int* counter, int which) : alive(counter), id(which) { ++*alive; }
    Counted(Counted&& o) noexcept : alive(std::exchange(o.alive, nullptr)), id(o.id) {}
    Counted& operator=(Counted&& o) noexcept {
        if (alive) --*alive;
        alive = std::exchange(o.alive, nullptr);
        id = o.id;
        return *this;
    }
    ~Counted() {
        if (alive) --*alive;
    }
    int* alive;
    int id;
};

using Size = std::pair<int, int>;

TEST(RecentTargets, ASizeUsedBeforeGetsItsOwnTargetsBack) {
    int alive = 0;
    gl::RecentTargets<Size, Counted> recent(4, 1e9);
    EXPECT_FALSE(recent.take({282, 240}).has_value()) << "nothing kept yet";
    recent.keep({282, 240}, Counted(&alive, 1), 282.0 * 240.0);
    recent.keep({254, 216}, Counted(&alive, 2), 254.0 * 216.0);
    EXPECT_EQ(alive, 2);
    std::optional<Counted> back = recent.take({282, 240});
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(back->id, 1);
    EXPECT_FALSE(recent.take({282, 240}).has_value()) << "taken targets are no longer kept";
    EXPECT_EQ(recent.size(), 1u);
    // Keeping a shape again replaces what was kept for it.
    recent.keep({254, 216}, Counted(&alive, 3), 254.0 * 216.0);
    EXPECT_EQ(recent.size(), 1u);
    EXPECT_EQ(recent.take({254, 216})->id, 3);
    back.reset();
    EXPECT_EQ(alive, 0) << "every target was freed once";
}

TEST(RecentTargets, AnExchangeKeepsTheCurrentTargetsAndTakesOrCreatesTheNext) {
    int alive = 0, created = 0;
    {
        gl::RecentTargets<Size, Counted> recent(4, 1e9);
        const auto create = [&] { return Counted(&alive, 100 + created++); };
        // The first shape: nothing current to keep.
        Counted current = recent.exchange({282, 240}, std::nullopt, Counted(&alive, 0), 0.0, create);
        EXPECT_EQ(current.id, 100);
        EXPECT_EQ(recent.size(), 0u);
        current = recent.exchange({254, 216}, Size{282, 240}, std::move(current), 282.0 * 240.0, create);
        EXPECT_EQ(current.id, 101) << "a new shape is created";
        current = recent.exchange({282, 240}, Size{254, 216}, std::move(current), 254.0 * 216.0, create);
        EXPECT_EQ(current.id, 100) << "a shape used before takes its targets back";
        EXPECT_EQ(created, 2);
        EXPECT_EQ(recent.size(), 1u);
        EXPECT_EQ(alive, 2);
    }
    EXPECT_EQ(alive, 0) << "every target was freed once";
}

TEST(RecentTargets, TheOldestGoBeyondTheCountOrTheCost) {
    int alive = 0;
    {
        gl::RecentTargets<Size, Counted> recent(3, 1e9);
        for (int i = 0; i < 5; ++i) recent.keep({100 + i, 100}, Counted(&alive, i), 1.0);
        EXPECT_EQ(recent.size(), 3u);
        EXPECT_EQ(alive, 3) << "the two oldest were freed";
        EXPECT_FALSE(recent.take({100, 100}).has_value());
        EXPECT_FALSE(recent.take({101, 100}).has_value());
        EXPECT_TRUE(recent.take({104, 100}).has_value());
    }
    EXPECT_EQ(alive, 0);
    gl::RecentTargets<Size, Counted> byCost(8, 100.0);
    byCost.keep({1, 1}, Counted(&alive, 1), 60.0);
    byCost.keep({2, 2}, Counted(&alive, 2), 30.0);
    byCost.keep({3, 3}, Counted(&alive, 3), 30.0); // 120 in all: the oldest (60) goes
    EXPECT_EQ(byCost.size(), 2u);
    EXPECT_FALSE(byCost.take({1, 1}).has_value());
    byCost.keep({4, 4}, Counted(&alive, 4), 500.0); // alone over the limit: not kept
    EXPECT_FALSE(byCost.take({4, 4}).has_value());
    EXPECT_EQ(byCost.size(), 2u);
    byCost.clear();
    EXPECT_EQ(alive, 0);
    gl::RecentTargets<Size, Counted> none(0, 1e9);
    none.keep({1, 1}, Counted(&alive, 5), 1.0);
    EXPECT_EQ(none.size(), 0u);
    EXPECT_EQ(alive, 0);
}

// The light maps' limit follows the asked maps (FrameRenderer::ensureTargets): raised, larger
// targets are kept; lowered, those past it go at once.
TEST(RecentTargets, ANewCostLimitKeepsLargerTargetsOrLetsThemGo) {
    int alive = 0;
    gl::RecentTargets<Size, Counted> recent(1, 100.0);
    recent.keep({512, 13}, Counted(&alive, 1), 164.0);
    EXPECT_FALSE(recent.holds({512, 13})) << "past the limit: not kept";
    EXPECT_EQ(alive, 0);
    recent.setMaxKeptCost(164.0);
    recent.keep({512, 13}, Counted(&alive, 2), 164.0);
    EXPECT_TRUE(recent.holds({512, 13}));
    EXPECT_FALSE(recent.holds({256, 13}));
    EXPECT_EQ(alive, 1);
    recent.setMaxKeptCost(200.0);
    EXPECT_TRUE(recent.holds({512, 13})) << "a higher limit lets it stay";
    recent.setMaxKeptCost(100.0);
    EXPECT_FALSE(recent.holds({512, 13})) << "a lower one lets it go at once";
    EXPECT_EQ(alive, 0);
}

} // namespace
} // namespace gis
