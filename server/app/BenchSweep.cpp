// gi-bench sweep: every technique over its one-knob-at-a-time parameter grid (analysis/SweepGrid.h),
// timed with glFinish per pass and compared with a cached CPU reference; one row per point appended
// to OUT/sweep.jsonl and OUT/sweep.csv as soon as it is measured, so an interrupted sweep resumes
// where it stopped (a point's key: scene, size, technique, canonical parameter JSON).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/Accuracy.h"
#include "analysis/Metrics.h"
#include "analysis/SweepGrid.h"
#include "app/BenchCommon.h"
#include "core/Error.h"
#include "core/Log.h"
#include "frame/Exposure.h"
#include "gi/Technique.h"
#include "gl/Platform.h"
#include "reference/ReferenceRenderer.h"
#include "render/FrameRenderer.h"
#include "scene/SceneLoader.h"

namespace gis::bench {
namespace {

constexpr const char* kSweepUsage = R"(usage: gi-bench sweep [options]

Runs each technique over its parameter grid, taken from the technique's own parameter table (frame
parameters such as exposure are not swept): the default point, then one knob at a time through that
knob's sweep values (numeric: --steps values across its range, geometric where the table marks the
range logScale; enums: every option; bools: both), walking outward from the default. Each point gets
a warm-up frame and the median of --frames frames (glFinish around each pass), and its relative RMSE,
SSIM and FLIP against a cached CPU reference. Rows are appended to OUT/sweep.jsonl and OUT/sweep.csv
point by point; a rerun with the same OUT skips points already there. Progress goes to stderr.

Skip rules (deterministic, also applied to rows read back on resume):
  - a point whose frame takes longer than --max-frame-ms is kept (timed by one frame when its
    warm-up is already over), and the knob's values farther from the default on that side are
    skipped;
  - a knob whose first value renders exactly the default image has no effect at the defaults (for
    example bias-compensation settings while compensation is off): its other values are skipped.)";

struct Options {
    std::vector<std::string> scenes = {"builtin:cornell"};
    std::vector<std::string> techniques;
    std::vector<std::string> knobs;
    int width = 128, height = 128, steps = 4, maxPoints = 0, frames = 3;
    double maxFrameMs = 2000;
    ReferenceOptions reference;
    std::string cacheDir = cli::defaultCacheDir(), out = "bench-sweep", gl;
    bool paperTables = false;
    bool refineReference = true;
};

/// One point to measure.
struct Planned {
    std::string technique;
    std::string set; ///< "grid" or "paper:<table>"
    std::string knob;
    int side = 0;
    nlohmann::json params;
    int width = 0, height = 0;
    nlohmann::json baseline; ///< technique params of an untimed baseline to compare with, or null
};

std::string pointKey(const std::string& scene, int w, int h, const std::string& technique,
                     const nlohmann::json& params) {
    return scene + "|" + std::to_string(w) + "x" + std::to_string(h) + "|" + technique + "|" + params.dump();
}

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

constexpr const char* kCsvHeader =
    "scene,width,height,technique,set,knob,value,changes,frame_ms,gpu_ms,frames,"
    "over_budget,relative_rmse,ssim,flip,reference_mode,reference_spp,params,relative_rmse_corrected,"
    "reference_noise,indirect_relative_rmse,indirect_relative_rmse_corrected,indirect_reference_noise,"
    "direct_relative_rmse";

std::string csvRow(const nlohmann::json& r) {
    auto num = [](const nlohmann::json& v) {
        if (!v.is_number()) return std::string();
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
        return std::string(buf);
    };
    const nlohmann::json& e = r["error"];
    auto err = [&](const char* k) { return e.is_object() && e.contains(k) ? num(e[k]) : std::string(); };
    auto part = [&](const char* which, const char* k) {
        return e.is_object() && e.contains(which) ? num(e[which][k]) : std::string();
    };
    std::string value = r["value"].is_null()
                            ? ""
                            : (r["value"].is_string() ? r["value"].get<std::string>() : r["value"].dump());
    std::vector<std::string> f = {
        r["scene"].get<std::string>(),
        std::to_string(r["size"][0].get<int>()),
        std::to_string(r["size"][1].get<int>()),
        r["technique"].get<std::string>(),
        r["set"].get<std::string>(),
        r["knob"].get<std::string>(),
        value,
        r["changes"].get<std::string>(),
        num(r["frame_ms"]),
        num(r["gpu_ms"]),
        std::to_string(r["frames"].get<int>()),
        r["over_budget"].get<bool>() ? "1" : "0",
        err("relative_rmse"),
        err("ssim"),
        err("flip"),
        r["reference"].is_object() ? r["reference"]["mode"].get<std::string>() : "",
        r["reference"].is_object() ? std::to_string(r["reference"]["spp"].get<int>()) : "",
        r["params"].dump(),
        err("relative_rmse_corrected"),
        err("reference_noise"),
        part("indirect", "relative_rmse"),
        part("indirect", "relative_rmse_corrected"),
        part("indirect", "reference_noise"),
        part("direct", "relative_rmse")};
    std::string line;
    for (size_t i = 0; i < f.size(); ++i) {
        if (i > 0) line += ',';
        line += csvField(f[i]);
    }
    return line;
}

/// The seed papers' table configurations, where the technique and its knobs exist in this build.
std::vector<Planned> paperPoints(const Options& o) {
    std::vector<Planned> out;
    auto selected = [&](const std::string& t) {
        return std::find(o.techniques.begin(), o.techniques.end(), t) != o.techniques.end();
    };
    auto add = [&](const std::string& set, const std::string& tech, const nlohmann::json& changes, int w,
                   int h, const nlohmann::json& baseline = nullptr) {
        if (!selected(tech)) return;
        ParamSet ps(findTechnique(tech).info.params);
        try {
            ps.apply(changes, set);
        } catch (const InputError&) {
            return; // a knob this build lacks: the report says the table is not available
        }
        nlohmann::json base = nullptr;
        if (!baseline.is_null()) {
            ParamSet b = ps;
            b.apply(baseline, set);
            base = b.toJson();
        }
        out.push_back({tech, "paper:" + set, "", 0, ps.toJson(), w, h, base});
    };
    // 001 Table 1: splatting against stencil gathering with 256 VPLs.
    add("001-t1", "multires_splat", {{"vpl_grid", 16}}, o.width, o.height);
    add("001-t1", "multires_gather", {{"vpl_grid", 16}}, o.width, o.height);
    // 003 Table 1: positive and negative light counts.
    for (auto [p, n] :
         std::vector<std::pair<int, int>>{{100, 50}, {150, 0}, {200, 100}, {300, 0}, {300, 150}, {450, 0}})
        add("003-t1", "second_order", {{"positive_count", p}, {"negative_count", n}}, o.width, o.height);
    // 003 Table 2: low-resolution share against the error to the unoptimised (full-resolution) image.
    for (double t : {0.0, 0.0125, 0.05, 0.2, 2.0})
        add("003-t2", "second_order", {{"discontinuity_threshold", t}}, o.width, o.height,
            {{"lowres_factor", 1}});
    add("003-t2", "second_order", {{"lowres_factor", 1}}, o.width, o.height, {{"lowres_factor", 1}});
    // 000 Tables 1-2: per-VPL subsplats against indirect resolution and VPL count; time against resolution.
    for (int s : {32, 64, 128, 256}) {
        for (int g : {4, 8, 16})
            add("000-t1", "multires_splat", {{"refinement", "illumination"}, {"vpl_grid", g}}, s, s);
        add("000-t2", "multires_splat", nlohmann::json::object(), s, s);
    }
    // 002: cost per compensation step.
    std::string ssbcTech;
    for (const auto& e : techniqueRegistry())
        if (e.info.params.find("ssbc_iterations") && selected(e.info.name) &&
            (ssbcTech.empty() || e.info.name == "ssbc"))
            ssbcTech = e.info.name;
    if (!ssbcTech.empty()) {
        const ParamSpec* spec = findTechnique(ssbcTech).info.params.find("ssbc_iterations");
        for (int k = static_cast<int>(spec->min); k <= static_cast<int>(spec->max); ++k)
            add("002", ssbcTech, {{"ssbc_iterations", k}}, o.width, o.height);
    }
    return out;
}

void checkScenes(const std::vector<std::string>& scenes) {
    const auto builtins = builtinSceneNames();
    for (const auto& s : scenes) {
        if (s.rfind("builtin:", 0) != 0) continue;
        if (std::find(builtins.begin(), builtins.end(), s.substr(8)) == builtins.end()) {
            std::vector<std::string> valid;
            for (const auto& b : builtins) valid.push_back("builtin:" + b);
            throw UsageError("--scenes: unknown scene '" + s + "' (valid: " + joinList(valid) +
                             ", or a .gltf/.glb file)");
        }
    }
}

Options parseOptions(const std::vector<std::string>& args) {
    Options o;
    o.reference.mode = "one-bounce-unoccluded";
    o.reference.spp = 65536;
    // A fifth of the smallest indirect error the 128x128 sweep measures (about 0.075 on cornell).
    o.reference.noiseTarget = 0.015;
    o.reference.noiseOfIndirect = true;
    cli::OptionTable options;
    options
        .value("--scenes", "LIST", "comma-separated scenes (default builtin:cornell)",
               [&](const std::string& v) { o.scenes = splitList(v); })
        .value("--techniques", "LIST", "comma-separated techniques (default: every registered technique)",
               [&](const std::string& v) { o.techniques = splitList(v); })
        .value("--size", "WxH", "image size, 16..4096 each (default 128x128)",
               [&](const std::string& v) { cli::parseSize("--size", v, 4096, o.width, o.height); })
        .integer("--steps", "N", "values per numeric knob", 2, 16, o.steps)
        .value("--knobs", "LIST", "vary only these knobs (each must belong to a selected technique)",
               [&](const std::string& v) { o.knobs = splitList(v); })
        .integer("--max-points", "N",
                 "at most N points per technique and scene, the default point included (0: all)", 0, 100000,
                 o.maxPoints)
        .integer("--frames", "N", "timed frames per point after the warm-up", 1, 1000, o.frames)
        .number("--max-frame-ms", "MS", "per-point frame budget for the skip rule (0 = none)", 0, 1e7,
                o.maxFrameMs)
        .value(
            "--reference", "MODE",
            "reference mode (default one-bounce-unoccluded: what VPL gathering without indirect visibility "
            "converges to)",
            [&](const std::string& v) { o.reference.mode = v; })
        .integer("--spp", "N", "reference samples per pixel at most", 1, 1000000, o.reference.spp)
        .number("--noise-target", "R",
                "stop each reference once the noise of its indirect light (relative to that light, estimated "
                "from the samples' spread) is at most R (0 = none: exactly --spp samples)",
                0, 0.5, o.reference.noiseTarget)
        .value("--cache-dir", "DIR", "reference cache ($GI_CACHE_DIR, default ~/.cache/gi-render)",
               [&](const std::string& v) { o.cacheDir = v; })
        .flag("--no-reference-refinement",
              "keep each scene's reference at --noise-target; by default, when its noise exceeds a fifth of "
              "the "
              "smallest error the scene's points reach, it is rendered again to that noise (up to --spp) and "
              "the "
              "errors are measured again (the timings stand)",
              [&] { o.refineReference = false; })
        .flag("--paper-tables",
              "also measure the configurations of the seed papers' tables (first scene only; see "
              "docs/accuracy.md)",
              [&] { o.paperTables = true; })
        .value("--out", "DIR", "output folder (default bench-sweep)",
               [&](const std::string& v) { o.out = v; })
        .value("--gl", "egl|osmesa", "headless GL backend (default: $GI_GL, else egl)",
               [&](const std::string& v) { o.gl = v; });
    if (printedHelp(args, kSweepUsage, options)) std::exit(0);
    options.parse(args);
    if (o.scenes.empty()) throw UsageError("--scenes needs at least one scene");
    checkScenes(o.scenes);
    if (o.techniques.empty())
        for (const auto& e : techniqueRegistry()) o.techniques.push_back(e.info.name);
    for (const auto& t : o.techniques) findTechnique(t, "--techniques"); // names the valid ones
    for (const auto& k : o.knobs) {
        bool found = false;
        std::set<std::string> valid;
        for (const auto& t : o.techniques)
            for (const auto& s : findTechnique(t).info.params.specs()) {
                valid.insert(s.name);
                found |= s.name == k;
            }
        if (!found)
            throw UsageError("--knobs: unknown knob '" + k + "' for the selected techniques (valid: " +
                             joinList({valid.begin(), valid.end()}) + ")");
    }
    const auto modes = referenceModes();
    if (std::find(modes.begin(), modes.end(), o.reference.mode) == modes.end())
        throw UsageError("--reference must be one of " + joinList(modes) + ", got '" + o.reference.mode +
                         "'");
    return o;
}

std::map<std::string, nlohmann::json> readRows(const std::string& path) {
    std::map<std::string, nlohmann::json> rows;
    std::ifstream f(path);
    std::string line;
    while (std::getline(f, line)) {
        if (line.empty()) continue;
        nlohmann::json r = nlohmann::json::parse(line, nullptr, false);
        if (r.is_discarded() || !r.contains("key")) continue; // a line cut short by an interrupted run
        rows[r["key"].get<std::string>()] = r;
    }
    return rows;
}

bool sameImage(const std::vector<float>& a, const std::vector<float>& b) {
    return a == b;
}

} // namespace

int sweep(const std::vector<std::string>& args) {
    const Options o = parseOptions(args);
    std::filesystem::create_directories(o.out);
    const std::string jsonlPath = o.out + "/sweep.jsonl", csvPath = o.out + "/sweep.csv";
    std::map<std::string, nlohmann::json> done = readRows(jsonlPath);
    {
        // The command is kept so the report can print how to regenerate it.
        std::string cmd = "gi-bench sweep";
        for (const auto& a : args) cmd += " " + a;
        // Every distinct command that added to this folder, in order (a denser pass over one knob
        // adds to an earlier sweep), so the report can print them all.
        std::ifstream previous(o.out + "/sweep-command.txt");
        bool known = false;
        for (std::string line; std::getline(previous, line);) known |= line == cmd;
        if (!known) std::ofstream(o.out + "/sweep-command.txt", std::ios::app) << cmd << "\n";
    }
    const bool newCsv = !std::filesystem::exists(csvPath);
    std::ofstream jsonl(jsonlPath, std::ios::app), csv(csvPath, std::ios::app);
    if (!jsonl || !csv) throw InputError(o.out, "cannot write the sweep files");
    if (newCsv) csv << kCsvHeader << "\n";

    // Plan everything first so progress can say [k/N].
    struct SceneWork {
        std::string name;
        std::shared_ptr<Scene> scene;
        std::vector<std::vector<Planned>> perTechnique;
        ReferenceImage reference, referenceDirect;
        double referenceTarget = 0; ///< the noise target `reference` was rendered to
    };
    std::vector<SceneWork> work;
    size_t total = 0;
    const std::vector<Planned> papers = o.paperTables ? paperPoints(o) : std::vector<Planned>{};
    for (size_t si = 0; si < o.scenes.size(); ++si) {
        SceneWork w{o.scenes[si], std::make_shared<Scene>(loadScene(o.scenes[si])), {}, {}, {}, 0};
        for (const auto& t : o.techniques) {
            const ParamTable& table = findTechnique(t).info.params;
            std::vector<std::string> knobs;
            for (const auto& k : o.knobs)
                if (table.find(k)) knobs.push_back(k);
            std::vector<Planned> plan;
            auto grid = oneAtATimeGrid(table, o.steps, knobs);
            if (!o.knobs.empty() && knobs.empty())
                grid.resize(1); // none of the chosen knobs: the default only
            if (o.maxPoints > 0 && static_cast<int>(grid.size()) > o.maxPoints) grid.resize(o.maxPoints);
            for (auto& g : grid)
                plan.push_back({t, "grid", g.knob, g.side, g.params, o.width, o.height, nullptr});
            if (si == 0)
                for (const auto& p : papers)
                    if (p.technique == t) plan.push_back(p);
            total += plan.size();
            w.perTechnique.push_back(std::move(plan));
        }
        work.push_back(std::move(w));
    }

    // A scene's reference at `options`, with its direct light and noise; recorded in references.jsonl.
    auto renderReference = [&](SceneWork& w, const ReferenceOptions& options) {
        FrameState s = makeFrameState(*w.scene, "none");
        s.width = o.width;
        s.height = o.height;
        validateReferenceOptions(options);
        bool hit = false;
        w.reference = renderReferenceCached(*w.scene, s, options, o.cacheDir, &hit);
        w.referenceTarget = options.noiseTarget;
        // The reference's direct light (pixel centres: exact and fast) splits its indirect light off.
        w.referenceDirect = renderReferenceCached(*w.scene, s, {.mode = "direct", .spp = 1}, o.cacheDir);
        const ImageView view(w.reference.rgb, o.width, o.height, 3);
        const nlohmann::json noise = referenceNoiseJson(w.reference, w.referenceDirect);
        std::fprintf(
            stderr,
            "gi-bench: reference %s %s %dx%d, %d spp, %s; noise %s of the image, %s of its indirect light\n",
            w.name.c_str(), o.reference.mode.c_str(), o.width, o.height, w.reference.spp,
            hit ? "from the cache" : (std::to_string(w.reference.seconds) + " s").c_str(),
            noise["image"].dump().c_str(), noise["indirect"].dump().c_str());
        nlohmann::json record = {{"scene", w.name},
                                 {"size", {o.width, o.height}},
                                 {"mode", o.reference.mode},
                                 {"spp", w.reference.spp},
                                 {"seconds", w.reference.seconds},
                                 {"key", w.reference.key},
                                 {"noise_target", options.noiseTarget},
                                 {"noise", noise["image"]},
                                 {"indirect_noise", noise["indirect"]}};
        std::ofstream(o.out + "/references.jsonl", std::ios::app) << record.dump() << "\n";
    };
    // Rows measured before against a reference refined for them (below) start from that one, so a
    // rerun does not measure their errors again against a noisier one.
    auto finestTarget = [&](const std::string& scene) {
        double finest = o.reference.noiseTarget;
        for (const auto& [key, row] : done)
            if (row["scene"] == scene && row["reference"].is_object() &&
                row["reference"].contains("noise_target") && row["reference"]["noise_target"].is_number() &&
                row["reference"]["noise_target"].get<double>() > 0)
                finest = std::min(finest, row["reference"]["noise_target"].get<double>());
        return finest;
    };
    // References first (CPU, cached) so they do not disturb the GL timings.
    for (auto& w : work) {
        ReferenceOptions options = o.reference;
        if (options.noiseTarget > 0) options.noiseTarget = finestTarget(w.name);
        renderReference(w, options);
    }

    auto backend = o.gl.empty() ? gl::defaultBackend() : gl::parseBackend(o.gl);
    auto context = gl::createContext(backend);
    const std::string glName = context->info().renderer;
    size_t index = 0, measured = 0, skipped = 0;
    auto measureScene = [&](SceneWork& w) {
        auto accuracy = [&](const FrameOutput& f, const FrameState& rendered) {
            AccuracyInputs in;
            in.exposureEv = frameExposureEv(rendered); // SSIM and FLIP compare what a viewer sees
            in.test = ImageView(f.linear, f.width, f.height, 4);
            in.reference = ImageView(w.reference.rgb, w.reference.width, w.reference.height, 3);
            in.referenceVariance = w.reference.variance;
            if (f.linearDirect.size() == f.linear.size()) {
                in.testDirect = ImageView(f.linearDirect, f.width, f.height, 4);
                in.referenceDirect =
                    ImageView(w.referenceDirect.rgb, w.referenceDirect.width, w.referenceDirect.height, 3);
                in.referenceDirectVariance = w.referenceDirect.variance;
            }
            return compareAccuracy(in);
        };
        const nlohmann::json referenceRecord = {{"mode", o.reference.mode},
                                                {"spp", w.reference.spp},
                                                {"key", w.reference.key},
                                                {"noise_target", w.referenceTarget}};
        for (auto& plan : w.perTechnique) {
            if (plan.empty()) continue;
            const std::string& technique = plan.front().technique;
            // One renderer per technique: switching techniques rebuilds them.
            FrameRenderer renderer(false);
            renderer.setScene(w.scene);
            FrameState state = makeFrameState(*w.scene, technique);
            int lastW = 0, lastH = 0;
            auto render = [&](const nlohmann::json& params, int width, int height, bool timed) {
                applyParams(state, params, "sweep");
                state.width = width;
                state.height = height;
                if (width != lastW || height != lastH) {
                    renderer.render(state, false); // compile and allocate outside the timed frames
                    lastW = width;
                    lastH = height;
                }
                return timed ? measure(renderer, state, o.frames, o.maxFrameMs)
                             : Measurement{{}, renderer.render(state, true, true), 1, false};
            };
            std::vector<float> defaultImage;
            const nlohmann::json defaults = plan.front().params;
            std::map<std::string, std::vector<float>> baselines;
            std::set<std::pair<std::string, int>> closedSides; // (knob, side) past the frame budget
            std::set<std::string> inertKnobs, triedKnobs;

            for (const Planned& p : plan) {
                ++index;
                const std::string changes = describeChanges(findTechnique(technique).info.params, p.params);
                const std::string label =
                    w.name + " " + technique + " " + changes +
                    (p.width != o.width || p.height != o.height
                         ? " @" + std::to_string(p.width) + "x" + std::to_string(p.height)
                         : "");
                char prefix[32];
                std::snprintf(prefix, sizeof prefix, "[%zu/%zu] ", index, total);
                if (!p.knob.empty() && (inertKnobs.count(p.knob) || closedSides.count({p.knob, p.side}))) {
                    std::fprintf(stderr, "%s%s: skipped (%s)\n", prefix, label.c_str(),
                                 inertKnobs.count(p.knob)
                                     ? "the knob has no effect at the defaults"
                                     : "a value closer to the default was over --max-frame-ms");
                    ++skipped;
                    continue;
                }
                const std::string key = pointKey(w.name, p.width, p.height, technique, p.params);
                const bool atSweepSize = p.width == o.width && p.height == o.height;
                nlohmann::json row;
                std::vector<float> image;
                if (auto it = done.find(key); it != done.end()) {
                    row = it->second;
                    std::fprintf(stderr, "%s%s: measured before\n", prefix, label.c_str());
                    const bool staleError =
                        atSweepSize && (!row["reference"].is_object() ||
                                        row["reference"].value("key", "") != w.reference.key);
                    if (staleError) {
                        // Timed before against another reference: the timing stands, the error is
                        // measured again (untimed) against this one; the appended row supersedes it.
                        const FrameOutput f = render(p.params, p.width, p.height, false).last;
                        image = f.linear;
                        row["error"] = accuracy(f, state);
                        row["reference"] = referenceRecord;
                        jsonl << row.dump() << "\n" << std::flush;
                        csv << csvRow(row) << "\n" << std::flush;
                        done[key] = row;
                        std::fprintf(stderr,
                                     "%s%s: error measured again against this reference: rel RMSE %.3f\n",
                                     prefix, label.c_str(), row["error"]["relative_rmse"].get<double>());
                    }
                    if (!p.baseline.is_null() && !row.contains("baseline_relative_rmse")) {
                        // Measured by the grid before a paper table asked for its baseline: add it,
                        // untimed; the appended row supersedes the earlier one.
                        image = render(p.params, p.width, p.height, false).last.linear;
                        const std::string bkey = p.baseline.dump() + std::to_string(p.width);
                        if (!baselines.count(bkey))
                            baselines[bkey] = render(p.baseline, p.width, p.height, false).last.linear;
                        row["baseline_params"] = p.baseline;
                        row["baseline_relative_rmse"] =
                            relativeRmse(ImageView(image.data(), p.width, p.height, 4),
                                         ImageView(baselines[bkey].data(), p.width, p.height, 4));
                        jsonl << row.dump() << "\n" << std::flush;
                        done[key] = row;
                    }
                } else {
                    Measurement m = render(p.params, p.width, p.height, true);
                    image = m.last.linear;
                    nlohmann::json passes = nlohmann::json::array();
                    for (const auto& q : m.stats["passes"])
                        passes.push_back({{"name", q["name"]}, {"ms", q["gpu_ms"]}});
                    row = {{"key", key},
                           {"scene", w.name},
                           {"size", {p.width, p.height}},
                           {"technique", technique},
                           {"set", p.set},
                           {"knob", p.knob},
                           {"value", p.knob.empty() ? nlohmann::json() : p.params[p.knob]},
                           {"changes", changes},
                           {"params", p.params},
                           {"frame_ms", m.stats["frame_ms"]},
                           {"gpu_ms", sumPassMs(m.stats)},
                           {"passes", passes},
                           {"counts", m.stats["counts"]},
                           {"frames", m.frames},
                           {"over_budget", m.overBudget},
                           {"gl", glName},
                           {"error", nullptr},
                           {"reference", nullptr}};
                    if (atSweepSize) {
                        row["error"] = accuracy(m.last, state);
                        row["reference"] = referenceRecord;
                    }
                    if (!p.baseline.is_null()) {
                        const std::string bkey = p.baseline.dump() + std::to_string(p.width);
                        if (!baselines.count(bkey))
                            baselines[bkey] = render(p.baseline, p.width, p.height, false).last.linear;
                        row["baseline_params"] = p.baseline;
                        row["baseline_relative_rmse"] =
                            relativeRmse(ImageView(image.data(), p.width, p.height, 4),
                                         ImageView(baselines[bkey].data(), p.width, p.height, 4));
                    }
                    if (!p.knob.empty() && !triedKnobs.count(p.knob)) {
                        if (defaultImage.empty())
                            defaultImage = render(defaults, o.width, o.height, false).last.linear;
                        row["same_as_default"] = sameImage(image, defaultImage);
                    }
                    if (p.knob.empty() && p.set == "grid") defaultImage = image;
                    jsonl << row.dump() << "\n" << std::flush;
                    csv << csvRow(row) << "\n" << std::flush;
                    done[key] = row;
                    ++measured;
                    char line[160];
                    std::snprintf(line, sizeof line, "%.1f ms%s", row["frame_ms"].get<double>(),
                                  m.overBudget ? " (over budget: one frame)" : "");
                    std::string msg = line;
                    if (row["error"].is_object()) {
                        std::snprintf(line, sizeof line, ", rel RMSE %.3f, SSIM %.3f, FLIP %.3f",
                                      row["error"]["relative_rmse"].get<double>(),
                                      row["error"]["ssim"].get<double>(), row["error"]["flip"].get<double>());
                        msg += line;
                        if (row["error"].contains("indirect")) {
                            std::snprintf(line, sizeof line, ", indirect %.3f (corrected %.3f)",
                                          row["error"]["indirect"]["relative_rmse"].get<double>(),
                                          row["error"]["indirect"]["relative_rmse_corrected"].get<double>());
                            msg += line;
                        }
                    }
                    std::fprintf(stderr, "%s%s: %s\n", prefix, label.c_str(), msg.c_str());
                }
                if (!p.knob.empty()) {
                    if (!triedKnobs.count(p.knob) && row.value("same_as_default", false))
                        inertKnobs.insert(p.knob);
                    triedKnobs.insert(p.knob);
                    if (p.side != 0 && o.maxFrameMs > 0 && row["frame_ms"].get<double>() > o.maxFrameMs)
                        closedSides.insert({p.knob, p.side});
                }
            }
        }
    };
    for (auto& w : work) {
        measureScene(w);
        // The noise must stay below a fifth of the smallest error the scene's table reports; when it
        // is not, the reference is rendered again to that noise (up to --spp) and the errors are
        // measured again against it (the timings stand).
        if (!o.refineReference || o.reference.noiseTarget <= 0) continue;
        double smallest = INFINITY;
        for (const auto& [key, row] : done)
            if (row["scene"] == w.name && row["size"][0] == o.width && row["size"][1] == o.height &&
                row["error"].is_object() && row["error"].contains("indirect"))
                smallest =
                    std::min(smallest, row["error"]["indirect"]["relative_rmse_corrected"].get<double>());
        const nlohmann::json noise = referenceNoiseJson(w.reference, w.referenceDirect);
        const double wanted = smallest / 5;
        if (!std::isfinite(smallest) || !noise["indirect"].is_number() || wanted <= 0 ||
            noise["indirect"].get<double>() <= wanted * 1.05 || w.reference.spp >= o.reference.spp)
            continue;
        std::fprintf(stderr,
                     "gi-bench: %s: the reference's noise %.4f is above a fifth of the smallest error %.4f: "
                     "rendering it again to %.4f and measuring the errors again\n",
                     w.name.c_str(), noise["indirect"].get<double>(), smallest, wanted);
        ReferenceOptions finer = o.reference;
        finer.noiseTarget = std::max(wanted, 1e-4);
        renderReference(w, finer);
        measureScene(w);
    }
    std::fprintf(stderr, "gi-bench: sweep done: %zu measured, %zu measured before, %zu skipped -> %s, %s\n",
                 measured, index - measured - skipped, skipped, jsonlPath.c_str(), csvPath.c_str());
    std::printf("measured %zu new points\n", measured);
    return 0;
}

} // namespace gis::bench
