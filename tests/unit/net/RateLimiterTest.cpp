// RateLimiter: burst, refill, unlimited, clocks going backwards, inexact intervals, threads.
#include <atomic>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "net/RateLimiter.h"

using gis::RateLimiter;

TEST(RateLimiter, BurstThenRefillAtRate) {
    RateLimiter l(2, 3);
    EXPECT_TRUE(l.allow(0.0));
    EXPECT_TRUE(l.allow(0.0));
    EXPECT_TRUE(l.allow(0.0));
    EXPECT_FALSE(l.allow(0.0));
    EXPECT_FALSE(l.allow(0.25)); // half a token
    EXPECT_TRUE(l.allow(0.5));   // one token after 0.5 s at 2/s
    EXPECT_FALSE(l.allow(0.5));
    // A long idle period refills only up to the burst.
    for (int i = 0; i < 3; ++i) EXPECT_TRUE(l.allow(100.0)) << i;
    EXPECT_FALSE(l.allow(100.0));
}

TEST(RateLimiter, ZeroRateIsUnlimited) {
    RateLimiter l(0, 0);
    for (int i = 0; i < 10000; ++i) ASSERT_TRUE(l.allow(0.0));
    EXPECT_TRUE(l.allow());
}

TEST(RateLimiter, TimeGoingBackwardsMintsNoTokens) {
    RateLimiter l(1, 1);
    EXPECT_TRUE(l.allow(100.0));
    EXPECT_FALSE(l.allow(50.0));
    // Only 0.5 s have passed since the last forward reading, whatever happened in between.
    EXPECT_FALSE(l.allow(100.5));
    EXPECT_TRUE(l.allow(101.0));
}

TEST(RateLimiter, InexactIntervalsStillYieldWholeTokens) {
    RateLimiter l(10, 1);
    double t = 0;
    for (int i = 0; i < 1000; ++i, t += 0.1) {
        ASSERT_TRUE(l.allow(t)) << i;
        ASSERT_FALSE(l.allow(t + 0.05)) << i;
    }
}

TEST(RateLimiter, BurstBelowOneStillAdmitsAtRate) {
    RateLimiter l(1, 0.2);
    EXPECT_EQ(l.burst(), 1);
    EXPECT_TRUE(l.allow(0.0));
    EXPECT_FALSE(l.allow(0.5));
    EXPECT_TRUE(l.allow(1.0));
}

TEST(RateLimiter, RejectsInvalidArguments) {
    EXPECT_THROW(RateLimiter(-1, 1), std::invalid_argument);
    EXPECT_THROW(RateLimiter(1, -1), std::invalid_argument);
    EXPECT_THROW(RateLimiter(std::numeric_limits<double>::infinity(), 1), std::invalid_argument);
    EXPECT_THROW(RateLimiter(1, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

TEST(RateLimiter, SteadyClockOverload) {
    RateLimiter l(0.01, 2); // one token per 100 s: the third call cannot have been refilled
    EXPECT_TRUE(l.allow());
    EXPECT_TRUE(l.allow());
    EXPECT_FALSE(l.allow());
}

TEST(RateLimiter, ConcurrentCallersShareOneBucket) {
    RateLimiter l(1, 100);
    std::atomic<int> allowed{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 8; ++t)
        threads.emplace_back([&] {
            for (int i = 0; i < 1000; ++i)
                if (l.allow(5.0)) ++allowed;
        });
    for (auto& t : threads) t.join();
    EXPECT_EQ(allowed.load(), 100);
}
