// gi-render: renders one frame (or the median of N frames) of a scene with a GI technique and writes
// the image and the per-pass stats. Exit codes: 0 success, 1 runtime failure, 2 bad usage.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/CommandLine.h"
#include "core/Error.h"
#include "core/JsonSchema.h"
#include "core/Log.h"
#include "encode/Encoder.h"
#include "effects/EffectPlan.h"
#include "analysis/Accuracy.h"
#include "analysis/Metrics.h"
#include "gi/Technique.h"
#include "gl/Platform.h"
#include "frame/Exposure.h"
#include "frame/FrameParams.h"
#include "reference/ReferenceRenderer.h"
#include "render/FrameRenderer.h"
#include "frame/Presets.h"
#include "frame/StateJson.h"
#include "job/RenderRequest.h"
#include "core/Timer.h"
#include "scene/GltfWriter.h"
#include "scene/SceneLoader.h"

namespace {

constexpr int kMaxSide = 4096; // --size, and the size a --request may ask for here

constexpr const char* kUsageHead = R"(usage: gi-render [options]

Renders a scene with a global-illumination technique and writes the image and per-pass timings.

)";

constexpr const char* kUsageTail = R"(
Examples:
  gi-render --scene builtin:cornell --technique rsm_gather --param vpl_grid=16 \
            --size 512x512 --out out.png --stats stats.json
  echo '{"scene": "builtin:cornell", "params": {"vpl_grid": 16}}' | gi-render --request - --out out.png
)";

using gis::cli::UsageError;

struct Options {
    std::string scene = "builtin:cornell";
    std::string technique = "rsm_gather";
    std::string preset;
    std::vector<std::pair<std::string, std::string>> params;
    int width = 512, height = 512;
    std::string out, stats;
    int quality = gis::kDefaultImageQuality;
    std::string request;
    std::string lights;                  ///< --lights FILE
    std::string exportGlb;               ///< --export FILE.glb
    std::vector<std::string> sceneFlags; ///< flags --request takes from its file instead
    int frames = 1;
    std::string gl;
    bool timerQueries = true;
    bool quiet = false;
    std::string referenceMode;
    gis::ReferenceOptions reference = [] {
        gis::ReferenceOptions r;
        r.spp = 256; // the CLI's default: a cleaner image than the library's
        return r;
    }();
    std::string cacheDir;
    bool useCache = true;
    std::string compare;
    bool explain = false;
    bool listResources = false;
};

/// Renders the CPU reference for `state` and writes it; returns the stats JSON.
nlohmann::json renderReference(const Options& o, const gis::Scene& scene, const gis::FrameState& state) {
    gis::ReferenceOptions ro = o.reference;
    ro.mode = o.referenceMode;
    gis::validateReferenceOptions(ro);
    gis::ReferenceImage image;
    bool hit = false;
    if (o.useCache) {
        image = gis::renderReferenceCached(scene, state, ro, o.cacheDir, &hit);
    } else {
        gis::ReferenceRenderer renderer(scene);
        image = renderer.render(state, ro, [&](int spp, double seconds) {
            if (!o.quiet)
                std::fprintf(stderr, "\rgi-render: reference %s %d spp, %.1f s", ro.mode.c_str(), spp,
                             seconds);
        });
        if (!o.quiet) std::fprintf(stderr, "\n");
    }
    if (!o.out.empty()) {
        std::vector<float> rgba(static_cast<size_t>(image.width) * image.height * 4, 1.0f);
        for (size_t i = 0, n = static_cast<size_t>(image.width) * image.height; i < n; ++i)
            for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = image.rgb[i * 3 + c];
        if (gis::imageFileNeedsLinear(o.out)) {
            gis::writeReferenceExr(o.out, image);
        } else {
            gis::ImageView view(rgba.data(), image.width, image.height, 4);
            const std::vector<std::uint8_t> rgba8 = gis::toneMapToRgba8(view, gis::frameExposureEv(state));
            gis::writeImageFile(o.out, image.width, image.height, rgba8, rgba, {{"gi:reference", ro.mode}},
                                o.quality);
        }
    }
    // The noise of the whole image (pixels the reference covers); null when unknown (one sample).
    nlohmann::json noise = nullptr;
    if (!image.variance.empty()) {
        const gis::ImageView view(image.rgb, image.width, image.height, 3);
        noise = gis::relativeNoise(view, image.variance, gis::maskFromNonZero(view));
    }
    return {{"reference", ro.mode}, {"size", {image.width, image.height}},
            {"spp", image.spp},     {"seconds", image.seconds},
            {"cache_hit", hit},     {"key", image.key},
            {"noise", noise},       {"scene", o.scene}};
}

void listTechniques() {
    int width = 0;
    for (const auto& e : gis::techniqueRegistry())
        width = std::max(width, static_cast<int>(e.info.name.size()));
    for (const auto& e : gis::techniqueRegistry())
        std::printf("%-*s  %s [%s]\n", width, e.info.name.c_str(), e.info.description.c_str(),
                    e.info.paper.c_str());
}

void writeText(const std::string& path, const std::string& text) {
    if (path == "-") {
        std::cout << text << "\n";
        return;
    }
    std::ofstream f(path);
    if (!f) throw gis::InputError(path, "cannot open for writing");
    f << text << "\n";
}

std::string requestName(const std::string& path) {
    return path == "-" ? "stdin" : path;
}

nlohmann::json readRequest(const std::string& path) {
    std::string text;
    if (path == "-") {
        text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
    } else {
        std::ifstream f(path, std::ios::binary);
        if (!f) throw gis::InputError(path, "cannot read the request file");
        text.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    }
    std::string parseError;
    nlohmann::json request = gis::parseJsonExplained(text, parseError);
    if (request.is_discarded())
        throw gis::InputError(requestName(path), "the request is not valid JSON: " + parseError);
    return request;
}

/// --request: parseRenderRequest + executeRenderJob, the server's path, with the CLI's bounds.
int runRequest(const Options& o) {
    if (!o.sceneFlags.empty())
        throw UsageError(
            o.sceneFlags.front() +
            " cannot be used with --request: the request file sets the scene, technique, preset, "
            "parameters, size, format, quality and compare");
    gis::RenderLimits limits;
    limits.maxWidth = limits.maxHeight = kMaxSide; // --size's bounds
    limits.maxReferenceSpp = 1000000;              // --spp's
    limits.maxReferenceSeconds = 0;                // a local run may take as long as it likes
    const nlohmann::json request = readRequest(o.request);
    gis::RenderJob job;
    try {
        job = gis::parseRenderRequest(request, limits);
    } catch (const gis::InputError& e) {
        throw UsageError(requestName(o.request) + ": " + e.what());
    }
    if (o.useCache) job.referenceCacheDir = o.cacheDir;
    if (!o.out.empty() && gis::codecForPath(o.out) != job.codec) {
        const std::string& ext = gis::codecInfo(job.codec).extensions.front();
        throw UsageError("--out '" + o.out + "' does not match the request's format '" +
                         gis::codecName(job.codec) + "': name it *." + ext);
    }
    const gis::gl::Backend backend = o.gl.empty() ? gis::gl::defaultBackend() : gis::gl::parseBackend(o.gl);
    // Scene and state before GL, as on the flag path: bad input fails fast.
    std::shared_ptr<const gis::Scene> scene = std::make_shared<gis::Scene>(gis::loadScene(job.scene));
    gis::makeJobFrameState(*scene, job);

    auto context = gis::gl::createContext(backend);
    if (!o.quiet)
        gis::logInfo("gl: " + context->info().backend + ", " + context->info().renderer + ", " +
                     context->info().version);
    gis::FrameRenderer renderer(o.timerQueries);
    gis::RenderResult result =
        gis::executeRenderJob(renderer, job, [&](const std::string&) { return scene; });
    result.stats["gl"] = {{"backend", context->info().backend}, {"renderer", context->info().renderer}};
    if (!o.out.empty()) gis::writeBinaryFile(o.out, result.image);
    if (!o.stats.empty()) writeText(o.stats, result.stats.dump(2));
    if (result.stats.contains("compare") && o.stats != "-")
        std::cout << result.stats["compare"].dump(2) << "\n";
    if (!o.quiet)
        gis::logInfo("gi-render: " + job.technique + " " + std::to_string(job.width) + "x" +
                     std::to_string(job.height) + " frame " +
                     std::to_string(result.stats["frame_ms"].get<double>()) + " ms, " +
                     gis::codecName(job.codec) + " " + std::to_string(result.image.size()) + " bytes");
    return 0;
}

/// What a flag asks for besides a render: print something and exit.
enum class Action { Render, ListTechniques, ListScenes, ListParams };

/// gi-render's options, each declared once: --help and the parse both come from here.
gis::cli::OptionTable optionTable(Options& o, Action& action, std::string& listParamsOf) {
    using gis::cli::parseNumber;
    gis::cli::OptionTable t;
    t.value("--scene", "NAME", "builtin:NAME or a .gltf/.glb file (default builtin:cornell)",
            [&](const std::string& v) { o.scene = v; })
        .value("--technique", "NAME", "GI technique (default rsm_gather; see --list-techniques)",
               [&](const std::string& v) { o.technique = v; })
        .value("--preset", "NAME",
               "start from the technique's preset: interactive, balanced or final (presets/presets.json or "
               "$GI_PRESETS; docs/accuracy.md); --param overrides it",
               [&](const std::string& v) { o.preset = v; })
        .value("--param", "NAME=VALUE", "set a frame or technique parameter (repeatable; see --list-params)",
               [&](const std::string& kv) {
                   const auto eq = kv.find('=');
                   if (eq == std::string::npos || eq == 0)
                       throw UsageError("--param must look like NAME=VALUE, got '" + kv + "'");
                   o.params.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
               })
        .value("--size", "WxH",
               "image size in pixels, 16.." + std::to_string(kMaxSide) + " each (default 512x512)",
               [&](const std::string& v) { gis::cli::parseSize("--size", v, kMaxSide, o.width, o.height); })
        .value("--out", "FILE",
               "write the image: .png, .jpg, .webp (tone-mapped) or .exr (linear radiance); the bytes "
               "equal the HTTP API's for the same request (PNG always, JPEG and WebP at the same "
               "--quality)",
               [&](const std::string& v) { o.out = v; })
        .integer("--quality", "N", "JPEG and lossy WebP quality (as the API)", 1, 100, o.quality)
        .value("--stats", "FILE",
               "write the stats JSON (per-pass ms, counts, params, scene_load_ms); '-' for stdout",
               [&](const std::string& v) { o.stats = v; })
        .value("--export", "FILE.glb",
               "write the scene (after loading, as the renderer sees it) as binary glTF and exit: open a "
               "built-in scene in other tools, or time the loader on any size (builtin:atrium-10k .. "
               "builtin:atrium-2000k, docs/scenes.md)",
               [&](const std::string& v) { o.exportGlb = v; })
        .value("--lights", "FILE",
               "replace the scene's lights with a JSON array of lights (or {\"lights\": [...]}), each "
               "{\"type\": \"spot\"|\"point\"|\"directional\", \"position\", \"direction\", \"intensity\" "
               "(cd; lux for directional), \"color\", \"range\", \"cone_deg\", \"inner_cone_deg\", "
               "\"enabled\"}: the request's \"lights\" (protocol/PROTOCOL.md)",
               [&](const std::string& v) { o.lights = v; })
        .value("--request", "FILE",
               "render a POST /api/render request (JSON; '-' for stdin) exactly as the server does: --out "
               "gets the encoded bytes, --stats the stats; scene, technique, preset, parameters, size, "
               "camera, light, format and compare come from the file",
               [&](const std::string& v) { o.request = v; })
        .integer("--frames", "N", "render a warm-up frame, then N frames, and report per-pass medians", 1,
                 10000, o.frames)
        .value("--gl", "egl|osmesa", "headless GL backend (default: $GI_GL, else egl)",
               [&](const std::string& v) { o.gl = v; })
        .flag("--no-timer-queries", "time passes with glFinish on the CPU instead of GPU timer queries",
              [&] { o.timerQueries = false; })
        .flag("--list-techniques", "list the techniques and exit", [&] { action = Action::ListTechniques; })
        .value("--list-params", "TECH", "list the frame parameters and TECH's parameters and exit",
               [&](const std::string& v) {
                   action = Action::ListParams;
                   listParamsOf = v;
               })
        .flag("--list-scenes", "list the built-in scenes and exit", [&] { action = Action::ListScenes; })
        .flag("--list-resources",
              "after rendering, print the frame's named resources (name, producer, format, size: the "
              "G-buffer, each light's shadow map and RSM, direct, indirect, ...)",
              [&] { o.listResources = true; })
        .flag("--explain",
              "print the effect plan (which effects run, why, measured values, estimated cost; "
              "docs/effects.md); exits after it unless --out, --stats or --compare is given. --param "
              "effects=auto applies the plan, effect_NAME=on|off forces one",
              [&] { o.explain = true; })
        .flag("--quiet", "only errors on stderr", [&] { o.quiet = true; })
        .flag("--help", "this text", [] {})
        .section("Ground truth and error (CPU reference renderer, Embree):")
        .value("--reference", "MODE",
               "render with the reference instead of GL: direct, one-bounce-unoccluded, one-bounce or "
               "path (.exr keeps linear radiance; .png/.jpg are tone-mapped)",
               [&](const std::string& v) { o.referenceMode = v; })
        .integer("--spp", "N", "reference samples per pixel", 1, 1000000, o.reference.spp)
        .value("--time-budget", "S", "stop the reference after S seconds (reports the spp reached)",
               [&](const std::string& v) {
                   o.reference.timeBudgetSeconds = parseNumber("--time-budget", v, 1e-3, 1e7);
               })
        .value("--noise-target", "R",
               "stop the reference once its relative noise (estimated from the samples' spread) is at "
               "most R, e.g. 0.01; --spp stays the upper bound",
               [&](const std::string& v) {
                   o.reference.noiseTarget = parseNumber("--noise-target", v, 1e-6, 0.999999);
               })
        .value("--noise-of", "WHAT",
               "total (default) or indirect: what --noise-target is relative to (the image, or the image "
               "less its direct light, as GI comparisons measure)",
               [&](const std::string& v) {
                   if (v != "total" && v != "indirect")
                       throw UsageError("--noise-of must be total or indirect, got '" + v + "'");
                   o.reference.noiseOfIndirect = v == "indirect";
               })
        .value("--seed", "N", "reference random seed, 0..2147483647 (default 1)",
               [&](const std::string& v) {
                   o.reference.seed =
                       static_cast<std::uint64_t>(gis::cli::parseInteger("--seed", v, 0, 2147483647));
               })
        .integer("--max-depth", "N", "path mode: vertices per path", 1, 64, o.reference.maxDepth)
        .value("--caustic-min-roughness", "R",
               "leave out the lights' reflection off specular lobes smoother than R that reaches a "
               "rougher surface (caustics the GL pipeline does not render; biased), 0..1 (default 0 = "
               "unbiased; docs/nondiffuse.md)",
               [&](const std::string& v) {
                   o.reference.causticMinRoughness =
                       static_cast<float>(parseNumber("--caustic-min-roughness", v, 0.0, 1.0));
               })
        .value("--cache-dir", "DIR",
               "reuse references rendered before ($GI_CACHE_DIR, default ~/.cache/gi-render)",
               [&](const std::string& v) { o.cacheDir = v; })
        .flag("--no-cache", "always render the reference", [&] { o.useCache = false; })
        .value("--compare", "REF.exr",
               "compare the rendered frame's linear radiance with a reference EXR of the same size: prints "
               "relative RMSE, RMSE, PSNR, max error, SSIM and FLIP (background pixels, black in the "
               "reference, are left out), the reference's own noise and the error corrected for it; and "
               "\"indirect\" (each side less its own direct light: the GI technique's error) and \"direct\" "
               "(the direct pass against the reference's, rendered here at pixel centres: the shadow "
               "map's error)",
               [&](const std::string& v) { o.compare = v; });
    return t;
}

int run(int argc, char** argv) {
    Options o;
    Action action = Action::Render;
    std::string listParamsOf;
    const std::vector<std::string> args(argv + 1, argv + argc);
    const gis::cli::OptionTable options = optionTable(o, action, listParamsOf);
    // Help wins over everything else on the line, mistakes included.
    if (gis::cli::OptionTable::asksForHelp(args)) {
        std::cout << kUsageHead << options.usage() << kUsageTail;
        return 0;
    }
    options.parse(args);
    switch (action) {
    case Action::Render:
        break;
    case Action::ListTechniques:
        listTechniques();
        return 0;
    case Action::ListScenes:
        for (const auto& n : gis::builtinSceneNames()) std::printf("builtin:%s\n", n.c_str());
        return 0;
    case Action::ListParams: {
        const auto& entry = gis::findTechnique(listParamsOf, "--list-params");
        std::printf("frame parameters (every technique):\n%s", gis::frameParamTable().describe().c_str());
        std::printf("%s parameters:\n%s", listParamsOf.c_str(),
                    entry.info.params.empty() ? "  (none)\n" : entry.info.params.describe().c_str());
        return 0;
    }
    }
    // Flags whose settings a --request file carries (or that do not apply to one frame of it).
    static const std::vector<std::string> kRequestConflicts = {
        "--scene",     "--technique", "--preset",    "--param",        "--size",        "--quality",
        "--frames",    "--explain",   "--reference", "--spp",          "--time-budget", "--seed",
        "--max-depth", "--compare",   "--lights",    "--noise-target", "--noise-of"};
    for (const std::string& a : args)
        if (std::find(kRequestConflicts.begin(), kRequestConflicts.end(), a) != kRequestConflicts.end())
            o.sceneFlags.push_back(a);
    if (o.quiet) gis::setLogLevel(gis::LogLevel::Error);
    if (o.cacheDir.empty()) o.cacheDir = gis::cli::defaultCacheDir();
    if (!o.referenceMode.empty()) {
        auto modes = gis::referenceModes();
        if (std::find(modes.begin(), modes.end(), o.referenceMode) == modes.end()) {
            std::string known;
            for (const auto& m : modes) known += (known.empty() ? "" : ", ") + m;
            throw UsageError("--reference must be one of " + known + ", got '" + o.referenceMode + "'");
        }
        if (!o.compare.empty())
            throw UsageError("--compare compares a GL frame: it cannot be used with --reference");
    }
    if (!o.request.empty()) return runRequest(o);
    if (!o.out.empty() && !gis::codecForPath(o.out) && !gis::imageFileNeedsLinear(o.out))
        throw UsageError("--out must end in " + gis::codecExtensionList() + " or .exr, got '" + o.out + "'");

    // Validate everything that needs no GL before creating a context.
    const gis::gl::Backend backend = o.gl.empty() ? gis::gl::defaultBackend() : gis::gl::parseBackend(o.gl);
    if (!o.exportGlb.empty()) {
        if (!o.exportGlb.ends_with(".glb"))
            throw UsageError("--export writes binary glTF: the file must end in .glb");
        const gis::Stopwatch loadClock;
        const gis::Scene loaded = gis::loadScene(o.scene);
        const double loadMs = loadClock.elapsedMs();
        gis::writeGlb(loaded, o.exportGlb);
        gis::logInfo("gi-render: " + o.scene + " (" + std::to_string(loaded.triangleCount()) +
                     " triangles, loaded in " + std::to_string(loadMs) + " ms) written to " + o.exportGlb);
        return 0;
    }
    const gis::Stopwatch loadClock;
    auto scene = std::make_shared<gis::Scene>(gis::loadScene(o.scene));
    const double sceneLoadMs = loadClock.elapsedMs();
    gis::FrameState state;
    {
        // The flags become the RenderJob of the equivalent request, and the state comes from it as in
        // executeRenderJob, so `--request` and the flags cannot drift apart. The flags are checked
        // first on their own state, for errors that name the flag.
        gis::RenderJob job;
        job.scene = o.scene;
        job.technique = o.technique;
        job.preset = o.preset;
        job.width = o.width;
        job.height = o.height;
        gis::FrameState typed = gis::makeFrameState(*scene, o.technique);
        if (!o.preset.empty()) gis::applyPreset(typed, o.preset);
        for (const auto& [k, v] : o.params) {
            gis::setParamFromString(typed, k, v, "--param " + k);
            job.params[k] = gis::paramsJson(typed)[k]; // the value as the parameter's type
        }
        if (!o.lights.empty()) {
            const nlohmann::json file = readRequest(o.lights);
            const nlohmann::json& list = file.is_object() && file.contains("lights") ? file["lights"] : file;
            gis::FrameState probe = typed;
            gis::setLightsJson(probe, list, "--lights " + o.lights); // names the file and the field
            job.lights = list;
        }
        state = gis::makeJobFrameState(*scene, job);
    }

    // Effect planning runs before GL (it needs only the scene) and never for a reference, which is
    // the ground truth the plan is measured against.
    if ((o.explain || gis::effectPlanRequested(state)) && o.referenceMode.empty()) {
        const gis::EffectPlan plan = gis::planEffects(*scene, state);
        gis::applyEffectPlan(state, plan);
        if (o.explain) {
            std::cout << gis::describe(plan);
            if (o.out.empty() && o.stats.empty() && o.compare.empty()) return 0;
        }
    }

    if (!o.referenceMode.empty()) {
        nlohmann::json summary = renderReference(o, *scene, state);
        if (!o.stats.empty()) writeText(o.stats, summary.dump(2));
        if (!o.quiet)
            gis::logInfo("gi-render: reference " + o.referenceMode + " " +
                         std::to_string(summary["spp"].get<int>()) + " spp in " +
                         std::to_string(summary["seconds"].get<double>()) + " s" +
                         (summary["cache_hit"].get<bool>() ? " (from the cache)" : ""));
        return 0;
    }
    gis::ReferenceImage compareWith;
    if (!o.compare.empty()) {
        compareWith = gis::readReferenceExr(o.compare);
        if (compareWith.width != o.width || compareWith.height != o.height)
            throw UsageError("--compare: '" + o.compare + "' is " + std::to_string(compareWith.width) + "x" +
                             std::to_string(compareWith.height) + " but --size is " +
                             std::to_string(o.width) + "x" + std::to_string(o.height));
    }

    auto context = gis::gl::createContext(backend);
    if (!o.quiet)
        gis::logInfo("gl: " + context->info().backend + ", " + context->info().renderer + ", " +
                     context->info().version);
    gis::FrameRenderer renderer(o.timerQueries);
    renderer.setScene(scene);

    const bool wantLinear = gis::imageFileNeedsLinear(o.out) || !o.compare.empty();
    const bool wantDirect = !o.compare.empty();
    gis::FrameOutput frame =
        renderer.render(state, wantLinear, wantDirect); // warm-up (shader JIT, allocation)
    std::vector<nlohmann::json> stats;
    for (int f = 0; f < o.frames; ++f) {
        frame = renderer.render(state, wantLinear, wantDirect);
        stats.push_back(frame.stats);
    }
    if (o.listResources) {
        std::printf("%-28s %-12s %-18s %s\n", "resource", "producer", "format", "size");
        for (const gis::FrameResource& r : renderer.resources().list()) {
            const std::string layers = r.layers > 1 ? " x " + std::to_string(r.layers) + " layers" : "";
            std::printf("%-28s %-12s %-18s %dx%d%s\n", r.name.c_str(), r.producer.c_str(), r.format.c_str(),
                        r.width, r.height, layers.c_str());
        }
    }
    nlohmann::json summary = gis::medianStats(stats);
    summary["scene"] = o.scene;
    summary["scene_load_ms"] = sceneLoadMs; // read, decode and finish on the CPU (not the GPU upload)
    summary["scene_triangles"] = scene->triangleCount();
    summary["gl"] = {{"backend", context->info().backend}, {"renderer", context->info().renderer}};

    if (!o.compare.empty()) {
        summary["compare"] = gis::compareWithReference(*scene, state, frame, compareWith,
                                                       o.useCache ? o.cacheDir : std::string());
        summary["compare"]["reference"]["file"] = o.compare;
        std::cout << summary["compare"].dump(2) << "\n";
    }
    if (!o.out.empty()) {
        // The same encoder and text chunks as executeRenderJob: a PNG equals the API's for the same request.
        gis::writeImageFile(o.out, frame.width, frame.height, frame.rgba8, frame.linear,
                            gis::renderImageMetadata(o.scene, state), o.quality);
    }
    if (!o.stats.empty()) writeText(o.stats, summary.dump(2));
    if (!o.quiet) {
        std::string line = "gi-render: " + state.technique + " " + std::to_string(o.width) + "x" +
                           std::to_string(o.height) + " frame " +
                           std::to_string(summary["frame_ms"].get<double>()) + " ms (median of " +
                           std::to_string(o.frames) + ")";
        for (const auto& p : summary["passes"])
            line += "\n  " + p["name"].get<std::string>() + ": " + std::to_string(p["gpu_ms"].get<double>()) +
                    " ms";
        gis::logInfo(line);
    }
    if (state.lightSource == "default") {
        gis::logWarn("gi-render: default lighting: " + state.lightNote + " (--lights FILE places your own)");
    }
    if (const nlohmann::json exposure = gis::baseExposureJson(state); exposure["source"] == "metered") {
        gis::logInfo("gi-render: exposure " + gis::evText(exposure["ev"].get<double>()) + ": " +
                     exposure["note"].get<std::string>() +
                     " (--param exposure=EV adds to it; --param metering=off makes it absolute)");
    }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    return gis::cli::runMain("gi-render", [&] { return run(argc, argv); });
}
