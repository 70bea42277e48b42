#include "session/Session.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

#include "core/Error.h"
#include "core/JsonSchema.h"
#include "core/Log.h"
#include "core/Timer.h"
#include "gi/Technique.h"
#include "frame/FrameParams.h"
#include "frame/VplBudget.h"
#include "render/FrameRenderer.h"
#include "frame/Presets.h"
#include "job/RenderRequest.h"
#include "frame/StateJson.h"
#include "scene/SceneLoader.h"
#include "session/RenderGate.h"
#if GIS_HAVE_EFFECTS
#include "effects/EffectPlan.h"
#endif

namespace gis {
namespace {

using Clock = std::chrono::steady_clock;

const char* stepName(int step) {
    static const char* names[] = {"interactive", "balanced", "final"};
    return step >= 0 && step < 3 ? names[step] : "fixed";
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

double Session::predictRefineMs(const std::string& sceneName, const FrameState& state, int step) const {
    const std::string prefix = sceneName + "/" + state.technique + "/";
    const double pixels = static_cast<double>(state.width) * state.height;
    if (auto own = mRefineCost.find(prefix + std::to_string(step)); own != mRefineCost.end())
        return own->second.msPerPixel * pixels;
    // Not rendered yet: scale the nearest measured step by pixels and VPLs (gather cost grows with
    // their product), so a final preset with 256 times the VPLs is predicted before it runs.
    for (int other = step - 1; other >= 0; --other)
        if (auto c = mRefineCost.find(prefix + std::to_string(other)); c != mRefineCost.end())
            return c->second.msPerPixel * pixels * static_cast<double>(std::max(1L, vplEstimate(state))) /
                   static_cast<double>(c->second.vpls);
    return 0.0;
}

Session::Session(std::string id, SessionConfig config, std::shared_ptr<SceneCache> scenes,
                 std::shared_ptr<const SceneCatalog> catalog, RenderGate* gate, std::string uploadDir)
    : mId(std::move(id)), mConfig(std::move(config)), mScenes(std::move(scenes)),
      mCatalog(std::move(catalog)), mGate(gate), mUploadDir(std::move(uploadDir)) {
    mScene = mScenes->get(mConfig.scene);
    mSceneName = mConfig.scene;
    mDesired = makeFrameState(*mScene, mConfig.technique);
    mDesired.width = mConfig.width;
    mDesired.height = mConfig.height;
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
            {"lighting", {{"source", mDesired.lightSource}, {"note", mDesired.lightNote}}}};
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
            if (options) mStream = *options;
            // A new or resumed controller has seen nothing yet: render the current state for it.
            markInput();
        } else {
            mViewers.push_back(link);
            if (mLastFrame.bytes) {
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

void Session::resize(int cssWidth, int cssHeight, double dpr) {
    const double w = std::max(1.0, std::round(cssWidth * dpr));
    const double h = std::max(1.0, std::round(cssHeight * dpr));
    // Scale down to fit the server's limit, keeping the aspect ratio; never below the 16 px minimum.
    const double fit = std::min({1.0, mConfig.limits.maxWidth / w, mConfig.limits.maxHeight / h});
    const int width = std::clamp(static_cast<int>(std::floor(w * fit)), 16, mConfig.limits.maxWidth);
    const int height = std::clamp(static_cast<int>(std::floor(h * fit)), 16, mConfig.limits.maxHeight);
    {
        std::lock_guard lock(mMutex);
        if (width == mDesired.width && height == mDesired.height) return;
        mDesired.width = width;
        mDesired.height = height;
        markInput();
    }
    mCv.notify_all();
}

void Session::apply(const nlohmann::json& msg, const std::shared_ptr<ClientLink>& from) {
    const std::string type = msg["type"];
    if (type == "resize") {
        resize(msg["size"][0], msg["size"][1], msg.value("dpr", 1.0));
        return;
    }
    std::unique_lock lock(mMutex);
    bool lightsChanged = false; // light_add and light_remove answer with the new state (its ids)
    try {
        if (type == "camera") {
            applyCameraJson(mDesired, msg, "");
        } else if (type == "light") {
            try {
                applyLightJson(mDesired, msg, "");
            } catch (const InputError& e) {
                if (e.reason().rfind("no light '", 0) == 0)
                    throw ProtocolError{"unknown_light", e.reason() + "; add one with a light_add message",
                                        e.where(), type};
                throw;
            }
        } else if (type == "light_add") {
            addLightJson(mDesired, msg.value("light", nlohmann::json::object()), "/light");
            lightsChanged = true;
        } else if (type == "light_remove") {
            try {
                removeLight(mDesired, msg["id"].get<std::string>(), "/id");
            } catch (const InputError& e) {
                throw ProtocolError{"unknown_light", e.reason(), e.where(), type};
            }
            lightsChanged = true;
        } else if (type == "technique") {
            FrameState next = mDesired;
            try {
                setTechnique(next, msg["name"], "/name");
            } catch (const InputError& e) {
                throw ProtocolError{"unknown_technique", e.reason(), "/name", type};
            }
            if (vplEstimate(next) > mConfig.limits.maxVpls)
                throw ProtocolError{
                    "limit_exceeded",
                    "technique '" + next.technique + "' asks for up to " + std::to_string(vplEstimate(next)) +
                        " VPLs by default; the server allows " + std::to_string(mConfig.limits.maxVpls),
                    "/name", type};
            // Explicit technique parameters belonged to the previous technique.
            for (auto it = mExplicit.begin(); it != mExplicit.end();)
                it = next.frameParams.has(it.key()) ? std::next(it) : mExplicit.erase(it);
            mDesired = std::move(next);
        } else if (type == "params") {
            FrameState next = mDesired;
            try {
                applyParams(next, msg["values"], "/values");
            } catch (const InputError& e) {
                throw ProtocolError{"invalid_param", e.reason(), e.where(), type};
            }
            if (vplEstimate(next) > mConfig.limits.maxVpls)
                throw ProtocolError{"limit_exceeded",
                                    "these parameters ask for up to " + std::to_string(vplEstimate(next)) +
                                        " VPLs; the server allows " + std::to_string(mConfig.limits.maxVpls),
                                    "/values", type};
            mDesired = std::move(next);
            for (const auto& [k, v] : msg["values"].items()) mExplicit[k] = v;
        } else if (type == "scene") {
            const std::string name = msg["name"];
            if (mCatalog) {
                try {
                    (void)mCatalog->resolve(name, mUploadDir);
                } catch (const InputError& e) {
                    throw ProtocolError{"unknown_scene", e.reason(), "/name", type};
                }
            } else if (name != mConfig.scene) {
                throw ProtocolError{"unknown_scene", "unknown scene '" + name + "'", "/name", type};
            }
            mSceneRequest = name;
        } else if (type == "quality") {
            mStream.adaptive = msg["adaptive"].get<bool>();
        } else if (type == "snapshot") {
            mSnapshotFor = from;
            mSnapshotCodec = msg.value("codec", "png") == "webp" ? ImageCodec::Webp : ImageCodec::Png;
            lock.unlock();
            mCv.notify_all();
            return;
        } else {
            throw ProtocolError{"unknown_type", "'" + type + "' does not steer a session", "/type", type};
        }
    } catch (const InputError& e) {
        throw ProtocolError{"invalid_message", e.reason(), e.where(), type};
    }
    markInput();
    nlohmann::json stateMsg;
    if (lightsChanged) stateMsg = {{"type", "state"}, {"state", stateJsonLocked()}};
    lock.unlock();
    mCv.notify_all();
    if (lightsChanged) broadcastText(stateMsg);
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
    if (mDirty) return true;
    if (!mStream.adaptive || mNextStep == Step::Done || mNextStep == Step::Interactive) return false;
    return mNextStep != Step::Balanced ||
           now >= mLastInput + std::chrono::milliseconds(mConfig.limits.settleMs);
}

void Session::workerMain() {
    std::unique_ptr<gl::Context> context;
    std::unique_ptr<FrameRenderer> renderer;
    try {
        context = gl::createContext(mConfig.backend);
        renderer = std::make_unique<FrameRenderer>();
        renderer->setScene(mScene);
    } catch (const std::exception& e) {
        fail(std::string("the renderer could not start: ") + e.what());
        return;
    }
    nlohmann::json presets;
    try {
        presets = loadPresets(defaultPresetsPath());
    } catch (const std::exception& e) {
        logWarn("session " + mId +
                ": no presets, adaptive quality renders every step as requested: " + e.what());
    }
    std::uint32_t frameId = 0;
    std::shared_ptr<const Scene> scene = mScene;
#if GIS_HAVE_EFFECTS
    std::string planKey;
    EffectPlan plan;
#endif
    while (!mStop) {
        FrameState state;
        nlohmann::json explicitParams;
        std::string sceneRequest;
        StreamOptions stream;
        std::shared_ptr<ClientLink> snapshotFor;
        ImageCodec snapshotCodec = ImageCodec::Png;
        int step = -1; // -1: fixed; else Step
        {
            std::unique_lock lock(mMutex);
            while (!mStop) {
                const auto now = Clock::now();
                if (readyLocked(now)) break;
                if (mStream.adaptive && mNextStep == Step::Balanced && !mDirty && mController)
                    mCv.wait_until(lock, mLastInput + std::chrono::milliseconds(mConfig.limits.settleMs));
                else
                    mCv.wait(lock);
            }
            if (mStop) break;
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
            try {
                const std::string path =
                    mCatalog ? mCatalog->resolve(sceneRequest, mUploadDir) : sceneRequest;
                Stopwatch loadClock;
                auto next =
                    mScenes->get(path, mCatalog ? mCatalog->loadOptions(sceneRequest) : SceneLoadOptions{});
                std::error_code sizeError;
                const auto bytes = std::filesystem::file_size(path, sizeError);
                logInfo("session " + mId + ": scene " + validUtf8(sceneRequest) + " loaded (" +
                        (sizeError ? std::string() : std::to_string(bytes) + " bytes, ") +
                        std::to_string(next->triangleCount()) + " triangles, " +
                        std::to_string(static_cast<long>(loadClock.elapsedMs())) + " ms)");
                renderer->setScene(next);
                scene = next;
                nlohmann::json stateMsg;
                {
                    std::lock_guard lock(mMutex);
                    FrameState fresh = makeFrameState(*next, mDesired.technique);
                    mDesired.camera = fresh.camera;
                    mDesired.lights = fresh.lights;
                    mDesired.lightSource = fresh.lightSource;
                    mDesired.lightNote = fresh.lightNote;
                    mScene = next;
                    mSceneName = sceneRequest;
                    stateMsg = {{"type", "state"}, {"state", stateJsonLocked()}};
                }
                broadcastText(stateMsg);
            } catch (const std::exception& e) {
                logWarn("session " + mId + ": scene " + validUtf8(sceneRequest) +
                        " refused: " + validUtf8(e.what()));
                broadcastText(errorMessage({"scene_load_failed", e.what(), "/name", "scene"}));
                if (mOnError) mOnError("scene_load_failed");
            }
        }
        {
            std::lock_guard lock(mMutex);
            state = mDesired;
        }
        // Adaptive steps: the step's preset under the client's explicit parameters, smaller frames
        // while interacting (protocol/PROTOCOL.md, "Adaptive quality").
        double scale = 1.0;
        if (step >= 0) {
            static const char* presetNames[] = {"interactive", "balanced", "final"};
            const FrameState requested = state;
            auto presetState = [&](int s) {
                FrameState out = requested;
                if (presets.is_null()) return out;
                try {
                    FrameState preset = requested;
                    preset.techniqueParams.resetToDefaults();
                    applyPreset(preset, presets, presetNames[s]);
                    nlohmann::json techniqueExplicit = nlohmann::json::object();
                    for (const auto& [k, v] : explicitParams.items())
                        if (preset.techniqueParams.has(k)) techniqueExplicit[k] = v;
                    preset.techniqueParams.apply(techniqueExplicit);
                    if (vplEstimate(preset) <= mConfig.limits.maxVpls) out = std::move(preset);
                } catch (const InputError&) {
                    // No preset for this technique: the step renders the parameters as they are.
                }
                return out;
            };
            state = presetState(step);
            // A snapshot is the best step that fits the refinement budget, judged like refinement:
            // a step never measured nor predictable counts as too slow, the interactive one (at full
            // size) always fits.
            if (snapshotFor && mConfig.limits.refineBudgetMs > 0) {
                while (step > static_cast<int>(Step::Interactive)) {
                    const double predictedMs = predictRefineMs(scene->name, state, step);
                    if (predictedMs > 0.0 && predictedMs <= mConfig.limits.refineBudgetMs) break;
                    state = presetState(--step);
                }
            }
            if (step == static_cast<int>(Step::Final) && state.frameParams.has("effects") &&
                !explicitParams.contains("effects")) {
                // The plan's bias compensation (and direct/bounce decisions), but not indirect
                // occlusion unless asked for: one cube shadow map per VPL costs minutes per frame on
                // CPU rendering at the final preset's VPL counts.
                state.frameParams.set("effects", "auto");
                if (state.frameParams.has("effect_occlusion") && !explicitParams.contains("effect_occlusion"))
                    state.frameParams.set("effect_occlusion", "off");
            }
            if (step != static_cast<int>(Step::Interactive) && !snapshotFor &&
                mConfig.limits.refineBudgetMs > 0) {
                const double predictedMs = predictRefineMs(scene->name, state, step);
                if (predictedMs > mConfig.limits.refineBudgetMs) continue; // too slow to refine to
            }
            if (step == static_cast<int>(Step::Interactive) && !snapshotFor) {
                scale = std::clamp(mConfig.limits.interactiveScale, 0.05, 1.0);
                state.width = std::max(16, static_cast<int>(std::lround(state.width * scale)));
                state.height = std::max(16, static_cast<int>(std::lround(state.height * scale)));
            }
        }
#if GIS_HAVE_EFFECTS
        // The effect plan: measured again only when the scene, the parameters, or the camera or light
        // change materially, never every frame.
        if (effectPlanRequested(state)) {
            const std::string key = effectPlanKey(*scene, state);
            if (key != planKey) {
                plan = planEffects(*scene, state);
                planKey = key;
            }
            applyEffectPlan(state, plan);
        }
#endif
        // Admission: at most the server's cap of renders at once, first come first served.
        Stopwatch queueClock;
        std::optional<RenderGate::Permit> permit;
        if (mGate) {
            permit = mGate->acquire(mStop);
            if (!permit) break;
        }
        const double queueMs = queueClock.elapsedMs();
        FrameOutput frame;
        Stopwatch renderClock;
        try {
            frame = renderer->render(state);
        } catch (const std::exception& e) {
            // A failed render leaves the context in an unknown state: the session ends rather than
            // failing again on every input.
            fail(std::string("the frame could not be rendered: ") + e.what());
            break;
        }
        permit.reset();
        if (step >= 0 && frame.width > 0 && frame.height > 0)
            mRefineCost[scene->name + "/" + state.technique + "/" + std::to_string(step)] = {
                renderClock.elapsedMs() / (static_cast<double>(frame.width) * frame.height),
                std::max(1L, vplEstimate(state))};
        const ImageCodec codec = snapshotFor ? snapshotCodec : stream.codec;
        Stopwatch encodeClock;
        std::vector<std::uint8_t> encoded;
        try {
            encoded = snapshotFor && codec == ImageCodec::Webp
                          ? encodeWebpLossless(frame.rgba8.data(), frame.width, frame.height)
                          : encodeImage(codec, frame.rgba8.data(), frame.width, frame.height, stream.quality);
        } catch (const std::exception& e) {
            fail(std::string("the frame could not be encoded: ") + e.what());
            break;
        }
        const double encodeMs = encodeClock.elapsedMs();
        ++frameId;
        ++mFramesRendered;
        std::vector<std::uint8_t> message =
            makeFrameMessage(frameId, frame.width, frame.height, codec, encoded);
        auto shared = std::make_shared<const std::string>(message.begin(), message.end());

        nlohmann::json stats = frame.stats;
        stats["type"] = "stats";
        stats["frame"] = frameId;
        stats["quality"] = stepName(step);
        stats["refined"] = step == static_cast<int>(Step::Balanced) || step == static_cast<int>(Step::Final);
        stats["scale"] = scale;
        stats["snapshot"] = snapshotFor != nullptr;
        stats["queue_ms"] = queueMs;
        stats["encode_ms"] = encodeMs;
        stats["bytes"] = shared->size();
        stats["codec"] = codecName(codec);
        stats["scene"] = mSceneName.empty() ? scene->name : mSceneName;

        FrameReport report;
        report.quality = stepName(step);
        report.snapshot = snapshotFor != nullptr;
        report.frameMs = stats.value("frame_ms", 0.0);
        report.queueMs = queueMs;
        report.encodeMs = encodeMs;
        report.bytes = shared->size();
        if (stats.contains("passes"))
            for (const auto& p : stats["passes"])
                report.passMs.emplace_back(p.value("name", ""), p.value("gpu_ms", 0.0));
        std::vector<std::shared_ptr<ClientLink>> targets;
        if (snapshotFor)
            targets.push_back(snapshotFor);
        else
            targets = clients();
        const std::size_t viewers = viewerCount();
        for (const auto& client : targets) {
            stats["viewers"] = viewers;
            stats["dropped_frames"] = client->droppedFrames();
            if (client->offerFrame(frameId, stats.dump(), shared, snapshotFor != nullptr))
                ++report.delivered;
            else
                ++report.dropped;
        }
        FrameObserver onFrame;
        {
            std::lock_guard lock(mMutex);
            onFrame = mOnFrame;
            if (!snapshotFor) mLastFrame = {frameId, stats, shared};
        }
        if (onFrame) onFrame(report);
    }
    renderer.reset(); // GL objects die while the context is still current
    context.reset();
}

} // namespace gis
