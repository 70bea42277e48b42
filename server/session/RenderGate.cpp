// Render admission: direct hand-off of slots to a FIFO of waiters.
#include "session/RenderGate.h"

#include <stdexcept>

namespace gis {

RenderGate::Permit& RenderGate::Permit::operator=(Permit&& o) noexcept {
    if (this != &o) {
        release();
        mGate = o.mGate;
        o.mGate = nullptr;
    }
    return *this;
}

void RenderGate::Permit::release() noexcept {
    if (mGate) {
        mGate->releaseSlot();
        mGate = nullptr;
    }
}

RenderGate::RenderGate(int capacity) : mCapacity(capacity) {
    if (capacity < 1) throw std::invalid_argument("RenderGate: capacity must be >= 1");
}

void RenderGate::admitLocked() {
    // The slot goes to the waiter, not to whoever grabs the mutex next: that is what keeps a
    // releasing thread from re-acquiring ahead of the queue.
    while (mActive < mCapacity && !mQueue.empty()) {
        Waiter* w = mQueue.front();
        mQueue.pop_front();
        w->granted = true;
        ++mActive;
        w->cv.notify_one();
    }
}

void RenderGate::releaseSlot() noexcept {
    std::lock_guard lock(mMutex);
    --mActive;
    admitLocked();
}

std::optional<RenderGate::Permit> RenderGate::acquire(const std::atomic<bool>& cancel) {
    const auto start = std::chrono::steady_clock::now();
    std::unique_lock lock(mMutex);
    if (cancel.load()) {
        ++mCancelled;
        return std::nullopt;
    }
    if (mQueue.empty() && mActive < mCapacity) {
        ++mActive;
        ++mGranted;
        return Permit(this);
    }
    Waiter self; // lives on this stack frame; only touched under mMutex
    auto pos = mQueue.insert(mQueue.end(), &self);
    while (!self.granted && !cancel.load()) self.cv.wait_for(lock, kCancelPoll);
    if (cancel.load()) {
        ++mCancelled;
        if (self.granted) {
            // Handed a slot as the cancel arrived: pass it on rather than keep a render nobody wants.
            --mActive;
            admitLocked();
        } else {
            mQueue.erase(pos);
        }
        return std::nullopt;
    }
    ++mGranted;
    mWaitTotal += std::chrono::steady_clock::now() - start;
    return Permit(this);
}

std::optional<RenderGate::Permit> RenderGate::tryAcquire() {
    std::lock_guard lock(mMutex);
    if (!mQueue.empty() || mActive >= mCapacity) return std::nullopt;
    ++mActive;
    ++mGranted;
    return Permit(this);
}

void RenderGate::wakeAll() {
    std::lock_guard lock(mMutex);
    for (Waiter* w : mQueue) w->cv.notify_one();
}

void RenderGate::setCapacity(int capacity) {
    if (capacity < 1) throw std::invalid_argument("RenderGate: capacity must be >= 1");
    std::lock_guard lock(mMutex);
    mCapacity = capacity;
    admitLocked();
}

int RenderGate::capacity() const {
    std::lock_guard lock(mMutex);
    return mCapacity;
}

int RenderGate::active() const {
    std::lock_guard lock(mMutex);
    return mActive;
}

int RenderGate::waiting() const {
    std::lock_guard lock(mMutex);
    return static_cast<int>(mQueue.size());
}

std::uint64_t RenderGate::granted() const {
    std::lock_guard lock(mMutex);
    return mGranted;
}

std::uint64_t RenderGate::cancelled() const {
    std::lock_guard lock(mMutex);
    return mCancelled;
}

double RenderGate::waitMsTotal() const {
    std::lock_guard lock(mMutex);
    return std::chrono::duration<double, std::milli>(mWaitTotal).count();
}

} // namespace gis
