// RenderGate: the cap, FIFO order, no starvation by a re-queuing session, cancellation, permits.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "session/RenderGate.h"

using gis::RenderGate;
using namespace std::chrono_literals;

namespace {

bool waitUntil(const std::function<bool()>& pred, std::chrono::milliseconds timeout = 5000ms) {
    auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!pred()) {
        if (std::chrono::steady_clock::now() > deadline) return false;
        std::this_thread::sleep_for(1ms);
    }
    return true;
}

// Worker threads that never outlive a failed assertion: on early exit they are cancelled, woken
// and joined, so a broken gate fails the test instead of hanging it.
struct Crew {
    explicit Crew(RenderGate& g) : gate(g) {}
    ~Crew() {
        abort = true;
        gate.wakeAll();
        join();
    }
    template <class F> void spawn(F&& f) { threads.emplace_back(std::forward<F>(f)); }
    void join() {
        for (auto& t : threads)
            if (t.joinable()) t.join();
    }

    RenderGate& gate;
    std::atomic<bool> abort{false};
    std::vector<std::thread> threads;
};

// Grant order as the holders record it; capacity 1 serialises the records themselves.
struct Log {
    void add(int id) {
        std::lock_guard lock(m);
        order.push_back(id);
    }
    std::vector<int> get() {
        std::lock_guard lock(m);
        return order;
    }
    std::mutex m;
    std::vector<int> order;
};

} // namespace

static_assert(!std::is_copy_constructible_v<RenderGate::Permit>);
static_assert(!std::is_copy_assignable_v<RenderGate::Permit>);
static_assert(std::is_nothrow_move_constructible_v<RenderGate::Permit>);
static_assert(std::is_nothrow_move_assignable_v<RenderGate::Permit>);

TEST(RenderGate, CapacityRespectedUnderContention) {
    RenderGate gate(3);
    Crew crew(gate);
    std::atomic<int> running{0}, maxRunning{0}, done{0};
    constexpr int kThreads = 16, kIters = 30;
    for (int t = 0; t < kThreads; ++t) {
        crew.spawn([&] {
            for (int i = 0; i < kIters; ++i) {
                auto permit = gate.acquire(crew.abort);
                if (!permit) return;
                int now = ++running;
                int seen = maxRunning.load();
                while (now > seen && !maxRunning.compare_exchange_weak(seen, now)) {
                }
                std::this_thread::sleep_for(200us);
                --running;
                ++done;
            }
        });
    }
    ASSERT_TRUE(waitUntil([&] { return done.load() == kThreads * kIters; }, 60s));
    crew.join();
    EXPECT_LE(maxRunning.load(), 3);
    EXPECT_EQ(maxRunning.load(), 3); // hand-off keeps every slot busy while anyone waits
    EXPECT_EQ(gate.granted(), std::uint64_t(kThreads) * kIters);
    EXPECT_EQ(gate.active(), 0);
    EXPECT_EQ(gate.waiting(), 0);
}

TEST(RenderGate, GrantsInFifoOrder) {
    RenderGate gate(1);
    Crew crew(gate);
    Log log;
    auto holder = gate.tryAcquire();
    ASSERT_TRUE(holder);
    constexpr int kWaiters = 6;
    for (int i = 0; i < kWaiters; ++i) {
        crew.spawn([&, i] {
            if (auto p = gate.acquire(crew.abort)) log.add(i);
        });
        // Start the next only once this one is in the queue, so arrival order is known.
        ASSERT_TRUE(waitUntil([&] { return gate.waiting() == i + 1; }));
    }
    holder.reset();
    ASSERT_TRUE(waitUntil([&] { return log.get().size() == kWaiters; }));
    crew.join();
    EXPECT_EQ(log.get(), (std::vector<int>{0, 1, 2, 3, 4, 5}));
}

TEST(RenderGate, ReacquiringSessionGoesBehindWaiters) {
    RenderGate gate(1);
    Crew crew(gate);
    Log log;
    constexpr int kHeavy = 100;
    std::atomic<bool> heavyHolds{false};
    crew.spawn([&] {
        for (int frame = 0; frame < 3; ++frame) {
            auto p = gate.acquire(crew.abort);
            if (!p) return;
            log.add(kHeavy);
            if (frame == 0) {
                heavyHolds = true;
                // Release only once both light sessions are queued behind this frame.
                if (!waitUntil([&] { return gate.waiting() == 2; })) return;
            }
        } // the permit goes and the loop re-queues at once, as a render worker does
    });
    ASSERT_TRUE(waitUntil([&] { return heavyHolds.load(); }));
    for (int i = 0; i < 2; ++i) {
        crew.spawn([&, i] {
            if (auto p = gate.acquire(crew.abort)) {
                log.add(i);
                std::this_thread::sleep_for(5ms); // give the heavy loop every chance to jump ahead
            }
        });
        ASSERT_TRUE(waitUntil([&] { return gate.waiting() == i + 1; }));
    }
    ASSERT_TRUE(waitUntil([&] { return log.get().size() == 5; }));
    crew.join();
    EXPECT_EQ(log.get(), (std::vector<int>{kHeavy, 0, 1, kHeavy, kHeavy}));
}

TEST(RenderGate, TryAcquireDoesNotJumpTheQueue) {
    RenderGate gate(1);
    Crew crew(gate);
    auto holder = gate.tryAcquire();
    ASSERT_TRUE(holder);
    EXPECT_FALSE(gate.tryAcquire());
    std::atomic<bool> got{false}, finish{false};
    crew.spawn([&] {
        auto p = gate.acquire(crew.abort);
        got = p.has_value();
        // Hold the slot, so the check below does not race this thread's release.
        waitUntil([&] { return finish.load(); });
    });
    ASSERT_TRUE(waitUntil([&] { return gate.waiting() == 1; }));
    holder.reset();
    // The freed slot already belongs to the waiter, even if it has not woken up yet.
    EXPECT_FALSE(gate.tryAcquire());
    ASSERT_TRUE(waitUntil([&] { return got.load(); }));
    finish = true;
    crew.join();
    EXPECT_TRUE(gate.tryAcquire());
}

TEST(RenderGate, CancelledWaiterLeavesQueueAndGateStillWorks) {
    RenderGate gate(1);
    Crew crew(gate);
    auto holder = gate.tryAcquire();
    ASSERT_TRUE(holder);
    std::atomic<bool> cancelFirst{false};
    std::atomic<int> firstResult{-1}, secondResult{-1};
    crew.spawn([&] { firstResult = gate.acquire(cancelFirst).has_value() ? 1 : 0; });
    ASSERT_TRUE(waitUntil([&] { return gate.waiting() == 1; }));
    crew.spawn([&] { secondResult = gate.acquire(crew.abort).has_value() ? 1 : 0; });
    ASSERT_TRUE(waitUntil([&] { return gate.waiting() == 2; }));

    cancelFirst = true;
    gate.wakeAll();
    ASSERT_TRUE(waitUntil([&] { return firstResult.load() != -1; }));
    EXPECT_EQ(firstResult.load(), 0);
    EXPECT_EQ(gate.waiting(), 1);
    EXPECT_EQ(gate.cancelled(), 1u);
    EXPECT_EQ(secondResult.load(), -1); // still waiting: the holder has not let go

    // The cancelled waiter was ahead in the queue; it must not hold up the one behind it.
    holder.reset();
    ASSERT_TRUE(waitUntil([&] { return secondResult.load() != -1; }));
    EXPECT_EQ(secondResult.load(), 1);
    crew.join();
    EXPECT_EQ(gate.active(), 0);
    EXPECT_EQ(gate.waiting(), 0);
    auto again = gate.tryAcquire();
    EXPECT_TRUE(again);
    EXPECT_EQ(gate.active(), 1);
}

TEST(RenderGate, CancelIsNoticedWithoutWakeAll) {
    RenderGate gate(1);
    Crew crew(gate);
    auto holder = gate.tryAcquire();
    std::atomic<bool> cancel{false}, returned{false};
    crew.spawn([&] {
        (void)gate.acquire(cancel);
        returned = true;
    });
    ASSERT_TRUE(waitUntil([&] { return gate.waiting() == 1; }));
    cancel = true; // no wakeAll(): the poll interval must pick it up
    EXPECT_TRUE(waitUntil([&] { return returned.load(); }, 2000ms));
    EXPECT_EQ(gate.waiting(), 0);
}

TEST(RenderGate, AlreadyCancelledReturnsAtOnce) {
    RenderGate gate(1);
    std::atomic<bool> cancel{true};
    EXPECT_FALSE(gate.acquire(cancel)); // even with a free slot
    EXPECT_EQ(gate.active(), 0);
    auto holder = gate.tryAcquire();
    EXPECT_FALSE(gate.acquire(cancel));
    EXPECT_EQ(gate.waiting(), 0);
    EXPECT_EQ(gate.cancelled(), 2u);
}

TEST(RenderGate, PermitMoveSemantics) {
    RenderGate gate(2);
    auto a = gate.tryAcquire();
    ASSERT_TRUE(a);
    RenderGate::Permit b = std::move(*a);
    EXPECT_FALSE(a->held());
    EXPECT_TRUE(b.held());
    a.reset(); // a moved-from permit releases nothing
    EXPECT_EQ(gate.active(), 1);

    auto c = gate.tryAcquire();
    ASSERT_TRUE(c);
    EXPECT_EQ(gate.active(), 2);
    EXPECT_FALSE(gate.tryAcquire());
    b = std::move(*c); // b's own slot is released, c's moves in
    EXPECT_EQ(gate.active(), 1);
    EXPECT_FALSE(c->held());
    EXPECT_TRUE(b.held());

    RenderGate::Permit& alias = b;
    b = std::move(alias); // self-move keeps the slot
    EXPECT_TRUE(b.held());
    EXPECT_EQ(gate.active(), 1);

    b.release();
    b.release();
    EXPECT_FALSE(b.held());
    EXPECT_EQ(gate.active(), 0);
    c.reset();
    {
        auto x = gate.tryAcquire();
        auto y = gate.tryAcquire();
        EXPECT_TRUE(x && y);
        EXPECT_FALSE(gate.tryAcquire()); // no double release let a third in
    }
    EXPECT_EQ(gate.active(), 0);
    EXPECT_EQ(gate.granted(), 4u);
}

TEST(RenderGate, RaisingCapacityAdmitsWaiters) {
    RenderGate gate(1);
    Crew crew(gate);
    auto holder = gate.tryAcquire();
    std::atomic<int> admitted{0};
    std::atomic<bool> finish{false};
    for (int i = 0; i < 2; ++i)
        crew.spawn([&] {
            if (auto p = gate.acquire(crew.abort)) {
                ++admitted;
                waitUntil([&] { return finish.load(); });
            }
        });
    ASSERT_TRUE(waitUntil([&] { return gate.waiting() == 2; }));
    gate.setCapacity(3);
    ASSERT_TRUE(waitUntil([&] { return admitted.load() == 2; }));
    EXPECT_EQ(gate.active(), 3);

    gate.setCapacity(1); // running renders finish; nobody new until below 1
    finish = true;
    crew.join();
    EXPECT_EQ(gate.active(), 1);
    EXPECT_FALSE(gate.tryAcquire());
    holder.reset();
    EXPECT_TRUE(gate.tryAcquire());
    EXPECT_THROW(gate.setCapacity(0), std::invalid_argument);
    EXPECT_THROW(RenderGate(0), std::invalid_argument);
}

TEST(RenderGate, AccumulatesWaitTime) {
    RenderGate gate(1);
    Crew crew(gate);
    auto holder = gate.tryAcquire();
    std::atomic<bool> got{false};
    crew.spawn([&] { got = gate.acquire(crew.abort).has_value(); });
    ASSERT_TRUE(waitUntil([&] { return gate.waiting() == 1; }));
    std::this_thread::sleep_for(30ms);
    holder.reset();
    ASSERT_TRUE(waitUntil([&] { return got.load(); }));
    crew.join();
    EXPECT_GE(gate.waitMsTotal(), 30.0);
    EXPECT_LT(gate.waitMsTotal(), 5000.0);
    EXPECT_EQ(gate.granted(), 2u);
}
