// One viewing session: its desired frame state, a render worker (thread + own GL context), and the
// clients attached to it (one controller, any number of viewers; session/ClientLink.h).
//
// Threads: the network thread calls attach/detach, apply, ack and the accessors; the worker renders.
// Input coalesces (the latest camera wins: the desired state is overwritten, never queued). The
// worker renders only when something changed (or a refinement step is due, or a snapshot was asked
// for), the controller is attached and its window has room, and the global RenderGate admits it.
// Every frame is encoded once and offered to every client; each client's window decides whether it
// gets it (protocol/PROTOCOL.md, "Connection flow" and "Adaptive quality").
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "encode/Encoder.h"
#include "gl/Platform.h"
#include "frame/FrameState.h"
#include "session/ClientLink.h"
#include "session/FramePublisher.h"
#include "session/AdaptiveQuality.h"
#include "session/ProtocolMessages.h"
#include "session/SceneCache.h"
#include "session/SceneCatalog.h"
#include "session/SessionLimits.h"
#include "session/VplPartPlanner.h"

namespace gis {

struct TileRect;
namespace reference {
class RayScene;
}

class RenderGate;

/// Server-wide limits a session enforces (protocol `welcome.limits`).
struct SessionConfig {
    gl::Backend backend = gl::Backend::Egl;
    std::string scene = "builtin:cornell";
    std::string technique = "rsm_gather";
    int width = 512, height = 512;
    SessionLimits limits;
};

/// How the controller wants frames (from `hello`).
struct StreamOptions {
    ImageCodec codec = ImageCodec::Jpeg;
    int quality = 85; ///< JPEG/WebP quality [1, 100]
    bool adaptive = true;
    int frameTargetMs = -1; ///< the client's frame-time target; -1: the server's (limits)
};

class Session {
public:
    /// What one rendered frame cost, for the server's metrics (called on the worker thread).
    using FrameObserver = std::function<void(const FrameReport&)>;
    using ErrorObserver = std::function<void(const std::string& code)>;

    /// Loads the configured scene through `scenes`; throws gis::Error if it cannot. `gate` is the
    /// server's admission cap (may be null: no cap). `uploadDir` is the session's sandbox (may be
    /// empty: no uploads).
    Session(std::string id, SessionConfig config, std::shared_ptr<SceneCache> scenes,
            std::shared_ptr<const SceneCatalog> catalog, RenderGate* gate, std::string uploadDir = {});
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    const std::string& id() const { return mId; }
    const std::string& uploadDir() const { return mUploadDir; }
    void setObservers(FrameObserver onFrame, ErrorObserver onError);

    /// Starts the render worker. Call once, after attaching the first controller.
    void start();
    /// Stops and joins the worker (GL resources freed on it); detaches every client; idempotent.
    void stop();

    /// Attaches a client. A controller replaces the previous one (which is closed) and sets the
    /// stream options; the current state is rendered again for it.
    void attach(const std::shared_ptr<ClientLink>& link, const StreamOptions* options = nullptr);
    void detach(const std::shared_ptr<ClientLink>& link);
    bool hasController() const;
    std::size_t viewerCount() const;
    /// Every attached client (the network layer closes them when the session ends).
    std::vector<std::shared_ptr<ClientLink>> clients() const;

    /// Applies one validated steering message from `from` through its handler (messageTypes(): the
    /// `session` rows of protocol/messages.json). Throws ProtocolError; the state is unchanged then.
    void apply(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    /// The message types apply() handles (gi-server checks them against protocol/messages.json).
    static std::vector<std::string> messageTypes();
    /// Sets the viewport (CSS px x dpr, capped by the limits); throws ProtocolError.
    void resize(int cssWidth, int cssHeight, double dpr);
    /// A client acknowledged frame `id`.
    void ack(const std::shared_ptr<ClientLink>& link, std::uint32_t id);

    /// The `state` object of protocol/PROTOCOL.md.
    nlohmann::json stateJson() const;
    StreamOptions streamOptions() const;
    /// Seconds since the controller last steered (idle timeout).
    double idleSeconds() const;
    std::uint64_t framesRendered() const { return mFramesRendered.load(); }
    /// True once the renderer failed (an exception from GL, the encoder or out of memory): the worker
    /// has stopped and the session should end with failure() as its reason. `onFailure` (called on
    /// the worker thread) wakes whoever ends it.
    bool failed() const { return mFailed.load(); }
    std::string failure() const;
    void setFailureObserver(std::function<void()> onFailure) { mOnFailure = std::move(onFailure); }
    /// The scenes this session may load (the catalogue plus its uploads).
    std::vector<std::string> sceneNames() const;

private:
    enum class Step { Interactive, Balanced, Final, Done };
    struct Worker;
    /// Encodes and offers one image to the clients (or to the snapshot's), with its stats; false when
    /// the encoder failed (the session has failed then).
    /// `patch` (a refinement step's canvas): send only that region where every client draws
    /// patches and none has missed one (else the whole image); the canvas stays the image that
    /// later steps and a joining viewer start from.
    bool deliver(Worker& w, const std::vector<std::uint8_t>& rgba, int width, int height,
                 nlohmann::json stats, const std::string& quality, const StreamOptions& stream,
                 const std::shared_ptr<ClientLink>& snapshotFor, ImageCodec snapshotCodec,
                 const TileRect* patch = nullptr);
    /// Renders a balanced or final step in tiles of about limits.sliceMs each, sending the image as
    /// it fills in; a technique with VPL parts (TechniqueInfo::vplParts) renders a tile too slow for
    /// one slice as several parts of its VPLs, sending the tile as its parts add up. Returns at the
    /// first slice boundary after input arrives (Abandoned, progress "abandoned"), when done, Retune
    /// when a smallest tile of a technique without parts overran the slice (the step starts again
    /// with fewer VPLs), or Failed when the renderer failed.
    enum class RefineResult { Done, Abandoned, Retune, Failed };
    struct Rendered; ///< a frame with its queue and render times (Session.cpp)
    enum class RenderStatus { Ok, Stopped, Failed };
    /// One render through the admission gate; Stopped when the session stops while waiting, Failed
    /// (after fail()) when the renderer threw.
    RenderStatus renderAdmitted(Worker& w, const FrameState& state, Rendered& out);
    RefineResult refineInTiles(Worker& w, const FrameState& full, int step, const StreamOptions& stream,
                               const std::string& note);
    /// Starts loading `request` on a thread of its own (Worker::load); the view in place keeps
    /// rendering and answering input until finishLoad swaps the scene in.
    void startLoad(Worker& w, std::string request);
    /// A loaded scene that will not be shown: logged (`what` happened, `why`), and the clients get
    /// the error scene_load_failed.
    void refuseScene(const std::string& request, const char* what, const std::string& why);
    /// Joins the finished load and starts its staged GL upload (continueUpload swaps the scene in:
    /// state message, fresh camera and lights, an interactive frame next), or reports why it failed;
    /// starts the request queued meanwhile instead.
    void finishLoad(Worker& w);
    /// Sends the next slice of a loaded scene's GL upload; swaps the scene in when it is complete.
    void continueUpload(Worker& w);
    /// The effect planner's ray structure of `scene` (Worker::planRays), or null while a thread of
    /// its own builds it (started here when none runs) or when it could not be built (`failed`).
    /// Defined where the effects library is built in (GIS_HAVE_EFFECTS).
    const reference::RayScene* planRaysFor(Worker& w, const std::shared_ptr<const Scene>& scene,
                                           bool& failed);
    /// Levels of detail for the scene shown (Worker::levels): built on a thread of their own the
    /// first time a frame asks for them (FrameRenderer::wantsLevels), handed to the renderer when ready
    /// (frames until then draw every triangle), dropped for the next scene.
    void provideLevels(Worker& w, const FrameState& state);
    /// True when input (or a snapshot, or stop) waits: refinement yields to it.
    bool inputPending() const;
    int frameTargetMs(const StreamOptions& stream) const;
    nlohmann::json stateJsonLocked() const;
    void markInput(); // requires mMutex
    /// What a message did, for apply()'s epilogue: nothing; input (the step starts again); input that
    /// changed the light list (a state message follows); or a snapshot request (not input).
    enum class Applied { Nothing, Input, InputAndLights, Snapshot };
    /// One client message applied to the desired state, with mMutex held; throws ProtocolError or
    /// InputError.
    using MessageHandler = Applied (Session::*)(const nlohmann::json&, const std::shared_ptr<ClientLink>&);
    static const std::map<std::string, MessageHandler>& messageHandlers();
    Applied onCamera(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    Applied onLight(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    Applied onLightAdd(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    Applied onLightRemove(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    Applied onTechnique(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    Applied onParams(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    Applied onResize(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    Applied onScene(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    Applied onQuality(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    Applied onSnapshot(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from);
    /// Throws limit_exceeded ("WHO for up to N VPLsHOW; the server allows M") when `next` asks for more
    /// VPLs than the server allows.
    void checkVplLimit(const FrameState& next, const std::string& who, const std::string& how,
                       const std::string& where, const std::string& request) const;
    /// The viewport (requires mMutex); false when the size did not change.
    bool resizeLocked(int cssWidth, int cssHeight, double dpr);
    bool readyLocked(std::chrono::steady_clock::time_point now) const;
    /// Input, or an adaptive step due (readyLocked less snapshots and whole images sent again).
    bool stepReadyLocked(std::chrono::steady_clock::time_point now) const;
    void workerMain();
    void broadcastText(const nlohmann::json& msg);
    /// A `progress` message (protocol/PROTOCOL.md) to every client: refinement steps and scene loads.
    void broadcastProgress(const char* state, const std::string& step, double share, double etaMs,
                           const std::string& reason);
    void fail(const std::string& reason);

    const std::string mId;
    const SessionConfig mConfig;
    std::shared_ptr<SceneCache> mScenes;
    std::shared_ptr<const SceneCatalog> mCatalog;
    RenderGate* mGate;
    const std::string mUploadDir;
    FrameObserver mOnFrame;
    ErrorObserver mOnError;
    std::function<void()> mOnFailure;
    std::atomic<bool> mFailed{false};
    std::string mFailure; ///< guarded by mMutex

    mutable std::mutex mMutex;
    std::condition_variable mCv;
    FrameState mDesired;
    Camera mSceneCamera; ///< the scene's own camera (state.scene_camera: what "reset camera" returns to)
    nlohmann::json mExplicit = nlohmann::json::object(); ///< parameters the client set (win over presets)
    std::string mSceneName;
    nlohmann::json mSceneLoad; ///< the last scene load's {ms, bytes, triangles} (state.load); null before one
    std::shared_ptr<const Scene> mScene;
    std::string mSceneRequest;
    bool mLoadDone = false; ///< the worker's scene load has ended (Worker::load); guarded by mMutex
    /// A refinement step waits for the planner's ray structure (planRaysFor): not ready to render
    /// until its build ends or input comes. Guarded by mMutex.
    bool mPlanRaysWaited = false;
    /// The frame last shown was rendered without its effect plan (the structure was being built).
    bool mPlanPendingShown = false;
    StreamOptions mStream;
    bool mDirty = true;
    Step mNextStep = Step::Done;
    std::chrono::steady_clock::time_point mLastInput = std::chrono::steady_clock::now();
    /// When the oldest input not yet answered arrived (set as mDirty turns true): stats.input.
    std::chrono::steady_clock::time_point mPendingSince = std::chrono::steady_clock::now();
    std::weak_ptr<ClientLink> mSnapshotFor;
    ImageCodec mSnapshotCodec = ImageCodec::Png;
    struct LastFrame {
        std::uint32_t id = 0;
        nlohmann::json stats;
        std::shared_ptr<const std::string> bytes;
    } mLastFrame; ///< replayed to a viewer that joins a still view (whole frames only)
    /// Patches were sent since mLastFrame: a viewer that joins needs the whole image again.
    bool mPatchedSinceLastFrame = false;
    /// The next image goes out whole (a client missed a patch, or a viewer joined after patches);
    /// when the worker is idle it sends the last image again.
    bool mWholeFrameWanted = false;
    std::shared_ptr<ClientLink> mController;
    /// The `seq` of the controller's last steering message (0: none since it attached).
    std::uint64_t mInputSeq = 0;
    std::vector<std::shared_ptr<ClientLink>> mViewers;
    /// Refinement's VPL-part fits by scene, technique and tile limits (session/VplPartPlanner.h): a
    /// step starts from the last one's instead of a prediction (worker thread only).
    std::map<std::string, VplPartPlanner::Memory> mPartMemory;
    std::atomic<bool> mStop{false};
    std::atomic<std::uint64_t> mFramesRendered{0};
    std::thread mWorker;
};

} // namespace gis
