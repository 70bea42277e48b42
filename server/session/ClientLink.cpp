#include "session/ClientLink.h"

#include <algorithm>
#include <cassert>

namespace gis {

const char* roleName(ClientRole role) {
    return role == ClientRole::Controller ? "controller" : "viewer";
}

ClientLink::ClientLink(ClientRole role, int maxInFlight, Wake wake, std::size_t maxQueuedText,
                       bool acceptsPatches)
    : mRole(role), mMaxInFlight(std::clamp(maxInFlight, 1, 4)), mAcceptsPatches(acceptsPatches),
      mMaxQueuedText(maxQueuedText), mWake(std::move(wake)) {}

bool ClientLink::pushText(std::string text) {
    Wake wake;
    {
        std::lock_guard lock(mMutex);
        if (mClosed) return false;
        const auto texts =
            std::count_if(mQueue.begin(), mQueue.end(), [](const Entry& e) { return e.frame == 0; });
        if (static_cast<std::size_t>(texts) >= mMaxQueuedText) {
            ++mDroppedText;
            return false;
        }
        mQueue.push_back({false, std::make_shared<const std::string>(std::move(text)), 0, false, false});
        wake = mWake;
    }
    if (wake) wake();
    return true;
}

bool ClientLink::offerFrame(std::uint32_t id, std::string stats, std::shared_ptr<const std::string> frame,
                            bool bypassWindow, bool patch) {
    assert(id != 0 && frame);
    assert(!patch || mAcceptsPatches);
    Wake wake;
    {
        std::lock_guard lock(mMutex);
        if (mClosed) return false;
        // A frame whose stats are still queued has not reached the client: the new one replaces it.
        // A pair whose stats already left must be completed, so only whole pairs are removed. A
        // patch replaces nothing: it is drawn over what came before it.
        for (auto it = mQueue.begin(); !patch && it != mQueue.end();) {
            if (it->frameHead && it->replaceable) {
                const std::uint32_t stale = it->frame;
                it = mQueue.erase(it);
                if (it != mQueue.end() && it->frame == stale) it = mQueue.erase(it);
                mInFlight.erase(stale);
                ++mDroppedFrames;
            } else {
                ++it;
            }
        }
        if (!bypassWindow && mInFlight.size() >= static_cast<std::size_t>(mMaxInFlight)) {
            ++mDroppedFrames;
            return false;
        }
        mQueue.push_back(
            {false, std::make_shared<const std::string>(std::move(stats)), id, true, !bypassWindow, patch});
        mQueue.push_back({true, std::move(frame), id, false, false, patch});
        if (!bypassWindow) mInFlight.insert(id);
        mNewestOffered = std::max(mNewestOffered, id);
        ++mOffered;
        wake = mWake;
    }
    if (wake) wake();
    return true;
}

bool ClientLink::ack(std::uint32_t id) {
    std::lock_guard lock(mMutex);
    if (id > mNewestOffered) return false;
    mInFlight.erase(mInFlight.begin(), mInFlight.upper_bound(id));
    return true;
}

std::uint32_t ClientLink::newestOffered() const {
    std::lock_guard lock(mMutex);
    return mNewestOffered;
}

bool ClientLink::windowFull() const {
    std::lock_guard lock(mMutex);
    return mInFlight.size() >= static_cast<std::size_t>(mMaxInFlight);
}

std::size_t ClientLink::inFlight() const {
    std::lock_guard lock(mMutex);
    return mInFlight.size();
}

bool ClientLink::pop(OutgoingMessage& out) {
    std::lock_guard lock(mMutex);
    if (mQueue.empty()) return false;
    out = {mQueue.front().binary, std::move(mQueue.front().data)};
    mQueue.pop_front();
    return true;
}

bool ClientLink::hasOutgoing() const {
    std::lock_guard lock(mMutex);
    return !mQueue.empty();
}

std::uint64_t ClientLink::droppedFrames() const {
    std::lock_guard lock(mMutex);
    return mDroppedFrames;
}

std::uint64_t ClientLink::droppedText() const {
    std::lock_guard lock(mMutex);
    return mDroppedText;
}

std::uint64_t ClientLink::framesOffered() const {
    std::lock_guard lock(mMutex);
    return mOffered;
}

void ClientLink::close() {
    std::lock_guard lock(mMutex);
    mClosed = true;
    mQueue.clear();
    mInFlight.clear();
    mWake = nullptr;
}

bool ClientLink::closed() const {
    std::lock_guard lock(mMutex);
    return mClosed;
}

} // namespace gis
