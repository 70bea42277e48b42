// gi-bench: accuracy against time. Subcommands:
//   compare A.exr B.exr         error metrics of A against the reference B
//   table [options]             renders technique configurations and references of one scene side by
//                               side and prints the error-versus-time table (Markdown and JSON)
//   passes [options]            per-pass times of configurations rendered interleaved in one run,
//                               their ratios, receiver counts and the error against a GL baseline
//   sweep [options]             every technique over its parameter grid: time and error per point,
//                               appended to CSV and JSON Lines, resumable (BenchSweep.cpp)
//   report [options]            docs/accuracy.md from a sweep: plots, Pareto fronts, paper tables and
//                               presets/presets.json (BenchReport.cpp)
// Exit codes: 0 success, 1 runtime failure, 2 bad usage.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/Accuracy.h"
#include "analysis/Metrics.h"
#include "app/BenchCommon.h"
#include "core/Error.h"
#include "core/Log.h"
#include "frame/Exposure.h"
#include "gl/Platform.h"
#include "reference/ReferenceRenderer.h"
#include "render/FrameRenderer.h"
#include "scene/SceneLoader.h"

namespace {

using namespace gis::bench;
namespace cli = gis::cli;

constexpr int kMaxEyeLevels = 16;
constexpr const char* kUsage =
    R"(usage: gi-bench COMMAND [options]   (gi-bench COMMAND --help for its options)

compare TEST.exr REFERENCE.exr
         prints relative RMSE, RMSE, PSNR, max error, SSIM and FLIP of TEST against REFERENCE (same
         size; pixels black in the reference are left out) as JSON, with the reference's own
         noise (when its EXR carries the variance, as gi-render's do) and the error corrected for it.
table    GL frame time and error against converged CPU references, one row per configuration.
passes   the median ms of each pass per configuration, interleaved, and the fill-rate saving.
sweep    each technique over its parameter grid: time and error per point (CSV, JSON Lines).
report   docs/accuracy.md, its plots and presets/presets.json from a sweep.
lights   frame time against light count.
point-shadows  a point light's cube shadow map against a dual paraboloid: time and disagreement.
)";

constexpr const char* kTableHelp = R"(usage: gi-bench table [options]

Renders each technique configuration with GL (median frame time over --frames after a warm-up) and
the CPU references, then prints one row per configuration: frame time, the sum of the GPU pass
times, and the error against every reference: whole image, indirect light alone (each side less its
own direct light: the GI technique's error) and the direct pass alone (the shadow map's error), each
corrected for the reference's noise, which is printed beside it.)";

constexpr const char* kPassesHelp = R"(usage: gi-bench passes [options]

Renders every configuration --frames times, interleaved (frame k of each configuration before frame
k+1 of any), and prints the median ms of each pass per configuration, the total, the ratio of each
total to the first configuration's, the receivers per eye level against the covered pixels
(fill-rate saving) and, with --baseline, the relative RMSE of each configuration against that GL
configuration. With --in-pieces, every configuration is rendered a second time as refinement renders
it, its gather in pieces that input could stop between: what the pieces cost. With --size-before,
every timed frame follows an untimed one of that size: the same command with and without it gives
what a change of size costs a frame (the live view's frame budget changes the size as the view's
cost moves).)";

int compare(const std::vector<std::string>& args) {
    if (args.size() != 2) throw UsageError("compare needs two files: TEST.exr REFERENCE.exr");
    gis::ReferenceImage a = gis::readReferenceExr(args[0]);
    gis::ReferenceImage b = gis::readReferenceExr(args[1]);
    if (a.width != b.width || a.height != b.height)
        throw gis::InputError(args[0], "is " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                                           " but " + args[1] + " is " + std::to_string(b.width) + "x" +
                                           std::to_string(b.height));
    gis::AccuracyInputs in;
    in.test = gis::ImageView(a.rgb, a.width, a.height, 3);
    in.reference = gis::ImageView(b.rgb, b.width, b.height, 3);
    in.referenceVariance = b.variance;
    nlohmann::json out = gis::compareAccuracy(in);
    out["test"] = args[0];
    out["reference"] = args[1];
    std::cout << out.dump(2) << "\n";
    return 0;
}

int passes(const std::vector<std::string>& args) {
    RunOptions o; // 512x512, 5 frames
    std::vector<Config> baseline;
    cli::OptionTable options;
    addRunOptions(options, o, "multires_splat, multires_gather");
    options.value("--baseline", "SPEC",
                  "GL configuration the errors are measured against (rendered once, untimed)",
                  [&](const std::string& v) { baseline = {parseConfig(v)}; });
    int beforeWidth = 0, beforeHeight = 0;
    options.value("--size-before", "WxH",
                  "an untimed frame of this size before each timed one, so that each timed frame "
                  "changes size (default: none)",
                  [&](const std::string& v) {
                      gis::cli::parseSize("--size-before", v, 4096, beforeWidth, beforeHeight);
                  });
    bool inPieces = false;
    options.flag("--in-pieces",
                 "each configuration also as refinement renders it: with an interrupt check that never "
                 "stops, so that its gather goes in pieces (a second column, \"CONFIG in pieces\")",
                 [&] { inPieces = true; });
    if (printedHelp(args, kPassesHelp, options)) return 0;
    options.parse(args);
    auto& [sceneName, width, height, frames, configs, jsonPath, gl, timerQueries] = o;
    if (configs.empty()) configs = {parseConfig("multires_splat"), parseConfig("multires_gather")};
    // Configurations rendered with the never-stopping check: the second half with --in-pieces.
    const size_t checkedFrom = configs.size();
    if (inPieces) {
        for (size_t i = 0; i < checkedFrom; ++i) {
            Config checked = configs[i];
            checked.label += " in pieces";
            configs.push_back(std::move(checked));
        }
    }

    auto scene = std::make_shared<gis::Scene>(gis::loadScene(sceneName));
    std::vector<gis::FrameState> states = makeStates(*scene, configs, width, height);
    std::vector<gis::FrameState> baseStates = makeStates(*scene, baseline, width, height);
    auto backend = gl.empty() ? gis::gl::defaultBackend() : gis::gl::parseBackend(gl);
    auto context = gis::gl::createContext(backend);
    // One renderer per configuration: a renderer switching techniques would rebuild the technique
    // (shaders, buffers) on every interleaved frame.
    std::vector<std::unique_ptr<gis::FrameRenderer>> renderers;
    for (size_t i = 0; i < configs.size() + 1; ++i) {
        renderers.push_back(std::make_unique<gis::FrameRenderer>(timerQueries));
        renderers.back()->setScene(scene);
        if (i >= checkedFrom && i < configs.size()) renderers.back()->setInterruptCheck([] { return false; });
    }

    std::vector<gis::FrameOutput> last(configs.size());
    std::vector<std::vector<nlohmann::json>> stats(configs.size());
    for (size_t i = 0; i < configs.size(); ++i) last[i] = renderers[i]->render(states[i], true); // warm-up
    std::vector<gis::FrameState> before = states;
    for (gis::FrameState& b : before) {
        b.width = beforeWidth;
        b.height = beforeHeight;
    }
    for (int k = 0; k < frames; ++k) {
        for (size_t i = 0; i < configs.size(); ++i) {
            gis::logInfo("gi-bench: frame " + std::to_string(k + 1) + "/" + std::to_string(frames) + " of " +
                         configs[i].label);
            if (beforeWidth > 0) renderers[i]->render(before[i], false);
            last[i] = renderers[i]->render(states[i], true);
            stats[i].push_back(last[i].stats);
        }
    }
    gis::FrameOutput base;
    if (!baseStates.empty()) {
        gis::logInfo("gi-bench: baseline " + baseline.front().label);
        base = renderers.back()->render(baseStates.front(), true);
    }

    // Pass names in pipeline order, as they first appear.
    std::vector<std::string> names;
    nlohmann::json rows = nlohmann::json::array();
    for (size_t i = 0; i < configs.size(); ++i) {
        nlohmann::json s = gis::medianStats(stats[i]);
        nlohmann::json row = {
            {"config", configs[i].label}, {"frame_ms", s["frame_ms"]}, {"counts", s["counts"]}};
        double total = 0;
        size_t insertAt = 0; // a new pass goes after the previous pass of its own pipeline
        for (const auto& p : s["passes"]) {
            const std::string name = p["name"].get<std::string>();
            auto found = std::find(names.begin(), names.end(), name);
            if (found == names.end()) found = names.insert(names.begin() + static_cast<long>(insertAt), name);
            insertAt = static_cast<size_t>(found - names.begin()) + 1;
            row["passes"][name] = p["gpu_ms"];
            total += p["gpu_ms"].get<double>();
        }
        row["total_ms"] = total;
        if (!baseStates.empty()) {
            gis::ImageView test(last[i].linear.data(), width, height, 4),
                ref(base.linear.data(), width, height, 4);
            row["relative_rmse_vs_baseline"] = gis::relativeRmse(test, ref);
        }
        rows.push_back(row);
    }

    std::printf(
        "scene %s, %dx%d, GL %s (%s), timing %s, median of %d interleaved frames%s\n\n", sceneName.c_str(),
        width, height, context->info().backend.c_str(), context->info().renderer.c_str(),
        timerQueries ? "timer queries" : "glFinish per pass", frames,
        beforeWidth > 0
            ? (", each after a frame of " + std::to_string(beforeWidth) + "x" + std::to_string(beforeHeight))
                  .c_str()
            : "");
    std::printf("| pass (ms) |");
    for (const auto& c : configs) std::printf(" %s |", c.label.c_str());
    std::printf("\n|---|");
    for (size_t i = 0; i < configs.size(); ++i) std::printf("---|");
    std::printf("\n");
    for (const auto& n : names) {
        std::printf("| %s |", n.c_str());
        for (const auto& row : rows)
            row["passes"].contains(n) ? std::printf(" %.1f |", row["passes"][n].get<double>())
                                      : std::printf(" - |");
        std::printf("\n");
    }
    const double first = std::max(rows[0]["total_ms"].get<double>(), 1e-9);
    std::printf("| **total** |");
    for (const auto& row : rows) std::printf(" **%.1f** |", row["total_ms"].get<double>());
    std::printf("\n| total / %s |", configs[0].label.c_str());
    for (const auto& row : rows) std::printf(" %.3f |", row["total_ms"].get<double>() / first);
    std::printf("\n| frame ms (wall, incl. read-back) |");
    for (const auto& row : rows) std::printf(" %.1f |", row["frame_ms"].get<double>());
    std::printf("\n");
    const double pixels = static_cast<double>(width) * height;
    std::printf("| receivers (fraction of %d pixels) |", width * height);
    for (const auto& row : rows) {
        const auto& c = row["counts"];
        if (c.contains("receivers_total"))
            std::printf(" %.0f (%.1f%%) |", c["receivers_total"].get<double>(),
                        100.0 * c["receivers_total"].get<double>() / pixels);
        else
            std::printf(" %.0f (100%%) |", pixels);
    }
    std::printf("\n");
    for (int l = 0; l < kMaxEyeLevels; ++l) {
        const std::string key = "receivers_l" + std::to_string(l);
        bool any = false;
        for (const auto& row : rows) any |= row["counts"].contains(key);
        if (!any) break;
        std::printf("| receivers level %d |", l);
        for (const auto& row : rows)
            row["counts"].contains(key) ? std::printf(" %.0f |", row["counts"][key].get<double>())
                                        : std::printf(" - |");
        std::printf("\n");
    }
    if (!baseStates.empty()) {
        std::printf("| rel. RMSE vs %s |", baseline.front().label.c_str());
        for (const auto& row : rows) std::printf(" %.4f |", row["relative_rmse_vs_baseline"].get<double>());
        std::printf("\n");
    }
    if (!jsonPath.empty()) {
        std::ofstream f(jsonPath);
        if (!f) throw gis::InputError(jsonPath, "cannot open for writing");
        f << nlohmann::json({{"scene", sceneName}, {"size", {width, height}}, {"rows", rows}}).dump(2)
          << "\n";
    }
    return 0;
}

int table(const std::vector<std::string>& args) {
    RunOptions o;
    o.width = o.height = 256;
    std::string cacheDir = cli::defaultCacheDir();
    std::vector<std::string> modes;
    gis::ReferenceOptions ro;
    ro.spp = 65536;
    ro.noiseTarget = 0.02;
    ro.noiseOfIndirect = true;
    cli::OptionTable options;
    addRunOptions(options, o, "none, rsm_gather");
    options
        .value("--reference", "MODE",
               "reference mode, repeatable (default: one-bounce-unoccluded, one-bounce)",
               [&](const std::string& v) { modes.push_back(v); })
        .integer("--spp", "N", "reference samples per pixel at most", 1, 1000000, ro.spp)
        .number(
            "--noise-target", "R",
            "stop each reference once its indirect light's relative noise is at most R (0 = exactly --spp "
            "samples)",
            0, 0.5, ro.noiseTarget)
        .value(
            "--caustic-min-roughness", "R",
            "leave out of the reference the lights' reflection off specular lobes smoother than R reaching a "
            "rougher surface (caustics the GL pipeline does not render; biased), 0..1 (default 0 = unbiased; "
            "docs/nondiffuse.md)",
            [&](const std::string& v) {
                ro.causticMinRoughness =
                    static_cast<float>(cli::parseNumber("--caustic-min-roughness", v, 0, 1));
            })
        .value("--cache-dir", "DIR", "reference cache ($GI_CACHE_DIR, default ~/.cache/gi-render)",
               [&](const std::string& v) { cacheDir = v; });
    if (printedHelp(args, kTableHelp, options)) return 0;
    options.parse(args);
    auto& [sceneName, width, height, frames, configs, jsonPath, gl, timerQueries] = o;
    if (configs.empty()) configs = {parseConfig("none"), parseConfig("rsm_gather")};
    if (modes.empty()) modes = {"one-bounce-unoccluded", "one-bounce"};

    auto scene = std::make_shared<gis::Scene>(gis::loadScene(sceneName));
    std::vector<gis::FrameState> states = makeStates(*scene, configs, width, height);

    // References first (CPU, cached), so GL timings are not disturbed by them.
    std::vector<gis::ReferenceImage> refs;
    std::vector<nlohmann::json> noise;
    // The direct light at pixel centres (exact): what splits each reference's indirect light off.
    const gis::ReferenceImage direct =
        gis::renderReferenceCached(*scene, states.front(), {.mode = "direct", .spp = 1}, cacheDir);
    for (const auto& m : modes) {
        ro.mode = m;
        gis::validateReferenceOptions(ro);
        bool hit = false;
        refs.push_back(gis::renderReferenceCached(*scene, states.front(), ro, cacheDir, &hit));
        noise.push_back(referenceNoiseJson(refs.back(), direct));
        gis::logInfo("gi-bench: reference " + m + ": " + std::to_string(refs.back().spp) + " spp, " +
                     (hit ? "from the cache" : std::to_string(refs.back().seconds) + " s") + "; noise " +
                     noise.back()["image"].dump() + " of the image, " + noise.back()["indirect"].dump() +
                     " of its indirect light");
    }

    auto backend = gl.empty() ? gis::gl::defaultBackend() : gis::gl::parseBackend(gl);
    auto context = gis::gl::createContext(backend);
    gis::FrameRenderer renderer(timerQueries);
    renderer.setScene(scene);
    nlohmann::json rows = nlohmann::json::array();
    for (size_t i = 0; i < configs.size(); ++i) {
        Measurement m = measure(renderer, states[i], frames);
        const gis::FrameOutput& f = m.last;
        const nlohmann::json& s = m.stats;
        const double gpu = sumPassMs(s);
        nlohmann::json row = {{"config", configs[i].label},
                              {"frame_ms", s["frame_ms"]},
                              {"gpu_ms", gpu},
                              {"counts", s["counts"]},
                              {"params", s["params"]}};
        for (size_t r = 0; r < refs.size(); ++r) {
            gis::AccuracyInputs in;
            in.exposureEv = gis::frameExposureEv(states[i]); // SSIM and FLIP compare what a viewer sees
            in.test = gis::ImageView(f.linear, f.width, f.height, 4);
            in.testDirect = gis::ImageView(f.linearDirect, f.width, f.height, 4);
            in.reference = gis::ImageView(refs[r].rgb, refs[r].width, refs[r].height, 3);
            in.referenceVariance = refs[r].variance;
            if (modes[r] != "direct") {
                in.referenceDirect = gis::ImageView(direct.rgb, direct.width, direct.height, 3);
                in.referenceDirectVariance = direct.variance;
            }
            row["error"][modes[r]] = gis::compareAccuracy(in);
        }
        rows.push_back(row);
    }

    std::printf("scene %s, %dx%d, GL %s (%s)\n", sceneName.c_str(), width, height,
                context->info().backend.c_str(), context->info().renderer.c_str());
    auto figure = [](const nlohmann::json& v) {
        char buf[32];
        if (!v.is_number()) return std::string("-");
        std::snprintf(buf, sizeof buf, "%.4f", v.get<double>());
        return std::string(buf);
    };
    for (size_t r = 0; r < modes.size(); ++r)
        std::printf("reference %s: %d spp, relative noise %s of the image, %s of its indirect light\n",
                    modes[r].c_str(), refs[r].spp, figure(noise[r]["image"]).c_str(),
                    figure(noise[r]["indirect"]).c_str());
    std::printf("(rel. RMSE corrected for the reference's noise; indirect = each side less its own direct "
                "light; direct = the direct pass against the reference's)\n\n");
    std::printf("| configuration | frame ms | GPU ms |");
    for (const auto& m : modes)
        std::printf(" rel. RMSE vs %s | indirect | direct | SSIM | FLIP |", m.c_str());
    std::printf("\n|---|---|---|");
    for (size_t r = 0; r < modes.size(); ++r) std::printf("---|---|---|---|---|");
    std::printf("\n");
    for (const auto& row : rows) {
        std::printf("| %s | %.1f | %.1f |", row["config"].get<std::string>().c_str(),
                    row["frame_ms"].get<double>(), row["gpu_ms"].get<double>());
        for (const auto& m : modes) {
            const auto& e = row["error"][m];
            const nlohmann::json none;
            const auto& ind = e.contains("indirect") ? e["indirect"] : none;
            const auto& dir = e.contains("direct") ? e["direct"] : none;
            std::printf(" %s | %s | %s | %.4f | %.4f |", figure(e["relative_rmse_corrected"]).c_str(),
                        figure(ind.is_object() ? ind["relative_rmse_corrected"] : none).c_str(),
                        figure(dir.is_object() ? dir["relative_rmse"] : none).c_str(),
                        e["ssim"].get<double>(), e["flip"].get<double>());
        }
        std::printf("\n");
    }
    if (!jsonPath.empty()) {
        std::ofstream f(jsonPath);
        if (!f) throw gis::InputError(jsonPath, "cannot open for writing");
        f << nlohmann::json({{"scene", sceneName},
                             {"size", {width, height}},
                             {"reference_spp", refs.empty() ? 0 : refs.front().spp},
                             {"reference_spp_max", ro.spp},
                             {"reference_noise_target", ro.noiseTarget},
                             {"rows", rows}})
                 .dump(2)
          << "\n";
    }
    return 0;
}

int run(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty() || args[0] == "--help" || args[0] == "-h") {
        std::cout << kUsage;
        return args.empty() ? 2 : 0;
    }
    std::string command = args[0];
    args.erase(args.begin());
    if (command == "compare") return compare(args);
    if (command == "table") return table(args);
    if (command == "passes") return passes(args);
    if (command == "sweep") return sweep(args);
    if (command == "report") return report(args);
    if (command == "lights") return lights(args);
    if (command == "point-shadows") return pointShadows(args);
    throw UsageError("unknown command '" + command +
                     "': use compare, table, passes, sweep, report, lights or point-shadows (see --help)");
}

} // namespace

int main(int argc, char** argv) {
    return gis::cli::runMain("gi-bench", [&] { return run(argc, argv); });
}
