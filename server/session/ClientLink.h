// One client connection attached to a session: its role, its window of unacknowledged frames and
// the queue of messages waiting for the network thread to write them.
//
// Pacing lives here so that a slow client only ever hurts itself: a frame offered while the
// client's window is full is skipped for that client, and a frame still waiting in the queue is
// replaced by a newer whole frame (latest wins; both are counted as dropped). A patch (a region drawn
// over the frames before it) replaces nothing and is never replaced but by a whole frame, since the
// image would lose its region. Frame bytes are shared between
// clients (encoded once). Thread-safe: the session's worker offers, the network thread pops and acks.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <string>

namespace gis {

enum class ClientRole { Controller, Viewer };
const char* roleName(ClientRole role);

struct OutgoingMessage {
    bool binary = false;
    std::shared_ptr<const std::string> data;
};

class ClientLink {
public:
    using Wake = std::function<void()>;
    /// `maxInFlight` in [1, 4] (the protocol's range); `maxQueuedText` bounds text messages.
    /// `acceptsPatches`: the client said in hello that it draws patches (protocol/PROTOCOL.md).
    ClientLink(ClientRole role, int maxInFlight, Wake wake, std::size_t maxQueuedText = 64,
               bool acceptsPatches = false);

    ClientRole role() const { return mRole; }
    int maxInFlight() const { return mMaxInFlight; }
    bool acceptsPatches() const { return mAcceptsPatches; }

    /// Queues a text message; beyond the text cap it is dropped and counted. Returns false then.
    bool pushText(std::string text);
    /// Offers frame `id` (its stats text and binary message). `bypassWindow` for snapshots, which the
    /// client asked for; `patch` for a region of the image (see the class comment). Returns false
    /// when the frame was skipped because the window is full.
    bool offerFrame(std::uint32_t id, std::string stats, std::shared_ptr<const std::string> frame,
                    bool bypassWindow = false, bool patch = false);
    /// Frees `id` and every older frame from the window (clients may acknowledge only the latest).
    /// False, changing nothing, when no frame `id` was ever offered to this client.
    bool ack(std::uint32_t id);
    /// The newest frame id offered to this client (0: none yet).
    std::uint32_t newestOffered() const;
    bool windowFull() const;
    std::size_t inFlight() const;

    bool pop(OutgoingMessage& out);
    bool hasOutgoing() const;
    /// Frames skipped or replaced for this client; text messages dropped at the cap.
    std::uint64_t droppedFrames() const;
    std::uint64_t droppedText() const;
    std::uint64_t framesOffered() const;

    /// After detach: nothing more is queued, and the worker stops waking the network thread.
    void close();
    bool closed() const;

private:
    struct Entry {
        bool binary = false;
        std::shared_ptr<const std::string> data;
        std::uint32_t frame = 0; ///< 0 for plain text messages
        bool frameHead = false;  ///< the stats half of a frame pair
        bool replaceable = false;
        bool patch = false;
    };
    const ClientRole mRole;
    const int mMaxInFlight;
    const bool mAcceptsPatches;
    const std::size_t mMaxQueuedText;
    Wake mWake;
    mutable std::mutex mMutex;
    std::deque<Entry> mQueue;
    std::set<std::uint32_t> mInFlight;
    std::uint64_t mDroppedFrames = 0;
    std::uint64_t mDroppedText = 0;
    std::uint64_t mOffered = 0;
    std::uint32_t mNewestOffered = 0;
    bool mClosed = false;
};

} // namespace gis
