#include "session/Session.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"
#include "core/Log.h"
#include "core/Timer.h"
#include "encode/Encoder.h"
#include "gi/Technique.h"
#include "render/FrameParams.h"
#include "render/FrameRenderer.h"
#include "scene/SceneLoader.h"
#if GIS_HAVE_EFFECTS
#include "analysis/EffectPlan.h"
#endif

namespace gis {
namespace {

constexpr float kDegToRad = 0.017453292519943295f;

glm::vec3 vec3From(const nlohmann::json& a) {
    return {a[0].get<float>(), a[1].get<float>(), a[2].get<float>()};
}
nlohmann::json toJson(glm::vec3 v) {
    return {v.x, v.y, v.z};
}

nlohmann::json techniquesJson() {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& e : techniqueRegistry())
        list.push_back({{"name", e.info.name},
                        {"description", e.info.description},
                        {"paper", e.info.paper},
                        {"params_schema", e.info.params.jsonSchema()}});
    return list;
}

} // namespace

#if GIS_HAVE_EFFECTS
namespace {
bool wantsEffectPlan(const FrameState& state) {
    const ParamSet& fp = state.frameParams;
    if (fp.has("effects") && fp.getEnum("effects") != "manual") return true;
    for (const char* e : {"effect_direct", "effect_indirect", "effect_occlusion", "effect_compensation"})
        if (fp.has(e) && fp.getEnum(e) != "auto") return true;
    return false;
}

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
        {"light",
         {q(s.light.position, step), q(dir(s.light.direction), 0.1f), s.lightEnabled, s.light.intensity,
          s.light.outerConeAngle}}}
        .dump();
}
} // namespace
#endif

Session::Session(std::string id, SessionConfig config, std::shared_ptr<SceneCache> scenes, Wake wake)
    : mId(std::move(id)), mConfig(std::move(config)), mScenes(std::move(scenes)), mWake(std::move(wake)) {
    mScene = mScenes->get(mConfig.scene);
    mSceneName = mConfig.scene;
    mDesired = makeFrameState(*mScene, mConfig.technique);
    mDesired.width = mConfig.width;
    mDesired.height = mConfig.height;
}

Session::~Session() {
    stop();
}

nlohmann::json Session::stateJson() const {
    const Camera& c = mDesired.camera;
    const Light& l = mDesired.light;
    return {{"scene", mSceneName},
            {"technique", mDesired.technique},
            {"params", paramsJson(mDesired)},
            {"size", {mDesired.width, mDesired.height}},
            {"camera",
             {{"position", toJson(c.position)},
              {"target", toJson(c.target)},
              {"up", toJson(c.up)},
              {"fov_deg", c.yfovRadians / kDegToRad}}},
            {"light",
             {{"position", toJson(l.position)},
              {"direction", toJson(l.direction)},
              {"intensity", l.intensity},
              {"color", toJson(l.color)},
              {"cone_deg", l.outerConeAngle / kDegToRad},
              {"enabled", mDesired.lightEnabled}}}};
}

void Session::start() {
    nlohmann::json scenes = nlohmann::json::array();
    for (const auto& n : builtinSceneNames()) scenes.push_back("builtin:" + n);
    if (mConfig.scene.rfind("builtin:", 0) != 0) scenes.push_back(mConfig.scene);
    nlohmann::json welcome;
    {
        std::lock_guard lock(mMutex);
        welcome = {{"type", "welcome"},
                   {"protocol", kProtocolVersion},
                   {"server", "gi-server/0.1.0"},
                   {"session", mId},
                   {"scenes", scenes},
                   {"techniques", techniquesJson()},
                   {"frame_params_schema", frameParamTable().jsonSchema()},
                   {"state", stateJson()}};
    }
    queueText(welcome);
    mWorker = std::thread([this] { workerMain(); });
}

void Session::stop() {
    {
        std::lock_guard lock(mMutex);
        mStop = true;
    }
    mCv.notify_all();
    if (mWorker.joinable()) mWorker.join();
}

void Session::queueText(const nlohmann::json& msg) {
    {
        std::lock_guard lock(mMutex);
        if (mOutgoing.size() >= mConfig.maxQueuedMessages) {
            ++mDroppedMessages;
            return;
        }
        mOutgoing.push_back({false, msg.dump()});
    }
    if (mWake) mWake();
}

void Session::queueError(const ProtocolError& error) {
    queueText(errorMessage(error));
}

bool Session::popOutgoing(OutgoingMessage& out) {
    std::lock_guard lock(mMutex);
    if (mOutgoing.empty()) return false;
    out = std::move(mOutgoing.front());
    mOutgoing.pop_front();
    return true;
}

bool Session::hasOutgoing() {
    std::lock_guard lock(mMutex);
    return !mOutgoing.empty();
}

void Session::handleText(std::string_view text) {
    try {
        apply(parseClientMessage(text));
    } catch (const ProtocolError& e) {
        queueError(e);
    }
}

void Session::apply(const nlohmann::json& msg) {
    const std::string type = msg["type"];
    if (type == "ping") {
        nlohmann::json pong = {{"type", "pong"}};
        if (msg.contains("t")) pong["t"] = msg["t"];
        queueText(pong);
        return;
    }
    if (type == "hello") {
        if (msg["protocol"].get<int>() != kProtocolVersion)
            throw ProtocolError{"protocol_mismatch",
                                "this server speaks protocol " + std::to_string(kProtocolVersion) +
                                    ", the client " + std::to_string(msg["protocol"].get<int>()),
                                "/protocol", type};
        return;
    }

    std::unique_lock lock(mMutex);
    if (type == "ack") {
        if (mInFlight && msg["frame"].get<std::uint32_t>() == mInFlightFrame) mInFlight = false;
    } else if (type == "camera") {
        Camera c = mDesired.camera;
        c.position = vec3From(msg["position"]);
        c.target = vec3From(msg["target"]);
        if (msg.contains("up")) c.up = vec3From(msg["up"]);
        if (msg.contains("fov_deg")) c.yfovRadians = msg["fov_deg"].get<float>() * kDegToRad;
        if (glm::length(c.target - c.position) < 1e-6f)
            throw ProtocolError{"invalid_message", "camera position and target must differ", "/target", type};
        if (glm::length(c.up) < 1e-6f)
            throw ProtocolError{"invalid_message", "camera up must not be zero", "/up", type};
        mDesired.camera = c;
        mDirty = true;
    } else if (type == "light") {
        Light l = mDesired.light;
        if (msg.contains("position")) l.position = vec3From(msg["position"]);
        if (msg.contains("direction")) {
            glm::vec3 d = vec3From(msg["direction"]);
            float len = glm::length(d);
            if (!(len > 1e-6f))
                throw ProtocolError{"invalid_message", "light direction must not be zero", "/direction",
                                    type};
            l.direction = d / len;
        }
        if (msg.contains("intensity")) l.intensity = msg["intensity"].get<float>();
        if (msg.contains("color")) l.color = vec3From(msg["color"]);
        if (msg.contains("cone_deg")) {
            float outer = msg["cone_deg"].get<float>() * kDegToRad;
            // Keep the soft edge's proportion: inner/outer as the scene defined it.
            float ratio = l.outerConeAngle > 0 ? l.innerConeAngle / l.outerConeAngle : 0.8f;
            l.outerConeAngle = outer;
            l.innerConeAngle = std::clamp(ratio, 0.0f, 0.99f) * outer;
        }
        if (msg.contains("enabled")) mDesired.lightEnabled = msg["enabled"].get<bool>();
        mDesired.light = l;
        mDirty = true;
    } else if (type == "technique") {
        try {
            setTechnique(mDesired, msg["name"], "/name");
        } catch (const InputError& e) {
            throw ProtocolError{"unknown_technique", e.reason(), "/name", type};
        }
        mDirty = true;
    } else if (type == "params") {
        try {
            if (!applyParams(mDesired, msg["values"], "/values").empty()) mDirty = true;
        } catch (const InputError& e) {
            throw ProtocolError{"invalid_param", e.reason(), e.where(), type};
        }
    } else if (type == "resize") {
        mDesired.width = msg["size"][0];
        mDesired.height = msg["size"][1];
        mDirty = true;
    } else if (type == "scene") {
        const std::string name = msg["name"];
        bool known = name == mConfig.scene;
        for (const auto& n : builtinSceneNames()) known = known || name == "builtin:" + n;
        if (!known)
            throw ProtocolError{"unknown_scene", "unknown scene '" + name + "': pick one from welcome.scenes",
                                "/name", type};
        mSceneRequest = name;
        mDirty = true;
    }
    lock.unlock();
    mCv.notify_all();
}

void Session::workerMain() {
    std::unique_ptr<gl::Context> context;
    std::unique_ptr<FrameRenderer> renderer;
    try {
        context = gl::createContext(mConfig.backend);
        renderer = std::make_unique<FrameRenderer>();
        renderer->setScene(mScene);
    } catch (const std::exception& e) {
        logError("session " + mId + ": " + e.what());
        queueError({"render_failed", std::string("the renderer could not start: ") + e.what(), "", ""});
        return;
    }
    std::uint32_t frameId = 0;
    std::shared_ptr<const Scene> scene = mScene;
#if GIS_HAVE_EFFECTS
    std::string planKey;
    EffectPlan plan;
#endif
    while (true) {
        FrameState state;
        std::string sceneRequest;
        {
            std::unique_lock lock(mMutex);
            mCv.wait(lock, [&] { return mStop || (mDirty && !mInFlight); });
            if (mStop) break;
            mDirty = false;
            sceneRequest = std::exchange(mSceneRequest, {});
        }
        if (!sceneRequest.empty()) {
            try {
                auto next = mScenes->get(sceneRequest);
                renderer->setScene(next);
                scene = next;
                nlohmann::json stateMsg;
                {
                    std::lock_guard lock(mMutex);
                    FrameState fresh = makeFrameState(*next, mDesired.technique);
                    mDesired.camera = fresh.camera;
                    mDesired.light = fresh.light;
                    mDesired.lightEnabled = fresh.lightEnabled;
                    mScene = next;
                    mSceneName = sceneRequest;
                    stateMsg = {{"type", "state"}, {"state", stateJson()}};
                }
                queueText(stateMsg);
            } catch (const std::exception& e) {
                queueError({"scene_load_failed", e.what(), "/name", "scene"});
            }
        }
        {
            std::lock_guard lock(mMutex);
            state = mDesired;
        }
#if GIS_HAVE_EFFECTS
        // The effect plan (frame parameters `effects`, `effect_*`): measured again only when the
        // scene, the parameters, or the camera or light change materially, never every frame.
        if (wantsEffectPlan(state)) {
            const std::string key = effectPlanKey(*scene, state);
            if (key != planKey) {
                plan = planEffects(*scene, state);
                planKey = key;
            }
            applyEffectPlan(state, plan);
        }
#endif

        FrameOutput frame;
        try {
            frame = renderer->render(state);
        } catch (const std::exception& e) {
            queueError({"render_failed", e.what(), "", ""});
            continue;
        }
        Stopwatch encodeClock;
        std::vector<std::uint8_t> jpeg;
        try {
            jpeg = encodeJpeg(frame.rgba8.data(), frame.width, frame.height, mConfig.jpegQuality);
        } catch (const std::exception& e) {
            queueError({"render_failed", e.what(), "", ""});
            continue;
        }
        const double encodeMs = encodeClock.elapsedMs();
        ++frameId;
        nlohmann::json stats = frame.stats;
        stats["type"] = "stats";
        stats["frame"] = frameId;
        stats["encode_ms"] = encodeMs;
        stats["bytes"] = jpeg.size() + kFrameHeaderSize;
        stats["codec"] = "jpeg";
        stats["scene"] = scene->name;
        std::vector<std::uint8_t> message =
            makeFrameMessage(frameId, frame.width, frame.height, FrameCodec::Jpeg, jpeg);
        {
            std::lock_guard lock(mMutex);
            // Frames bypass the text cap: at most one is ever queued (one in flight).
            mOutgoing.push_back({false, stats.dump()});
            mOutgoing.push_back({true, std::string(message.begin(), message.end())});
            mInFlight = true;
            mInFlightFrame = frameId;
            ++mFramesSent;
        }
        if (mWake) mWake();
    }
    renderer.reset(); // GL objects die while the context is still current
    context.reset();
}

} // namespace gis
