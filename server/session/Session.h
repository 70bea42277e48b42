// One client's viewing session: its desired frame state, a render worker (thread + own GL context),
// and the queue of messages going back to the client.
//
// Threads: the network thread calls handleText(), popOutgoing() and stop(); the worker renders.
// Input coalesces (the latest camera wins: the desired state is overwritten, never queued). At most
// one frame is in flight: the worker renders only when the state changed and the previous frame was
// acknowledged. The worker calls `wake` after queueing output so the network loop can write.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "gl/Platform.h"
#include "render/FrameState.h"
#include "session/ProtocolMessages.h"
#include "session/SceneCache.h"

namespace gis {

struct SessionConfig {
    gl::Backend backend = gl::Backend::Egl;
    std::string scene = "builtin:cornell";
    std::string technique = "rsm_gather";
    int width = 512, height = 512;
    int jpegQuality = 85;              ///< [1, 100]
    std::size_t maxQueuedMessages = 64; ///< text messages beyond this are dropped (counted)
};

struct OutgoingMessage {
    bool binary = false;
    std::string data;
};

class Session {
public:
    using Wake = std::function<void()>;
    /// Loads the configured scene through `scenes`; throws gis::Error if it cannot.
    Session(std::string id, SessionConfig config, std::shared_ptr<SceneCache> scenes, Wake wake);
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    const std::string& id() const { return mId; }
    /// Starts the render worker and queues the `welcome` message.
    void start();
    /// Handles one client text message; errors are queued as `error` messages.
    void handleText(std::string_view text);
    /// Queues an error produced by the network layer (oversize, binary input).
    void queueError(const ProtocolError& error);
    bool popOutgoing(OutgoingMessage& out);
    bool hasOutgoing();
    /// Stops and joins the worker; idempotent.
    void stop();

    std::uint64_t framesSent() const { return mFramesSent; }

private:
    void apply(const nlohmann::json& msg);
    void queueText(const nlohmann::json& msg);
    nlohmann::json stateJson() const; // requires mMutex
    void workerMain();

    const std::string mId;
    const SessionConfig mConfig;
    std::shared_ptr<SceneCache> mScenes;
    Wake mWake;

    mutable std::mutex mMutex;
    std::condition_variable mCv;
    FrameState mDesired;
    std::string mSceneName;
    std::shared_ptr<const Scene> mScene;
    std::string mSceneRequest;
    bool mDirty = true;
    bool mInFlight = false;
    std::uint32_t mInFlightFrame = 0;
    bool mStop = false;
    std::deque<OutgoingMessage> mOutgoing;
    std::size_t mDroppedMessages = 0;
    std::uint64_t mFramesSent = 0;
    std::thread mWorker;
};

} // namespace gis
