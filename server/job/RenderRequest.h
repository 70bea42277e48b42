// One-shot renders: the request of POST /api/render and gi-render --request (schema:
// protocol/http/render_request.json), parsed into a RenderJob, rendered and encoded by
// executeRenderJob. gi-render's flag path builds the same RenderJob and FrameState
// (makeJobFrameState) and writes PNGs with the same encoder and text chunks (renderImageMetadata), so
// a request and the equivalent command line give byte-identical PNGs.
//
// Library gis::render_job (not gis::render): it encodes, and compares with the CPU reference and
// applies the effect plan when those optional layers are built, and those layers depend on gis::render.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "encode/Encoder.h"
#include "render/FrameRenderer.h"
#include "frame/FrameState.h"
#include "scene/Scene.h"

namespace gis {

/// What one request may ask for; the server's configuration (gi-render passes its own flags' bounds).
struct RenderLimits {
    int maxWidth = 2048;
    int maxHeight = 2048;
    bool allowCompare = true;        ///< false: a request with "compare" is refused
    int maxReferenceSpp = 1024;      ///< compare.spp
    double maxReferenceSeconds = 60; ///< cap on compare.time_budget_s, and the budget of a request that
                                     ///< gives none (a reference at full spp can take hours); 0 = no cap
};

/// "compare": the CPU reference to measure the frame against (server/reference).
struct RenderCompare {
    std::string mode; ///< referenceModes()
    int spp = 64;
    double timeBudgetSeconds = 0; ///< 0 = none
    double noiseTarget = 0;       ///< relative noise to stop at, (0, 0.5]; 0 = none (spp then is the cap)
    bool noiseOfIndirect = true;  ///< the noise target is relative to the indirect light (else the image)
};

/// Everything a one-shot render depends on besides the scene's contents. Parameters, camera and
/// light are kept as the request's JSON (already validated) and applied on top of the scene's own
/// state by makeJobFrameState, in that order: technique defaults, preset, params, camera, lights, light.
struct RenderJob {
    std::string scene; ///< handed to the caller's scene resolver
    std::string technique = "rsm_gather";
    std::string preset;                               ///< "" = none
    nlohmann::json params = nlohmann::json::object(); ///< {name: value}, frame and technique tables
    int width = 512;
    int height = 512;
    std::optional<nlohmann::json> camera; ///< applyCameraJson object; absent = the scene's camera
    std::optional<nlohmann::json> lights; ///< setLightsJson array; absent = the scene's lights
    std::optional<nlohmann::json> light;  ///< editLightJson object (first light or "id"); absent = as is
    ImageCodec codec = ImageCodec::Png;
    int quality = kDefaultImageQuality; ///< jpeg and webp
    std::optional<RenderCompare> compare;
    /// Set by the caller, never by a request: where references are cached ("" = render every time).
    std::string referenceCacheDir;
};

/// The parsed schema (embedded in the binary), e.g. for the server to publish.
const nlohmann::json& renderRequestSchema();

/// Validates a request against the schema, the limits, the technique and parameter tables, the
/// presets and the camera/light rules; everything but the scene's existence (the resolver's job).
/// Throws InputError(JSON pointer of the offending field, what is wrong and how to fix it).
RenderJob parseRenderRequest(const nlohmann::json& request, const RenderLimits& limits = {});

/// The FrameState `job` renders in `scene` (before any effect plan). Throws InputError for a job that
/// parseRenderRequest would have refused.
FrameState makeJobFrameState(const Scene& scene, const RenderJob& job);

/// True when the state's frame parameters ask for the effect plan (`effects` = auto or an
/// `effect_*` forced); executeRenderJob then plans and applies it as gi-render does.
bool effectPlanRequested(const FrameState& state);

/// The PNG text chunks of a rendered frame: gi:technique, gi:scene, gi:params (paramsJson, compact).
/// Only values the image depends on: no times, so equal requests give equal bytes.
ImageMetadata renderImageMetadata(const std::string& sceneName, const FrameState& state);

/// Whether this build can honour "compare" (the reference and analysis layers are built).
bool renderJobsCanCompare();

struct RenderResult {
    std::vector<std::uint8_t> image; ///< the encoded file, exactly as written or sent
    std::string mimeType;
    /// FrameRenderer's stats plus "scene", "codec", "bytes", "encode_ms" and, with compare, "compare":
    /// the metrics of analysis/Metrics.h and {"reference": {mode, spp, seconds, cache_hit, key}}.
    nlohmann::json stats;
    /// With compare: the reference, tone-mapped like the frame, as a PNG (empty otherwise).
    std::vector<std::uint8_t> referenceImage;
};

using SceneResolver = std::function<std::shared_ptr<const Scene>(const std::string& name)>;

/// Resolves the scene (the resolver may refuse names: the server sandboxes them), builds the state,
/// applies the effect plan when asked and available, renders one frame, encodes it and, with
/// compare, renders or loads the reference and measures. Call on the thread where the renderer's GL
/// context is current. Throws InputError for bad requests and scenes, gis::Error for failures.
RenderResult executeRenderJob(FrameRenderer& renderer, const RenderJob& job,
                              const SceneResolver& resolveScene);

struct ReferenceImage;
class ReferenceRenderer;
/// The accuracy of `frame` (rendered with its linear radiance and direct pass) against `reference` of the
/// same view: analysis/Accuracy.h's JSON (whole image, indirect light, direct pass, each with the
/// reference's noise) plus "reference": {mode, spp, seconds, key}. The reference's direct light comes
/// from a pixel-centre "direct" render, cached in `cacheDir` when it is not empty, rendered with
/// `referenceRenderer` when given. Throws InputError when the sizes disagree or the build has no reference.
nlohmann::json compareWithReference(const Scene& scene, const FrameState& state, const FrameOutput& frame,
                                    const ReferenceImage& reference, const std::string& cacheDir,
                                    ReferenceRenderer* referenceRenderer = nullptr);

} // namespace gis
