// One-shot render requests (RenderRequest.h): schema check with hints per field, the semantic checks
// of the parameter tables and StateJson, and the render/encode/compare sequence gi-render shares.
#include "job/RenderRequest.h"

#include <algorithm>
#include <cmath>
#include <span>

#include "core/EmbeddedFiles.h"
#include "core/Error.h"
#include "core/JsonSchema.h"
#include "core/Timer.h"
#include "frame/Exposure.h"
#include "frame/FrameParams.h"
#include "frame/Presets.h"
#include "frame/StateJson.h"
#if GIS_HAVE_REFERENCE && GIS_HAVE_ANALYSIS
#include "analysis/Accuracy.h"
#include "analysis/Metrics.h"
#include "reference/ReferenceRenderer.h"
#define GIS_RENDER_JOB_COMPARE 1
#else
#define GIS_RENDER_JOB_COMPARE 0
#endif
#if GIS_HAVE_EFFECTS
#include "effects/EffectPlan.h"
#endif

namespace gis {
namespace embedded {
std::span<const EmbeddedFile> httpSchemas(); // protocol/http/*.json, gis_embed_files in CMakeLists.txt
} // namespace embedded

namespace {

constexpr const char* kKnownFields =
    "scene, technique, preset, params, size, format, quality, camera, light, lights, compare";

/// How to fix a schema violation at `pointer`, by the request field it is in.
std::string hintFor(const std::string& pointer, const std::string& message, const RenderLimits& limits) {
    if (pointer.empty()) return "a request needs at least {\"scene\": \"builtin:cornell\"}";
    const auto end = pointer.find('/', 1);
    const std::string field = pointer.substr(1, end == std::string::npos ? std::string::npos : end - 1);
    if (field == "scene") return "scene names the scene to render, e.g. \"builtin:cornell\"";
    if (field == "technique") return "technique is a name from GET /api/techniques, e.g. \"rsm_gather\"";
    if (field == "preset") return "preset is one of interactive, balanced, final";
    if (field == "params")
        return "params is an object {name: value} of frame and technique parameters (GET /api/techniques, "
               "gi-render --list-params TECH)";
    if (field == "size")
        return "size is [width, height] in pixels, 16.." + std::to_string(limits.maxWidth) + " by 16.." +
               std::to_string(limits.maxHeight);
    if (field == "format") return "format is one of png, jpeg, webp";
    if (field == "quality") return "quality is an integer from 1 to 100, for jpeg and webp";
    if (field == "camera")
        return "camera is {\"position\": [x, y, z], \"target\": [x, y, z]} in metres, optionally with \"up\" "
               "and \"fov_deg\" (1..170)";
    if (field == "light")
        return "light edits the scene's first light (or the one named by \"id\") with any of type (spot, "
               "point, "
               "directional), position [x, y, z], direction [x, y, z] (components in [-1, 1]), intensity (>= "
               "0; cd, "
               "lux for directional), color [r, g, b] in [0, 1], range (>= 0 m), cone_deg (1..85), "
               "inner_cone_deg, "
               "enabled";
    if (field == "lights")
        return "lights replaces the scene's lights: an array of lights, each with a type (spot, point, "
               "directional) and the fields of light";
    if (field == "compare")
        return "compare is {\"mode\": \"direct\" | \"one-bounce-unoccluded\" | \"one-bounce\" | \"path\", "
               "\"spp\": samples per pixel, \"time_budget_s\": seconds, \"noise_target\": relative noise to "
               "stop at (e.g. 0.05), \"noise_of\": \"indirect\" | \"image\"}";
    if (message.rfind("unknown field", 0) == 0) return std::string("known fields: ") + kKnownFields;
    return {};
}

/// The parameter tables with the job's technique, preset and params, without a scene: validates them
/// and is the part of makeJobFrameState that does not depend on the scene.
void applyJobParams(FrameState& state, const RenderJob& job) {
    setTechnique(state, job.technique, "/technique");
    if (!job.preset.empty()) {
        try {
            applyPreset(state, job.preset);
        } catch (const InputError& e) {
            throw InputError("/preset", e.what());
        }
    }
    applyParams(state, job.params, "/params");
}

#if GIS_RENDER_JOB_COMPARE
ReferenceOptions referenceOptions(const RenderCompare& compare) {
    ReferenceOptions options;
    options.mode = compare.mode;
    options.spp = compare.spp;
    options.timeBudgetSeconds = compare.timeBudgetSeconds;
    options.noiseTarget = compare.noiseTarget;
    options.noiseOfIndirect = compare.noiseOfIndirect;
    try {
        validateReferenceOptions(options);
    } catch (const InputError& e) {
        throw InputError("/compare", e.what());
    }
    return options;
}
#endif

// A request's "light": edits the light named by its "id", or the first one.
void editRequestLight(FrameState& state, const nlohmann::json& light) {
    std::string id;
    if (light.is_object())
        if (auto i = light.find("id"); i != light.end() && i->is_string()) id = i->get<std::string>();
    editLightJson(state, id, light, "/light", true);
}

} // namespace

const nlohmann::json& renderRequestSchema() {
    static const nlohmann::json schema = [] {
        auto text = findEmbedded(embedded::httpSchemas(), "http/render_request.json");
        GIS_ASSERT_MSG(text.has_value(), "protocol/http/render_request.json is not embedded");
        return nlohmann::json::parse(*text);
    }();
    return schema;
}

RenderJob parseRenderRequest(const nlohmann::json& request, const RenderLimits& limits) {
    if (!request.is_object())
        throw InputError("", "a render request is a JSON object such as {\"scene\": \"builtin:cornell\"}");
    if (auto v = validateJson(request, renderRequestSchema())) {
        // A parameter value of the wrong type (null, an array) is left to the parameter tables below,
        // whose error names the parameter's type and range, when nothing else is wrong.
        bool tablesJudge = false;
        if (v->pointer.rfind("/params/", 0) == 0) {
            nlohmann::json rest = request;
            rest["params"] = nlohmann::json::object();
            tablesJudge = !validateJson(rest, renderRequestSchema()).has_value();
        }
        if (!tablesJudge) {
            const std::string hint = hintFor(v->pointer, v->message, limits);
            throw InputError(v->pointer, v->message + (hint.empty() ? "" : " (" + hint + ")"));
        }
    }

    RenderJob job;
    job.scene = request["scene"].get<std::string>();
    job.technique = request.value("technique", job.technique);
    job.preset = request.value("preset", std::string());
    if (auto p = request.find("params"); p != request.end()) job.params = *p;
    if (auto s = request.find("size"); s != request.end()) {
        // Compared as doubles: the schema lets 1e12 through as an integer, and int cannot hold it.
        const double w = (*s)[0].get<double>(), h = (*s)[1].get<double>();
        if (w > limits.maxWidth)
            throw InputError("/size/0", "width " + (*s)[0].dump() + " is above the limit of " +
                                            std::to_string(limits.maxWidth) + " pixels: ask for at most " +
                                            std::to_string(limits.maxWidth));
        if (h > limits.maxHeight)
            throw InputError("/size/1", "height " + (*s)[1].dump() + " is above the limit of " +
                                            std::to_string(limits.maxHeight) + " pixels: ask for at most " +
                                            std::to_string(limits.maxHeight));
        job.width = static_cast<int>(w);
        job.height = static_cast<int>(h);
    }
    if (auto f = request.find("format"); f != request.end()) job.codec = parseImageCodec(*f, "/format");
    job.quality = request.value("quality", job.quality);

    // Everything the FrameState needs, checked now so that a bad request fails before any GL work:
    // the parameters on a scene-less state, camera and light on default ones.
    FrameState probe;
    probe.frameParams = ParamSet(frameParamTable());
    applyJobParams(probe, job);
    if (auto c = request.find("camera"); c != request.end()) {
        applyCameraJson(probe, *c, "/camera");
        job.camera = *c;
    }
    if (auto l = request.find("lights"); l != request.end()) {
        setLightsJson(probe, *l, "/lights");
        job.lights = *l;
    }
    if (auto l = request.find("light"); l != request.end()) {
        // The scene's light ids are known only once it is loaded (makeJobFrameState checks them).
        if (!request.contains("lights")) {
            std::string id = "light0";
            if (l->is_object())
                if (auto i = l->find("id"); i != l->end() && i->is_string()) id = i->get<std::string>();
            probe.lights = {{id, Light{}, true}};
        }
        editRequestLight(probe, *l);
        job.light = *l;
    }

    if (auto c = request.find("compare"); c != request.end()) {
        if (!renderJobsCanCompare())
            throw InputError("/compare",
                             "this build has no CPU reference renderer (Embree): leave out compare");
        if (!limits.allowCompare)
            throw InputError("/compare", "this server does not render references: leave out compare");
        RenderCompare cmp;
        cmp.mode = (*c)["mode"].get<std::string>();
        if (auto spp = c->find("spp"); spp != c->end()) {
            if (spp->get<double>() > limits.maxReferenceSpp)
                throw InputError("/compare/spp", "spp " + spp->dump() + " is above the limit of " +
                                                     std::to_string(limits.maxReferenceSpp) +
                                                     ": ask for fewer samples per pixel");
            cmp.spp = static_cast<int>(spp->get<double>());
        }
        // With a noise target the render stops when the noise reaches it; spp is then only the cap,
        // the server's own unless the request asks for fewer.
        cmp.noiseTarget = c->value("noise_target", 0.0);
        cmp.noiseOfIndirect = c->value("noise_of", std::string("indirect")) == "indirect";
        if (cmp.noiseTarget > 0 && !c->contains("spp")) cmp.spp = limits.maxReferenceSpp;
        cmp.timeBudgetSeconds = c->value("time_budget_s", 0.0);
        if (limits.maxReferenceSeconds > 0) {
            if (cmp.timeBudgetSeconds > limits.maxReferenceSeconds)
                throw InputError("/compare/time_budget_s",
                                 "time_budget_s " + nlohmann::json(cmp.timeBudgetSeconds).dump() +
                                     " is above the limit of " +
                                     nlohmann::json(limits.maxReferenceSeconds).dump() + " seconds");
            if (cmp.timeBudgetSeconds == 0) cmp.timeBudgetSeconds = limits.maxReferenceSeconds;
        }
#if GIS_RENDER_JOB_COMPARE
        referenceOptions(cmp); // the reference layer's own checks, before any rendering
#endif
        job.compare = cmp;
    }
    return job;
}

FrameState makeJobFrameState(const Scene& scene, const RenderJob& job) {
    FrameState state = makeFrameState(scene, job.technique);
    applyJobParams(state, job);
    if (job.camera) applyCameraJson(state, *job.camera, "/camera");
    if (job.lights) {
        setLightsJson(state, *job.lights, "/lights");
        state.lightSource = "request";
        state.lightNote = "the request's " + std::to_string(state.lights.size()) + " lights";
    }
    if (job.light) {
        editRequestLight(state, *job.light);
        state.lightSource = "request";
        if (!job.lights) state.lightNote = "the scene's lights with the request's light";
    }
    state.width = job.width;
    state.height = job.height;
    return state;
}

bool effectPlanRequested(const FrameState& state) {
    const ParamSet& fp = state.frameParams;
    if (fp.has("effects") && fp.getEnum("effects") != "manual") return true;
    for (const char* e : {"effect_direct", "effect_indirect", "effect_occlusion", "effect_compensation"})
        if (fp.has(e) && fp.getEnum(e) != "auto") return true;
    return false;
}

ImageMetadata renderImageMetadata(const std::string& sceneName, const FrameState& state) {
    return {
        {"gi:technique", state.technique}, {"gi:scene", sceneName}, {"gi:params", paramsJson(state).dump()}};
}

bool renderJobsCanCompare() {
    return GIS_RENDER_JOB_COMPARE != 0;
}

#if GIS_RENDER_JOB_COMPARE
nlohmann::json compareWithReference(const Scene& scene, const FrameState& state, const FrameOutput& frame,
                                    const ReferenceImage& reference, const std::string& cacheDir,
                                    ReferenceRenderer* referenceRenderer) {
    const auto pixels = static_cast<size_t>(frame.width) * static_cast<size_t>(frame.height);
    if (reference.width != frame.width || reference.height != frame.height ||
        frame.linear.size() != pixels * 4)
        throw InputError("reference", "is " + std::to_string(reference.width) + "x" +
                                          std::to_string(reference.height) + ", the frame " +
                                          std::to_string(frame.width) + "x" + std::to_string(frame.height));
    AccuracyInputs in;
    in.test = ImageView(frame.linear, frame.width, frame.height, 4);
    in.reference = ImageView(reference.rgb, reference.width, reference.height, 3);
    in.referenceVariance = reference.variance;
    in.exposureEv = frameExposureEv(state);
    // The reference's own direct light at pixel centres (exact, fast; cached beside the reference):
    // the split into indirect light and direct pass. A direct reference has nothing to split.
    ReferenceImage direct;
    const bool split = reference.mode != "direct" && frame.linearDirect.size() == pixels * 4;
    if (split) {
        const ReferenceOptions directOptions{.mode = "direct", .spp = 1};
        if (!cacheDir.empty()) {
            direct = renderReferenceCached(scene, state, directOptions, cacheDir);
        } else if (referenceRenderer) {
            direct = referenceRenderer->render(state, directOptions);
        } else {
            direct = ReferenceRenderer(scene).render(state, directOptions);
        }
        in.testDirect = ImageView(frame.linearDirect, frame.width, frame.height, 4);
        in.referenceDirect = ImageView(direct.rgb, direct.width, direct.height, 3);
        in.referenceDirectVariance = direct.variance;
    }
    nlohmann::json out = compareAccuracy(in);
    out["reference"] = {{"mode", reference.mode},
                        {"spp", reference.spp},
                        {"seconds", reference.seconds},
                        {"key", reference.key}};
    if (split) out["direct"]["reference"] = {{"mode", "direct"}, {"spp", direct.spp}, {"key", direct.key}};
    return out;
}
#else
nlohmann::json compareWithReference(const Scene&, const FrameState&, const FrameOutput&,
                                    const ReferenceImage&, const std::string&, ReferenceRenderer*) {
    throw InputError("/compare", "this build has no CPU reference renderer (Embree): leave out compare");
}
#endif

RenderResult executeRenderJob(FrameRenderer& renderer, const RenderJob& job,
                              const SceneResolver& resolveScene) {
    std::shared_ptr<const Scene> scene = resolveScene(job.scene);
    if (!scene) throw InputError("/scene", "unknown scene '" + job.scene + "'");
    FrameState state = makeJobFrameState(*scene, job);
#if GIS_HAVE_EFFECTS
    if (effectPlanRequested(state)) applyEffectPlan(state, planEffects(*scene, state));
#endif
    if (renderer.scene() != scene.get()) renderer.setScene(scene);
    const bool wantLinear = job.compare.has_value();
    FrameOutput frame = renderer.render(state, wantLinear, wantLinear);

    RenderResult result;
    Stopwatch encodeClock;
    result.image = encodeImage(job.codec, frame.rgba8.data(), frame.width, frame.height, job.quality,
                               renderImageMetadata(job.scene, state));
    result.mimeType = codecMimeType(job.codec);
    result.stats = std::move(frame.stats);
    result.stats["scene"] = job.scene;
    result.stats["codec"] = codecName(job.codec);
    result.stats["bytes"] = result.image.size();
    result.stats["encode_ms"] = encodeClock.elapsedMs();

    if (job.compare) {
#if GIS_RENDER_JOB_COMPARE
        const ReferenceOptions options = referenceOptions(*job.compare);
        bool cacheHit = false;
        ReferenceImage reference;
        std::unique_ptr<ReferenceRenderer> referenceRenderer;
        if (!job.referenceCacheDir.empty()) {
            reference = renderReferenceCached(*scene, state, options, job.referenceCacheDir, &cacheHit);
        } else {
            referenceRenderer = std::make_unique<ReferenceRenderer>(*scene);
            reference = referenceRenderer->render(state, options);
        }
        const ImageView truth(reference.rgb.data(), reference.width, reference.height, 3);
        nlohmann::json compare = compareWithReference(*scene, state, frame, reference, job.referenceCacheDir,
                                                      referenceRenderer.get());
        compare["reference"]["cache_hit"] = cacheHit;
        if (options.noiseTarget > 0)
            compare["reference"]["noise_target"] = {{"value", options.noiseTarget},
                                                    {"of", options.noiseOfIndirect ? "indirect" : "image"}};
        result.stats["compare"] = std::move(compare);
        // The reference as a PNG through the same display transform as gi-render --reference, so a
        // client can show it beside the frame.
        const std::vector<std::uint8_t> rgba8 = toneMapToRgba8(truth, frameExposureEv(state));
        result.referenceImage = encodePng(rgba8.data(), reference.width, reference.height);
#else
        throw InputError("/compare", "this build has no CPU reference renderer (Embree): leave out compare");
#endif
    }
    return result;
}

} // namespace gis
