// Owns the service-wide cap on concurrent renders and the fair (FIFO) order in which sessions get them.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <list>
#include <mutex>
#include <optional>

namespace gis {

/// At most capacity() renders run at once across all sessions. Waiters are served strictly in
/// arrival order: a released slot is handed directly to the oldest waiter, so a session that
/// re-queues right after its frame lands behind everyone already waiting and cannot starve them.
///
/// Cancellation: acquire() takes the session's cancel flag. Call wakeAll() after setting it for an
/// immediate return; without that, waiters also re-check the flag every kCancelPoll, so a forgotten
/// wakeAll() costs latency, never a hang.
class RenderGate {
public:
    static constexpr std::chrono::milliseconds kCancelPoll{50};

    /// One running render's slot; releases on destruction. Move-only.
    class Permit {
    public:
        Permit(Permit&& o) noexcept : mGate(o.mGate) { o.mGate = nullptr; }
        Permit& operator=(Permit&& o) noexcept;
        Permit(const Permit&) = delete;
        Permit& operator=(const Permit&) = delete;
        ~Permit() { release(); }

        /// Gives the slot back early; idempotent.
        void release() noexcept;
        bool held() const { return mGate != nullptr; }

    private:
        friend class RenderGate;
        explicit Permit(RenderGate* gate) : mGate(gate) {}
        RenderGate* mGate;
    };

    /// capacity >= 1, else std::invalid_argument.
    explicit RenderGate(int capacity);
    /// Permits hold a pointer to the gate: it must outlive them, and it does not move.
    RenderGate(const RenderGate&) = delete;
    RenderGate& operator=(const RenderGate&) = delete;

    /// Blocks until a slot is handed to this caller (nullopt if `cancel` is or becomes true first;
    /// the caller then leaves the queue, and a slot handed over at the same moment passes on).
    std::optional<Permit> acquire(const std::atomic<bool>& cancel);
    /// A slot now if one is free and nobody is waiting (no queue jumping), else nullopt.
    std::optional<Permit> tryAcquire();
    /// Wakes every waiter to re-check its cancel flag.
    void wakeAll();

    /// Raising it admits waiters at once; lowering it lets running renders finish and admits no one
    /// until active() drops below the new value. capacity >= 1, else std::invalid_argument.
    void setCapacity(int capacity);

    int capacity() const;
    int active() const;
    int waiting() const;
    /// Permits handed out so far.
    std::uint64_t granted() const;
    /// acquire() calls that returned nullopt because of their cancel flag.
    std::uint64_t cancelled() const;
    /// Total time granted acquire() calls spent queued, in milliseconds.
    double waitMsTotal() const;

private:
    struct Waiter {
        std::condition_variable cv;
        bool granted = false;
    };

    void releaseSlot() noexcept;
    void admitLocked(); // hands free slots to the oldest waiters; caller holds mMutex

    mutable std::mutex mMutex;
    int mCapacity;
    int mActive = 0;
    std::list<Waiter*> mQueue; // list: a cancelled waiter leaves from the middle in O(1)
    std::uint64_t mGranted = 0;
    std::uint64_t mCancelled = 0;
    std::chrono::steady_clock::duration mWaitTotal{0};
};

} // namespace gis
