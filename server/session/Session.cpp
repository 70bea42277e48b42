#include "session/Session.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <exception>
#include <filesystem>
#include <optional>
#include <thread>

#include "core/Error.h"
#include "core/JsonSchema.h"
#include "core/Log.h"
#include "core/Timer.h"
#include "gi/Technique.h"
#include "frame/Exposure.h"
#include "frame/FrameParams.h"
#include "frame/VplBudget.h"
#include "render/FrameRenderer.h"
#include "frame/Presets.h"
#include "job/RenderRequest.h"
#include "frame/StateJson.h"
#include "frame/Tiles.h"
#include "scene/SceneLoader.h"
#include "session/RenderGate.h"
#include "session/VplPartPlanner.h"
#if GIS_HAVE_EFFECTS
#include "effects/EffectPlan.h"
#include "reference/RayScene.h"
#endif

namespace gis {
namespace {

using Clock = std::chrono::steady_clock;

// Refinement tiles: 16 px cells, kMinRefineTileSide at the smallest (session/AdaptiveQuality.h).
constexpr int kTileAlign = 16;
constexpr int kMinTileSide = kMinRefineTileSide;
// Tiles whose VPLs render in parts (FrameState::VplPart): at most 64 x 64 inner pixels or twice the
// guard band (so the guard is not most of what a part renders), fewer when a part's fixed work
// (G-buffer, direct light, composite, read-back) would fill the slice (session/VplPartPlanner.h); at
// most 4096 parts (each at least one VPL).
constexpr int kPartTileSide = 64;
constexpr int kMaxVplParts = 4096;
// The canvas a refinement step starts from is resized in this many bands of rows, input's check
// between them.
constexpr int kCanvasBands = 8;
// A scene load's progress messages: at most one per 100 ms (a load reports every image and mesh).
constexpr double kLoadProgressMs = 100.0;

std::string mebibytes(std::uintmax_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
    return text;
}

const char* stepName(int step) {
    return qualityStepName(static_cast<QualityStep>(step));
}

} // namespace

#if GIS_HAVE_EFFECTS
namespace {
// Camera and light rounded to a tenth of the scene's size and about 6 degrees: moving less than that
// keeps the plan (it is an estimate from a few thousand rays anyway).
std::string effectPlanKey(const Scene& scene, const FrameState& s) {
    const float step = std::max(glm::length(scene.bounds.max - scene.bounds.min), 1e-3f) * 0.1f;
    auto q = [](glm::vec3 v, float unit) {
        return nlohmann::json::array(
            {std::lround(v.x / unit), std::lround(v.y / unit), std::lround(v.z / unit)});
    };
    auto dir = [](glm::vec3 v) {
        const float l = glm::length(v);
        return l > 1e-12f ? v / l : glm::vec3(0.0f, 0.0f, -1.0f);
    };
    return nlohmann::json{
        {"scene", scene.name},
        // The same name can be a new scene (an upload replaced under its name).
        {"scene_object", reinterpret_cast<std::uintptr_t>(&scene)},
        {"technique", s.technique},
        {"params", s.techniqueParams.toJson()},
        {"frame", s.frameParams.toJson()},
        {"camera", {q(s.camera.position, step), q(dir(s.camera.target - s.camera.position), 0.1f)}},
        {"lights",
         [&] {
             nlohmann::json lights = nlohmann::json::array();
             for (const FrameLight& l : s.lights)
                 lights.push_back({l.id, static_cast<int>(l.light.type), q(l.light.position, step),
                                   q(dir(l.light.direction), 0.1f), l.enabled, l.light.intensity,
                                   l.light.color.r, l.light.color.g, l.light.color.b, l.light.range,
                                   l.light.outerConeAngle});
             return lights;
         }()}}
        .dump();
}
} // namespace
#endif

Session::Session(std::string id, SessionConfig config, std::shared_ptr<SceneCache> scenes,
                 std::shared_ptr<const SceneCatalog> catalog, RenderGate* gate, std::string uploadDir)
    : mId(std::move(id)), mConfig(std::move(config)), mScenes(std::move(scenes)),
      mCatalog(std::move(catalog)), mGate(gate), mUploadDir(std::move(uploadDir)) {
    mScene = mScenes->get(mConfig.scene);
    mSceneName = mConfig.scene;
    mDesired = makeFrameState(*mScene, mConfig.technique);
    mDesired.width = mConfig.width;
    mDesired.height = mConfig.height;
    mSceneCamera = mDesired.camera;
}

Session::~Session() {
    stop();
}

void Session::setObservers(FrameObserver onFrame, ErrorObserver onError) {
    std::lock_guard lock(mMutex);
    mOnFrame = std::move(onFrame);
    mOnError = std::move(onError);
}

nlohmann::json Session::stateJsonLocked() const {
    return {{"scene", mSceneName},
            {"technique", mDesired.technique},
            {"params", paramsJson(mDesired)},
            {"size", {mDesired.width, mDesired.height}},
            {"camera", cameraJson(mDesired.camera)},
            {"light", lightJson(mDesired)},
            {"lights", lightsJson(mDesired)},
            {"lighting",
             {{"source", mDesired.lightSource},
              {"note", mDesired.lightNote},
              {"exposure", baseExposureJson(mDesired)}}},
            {"scene_camera", cameraJson(mSceneCamera)},
            {"load", mSceneLoad.is_null() ? nlohmann::json(nullptr) : mSceneLoad},
            {"bounds",
             {{"min", {mScene->bounds.min.x, mScene->bounds.min.y, mScene->bounds.min.z}},
              {"max", {mScene->bounds.max.x, mScene->bounds.max.y, mScene->bounds.max.z}}}}};
}

nlohmann::json Session::stateJson() const {
    std::lock_guard lock(mMutex);
    return stateJsonLocked();
}

StreamOptions Session::streamOptions() const {
    std::lock_guard lock(mMutex);
    return mStream;
}

double Session::idleSeconds() const {
    std::lock_guard lock(mMutex);
    return std::chrono::duration<double>(Clock::now() - mLastInput).count();
}

std::vector<std::string> Session::sceneNames() const {
    return mCatalog ? mCatalog->list(mUploadDir) : std::vector<std::string>{mConfig.scene};
}

void Session::start() {
    mWorker = std::thread([this] {
        // Nothing the renderer throws may leave the thread (std::terminate would end every session):
        // the session fails alone and the network layer ends it with the reason.
        try {
            workerMain();
        } catch (const std::exception& e) {
            fail(std::string("the renderer stopped: ") + e.what());
        } catch (...) {
            fail("the renderer stopped on an unknown error");
        }
    });
}

void Session::stop() {
    {
        // Under the mutex: the worker tests mStop and then waits while holding it, so a store
        // without the lock could fall between the two and the notify below would be lost.
        std::lock_guard lock(mMutex);
        mStop = true;
    }
    if (mGate) mGate->wakeAll();
    mCv.notify_all();
    if (mWorker.joinable()) mWorker.join();
    std::lock_guard lock(mMutex);
    if (mController) mController->close();
    for (auto& v : mViewers) v->close();
    mController.reset();
    mViewers.clear();
}

void Session::attach(const std::shared_ptr<ClientLink>& link, const StreamOptions* options) {
    {
        std::lock_guard lock(mMutex);
        if (link->role() == ClientRole::Controller) {
            if (mController && mController != link) mController->close();
            mController = link;
            mInputSeq = 0; // a new connection numbers its messages afresh
            if (options) mStream = *options;
            // A new or resumed controller has seen nothing yet: render the current state for it.
            markInput();
        } else {
            mViewers.push_back(link);
            // Patches sent since the last whole frame would be missing from this viewer's image: the
            // worker sends the current one whole instead (replaying the old one would fill the
            // viewer's window and crowd it out).
            if (mPatchedSinceLastFrame) {
                mWholeFrameWanted = true;
            } else if (mLastFrame.bytes) {
                nlohmann::json stats = mLastFrame.stats;
                stats["viewers"] = mViewers.size();
                stats["dropped_frames"] = 0;
                link->offerFrame(mLastFrame.id, stats.dump(), mLastFrame.bytes);
            }
        }
    }
    mCv.notify_all();
}

void Session::detach(const std::shared_ptr<ClientLink>& link) {
    {
        std::lock_guard lock(mMutex);
        if (mController == link) mController.reset();
        std::erase(mViewers, link);
    }
    link->close();
    mCv.notify_all();
}

bool Session::hasController() const {
    std::lock_guard lock(mMutex);
    return mController != nullptr;
}

std::size_t Session::viewerCount() const {
    std::lock_guard lock(mMutex);
    return mViewers.size();
}

std::vector<std::shared_ptr<ClientLink>> Session::clients() const {
    std::lock_guard lock(mMutex);
    std::vector<std::shared_ptr<ClientLink>> out = mViewers;
    if (mController) out.push_back(mController);
    return out;
}

void Session::markInput() {
    mPlanRaysWaited = false; // the step that waited is replaced; the next one asks again
    if (!mDirty) mPendingSince = Clock::now();
    mDirty = true;
    mNextStep = Step::Interactive;
    mLastInput = Clock::now();
}

void Session::ack(const std::shared_ptr<ClientLink>& link, std::uint32_t id) {
    if (!link->ack(id))
        throw ProtocolError{"invalid_message",
                            "frame " + std::to_string(id) +
                                " was never sent on this connection (the newest is " +
                                std::to_string(link->newestOffered()) + ")",
                            "/frame", "ack"};
    // The worker reads the window while holding mMutex; passing through it orders this ack before
    // the worker's next check or after its wait began, so the notify cannot be lost.
    { std::lock_guard lock(mMutex); }
    mCv.notify_all();
}

bool Session::resizeLocked(int cssWidth, int cssHeight, double dpr) {
    const double w = std::max(1.0, std::round(cssWidth * dpr));
    const double h = std::max(1.0, std::round(cssHeight * dpr));
    // Scale down to fit the server's limit, keeping the aspect ratio; never below the 16 px minimum.
    const double fit = std::min({1.0, mConfig.limits.maxWidth / w, mConfig.limits.maxHeight / h});
    const int width = std::clamp(static_cast<int>(std::floor(w * fit)), 16, mConfig.limits.maxWidth);
    const int height = std::clamp(static_cast<int>(std::floor(h * fit)), 16, mConfig.limits.maxHeight);
    if (width == mDesired.width && height == mDesired.height) return false;
    mDesired.width = width;
    mDesired.height = height;
    return true;
}

void Session::resize(int cssWidth, int cssHeight, double dpr) {
    {
        std::lock_guard lock(mMutex);
        if (!resizeLocked(cssWidth, cssHeight, dpr)) return;
        markInput();
    }
    mCv.notify_all();
}

const std::map<std::string, Session::MessageHandler>& Session::messageHandlers() {
    static const std::map<std::string, MessageHandler> handlers = {
        {"camera", &Session::onCamera},       {"light", &Session::onLight},
        {"light_add", &Session::onLightAdd},  {"light_remove", &Session::onLightRemove},
        {"technique", &Session::onTechnique}, {"params", &Session::onParams},
        {"resize", &Session::onResize},       {"scene", &Session::onScene},
        {"quality", &Session::onQuality},     {"snapshot", &Session::onSnapshot}};
    return handlers;
}

std::vector<std::string> Session::messageTypes() {
    std::vector<std::string> out;
    for (const auto& [type, handler] : messageHandlers()) out.push_back(type);
    return out;
}

void Session::apply(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from) {
    const std::string type = msg["type"];
    const auto handler = messageHandlers().find(type);
    if (handler == messageHandlers().end())
        throw ProtocolError{"unknown_type", "'" + type + "' does not steer a session", "/type", type};
    std::unique_lock lock(mMutex);
    // The controller numbers its steering messages (`seq`); frames echo the last one their state
    // includes (stats.input_seq), so the client knows which of its inputs a frame shows. A refused
    // message counts too: every frame after it is as it asked, unchanged.
    if (from == mController && msg.contains("seq")) mInputSeq = msg["seq"].get<std::uint64_t>();
    Applied applied = Applied::Nothing;
    try {
        applied = (this->*handler->second)(msg, from);
    } catch (const InputError& e) {
        throw ProtocolError{"invalid_message", e.reason(), e.where(), type};
    }
    if (applied == Applied::Nothing) return;
    if (applied != Applied::Snapshot) markInput();
    nlohmann::json stateMsg;
    // light_add and light_remove answer with the new state (its ids).
    if (applied == Applied::InputAndLights) stateMsg = {{"type", "state"}, {"state", stateJsonLocked()}};
    lock.unlock();
    mCv.notify_all();
    if (applied == Applied::InputAndLights) broadcastText(stateMsg);
}

void Session::checkVplLimit(const FrameState& next, const std::string& who, const std::string& how,
                            const std::string& where, const std::string& request) const {
    const long vpls = vplEstimate(next);
    if (vpls > mConfig.limits.maxVpls)
        throw ProtocolError{"limit_exceeded",
                            who + " for up to " + std::to_string(vpls) + " VPLs" + how +
                                "; the server allows " + std::to_string(mConfig.limits.maxVpls),
                            where, request};
}

Session::Applied Session::onCamera(const nlohmann::json& msg, const std::shared_ptr<ClientLink>&) {
    applyCameraJson(mDesired, msg, "");
    return Applied::Input;
}

Session::Applied Session::onLight(const nlohmann::json& msg, const std::shared_ptr<ClientLink>&) {
    try {
        applyLightJson(mDesired, msg, "");
    } catch (const InputError& e) {
        if (e.reason().rfind("no light '", 0) == 0)
            throw ProtocolError{"unknown_light", e.reason() + "; add one with a light_add message", e.where(),
                                "light"};
        throw;
    }
    return Applied::Input;
}

Session::Applied Session::onLightAdd(const nlohmann::json& msg, const std::shared_ptr<ClientLink>&) {
    addLightJson(mDesired, msg.value("light", nlohmann::json::object()), "/light");
    return Applied::InputAndLights;
}

Session::Applied Session::onLightRemove(const nlohmann::json& msg, const std::shared_ptr<ClientLink>&) {
    try {
        removeLight(mDesired, msg["id"].get<std::string>(), "/id");
    } catch (const InputError& e) {
        throw ProtocolError{"unknown_light", e.reason(), e.where(), "light_remove"};
    }
    return Applied::InputAndLights;
}

Session::Applied Session::onTechnique(const nlohmann::json& msg, const std::shared_ptr<ClientLink>&) {
    FrameState next = mDesired;
    try {
        setTechnique(next, msg["name"], "/name");
    } catch (const InputError& e) {
        throw ProtocolError{"unknown_technique", e.reason(), "/name", "technique"};
    }
    checkVplLimit(next, "technique '" + next.technique + "' asks", " by default", "/name", "technique");
    // Explicit technique parameters belonged to the previous technique.
    for (auto it = mExplicit.begin(); it != mExplicit.end();)
        it = next.frameParams.has(it.key()) ? std::next(it) : mExplicit.erase(it);
    mDesired = std::move(next);
    return Applied::Input;
}

Session::Applied Session::onParams(const nlohmann::json& msg, const std::shared_ptr<ClientLink>&) {
    FrameState next = mDesired;
    try {
        applyParams(next, msg["values"], "/values");
    } catch (const InputError& e) {
        throw ProtocolError{"invalid_param", e.reason(), e.where(), "params"};
    }
    checkVplLimit(next, "these parameters ask", "", "/values", "params");
    mDesired = std::move(next);
    for (const auto& [k, v] : msg["values"].items()) mExplicit[k] = v;
    return Applied::Input;
}

Session::Applied Session::onResize(const nlohmann::json& msg, const std::shared_ptr<ClientLink>&) {
    return resizeLocked(msg["size"][0], msg["size"][1], msg.value("dpr", 1.0)) ? Applied::Input
                                                                               : Applied::Nothing;
}

Session::Applied Session::onScene(const nlohmann::json& msg, const std::shared_ptr<ClientLink>&) {
    const std::string name = msg["name"];
    if (mCatalog) {
        try {
            (void)mCatalog->resolve(name, mUploadDir);
        } catch (const InputError& e) {
            throw ProtocolError{"unknown_scene", e.reason(), "/name", "scene"};
        }
    } else if (name != mConfig.scene) {
        throw ProtocolError{"unknown_scene", "unknown scene '" + name + "'", "/name", "scene"};
    }
    mSceneRequest = name;
    return Applied::Input;
}

Session::Applied Session::onQuality(const nlohmann::json& msg, const std::shared_ptr<ClientLink>&) {
    mStream.adaptive = msg["adaptive"].get<bool>();
    if (msg.contains("frame_target_ms")) mStream.frameTargetMs = msg["frame_target_ms"].get<int>();
    return Applied::Input;
}

Session::Applied Session::onSnapshot(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from) {
    mSnapshotFor = from;
    // The schema admits only lossless codecs (protocol/schema/snapshot.json).
    mSnapshotCodec = parseImageCodec(msg.value("codec", "png"), "/codec");
    return Applied::Snapshot;
}

void Session::fail(const std::string& reason) {
    logError("session " + mId + ": " + reason);
    {
        std::lock_guard lock(mMutex);
        if (mFailure.empty()) mFailure = reason;
    }
    mFailed = true;
    if (mOnError) mOnError("render_failed");
    if (mOnFailure) mOnFailure();
}

std::string Session::failure() const {
    std::lock_guard lock(mMutex);
    return mFailure;
}

void Session::broadcastText(const nlohmann::json& msg) {
    const std::string text = msg.dump();
    for (const auto& c : clients()) c->pushText(text);
}

bool Session::readyLocked(Clock::time_point now) const {
    if (!mSnapshotFor.expired()) return true;
    if (!mController || mController->windowFull()) return false;
    return mWholeFrameWanted || stepReadyLocked(now);
}

bool Session::stepReadyLocked(Clock::time_point now) const {
    if (mDirty) return true;
    if (mPlanRaysWaited) return false;
    if (!mStream.adaptive || mNextStep == Step::Done || mNextStep == Step::Interactive) return false;
    return mNextStep != Step::Balanced ||
           now >= mLastInput + std::chrono::milliseconds(mConfig.limits.settleMs);
}

struct Session::Worker {
    std::unique_ptr<FrameRenderer> renderer;
    std::shared_ptr<const Scene> scene;
    std::uint32_t frameId = 0;
    /// Which state each step renders, and what the steps measured (session/AdaptiveQuality.h).
    std::unique_ptr<AdaptiveQuality> quality;
    /// The last image sent to the controller (RGBA8): the canvas a tiled step starts from.
    std::vector<std::uint8_t> lastImage;
    int lastWidth = 0, lastHeight = 0;
    /// The controller's last steering `seq` included in the state being rendered (0: none).
    std::uint64_t stateSeq = 0;
    /// A refinement step's image so far (refineInTiles), kept between steps for its allocation.
    std::vector<std::uint8_t> canvas;
    /// Its stats and step: what a whole image sent again (Session::mWholeFrameWanted) carries.
    nlohmann::json lastStats;
    std::string lastQuality;
    /// A scene loading on a thread of its own (file, decoding, finishing: no GL), so the view in
    /// place keeps answering input; the worker swaps it in when the thread is done (finishLoad).
    struct Load {
        std::string request;                ///< the scene as the client named it
        std::atomic<bool> cancelled{false}; ///< a newer scene was asked for: stop at the next check
        std::thread thread;                 ///< joined by finishLoad or ~Worker
        std::shared_ptr<const Scene> scene; ///< the thread's result, with
        std::shared_ptr<const SceneGpu::Prepared> gpu; ///< its upload built (no GL), or
        std::exception_ptr error;                      ///< why it failed
        nlohmann::json info;                           ///< state.load: ms, bytes, triangles, ...
    };
    std::unique_ptr<Load> load;
    std::string queuedRequest; ///< asked for while `load` ran: started when it ends (the newer wins)
    /// A loaded scene whose GL upload is under way: sent in slices of about limits.sliceMs between
    /// frames (continueUpload), so that input is answered meanwhile; swapped in when complete.
    struct Upload {
        std::string request;
        std::shared_ptr<const Scene> scene; ///< what the pieces read: kept until the swap
        std::unique_ptr<SceneGpu> gpu;
        nlohmann::json info;       ///< state.load, completed by the upload's figures
        double renderThreadMs = 0; ///< every slice together
        double longestSliceMs = 0;
        int slices = 0;
    };
    std::unique_ptr<Upload> upload;
    /// The effect planner's ray structure of the scene shown, built on a thread of its own the first
    /// time a frame asks for a plan and kept while that scene is shown: a plan then costs its rays
    /// (milliseconds) rather than the structure's build (0.5-0.8 s at 2M triangles). planRaysFor.
    struct PlanRays {
        std::shared_ptr<const Scene> scene;
        std::atomic<bool> cancelled{false}; ///< its scene is no longer shown, or the session ends
        std::thread thread;
        /// Set last by the thread (under Session::mMutex, with the wake-up of a step that waits).
        std::atomic<bool> done{false};
        std::shared_ptr<const reference::RayScene> rays; ///< the thread's result, or
        std::string error;                               ///< why there is none
        double buildMs = 0.0;
    };
    std::unique_ptr<PlanRays> planRays;
    /// Builds for a scene no longer shown: joined once done (or when the session ends).
    std::vector<std::unique_ptr<PlanRays>> retiredPlanRays;
    /// The levels of detail of the scene shown (SceneGpu::prepareLevels: 0.25-0.35 s for the atrium's
    /// 560k triangles, several times its load), built on a thread of their own so that a new scene
    /// shows at once and input is answered meanwhile; provideLevels.
    struct Levels {
        std::shared_ptr<const Scene> scene;
        std::atomic<bool> cancelled{false}; ///< its scene is no longer shown, or the session ends
        std::atomic<bool> done{false};
        std::thread thread;
        std::shared_ptr<const SceneGpu::LodSet> set; ///< the thread's result (null: cancelled)
        double buildMs = 0.0;
        bool handed = false; ///< given to the renderer
    };
    std::unique_ptr<Levels> levels;
    std::vector<std::unique_ptr<Levels>> retiredLevels;
    /// Lets go of a build (PlanRays, Levels) for a scene no longer shown: one still running is
    /// cancelled and joined later (joinFinished), never waited for.
    template <typename Build>
    static void drop(std::unique_ptr<Build>& build, std::vector<std::unique_ptr<Build>>& retired) {
        if (!build) return;
        if (build->thread.joinable() && !build->done) {
            build->cancelled = true;
            retired.push_back(std::move(build));
            return;
        }
        if (build->thread.joinable()) build->thread.join();
        build.reset();
    }
    template <typename Build> static void joinFinished(std::vector<std::unique_ptr<Build>>& retired) {
        std::erase_if(retired, [](std::unique_ptr<Build>& b) {
            if (!b->done) return false;
            if (b->thread.joinable()) b->thread.join();
            return true;
        });
    }
    /// The session ends: builds stop at their next check, and the teardown joins them.
    template <typename Build>
    static void cancelAndJoin(std::unique_ptr<Build>& build, std::vector<std::unique_ptr<Build>>& retired) {
        if (build) retired.push_back(std::move(build));
        for (auto& b : retired) b->cancelled = true;
        for (auto& b : retired)
            if (b->thread.joinable()) b->thread.join();
    }
    ~Worker() {
        if (load && load->thread.joinable()) {
            load->cancelled = true; // the session ends: a long load must not hold its teardown
            load->thread.join();
        }
        // Builds stop at their next check (Embree's progress, the next mesh): the teardown does not
        // wait for them to finish.
        cancelAndJoin(planRays, retiredPlanRays);
        cancelAndJoin(levels, retiredLevels);
    }
};

void Session::provideLevels(Worker& w, const FrameState& state) {
    Worker::joinFinished(w.retiredLevels);
    const std::shared_ptr<const Scene> shown = w.scene;
    if (w.levels && w.levels->scene != shown) Worker::drop(w.levels, w.retiredLevels);
    if (!shown) return;
    if (!w.levels) {
        if (!FrameRenderer::wantsLevels(state)) return; // not asked for yet
        auto build = std::make_unique<Worker::Levels>();
        build->scene = shown;
        // Another session on this scene built them already.
        if (auto shared = mScenes->levels(shown)) {
            build->set = std::move(shared);
            build->done = true;
            build->handed = true;
            w.renderer->setSceneLevels(build->set);
            w.levels = std::move(build);
            logInfo("session " + mId + ": the levels of detail for " + validUtf8(shown->name) +
                    " are shared with another session");
            return;
        }
        Worker::Levels* raw = build.get();
        build->thread = std::thread([this, raw] {
            const Stopwatch clock;
            try {
                raw->set = SceneGpu::prepareLevels(
                    *raw->scene, [this, raw] { return raw->cancelled.load() || mStop.load(); });
            } catch (const std::exception& e) {
                logWarn("session " + mId + ": no levels of detail (" + e.what() +
                        "): every triangle is drawn");
            }
            raw->buildMs = clock.elapsedMs();
            raw->done = true;
        });
        w.levels = std::move(build);
        return;
    }
    if (w.levels->handed || !w.levels->done) return;
    w.levels->thread.join();
    w.levels->handed = true;
    if (!w.levels->set) return;
    w.renderer->setSceneLevels(w.levels->set);
    mScenes->keepLevels(shown, w.levels->set);
    logInfo("session " + mId + ": levels of detail for " + validUtf8(shown->name) + " built in " +
            std::to_string(std::lround(w.levels->buildMs)) + " ms (" +
            std::to_string(w.levels->set->triangles) + " triangles)");
}

void Session::startLoad(Worker& w, std::string request) {
    w.load = std::make_unique<Worker::Load>();
    Worker::Load* load = w.load.get();
    load->request = std::move(request);
    // The thread touches only the load record, the scene cache and the clients' outboxes; the
    // worker joins it before reading the record (finishLoad) or before the session ends (~Worker).
    load->thread = std::thread([this, load] {
        const std::string& name = load->request;
        try {
            const std::string path = mCatalog ? mCatalog->resolve(name, mUploadDir) : name;
            std::error_code sizeError;
            const auto bytes = std::filesystem::file_size(path, sizeError);
            const std::string sizeText = sizeError ? std::string() : " (" + mebibytes(bytes) + ")";
            // The client shows that a load is under way (a large file takes seconds) and what it
            // cost; the scene cache answers at once for a scene another session holds.
            broadcastProgress("loading", "scene", 0.0, 0.0, "loading " + validUtf8(name) + sizeText);
            Stopwatch loadClock;
            SceneLoadOptions loadOptions = mCatalog ? mCatalog->loadOptions(name) : SceneLoadOptions{};
            // Where a long load is, at most every kLoadProgressMs: the bytes read, the images
            // decoded and the meshes read, and the time left at the rate so far.
            double lastReportMs = 0.0;
            loadOptions.onProgress = [&](const SceneLoadProgress& p) {
                const double nowMs = loadClock.elapsedMs();
                if (nowMs - lastReportMs < kLoadProgressMs) return;
                lastReportMs = nowMs;
                const double etaMs = p.share > 0.02 ? nowMs * (1.0 - p.share) / p.share : 0.0;
                broadcastProgress("loading", "scene", p.share, etaMs,
                                  "loading " + validUtf8(name) + sizeText + ": " + p.describe());
            };
            loadOptions.cancelled = [this, load] { return load->cancelled.load() || mStop.load(); };
            try {
                load->scene = mScenes->get(path, loadOptions);
            } catch (const LoadCancelled&) {
                // Said by the load that replaces it ('loading'), or by nobody when the session ends.
                logInfo("session " + mId + ": scene " + validUtf8(name) + " load cancelled after " +
                        std::to_string(std::lround(loadClock.elapsedMs())) + " ms");
                throw;
            } catch (...) {
                broadcastProgress("load_failed", "scene", 0.0, 0.0, "could not load " + validUtf8(name));
                throw;
            }
            const Scene& next = *load->scene;
            // The CPU half of the GL upload (vertex layout, runs, texture mipmaps), here rather
            // than on the render thread.
            load->gpu = SceneGpu::prepare(next, loadOptions.cancelled);
            const double loadMs = loadClock.elapsedMs();
            logInfo("session " + mId + ": scene " + validUtf8(name) + " loaded (" +
                    (sizeError ? std::string() : std::to_string(bytes) + " bytes, ") +
                    std::to_string(next.triangleCount()) + " triangles, " +
                    std::to_string(static_cast<long>(loadMs)) + " ms)");
            broadcastProgress("loaded", "scene", 1.0, 0.0,
                              "loaded " + validUtf8(name) + sizeText + ": " +
                                  std::to_string(next.triangleCount()) + " triangles in " +
                                  std::to_string(std::lround(loadMs)) + " ms");
            load->info = {{"ms", loadMs},
                          {"bytes", sizeError ? nlohmann::json(nullptr) : nlohmann::json(bytes)},
                          {"triangles", next.triangleCount()},
                          {"triangles_stored", next.storedTriangleCount()},
                          {"instances", next.instanceCount()}};
        } catch (...) {
            load->scene.reset();
            load->error = std::current_exception();
        }
        {
            std::lock_guard lock(mMutex);
            mLoadDone = true;
        }
        mCv.notify_all();
    });
}

void Session::refuseScene(const std::string& request, const char* what, const std::string& why) {
    logWarn("session " + mId + ": scene " + validUtf8(request) + " " + what + ": " + validUtf8(why));
    broadcastText(errorMessage({"scene_load_failed", why, "/name", "scene"}));
    if (mOnError) mOnError("scene_load_failed");
}

void Session::finishLoad(Worker& w) {
    const std::unique_ptr<Worker::Load> load = std::move(w.load);
    load->thread.join();
    if (!w.queuedRequest.empty()) { // asked for another scene meanwhile: this one is already old
        startLoad(w, std::exchange(w.queuedRequest, {}));
        return;
    }
    if (load->error) {
        try {
            std::rethrow_exception(load->error);
        } catch (const LoadCancelled&) {
            // Only a newer request (started above) or the session's end cancels a load.
        } catch (const std::exception& e) {
            refuseScene(load->request, "refused", e.what());
        }
        return;
    }
    // The GL upload (buffers, textures with their mipmaps) is the part of a load that needs the
    // render thread: it goes in slices between frames (continueUpload), the first one now.
    w.upload.reset(); // an older scene's upload still under way: this one is newer
    auto upload = std::make_unique<Worker::Upload>();
    upload->request = load->request;
    upload->scene = load->scene;
    upload->info = std::move(load->info);
    const Stopwatch stageClock;
    try {
        upload->gpu = std::make_unique<SceneGpu>(*upload->scene, std::move(load->gpu), SceneGpu::Staged{});
    } catch (const std::exception& e) {
        refuseScene(load->request, "could not be uploaded", e.what());
        return;
    }
    upload->renderThreadMs = upload->longestSliceMs = stageClock.elapsedMs();
    w.upload = std::move(upload);
    continueUpload(w);
}

void Session::continueUpload(Worker& w) {
    Worker::Upload& upload = *w.upload;
    const Stopwatch sliceClock;
    bool done = false;
    try {
        done = upload.gpu->uploadSome(static_cast<double>(mConfig.limits.sliceMs));
    } catch (const std::exception& e) {
        refuseScene(upload.request, "could not be uploaded", e.what());
        w.upload.reset();
        return;
    }
    const double sliceMs = sliceClock.elapsedMs();
    upload.renderThreadMs += sliceMs;
    upload.longestSliceMs = std::max(upload.longestSliceMs, sliceMs);
    ++upload.slices;
    if (!done) return;

    const std::unique_ptr<Worker::Upload> finished = std::move(w.upload);
    const std::shared_ptr<const Scene>& next = finished->scene;
    if (w.planRays && w.planRays->scene != next)
        Worker::drop(w.planRays, w.retiredPlanRays); // the old scene's structure
    const Stopwatch swapClock;
    w.renderer->setScene(next, std::move(finished->gpu));
    finished->renderThreadMs += swapClock.elapsedMs();
    finished->info["upload_ms"] = finished->renderThreadMs;
    finished->info["upload_slice_max_ms"] = std::max(finished->longestSliceMs, swapClock.elapsedMs());
    finished->info["upload_slices"] = finished->slices;
    logInfo("session " + mId + ": scene " + validUtf8(finished->request) + " uploaded to GL in " +
            std::to_string(std::lround(finished->renderThreadMs)) + " ms of the render thread (" +
            std::to_string(finished->slices) + " slices, the longest " +
            std::to_string(std::lround(finished->longestSliceMs)) + " ms)");
    w.scene = next;
    nlohmann::json stateMsg;
    {
        std::lock_guard lock(mMutex);
        FrameState fresh = makeFrameState(*next, mDesired.technique);
        mDesired.camera = fresh.camera;
        mSceneCamera = fresh.camera;
        mDesired.lights = fresh.lights;
        mDesired.lightSource = fresh.lightSource;
        mDesired.lightNote = fresh.lightNote;
        mDesired.baseExposure = fresh.baseExposure;
        mScene = next;
        mSceneName = finished->request;
        mSceneLoad = std::move(finished->info);
        stateMsg = {{"type", "state"}, {"state", stateJsonLocked()}};
        markInput(); // the new scene's first frame is interactive, then it refines
    }
    broadcastText(stateMsg);
}

#if GIS_HAVE_EFFECTS
const reference::RayScene* Session::planRaysFor(Worker& w, const std::shared_ptr<const Scene>& scene,
                                                bool& failed) {
    failed = false;
    Worker::joinFinished(w.retiredPlanRays);
    if (w.planRays && w.planRays->scene != scene) Worker::drop(w.planRays, w.retiredPlanRays);
    if (!w.planRays) {
        w.planRays = std::make_unique<Worker::PlanRays>();
        Worker::PlanRays* build = w.planRays.get();
        build->scene = scene;
        // Another session on this scene built it already.
        if (auto shared = mScenes->planRays(scene)) {
            build->rays = std::move(shared);
            build->done = true;
            logInfo("session " + mId + ": the effect planner's ray structure for " + validUtf8(scene->name) +
                    " is shared with another session");
            return build->rays.get();
        }
        build->thread = std::thread([this, build] {
            Stopwatch clock;
            std::shared_ptr<const reference::RayScene> rays;
            std::string error;
            try {
                // The planner traces a few thousand rays: the faster build (RaySceneOptions).
                reference::RaySceneOptions options;
                options.fastBuild = true;
                options.cancelled = [this, build] { return build->cancelled.load() || mStop.load(); };
                rays = std::make_shared<const reference::RayScene>(*build->scene, options);
            } catch (const reference::BuildCancelled&) {
                error = "cancelled";
            } catch (const std::exception& e) {
                error = e.what();
            } catch (...) {
                error = "unknown error";
            }
            {
                std::lock_guard lock(mMutex);
                build->rays = std::move(rays);
                build->error = std::move(error);
                build->buildMs = clock.elapsedMs();
                build->done = true;
                mPlanRaysWaited = false; // a step that waited for it may render now
                if (mPlanPendingShown && !mStream.adaptive) {
                    // Fixed quality renders on input only: the view shown was not planned.
                    if (!mDirty) mPendingSince = Clock::now();
                    mDirty = true;
                }
            }
            mCv.notify_all();
        });
        logInfo("session " + mId + ": building the effect planner's ray structure for " +
                validUtf8(scene->name) + " (" + std::to_string(scene->triangleCount()) + " triangles)");
    }
    if (!w.planRays->done) return nullptr;
    if (w.planRays->thread.joinable()) {
        w.planRays->thread.join();
        if (w.planRays->rays) {
            logInfo("session " + mId + ": effect planner's ray structure built in " +
                    std::to_string(std::lround(w.planRays->buildMs)) + " ms");
            mScenes->keepPlanRays(scene, w.planRays->rays);
        } else
            logWarn("session " + mId + ": the effect planner's ray structure could not be built (" +
                    validUtf8(w.planRays->error) + "): effects render as the technique's parameters say");
    }
    failed = w.planRays->rays == nullptr;
    return w.planRays->rays.get();
}
#endif

int Session::frameTargetMs(const StreamOptions& stream) const {
    return stream.frameTargetMs >= 0 ? stream.frameTargetMs : mConfig.limits.frameTargetMs;
}

bool Session::inputPending() const {
    std::lock_guard lock(mMutex);
    return mStop || mDirty || !mSnapshotFor.expired() || !mSceneRequest.empty() || mLoadDone;
}

bool Session::deliver(Worker& w, const std::vector<std::uint8_t>& rgba, int width, int height,
                      nlohmann::json stats, const std::string& quality, const StreamOptions& stream,
                      const std::shared_ptr<ClientLink>& snapshotFor, ImageCodec snapshotCodec,
                      const TileRect* patch) {
    const ImageCodec codec = snapshotFor ? snapshotCodec : stream.codec;
    std::vector<std::shared_ptr<ClientLink>> targets;
    if (snapshotFor)
        targets.push_back(snapshotFor);
    else
        targets = clients();
    // A patch goes out only where every client draws patches and none has missed one: encoding the
    // whole canvas of a large view took 50-70 ms a tile send, time that input waited behind.
    std::optional<TileRect> region;
    if (patch && !snapshotFor) {
        std::lock_guard lock(mMutex);
        if (!mWholeFrameWanted) region = patchToSend(*patch, width, height, targets);
    }
    if (!region && !snapshotFor) {
        std::lock_guard lock(mMutex);
        mWholeFrameWanted = false;
    }
    EncodedFrame frame;
    try {
        // A snapshot is lossless in whichever codec it asked for.
        frame = encodeFrame(rgba, width, height, region, codec, stream.quality, snapshotFor != nullptr,
                            w.frameId + 1);
    } catch (const std::exception& e) {
        fail(std::string("the frame could not be encoded: ") + e.what());
        return false;
    }
    ++w.frameId;
    ++mFramesRendered;
    // An image sent again keeps the number of the state it shows.
    if (w.stateSeq > 0 && !stats.contains("input_seq")) stats["input_seq"] = w.stateSeq;
    addPublishingStats(stats, frame, quality, snapshotFor != nullptr,
                       mSceneName.empty() ? w.scene->name : mSceneName, width, height);
    FrameReport report = reportOf(stats, frame, quality, snapshotFor != nullptr);
    const bool patchMissed =
        offerToClients(targets, stats, frame, snapshotFor != nullptr, viewerCount(), report);
    const std::uint32_t frameId = frame.id;
    const auto& shared = frame.message;
    FrameObserver onFrame;
    {
        std::lock_guard lock(mMutex);
        onFrame = mOnFrame;
        // A viewer that joined while this patch was encoded has neither it nor (attach saw no patch
        // yet) a reason to get the image whole: it needs one like a client that missed a patch.
        const bool joinedMeanwhile =
            region && std::any_of(mViewers.begin(), mViewers.end(), [&](const auto& v) {
                return std::find(targets.begin(), targets.end(), v) == targets.end();
            });
        if (patchMissed || joinedMeanwhile) mWholeFrameWanted = true;
        if (!snapshotFor) {
            if (region) {
                mPatchedSinceLastFrame = true;
            } else {
                mLastFrame = {frameId, stats, shared};
                mPatchedSinceLastFrame = false;
            }
        }
    }
    if (!snapshotFor) {
        w.lastImage = rgba;
        w.lastWidth = width;
        w.lastHeight = height;
        w.lastStats = stats;
        w.lastStats.erase("patch");
        w.lastQuality = quality;
    }
    if (onFrame) onFrame(report);
    return true;
}

struct Session::Rendered {
    FrameOutput frame;
    double queueMs = 0, renderMs = 0;
};

Session::RenderStatus Session::renderAdmitted(Worker& w, const FrameState& state, Rendered& out) {
    // Admission: at most the server's cap of renders at once, first come first served.
    Stopwatch queueClock;
    std::optional<RenderGate::Permit> permit;
    if (mGate) {
        permit = mGate->acquire(mStop);
        if (!permit) return RenderStatus::Stopped;
    }
    out.queueMs = queueClock.elapsedMs();
    Stopwatch renderClock;
    try {
        provideLevels(w, state);
        out.frame = w.renderer->render(state);
    } catch (const std::exception& e) {
        // A failed render leaves the context in an unknown state: the session ends rather than
        // failing again on every input.
        fail(std::string("the frame could not be rendered: ") + e.what());
        return RenderStatus::Failed;
    }
    out.renderMs = renderClock.elapsedMs();
    return RenderStatus::Ok;
}

void Session::broadcastProgress(const char* state, const std::string& step, double share, double etaMs,
                                const std::string& reason) {
    broadcastText({{"type", "progress"},
                   {"state", state},
                   {"step", step},
                   {"share", share},
                   {"eta_ms", etaMs >= 0.0 ? nlohmann::json(etaMs) : nlohmann::json(nullptr)},
                   {"reason", reason}});
}

Session::RefineResult Session::refineInTiles(Worker& w, const FrameState& full, int step,
                                             const StreamOptions& stream, const std::string& note) {
    const std::string stepLabel = stepName(step);
    const double fullPixels = static_cast<double>(full.width) * full.height;
    auto progress = [&](const char* state, double share, double etaMs, const std::string& reason) {
        broadcastProgress(state, stepLabel, share, etaMs, reason);
    };
    const int sliceMs = std::max(5, mConfig.limits.sliceMs);
    const long vpls = std::max(1L, vplEstimate(full));
    const TechniqueInfo& info = findTechniqueInfo(full.technique);
    // A technique that renders its VPLs in parts (TechniqueInfo::vplParts) spreads a tile too slow
    // for one slice over several; others get smaller tiles, down to kMinTileSide.
    const bool splittable = info.vplParts && info.vplParts(full.techniqueParams) && vpls > 1;
    // ms per rendered pixel of this step's tiles (all their parts): measured once a tile ran, before
    // that from the last complete step of its kind (scaled to these VPLs) or the interactive frames'
    // model, with a margin (small tiles cost more per pixel than a whole step's average), else a
    // smallest first tile.
    double rate = 0.0;
    double predicted = w.quality->predictStepMs(w.scene->name, full, static_cast<QualityStep>(step));
    if (!(predicted > 0.0))
        predicted = w.quality->budget().predictMs(w.scene->name + "/" + full.technique, fullPixels,
                                                  vplEstimate(full));
    if (predicted > 0.0) rate = 2.0 * predicted / fullPixels;
    const int guard = tileGuardPx(full);
    TilePlan plan(full.width, full.height, kTileAlign, kMinTileSide);
    Stopwatch stepClock;
    Stopwatch sinceSend;
    bool sentOnce = false;
    TileRect unsent; // the canvas's pixels pasted since the last send
    double renderedMs = 0.0;
    double vplRenderedMs = 0.0; // of that in the technique's VPL passes; below 0: it names none
    // VPL parts: tiles of partSide^2 inner pixels (smaller when a part's fixed work alone would fill
    // most of a slice), in as many parts as the parts measured so far say fit 70 % of a slice. The
    // planner counts rendered pixels, the guard band included.
    VplPartPlanner::Limits partLimits;
    partLimits.targetMs = 0.7 * sliceMs;
    const int partSide = std::max(kPartTileSide, 2 * guard);
    partLimits.tilePixels = double(partSide + 2 * guard) * (partSide + 2 * guard);
    partLimits.minTilePixels = double(kMinTileSide + 2 * guard) * (kMinTileSide + 2 * guard);
    partLimits.maxParts = kMaxVplParts;
    VplPartPlanner partPlanner(partLimits);
    // The last step with these tiles taught the planner what a part costs: start from it. Whatever
    // way this step ends (done, abandoned for input, failed), what it learned is kept for the next.
    const std::string partKey = w.scene->name + "/" + full.technique + "/" +
                                std::to_string(static_cast<long>(partLimits.tilePixels)) + "/" +
                                std::to_string(static_cast<long>(partLimits.minTilePixels)) + "/" +
                                std::to_string(sliceMs);
    if (splittable)
        if (const auto known = mPartMemory.find(partKey); known != mPartMemory.end())
            partPlanner.recall(known->second, vpls);
    struct KeepFits {
        std::map<std::string, VplPartPlanner::Memory>& memory;
        const std::string& key;
        const VplPartPlanner& planner;
        long vpls;
        bool enabled;
        ~KeepFits() {
            if (!enabled) return;
            VplPartPlanner::Memory learned = planner.remember(vpls);
            if (!learned.empty()) memory[key] = std::move(learned);
        }
    } keepFits{mPartMemory, partKey, partPlanner, vpls, splittable};
    int maxPartsUsed = 1;
    // The step's first tile draws the light views and environment cubes that its later tiles reuse
    // (hundreds of ms with a large scene): that tile's time would size the rest for work they do not
    // do, so it is left out of the rate and the part planner once per step.
    bool skippedOneTimeWork = false;
    auto drewOneTimeWork = [](const FrameOutput& f) {
        const nlohmann::json& c = f.stats.value("counts", nlohmann::json::object());
        const bool lightViews = c.value("triangles_light_views", 0.0) > 0.0;
        const bool envCubes = c.value("env_probes", 0.0) > 0.0 && c.value("env_cubes_reused", 1.0) == 0.0;
        return lightViews || envCubes;
    };
    // The step's predicted time from a measured step alone (the interactive frames' model mispredicts
    // a whole step several-fold); not known: the client shows no time left until tiles measured it.
    const double stepPredictedMs =
        w.quality->predictStepMs(w.scene->name, full, static_cast<QualityStep>(step));
    // The step's pace is measured from the end of its one-time work (or of its first part).
    std::optional<std::pair<double, double>> paceFrom; // (elapsed ms, share)
    progress("refining", 0.0, stepPredictedMs > 0.0 ? stepPredictedMs : -1.0,
             "the view is still: rendering the " + stepLabel + " step in tiles of about " +
                 std::to_string(sliceMs) + " ms" + (note.empty() ? std::string() : "; " + note));
    double shareDone = 0.0; // tiles and parts rendered (plan.shareDone() counts a tile once it starts)
    auto abandoned = [&](bool midPart = false) {
        progress("abandoned", shareDone, 0.0,
                 midPart ? "input arrived: the tile in progress stopped early and the frame answers it first"
                         : "input arrived: the frame answers it first");
        return RefineResult::Abandoned;
    };
    // Input stops the part in progress at its next stage (light views, eye passes, eye hierarchy,
    // technique) rather than at its end: its wait is one stage, not one part. Only refinement is
    // interrupted; a frame that answers input runs to the end.
    w.renderer->setInterruptCheck([this] { return inputPending(); });
    struct EndInterrupts {
        FrameRenderer& renderer;
        ~EndInterrupts() { renderer.setInterruptCheck({}); }
    } endInterrupts{*w.renderer};
    // The image so far: the last frame stretched to full size, in bands that input stops between
    // (a 960 x 800 canvas is a few ms of one core, more when the cores are busy). The buffer is the
    // last step's: a fresh 3 MB buffer's pages cost about 9 ms more (Tiles.ResizeIsBilinearWithinOneLevel).
    std::vector<std::uint8_t>& canvas = w.canvas;
    canvas.resize(static_cast<std::size_t>(full.width) * full.height * 4);
    for (int band = 0; band < kCanvasBands; ++band) {
        if (inputPending()) return abandoned();
        resizeRgba8Rows(w.lastImage, w.lastWidth, w.lastHeight, canvas, full.width, full.height,
                        full.height * band / kCanvasBands, full.height * (band + 1) / kCanvasBands);
    }
    while (!plan.done()) {
        if (inputPending()) return abandoned();
        // Until a tile of this step was measured, its predicted cost is trusted three times over (the
        // interactive frames' model has under-predicted the per-VPL cost of full-size tiles 3-fold).
        const double sizingRate = renderedMs > 0.0 ? rate : 3.0 * rate;
        double pixels = rate > 0.0 ? sliceMs / sizingRate : double(kMinTileSide) * kMinTileSide;
        int parts = 1;
        const bool planned = splittable && rate > 0.0 && pixels < partLimits.tilePixels;
        if (planned) {
            const VplPartPlan partPlan = partPlanner.plan(vpls, sizingRate);
            parts = partPlan.parts;
            pixels = partPlan.pixels;
        }
        // The guard band is rendered too: ask for fewer inner pixels so the whole tile fits the slice.
        const double side = std::sqrt(std::max(pixels, 1.0));
        const double inner = std::max(1.0, side - 2.0 * guard);
        const double shareBefore = plan.shareDone();
        const TileRect rect = plan.next(inner * inner);
        const double shareAfter = plan.shareDone();
        const FrameState tile = tileState(full, rect, guard);
        const double tilePixels = static_cast<double>(tile.width) * tile.height;
        double tileMs = 0.0;
        bool measureTile = true;
        for (int part = 0; part < parts; ++part) {
            if (part > 0 && inputPending()) return abandoned();
            FrameState piece = tile;
            if (parts > 1) piece.vplPart = {part, parts};
            Rendered rendered;
            if (const RenderStatus status = renderAdmitted(w, piece, rendered); status != RenderStatus::Ok)
                return status == RenderStatus::Failed ? RefineResult::Failed : RefineResult::Abandoned;
            if (rendered.frame.interrupted) return abandoned(true);
            const FrameOutput& frame = rendered.frame;
            tileMs += rendered.renderMs;
            const bool oneTime = !skippedOneTimeWork && drewOneTimeWork(frame);
            if (oneTime) {
                skippedOneTimeWork = true;
                measureTile = false;
            }
            if (planned && !oneTime) partPlanner.record(tilePixels, parts, rendered.renderMs);
            renderedMs += rendered.renderMs;
            if (vplRenderedMs >= 0.0) {
                const double vplMs = vplPassesMs(full.technique, frame.stats);
                vplRenderedMs = vplMs >= 0.0 ? vplRenderedMs + vplMs : -1.0;
            }
            pasteTile(canvas, full.width, full.height, frame.rgba8, frame.width, frame.height, rect, guard);
            unsent = unite(unsent, clipToImage(rect, full.width, full.height));

            // Input waits: its frame goes first, the unsent tiles are not worth encoding.
            const double share = shareBefore + (shareAfter - shareBefore) * (part + 1) / parts;
            shareDone = share;
            if (inputPending()) return abandoned();
            const bool last = plan.done() && part + 1 == parts;
            const double nowMs = stepClock.elapsedMs();
            if (oneTime || !paceFrom) paceFrom = {nowMs, share};
            const double etaMs = stepEtaMs(nowMs, share, paceFrom->first, paceFrom->second, stepPredictedMs);
            // Send when the controller's window has room, at most every 150 ms, and always the last
            // tile (waiting for room, unless input comes first).
            bool send = false;
            {
                std::unique_lock lock(mMutex);
                if (last)
                    mCv.wait(lock,
                             [&] { return mStop || mDirty || !mController || !mController->windowFull(); });
                // Keep one slot of a larger window free for the answer to input: a tile the client is
                // still decoding must not hold it back.
                const bool slotLeft =
                    mController && !mController->windowFull() &&
                    (last || mController->maxInFlight() < 2 ||
                     mController->inFlight() + 1 < static_cast<std::size_t>(mController->maxInFlight()));
                send = slotLeft && (last || !sentOnce || sinceSend.elapsedMs() >= 150.0);
            }
            if (!send) continue;
            nlohmann::json stats = frame.stats;
            stats["size"] = {full.width, full.height};
            stats["tile"] = {
                {"x", rect.x}, {"y", rect.y}, {"size", {rect.width, rect.height}}, {"guard", guard}};
            stats["scale"] = 1.0;
            stats["queue_ms"] = rendered.queueMs;
            stats["params"] = paramsJson(full);
            if (!full.plan.is_null()) stats["plan"] = full.plan;
            stats["refine"] = {{"step", stepLabel},
                               {"tiles_done", plan.tilesDone()},
                               {"share", share},
                               {"elapsed_ms", stepClock.elapsedMs()},
                               {"render_ms", renderedMs},
                               {"eta_ms", last           ? nlohmann::json(0.0)
                                          : etaMs >= 0.0 ? nlohmann::json(etaMs)
                                                         : nlohmann::json(nullptr)},
                               {"complete", last},
                               {"vpl_parts", parts},
                               {"vpl_parts_done", part + 1}};
            // Only the tiles pasted since the last send; a client whose image has another size (the
            // interactive frame's) stretches it to the full size first, as the canvas here was.
            if (!deliver(w, canvas, full.width, full.height, std::move(stats), stepLabel, stream, nullptr,
                         ImageCodec::Png, &unsent))
                return RefineResult::Failed;
            unsent = {};
            sentOnce = true;
            sinceSend = Stopwatch();
        }
        maxPartsUsed = std::max(maxPartsUsed, parts);
        const double measured = tileMs / tilePixels;
        // A slow tile counts at once (tiles must not overrun); a cheap one (mostly background) lowers
        // the estimate by at most a fifth, since the next one may cover geometry.
        if (measureTile) rate = rate > 0.0 ? std::max(measured, 0.8 * rate) : measured;
        // A smallest tile over the slice that cannot split its VPLs: its cost is mostly per VPL (each
        // batch of them is a draw), so the step starts again with the VPLs this measurement allows
        // (workerMain caps them).
        if (measureTile && !splittable && rect.width <= kMinTileSide && tileMs > 1.5 * sliceMs) {
            const bool news =
                w.quality->recordMinTileCost(w.scene->name, full, static_cast<QualityStep>(step), tileMs);
            if (news && vpls > 16 && info.limitVpls && !plan.done()) {
                progress("abandoned", shareDone, 0.0,
                         "a " + std::to_string(kMinTileSide) + " x " + std::to_string(kMinTileSide) +
                             " tile took " + std::to_string(std::lround(tileMs)) +
                             " ms: starting again with fewer VPLs");
                return RefineResult::Retune;
            }
        }
    }
    // The whole step's cost per pixel, which predicts the next one (and its refinement-budget check);
    // single tiles would over-predict it, their fixed costs and the slowest regions included.
    w.quality->recordStepCost(w.scene->name, full, static_cast<QualityStep>(step), renderedMs / fullPixels,
                              vplRenderedMs >= 0.0 ? vplRenderedMs / fullPixels : -1.0);
    if (step == static_cast<int>(Step::Final)) {
        std::string done =
            "converged: the final step took " + std::to_string(std::lround(stepClock.elapsedMs())) + " ms";
        if (maxPartsUsed > 1) done += " in tiles of up to " + std::to_string(maxPartsUsed) + " VPL parts";
        progress("done", 1.0, 0.0, done);
    }
    return RefineResult::Done;
}

void Session::workerMain() {
    Worker w;
    std::unique_ptr<gl::Context> context;
    try {
        context = gl::createContext(mConfig.backend);
        w.renderer = std::make_unique<FrameRenderer>();
        w.renderer->setReuseLightPasses(true);
        w.renderer->setLevelsOnDemand(false); // provideLevels builds them off this thread
        w.renderer->setScene(mScene);
    } catch (const std::exception& e) {
        fail(std::string("the renderer could not start: ") + e.what());
        return;
    }
    {
        nlohmann::json presets;
        try {
            presets = loadPresets(defaultPresetsPath());
        } catch (const std::exception& e) {
            logWarn("session " + mId +
                    ": no presets, adaptive quality renders every step as requested: " + e.what());
        }
        w.quality = std::make_unique<AdaptiveQuality>(mConfig.limits, std::move(presets));
    }
    w.scene = mScene;
#if GIS_HAVE_EFFECTS
    std::string planKey;
    EffectPlan plan;
#endif
    while (!mStop) {
        {
            std::unique_lock lock(mMutex);
            if (std::exchange(mLoadDone, false)) {
                lock.unlock();
                finishLoad(w);
                continue;
            }
        }
        // A loaded scene's upload under way: a slice of it each turn, and a frame of the scene in
        // place only to answer input or a snapshot (its refinement waits for the new scene).
        if (w.upload) {
            continueUpload(w);
            std::lock_guard lock(mMutex);
            if (w.upload && !mStop && !mDirty && mSnapshotFor.expired()) continue;
        }
        FrameState state;
        nlohmann::json explicitParams;
        std::string sceneRequest;
        StreamOptions stream;
        std::shared_ptr<ClientLink> snapshotFor;
        ImageCodec snapshotCodec = ImageCodec::Png;
        int step = -1;                                   // -1: fixed; else Step
        std::optional<Clock::time_point> answersInputOf; // the input this frame answers arrived then
        double inputWaitMs = 0.0, windowWaitMs = 0.0;
        {
            std::unique_lock lock(mMutex);
            std::optional<Clock::time_point> windowWaitFrom;
            while (!mStop) {
                const auto now = Clock::now();
                if (mLoadDone || w.upload || readyLocked(now)) break;
                if (mDirty && mController && mController->windowFull() && !windowWaitFrom)
                    windowWaitFrom = now;
                if (mStream.adaptive && mNextStep == Step::Balanced && !mDirty && mController &&
                    !mPlanRaysWaited)
                    mCv.wait_until(lock, mLastInput + std::chrono::milliseconds(mConfig.limits.settleMs));
                else
                    mCv.wait(lock);
            }
            if (mStop) break;
            // The loop's top swaps a loaded scene in, or sends the next slice of its upload.
            if ((mLoadDone || w.upload) && !readyLocked(Clock::now())) continue;
            // A viewer joined after patches and nothing else is to render: the last image again, whole.
            if (mWholeFrameWanted && mSnapshotFor.expired() && !stepReadyLocked(Clock::now())) {
                const StreamOptions current = mStream;
                lock.unlock();
                if (w.lastImage.empty()) {
                    std::lock_guard relock(mMutex);
                    mWholeFrameWanted = false;
                } else if (!deliver(w, w.lastImage, w.lastWidth, w.lastHeight, w.lastStats, w.lastQuality,
                                    current, nullptr, ImageCodec::Png)) {
                    break;
                }
                continue;
            }
            // A viewer's snapshot waits while the controller has input to answer: viewers never delay
            // the controller by more than the frame already rendering.
            const bool controllerWaits = mDirty && mController && !mController->windowFull();
            if (!controllerWaits) {
                snapshotFor = mSnapshotFor.lock();
                mSnapshotFor.reset();
            }
            snapshotCodec = mSnapshotCodec;
            stream = mStream;
            if (snapshotFor) {
                step = static_cast<int>(Step::Final);
            } else if (!mStream.adaptive) {
                mDirty = false;
                mNextStep = Step::Done;
            } else if (mDirty) {
                mDirty = false;
                answersInputOf = mPendingSince;
                inputWaitMs = std::chrono::duration<double, std::milli>(Clock::now() - mPendingSince).count();
                if (windowWaitFrom)
                    windowWaitMs =
                        std::chrono::duration<double, std::milli>(Clock::now() - *windowWaitFrom).count();
                step = static_cast<int>(Step::Interactive);
                mNextStep = Step::Balanced;
            } else {
                step = static_cast<int>(mNextStep);
                mNextStep = mNextStep == Step::Balanced ? Step::Final : Step::Done;
            }
            sceneRequest = std::exchange(mSceneRequest, {});
            explicitParams = mExplicit;
        }
        if (!sceneRequest.empty()) {
            w.upload.reset(); // a scene still uploading is older than this request
            if (w.load) {
                // The newer request wins: the load under way stops at its next check (between file
                // chunks, images or meshes) and this one starts when it has.
                w.load->cancelled = true;
                w.queuedRequest = std::move(sceneRequest);
            } else
                startLoad(w, std::move(sceneRequest));
        }
        const std::shared_ptr<const Scene>& scene = w.scene;
        {
            std::lock_guard lock(mMutex);
            state = mDesired;
            w.stateSeq = mInputSeq;
        }
        // Adaptive steps: the step's preset under the client's explicit parameters; interactive
        // frames sized (and their VPLs capped) by the frame budget (protocol/PROTOCOL.md, "Adaptive
        // quality"; session/AdaptiveQuality.h).
        AdaptiveQuality::Plan quality =
            w.quality->plan(scene->name, state, explicitParams, static_cast<QualityStep>(step),
                            snapshotFor != nullptr, frameTargetMs(stream), [&w](const FrameState& s) {
                                return w.renderer && w.renderer->keepsLightViews(s);
                            });
        if (quality.skip) {
            broadcastProgress("skipped", qualityStepName(quality.step), 0.0, quality.predictedMs,
                              quality.why);
            continue;
        }
        step = static_cast<int>(quality.step);
        state = std::move(quality.state);
        const double scale = quality.scale;
        const std::string& refineNote = quality.why;
        const nlohmann::json& budgetJson = quality.budget;
        const std::string& budgetKey = quality.budgetKey;
        const std::string& techniqueParamsKey = quality.techniqueParamsKey;
        // A refinement step renders in tiles that input stops between (and its effect plan stops too).
        const bool refinement = !snapshotFor && (step == static_cast<int>(Step::Balanced) ||
                                                 step == static_cast<int>(Step::Final));
#if GIS_HAVE_EFFECTS
        // The effect plan: measured again only when the scene, the parameters, or the camera or light
        // change materially, never every frame.
        if (effectPlanRequested(state)) {
            bool raysFailed = false;
            const reference::RayScene* rays = planRaysFor(w, scene, raysFailed);
            if (rays) {
                const std::string key = effectPlanKey(*scene, state);
                if (key != planKey) {
                    // A refinement step's plan (tens of ms of rays) stops for input like its tiles;
                    // a frame that answers input, or a snapshot, plans to the end.
                    EffectPlanOptions options;
                    if (refinement) options.stop = [this] { return inputPending(); };
                    EffectPlan fresh = planEffects(*scene, *rays, state, options);
                    if (fresh.stopped) {
                        // Whatever stopped it is served first; the step comes again after it.
                        std::lock_guard lock(mMutex);
                        if (!mDirty) mNextStep = static_cast<Step>(step);
                        continue;
                    }
                    plan = std::move(fresh);
                    planKey = key;
                }
                applyEffectPlan(state, plan);
                std::lock_guard lock(mMutex);
                mPlanPendingShown = false;
            } else if (!raysFailed && refinement) {
                // A refinement step waits for the structure (input does not: it still renders at
                // once), and is taken up again when the build ends.
                bool wait = false;
                {
                    std::lock_guard lock(mMutex);
                    if (!mDirty) {
                        mNextStep = static_cast<Step>(step);
                        mPlanRaysWaited = wait = !w.planRays->done;
                    }
                }
                if (wait)
                    broadcastProgress("refining", qualityStepName(static_cast<QualityStep>(step)), 0.0, 0.0,
                                      "measuring the scene for the effect plan (its ray structure: " +
                                          std::to_string(scene->triangleCount()) + " triangles)");
                continue;
            } else {
                // Interactive frames and snapshots do not wait: the technique's parameters decide.
                // A fixed-quality view is rendered again when the plan is ready (the build's end).
                if (!raysFailed && !snapshotFor) {
                    std::lock_guard lock(mMutex);
                    mPlanPendingShown = true;
                }
                state.plan = {{"mode", "auto"},
                              {"pending", raysFailed ? "the scene's ray structure could not be built: the "
                                                       "technique's parameters decide"
                                                     : "measuring the scene: the technique's parameters "
                                                       "decide until the plan is ready"}};
            }
        }
#endif
        if (refinement) {
            const RefineResult result = refineInTiles(w, state, step, stream, refineNote);
            if (result == RefineResult::Failed) break;
            if (result == RefineResult::Retune) {
                // The same step again, now capped by the smallest tile's measured cost.
                std::lock_guard lock(mMutex);
                if (!mDirty) mNextStep = static_cast<Step>(step);
            }
            continue;
        }
        Rendered rendered;
        if (renderAdmitted(w, state, rendered) != RenderStatus::Ok) break;
        const FrameOutput& frame = rendered.frame;
        const double queueMs = rendered.queueMs;
        if (step >= 0 && frame.width > 0 && frame.height > 0) {
            const double pixels = static_cast<double>(frame.width) * frame.height;
            const double vplMs = vplPassesMs(state.technique, frame.stats);
            w.quality->recordStepCost(scene->name, state, static_cast<QualityStep>(step),
                                      rendered.renderMs / pixels, vplMs >= 0.0 ? vplMs / pixels : -1.0);
        }
        nlohmann::json stats = frame.stats;
        stats["scale"] = scale;
        stats["queue_ms"] = queueMs;
        if (!budgetJson.is_null()) {
            stats["budget"] = budgetJson;
            noteReceiverCap(stats["budget"], frame.stats, frame.width, frame.height);
        }
        if (answersInputOf) {
            // How long the input waited for the worker (a tile or an unacknowledged frame ahead of
            // it), and from its arrival to the frame about to be encoded. The arrival on the wall
            // clock lets a client on the same machine split the rest between the two directions.
            const double renderedMs =
                std::chrono::duration<double, std::milli>(Clock::now() - *answersInputOf).count();
            const double nowUnixMs =
                std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch())
                    .count();
            stats["input"] = {{"wait_ms", inputWaitMs},
                              {"window_wait_ms", windowWaitMs},
                              {"rendered_ms", renderedMs},
                              {"arrived_unix_ms", std::floor((nowUnixMs - renderedMs) * 10.0) / 10.0}};
        }
        if (!deliver(w, frame.rgba8, frame.width, frame.height, std::move(stats), stepName(step), stream,
                     snapshotFor, snapshotCodec))
            break;
        if (step == static_cast<int>(Step::Interactive) && !snapshotFor) {
            const TechniqueInfo& info = findTechniqueInfo(state.technique);
            FrameCost cost = FrameCost::ofFrame(
                frame.stats, frame.width, frame.height, vplEstimate(state),
                frameVplCostExponent(info, frame.stats.value("counts", nlohmann::json::object())),
                info.lightViewPasses);
            cost.vplPassesMs = vplPassesMs(state.technique, frame.stats);
            cost.techniqueParams = techniqueParamsKey;
            {
                std::lock_guard lock(mMutex);
                cost.encodeMs = mLastFrame.stats.value("encode_ms", 0.0);
            }
            w.quality->budget().record(budgetKey, cost);
        }
    }
    w.upload.reset(); // GL objects die while the context is still current
    w.renderer.reset();
    context.reset();
}

} // namespace gis
