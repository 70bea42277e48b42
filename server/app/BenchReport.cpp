// gi-bench report: docs/accuracy.md from a sweep (BenchSweep.cpp): per scene an error-versus-time
// plot (gnuplot, when installed) with each technique's Pareto front, a table of the fronts, the seed
// papers' tables as this renderer measures them beside the papers' own numbers, and the presets
// chosen from the fronts (presets/presets.json, read by frame/Presets.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <iostream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/Pareto.h"
#include "analysis/SweepGrid.h"
#include "app/BenchCommon.h"
#include "core/Error.h"
#include "gi/Technique.h"
#include "frame/Presets.h"

namespace gis::bench {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kReportUsage = R"(usage: gi-bench report [options]

Reads a sweep (gi-bench sweep) and writes the accuracy report: per scene an error-versus-time plot
with each technique's Pareto front (gnuplot PNG; skipped with a note when gnuplot is missing), a
table of the fronts, the seed papers' tables as measured here beside the papers' numbers, and the
presets chosen from the fronts.

The error axis (--metric) is by default the technique's indirect light alone (each side less its
own direct light), relative RMSE corrected for the reference's noise; "image" uses the whole image
(also corrected). Each scene's reference noise is printed with its table, with a warning where it
exceeds a fifth of the smallest error the table reports.

Presets, per technique, from the front of the points measured in every scene (mean frame time and
geometric-mean error over the scenes): interactive = the most accurate front point at most --budget-ms (the
fastest point when none is), final = the most accurate point, balanced = the front's knee in
log-log space (kept between the two). Errors within the references' mean noise of a more
accurate point count as equal, and of equals the fastest is chosen.)";

struct ReportOptions {
    std::string in = "bench-sweep", out = "docs/accuracy.md", images, presets = "presets/presets.json";
    double budgetMs = 100;
    double finalMs = 400;
    bool indirectMetric = true;
};

bool gIndirectMetric = true; // ReportOptions::indirectMetric, for err()

std::string fmt(double v, int digits = 1) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}
std::string fmtG(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
}

std::string slug(const std::string& scene) {
    std::string s = scene.rfind("builtin:", 0) == 0 ? scene.substr(8) : fs::path(scene).stem().string();
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return s;
}

/// The error axis of one row: the indirect light's or the whole image's relative RMSE, corrected for
/// the reference's noise where the row has it (rows of older sweeps have only the raw whole-image one).
const json* metricOf(const json& r) {
    const json& e = r["error"];
    if (!e.is_object()) return nullptr;
    if (gIndirectMetric) return e.contains("indirect") ? &e["indirect"]["relative_rmse_corrected"] : nullptr;
    return e.contains("relative_rmse_corrected") ? &e["relative_rmse_corrected"] : &e["relative_rmse"];
}

double err(const json& r) {
    const json* m = metricOf(r);
    return std::max(m ? m->get<double>() : 0.0, 1e-6);
}

std::string metricName() {
    return gIndirectMetric ? "indirect-light relative RMSE" : "relative RMSE";
}

const ParamTable* tableOf(const std::string& technique) {
    for (const auto& e : techniqueRegistry())
        if (e.info.name == technique) return &e.info.params;
    return nullptr;
}

std::string changesOf(const json& row) {
    if (const ParamTable* t = tableOf(row["technique"].get<std::string>()))
        return describeChanges(*t, row["params"]);
    return row.value("changes", std::string("?"));
}

struct Data {
    std::vector<json> rows;
    int width = 0, height = 0;
    std::vector<std::string> scenes, techniques;
    std::string sweepCommand;
    std::map<std::string, json> references; ///< the last references.jsonl record per scene at the sweep size
};

Data load(const ReportOptions& o) {
    Data d;
    const std::string path = o.in + "/sweep.jsonl";
    std::ifstream f(path);
    if (!f) throw InputError(path, "cannot read the sweep (run gi-bench sweep --out " + o.in + " first)");
    std::string line;
    std::map<std::string, size_t> keys; // a later row for a key supersedes the earlier one
    while (std::getline(f, line)) {
        json r = json::parse(line, nullptr, false);
        if (r.is_discarded() || !r.contains("key")) continue;
        const std::string key = r["key"];
        if (auto it = keys.find(key); it != keys.end()) {
            d.rows[it->second] = r;
            continue;
        }
        keys[key] = d.rows.size();
        d.rows.push_back(r);
    }
    if (d.rows.empty()) throw InputError(path, "holds no measured points");
    for (const auto& r : d.rows) {
        if (r["set"] == "grid" && d.width == 0) {
            d.width = r["size"][0];
            d.height = r["size"][1];
        }
        const std::string s = r["scene"], t = r["technique"];
        if (std::find(d.scenes.begin(), d.scenes.end(), s) == d.scenes.end()) d.scenes.push_back(s);
        if (std::find(d.techniques.begin(), d.techniques.end(), t) == d.techniques.end())
            d.techniques.push_back(t);
    }
    if (d.width == 0) {
        d.width = d.rows.front()["size"][0];
        d.height = d.rows.front()["size"][1];
    }
    // One line per command that added to the folder (BenchSweep.cpp).
    std::ifstream c(o.in + "/sweep-command.txt");
    for (std::string command; std::getline(c, command);)
        if (!command.empty()) d.sweepCommand += (d.sweepCommand.empty() ? "" : "\n") + command;
    std::ifstream refs(o.in + "/references.jsonl");
    while (std::getline(refs, line)) {
        json r = json::parse(line, nullptr, false);
        if (r.is_discarded() || !r.contains("scene") || !r.contains("size")) continue;
        if (r["size"][0] == d.width && r["size"][1] == d.height) d.references[r["scene"]] = r;
    }
    return d;
}

/// Rows of one scene and technique at the sweep size that have an error.
std::vector<const json*> accuracyRows(const Data& d, const std::string& scene, const std::string& technique) {
    std::vector<const json*> out;
    for (const auto& r : d.rows)
        if (r["scene"] == scene && r["technique"] == technique && r["size"][0] == d.width &&
            r["size"][1] == d.height && metricOf(r))
            out.push_back(&r);
    return out;
}

std::vector<const json*> frontOf(const std::vector<const json*>& rows) {
    std::vector<TradeoffPoint> pts;
    for (const json* r : rows) pts.push_back({(*r)["frame_ms"].get<double>(), err(*r)});
    std::vector<const json*> out;
    for (size_t i : paretoFront(pts)) out.push_back(rows[i]);
    return out;
}

/// The row of `technique` at size w x h whose parameters are the defaults with `overrides`.
const json* findRow(const Data& d, const std::string& scene, const std::string& technique, int w, int h,
                    const json& overrides) {
    const ParamTable* t = tableOf(technique);
    if (!t) return nullptr;
    json expected = defaultParams(*t);
    for (const auto& [k, v] : overrides.items()) {
        if (!expected.contains(k)) return nullptr;
        expected[k] = v;
    }
    ParamSet check(*t);
    try {
        check.apply(expected); // the table's own rounding of floats and ints
    } catch (const InputError&) {
        return nullptr;
    }
    expected = check.toJson();
    // Knobs added to or removed from the table since the sweep are left out of the match.
    auto matches = [&](const json& params) {
        for (const auto& [k, v] : expected.items())
            if (params.contains(k) && params[k] != v) return false;
        for (const auto& item : overrides.items())
            if (!params.contains(item.key())) return false;
        return true;
    };
    for (const auto& r : d.rows)
        if (r["scene"] == scene && r["technique"] == technique && r["size"][0] == w && r["size"][1] == h &&
            matches(r["params"]))
            return &r;
    return nullptr;
}

double passMs(const json& row, const std::string& name) {
    for (const auto& p : row["passes"])
        if (p["name"] == name) return p["ms"].get<double>();
    return 0;
}

bool havePlotter() {
    return std::system("command -v gnuplot >/dev/null 2>&1") == 0;
}

/// Writes the gnuplot script and, when gnuplot runs, the PNG; returns whether the PNG exists.
bool plotScene(const Data& d, const std::string& scene, const ReportOptions& o,
               const std::string& referenceMode, const std::string& glName) {
    const std::string base = "accuracy_" + slug(scene);
    std::ostringstream g;
    g << "# Generated by gi-bench report: error against frame time, " << scene << ", " << d.width << "x"
      << d.height << "\n";
    g << "set terminal pngcairo size 760,460 font 'sans,9'\nset output '" << base << ".png'\n";
    g << "set termoption noenhanced\nset logscale xy\nset grid\nset key outside right top\n";
    g << "set xlabel 'frame time (ms, " << d.width << "x" << d.height << ", " << glName << ")'\n";
    g << "set ylabel '" << metricName() << " vs " << referenceMode << "'\n";
    g << "set title '" << scene << ": all points (dots) and Pareto fronts (lines)'\n";
    std::string plot;
    int n = 0;
    for (const auto& t : d.techniques) {
        auto rows = accuracyRows(d, scene, t);
        if (rows.empty()) continue;
        ++n;
        g << "$all" << n << " << EOD\n";
        for (const json* r : rows) g << (*r)["frame_ms"].get<double>() << " " << err(*r) << "\n";
        g << "EOD\n$front" << n << " << EOD\n";
        for (const json* r : frontOf(rows)) g << (*r)["frame_ms"].get<double>() << " " << err(*r) << "\n";
        g << "EOD\n";
        plot += std::string(plot.empty() ? "plot " : ", \\\n     ") + "$all" + std::to_string(n) +
                " with points pt 7 ps 0.5 lc " + std::to_string(n) + " notitle, $front" + std::to_string(n) +
                " with linespoints pt 7 ps 0.9 lw 1.5 lc " + std::to_string(n) + " title '" + t + "'";
    }
    g << plot << "\n";
    fs::create_directories(o.images);
    std::ofstream(o.images + "/" + base + ".gp") << g.str();
    if (!havePlotter()) return false;
    const std::string cmd = "cd '" + o.images + "' && gnuplot '" + base + ".gp'";
    return std::system(cmd.c_str()) == 0 && fs::exists(o.images + "/" + base + ".png");
}

struct PresetRow {
    std::string technique, name, changes;
    json params;
    double timeMs = 0, error = 0;
};

/// The noise of the error axis: each scene's reference noise for the metric, their geometric mean over
/// the scenes, like the errors (0 when no scene's is known).
double meanMetricNoise(const Data& d) {
    double sumLog = 0;
    int n = 0;
    for (const auto& s : d.scenes)
        if (auto it = d.references.find(s); it != d.references.end()) {
            const json& v = it->second[gIndirectMetric ? "indirect_noise" : "noise"];
            if (v.is_number() && v.get<double>() > 0) {
                sumLog += std::log(v.get<double>());
                ++n;
            }
        }
    return n ? std::exp(sumLog / n) : 0.0;
}

/// Presets per technique from the front of the mean time and the geometric-mean error over the scenes:
/// relative errors of different scenes differ by large factors (a scene whose reference holds effects no
/// technique renders has errors far above 1), and a geometric mean weighs equal ratios alike, so such a
/// scene scales every point equally instead of deciding the ranking.
std::vector<PresetRow> choose(const Data& d, double budgetMs, double finalMs, json& file) {
    std::vector<PresetRow> out;
    json techs = json::object();
    for (const auto& t : d.techniques) {
        std::map<std::string, std::vector<const json*>> byParams;
        std::vector<std::string> order;
        for (const auto& s : d.scenes)
            for (const json* r : accuracyRows(d, s, t)) {
                const std::string k = (*r)["params"].dump();
                if (!byParams.count(k)) order.push_back(k);
                byParams[k].push_back(r);
            }
        std::vector<TradeoffPoint> pts;
        std::vector<const json*> rep;
        for (const auto& k : order) {
            const auto& rs = byParams[k];
            if (rs.size() != d.scenes.size()) continue; // compare only points every scene measured
            TradeoffPoint p;
            double sumLogError = 0;
            for (const json* r : rs) {
                p.timeMs += (*r)["frame_ms"].get<double>() / static_cast<double>(rs.size());
                sumLogError += std::log(err(*r)); // err() >= 1e-6
            }
            p.error = std::exp(sumLogError / static_cast<double>(rs.size()));
            pts.push_back(p);
            rep.push_back(rs.front());
        }
        if (pts.empty()) continue;
        auto front = paretoFront(pts);
        std::vector<TradeoffPoint> fpts;
        for (size_t i : front) fpts.push_back(pts[i]);
        PresetChoice c = choosePresets(fpts, budgetMs, meanMetricNoise(d), finalMs);
        const ParamTable* table = tableOf(t);
        const json defaults = table ? defaultParams(*table) : json::object();
        json presets = json::object();
        for (const auto& [name, idx] : std::vector<std::pair<std::string, size_t>>{
                 {"interactive", c.interactive}, {"balanced", c.balanced}, {"final", c.final}}) {
            const json& params = (*rep[front[idx]])["params"];
            json diff = json::object();
            for (const auto& [k, v] : params.items())
                if (!defaults.contains(k) || defaults[k] != v) diff[k] = v;
            presets[name] = diff;
            out.push_back({t, name, changesOf(*rep[front[idx]]), diff, fpts[idx].timeMs, fpts[idx].error});
        }
        // The front's most accurate point, for comparison (not a preset when the final budget excludes it).
        if (c.final != fpts.size() - 1) {
            const json& params = (*rep[front.back()])["params"];
            out.push_back({t, "(most accurate)", changesOf(*rep[front.back()]), params, fpts.back().timeMs,
                           fpts.back().error});
        }
        techs[t] = presets;
    }
    file["techniques"] = techs;
    // The service's default technique: of the interactive presets within the budget, the most accurate
    // (without the direct-only "none"). Errors within the noise count as equal; of equals, the one whose
    // final preset is more accurate (beyond the noise) wins, since the frame budget sizes the live frames
    // of either and a still view shows the final step longest; then the faster.
    const double tolerance = meanMetricNoise(d);
    auto finalError = [&](const std::string& technique) {
        for (const PresetRow& p : out)
            if (p.technique == technique && p.name == "final") return p.error;
        return std::numeric_limits<double>::infinity();
    };
    std::vector<const PresetRow*> candidates;
    std::vector<TechniquePresets> measured;
    const PresetRow* lowest = nullptr; // the lowest error, which the noise may tie with the chosen one's
    for (const PresetRow& p : out) {
        if (p.name != "interactive" || p.technique == "none") continue;
        candidates.push_back(&p);
        measured.push_back({{p.timeMs, p.error}, {0.0, finalError(p.technique)}});
        if (p.timeMs <= budgetMs && (!lowest || p.error < lowest->error)) lowest = &p;
    }
    const int chosen = chooseDefaultTechnique(measured, budgetMs, tolerance);
    const PresetRow* best = chosen >= 0 ? candidates[static_cast<size_t>(chosen)] : nullptr;
    if (best) {
        const std::string preset = "its interactive preset (" + best->changes + ")";
        const std::string within =
            " within " + fmt(budgetMs, 0) + " ms at the sweep size (" + fmt(best->timeMs) + " ms)";
        std::string reason;
        if (lowest == best) {
            reason = preset + " has the lowest geometric-mean " + metricName() + ", " + fmt(best->error, 4) +
                     ", of the interactive presets" + within;
        } else {
            reason = preset + ", at " + fmt(best->error, 4) + " geometric-mean " + metricName() + within +
                     ", is within the references' noise (" + fmt(tolerance, 4) + ") of the lowest (" +
                     lowest->technique + ", " + fmt(lowest->error, 4) + ")";
            if (finalError(best->technique) + tolerance < finalError(lowest->technique))
                reason += ", and its final preset is the more accurate (" +
                          fmt(finalError(best->technique), 4) + " against " +
                          fmt(finalError(lowest->technique), 4) + ")";
            else
                reason += ", and it is the faster";
        }
        file["default_technique"] = {{"name", best->technique}, {"reason", reason}};
    }
    return out;
}

ReportOptions parseOptions(const std::vector<std::string>& args) {
    ReportOptions o;
    cli::OptionTable options;
    options
        .value("--in", "DIR", "sweep folder (default bench-sweep)", [&](const std::string& v) { o.in = v; })
        .value("--out", "FILE", "Markdown report (default docs/accuracy.md)",
               [&](const std::string& v) { o.out = v; })
        .value("--images", "DIR", "plots and their gnuplot scripts (default: images/ beside --out)",
               [&](const std::string& v) { o.images = v; })
        .value("--presets", "FILE", "presets written here (default presets/presets.json)",
               [&](const std::string& v) { o.presets = v; })
        .number("--budget-ms", "MS", "frame-time budget of the interactive preset at the sweep size", 0, 1e7,
                o.budgetMs)
        .number(
            "--final-ms", "MS",
            "frame-time budget of the final preset at the sweep size (what gi-server's 30 s refinement "
            "budget affords at 960x800, 47x the pixels of 128x128, with the tiles' overhead; 0 = none, the "
            "most accurate point)",
            0, 1e7, o.finalMs)
        .value("--metric", "WHAT", "indirect (default) or image: the error axis of the fronts and presets",
               [&](const std::string& m) {
                   if (m != "indirect" && m != "image")
                       throw UsageError("report: --metric must be indirect or image, got '" + m + "'");
                   o.indirectMetric = m == "indirect";
               });
    if (printedHelp(args, kReportUsage, options)) std::exit(0);
    options.parse(args);
    if (o.images.empty()) o.images = (fs::path(o.out).parent_path() / "images").string();
    if (o.images.empty()) o.images = "images";
    return o;
}

std::string rel(const std::string& target, const std::string& fromFile) {
    fs::path dir = fs::path(fromFile).parent_path();
    if (dir.empty()) dir = ".";
    return fs::relative(fs::absolute(target), fs::absolute(dir)).generic_string();
}

} // namespace

int report(const std::vector<std::string>& args) {
    const ReportOptions o = parseOptions(args);
    gIndirectMetric = o.indirectMetric;
    const Data d = load(o);
    {
        bool any = false;
        for (const auto& r : d.rows) any |= metricOf(r) != nullptr;
        if (!any)
            throw InputError(
                o.in + "/sweep.jsonl",
                "no row has the " + metricName() +
                    " (a sweep from before the indirect split): rerun gi-bench sweep with the same "
                    "--out to measure it, or pass --metric image");
    }
    std::string referenceMode = "the reference", glName = "GL", refSpp;
    for (const auto& r : d.rows) {
        if (r["reference"].is_object()) {
            referenceMode = r["reference"]["mode"];
            refSpp = std::to_string(r["reference"]["spp"].get<int>());
        }
        if (r.contains("gl")) glName = r["gl"];
    }
    std::string reportCommand = "gi-bench report";
    for (const auto& a : args) reportCommand += " " + a;

    std::ostringstream md;
    md << "# Accuracy against time\n\n";
    md << "Generated by `gi-bench report`; regenerate with:\n\n```\n"
       << (d.sweepCommand.empty() ? "gi-bench sweep ..." : d.sweepCommand) << "\n"
       << reportCommand << "\n```\n\n";
    md << "Measured at " << d.width << "x" << d.height << " on " << glName << " (" << d.rows.size()
       << " points). Error is against the CPU reference `" << referenceMode << "`"
       << (refSpp.empty() ? "" : " (each scene's samples per pixel and noise are given with its table)")
       << ". The fronts and presets use the " << metricName()
       << (gIndirectMetric
               ? " (each side's total less its own direct light, so that a better shadow map does not pass "
                 "for better GI)"
               : "")
       << "; the tables also give the whole image's relative RMSE and the direct pass's against the "
          "reference's direct light (what the shadow map costs). Relative RMSE is on linear radiance and "
          "corrected for the reference's noise: sqrt(max(0, error^2 - noise^2)), with the noise estimated "
          "from the spread of the reference's samples (`server/analysis/Accuracy.h`); SSIM and FLIP are on "
          "the tone-mapped image; background left out; definitions in `server/analysis/Metrics.h`. Frame "
          "time is the median wall time of the timed "
          "frames "
          "with glFinish around each pass (llvmpipe's timer queries attribute deferred work to later "
          "passes). "
          "The machine's 2 CPU cores are shared with other jobs, so absolute times are noisy; the ratios "
          "within "
          "one run are what count.\n\n";

    md << "## How the sweep is built\n\n"
          "- **Grid.** Each technique's own parameter table (frame parameters such as exposure, tone map and "
          "shadow-map size are not swept): the default point, then one knob at a time through "
          "`ParamTable::sweepValues` (numeric knobs: `--steps` values across the table's range, geometric "
          "where "
          "the table marks it `logScale`; enums: every option; bools: both), walking outward from the "
          "default on "
          "each side. `--knobs` restricts the knobs, `--max-points` caps the points per technique and scene "
          "(default point first, knobs in table order).\n"
          "- **Skip rules.** A point whose frame exceeds `--max-frame-ms` is kept (timed by one frame when "
          "its "
          "warm-up already exceeds the budget) and the knob's values farther out on that side are skipped. A "
          "knob "
          "whose first value renders exactly the default image has no effect at the defaults "
          "(bias-compensation "
          "settings while compensation is off, for example) and its other values are skipped. Both rules are "
          "applied to rows read back on resume too, so reruns plan the same points.\n"
          "- **Resume.** Rows are appended to `sweep.jsonl` and `sweep.csv` point by point; the key is "
          "scene, "
          "size, technique and the canonical parameter JSON, and a rerun with the same output folder skips "
          "the "
          "points it finds.\n"
          "- **Pareto front.** A point is on its technique's front when no other point of that technique is "
          "both "
          "at least as fast and at least as accurate (the error axis above).\n\n";

    // Per scene: plot and fronts.
    const bool plotter = havePlotter();
    for (const auto& scene : d.scenes) {
        md << "## " << scene << "\n\n";
        if (plotScene(d, scene, o, referenceMode, glName))
            md << "![Error against frame time, " << scene << "]("
               << rel(o.images + "/accuracy_" + slug(scene) + ".png", o.out) << ")\n\n";
        else
            md << "(Plot skipped: " << (plotter ? "gnuplot failed" : "gnuplot is not installed")
               << "; the script is " << rel(o.images + "/accuracy_" + slug(scene) + ".gp", o.out) << ".)\n\n";
        auto figure = [](const json& parent, const char* key) {
            return parent.is_object() && parent.contains(key) && parent[key].is_number() ? fmt(parent[key], 4)
                                                                                         : std::string("-");
        };
        double noise = -1;
        if (auto it = d.references.find(scene); it != d.references.end()) {
            const json& r = it->second;
            const json& v = r[gIndirectMetric ? "indirect_noise" : "noise"];
            if (v.is_number()) noise = v.get<double>();
            md << "Reference `" << r["mode"].get<std::string>() << "` at " << r["spp"].get<int>()
               << " spp; its relative noise (from the samples' spread) is " << figure(r, "noise")
               << " of the image and " << figure(r, "indirect_noise") << " of its indirect light.\n\n";
        }
        md << "| technique | points | front point | frame ms | GPU ms | indirect rel. RMSE | image rel. RMSE "
              "| "
              "direct pass | SSIM | FLIP |\n"
              "|---|---|---|---|---|---|---|---|---|---|\n";
        double smallest = INFINITY;
        for (const auto& t : d.techniques) {
            auto rows = accuracyRows(d, scene, t);
            if (rows.empty()) continue;
            for (const json* r : frontOf(rows)) {
                const auto& e = (*r)["error"];
                const json none;
                smallest = std::min(smallest, err(*r));
                md << "| " << t << " | " << rows.size() << " | " << changesOf(*r)
                   << ((*r)["over_budget"].get<bool>() ? " (1 frame)" : "") << " | " << fmt((*r)["frame_ms"])
                   << " | " << fmt((*r)["gpu_ms"]) << " | "
                   << figure(e.contains("indirect") ? e["indirect"] : none, "relative_rmse_corrected")
                   << " | "
                   << figure(e, e.contains("relative_rmse_corrected") ? "relative_rmse_corrected"
                                                                      : "relative_rmse")
                   << " | " << figure(e.contains("direct") ? e["direct"] : none, "relative_rmse") << " | "
                   << fmt(e["ssim"], 4) << " | " << fmt(e["flip"], 4) << " |\n";
            }
        }
        md << "\n";
        if (std::isfinite(smallest) && smallest > 1)
            md << "**Every point's error exceeds 1 here:** the reference holds light that no technique "
                  "renders (on "
                  "`builtin:gallery`, the spotlight's caustics off near-mirror lobes, which the non-diffuse "
                  "section "
                  "leaves out of its reference), so this scene scales every technique's error alike.\n\n";
        if (noise >= 0 && std::isfinite(smallest) &&
            noise > smallest / 5 * 1.05) // the sweep refines with the same 5% slack
            md << "**The reference's noise (" << fmt(noise, 4)
               << ") is more than a fifth of the smallest error "
               << "in this table (" << fmt(smallest, 4)
               << "):** errors corrected for it are estimates, and differences smaller than the noise are "
                  "not resolved; a lower `--noise-target` (or a higher `--spp` cap) resolves them.\n\n";
    }

    // Presets.
    json presetFile = {
        {"comment", "Quality presets per technique chosen by gi-bench report from measured Pareto "
                    "fronts (docs/accuracy.md); each preset lists only the parameters that differ "
                    "from the technique's defaults."},
        {"generated_by", {d.sweepCommand, reportCommand}},
        {"rule",
         "interactive: most accurate front point with mean frame time <= " + fmt(o.budgetMs, 0) +
             " ms at the sweep size (else the fastest); balanced: the knee of the front in "
             "log-log space; final: the most accurate point with mean frame time <= " +
             fmt(o.finalMs, 0) +
             " ms (0: no limit); mean frame time and geometric-mean error over the scenes; errors within "
             "the references' noise count as equal and the fastest of equals is chosen"},
        {"metric", metricName()},
        {"sweep", {{"scenes", d.scenes}, {"size", {d.width, d.height}}}}};
    const auto presets = choose(d, o.budgetMs, o.finalMs, presetFile);
    fs::path pp(o.presets);
    if (pp.has_parent_path()) fs::create_directories(pp.parent_path());
    std::ofstream(o.presets) << presetFile.dump(2) << "\n";
    md << "## Presets\n\n"
       << "`" << rel(o.presets, o.out)
       << "` holds three presets per technique, chosen from the measured fronts, not by hand. Per technique, "
          "the "
          "points measured in every scene are averaged over the scenes (the mean frame time and the "
          "geometric "
          "mean of the error, so that a scene whose errors are all large scales every point alike instead of "
          "deciding the ranking) and "
          "their "
          "Pareto front is taken; errors within the references' noise (its geometric mean, "
       << fmt(meanMetricNoise(d), 4)
       << ") of a more accurate point count as equal, and of equals the fastest is chosen; then "
          "**interactive** is the most accurate front point with a mean frame "
          "time of "
          "at most "
       << fmt(o.budgetMs, 0) << " ms at " << d.width << "x" << d.height
       << " (the fastest front point when none is that fast), **final** the most accurate point "
       << (o.finalMs > 0
               ? "of at most " + fmt(o.finalMs, 0) +
                     " ms (what gi-server's refinement budget affords at a 960x800 view; the front's "
                     "most accurate point is listed beside it) "
               : std::string())
       << "and **balanced** "
          "the knee of the front (the point farthest below the chord from its fastest to its most accurate "
          "end in "
          "log(time)-log(error) space, kept between the other two).\n\n"
          "File format: `{\"techniques\": {TECH: {\"interactive\": {param: value}, \"balanced\": {...}, "
          "\"final\": "
          "{...}}}, ...}`; a preset lists only the parameters that differ from the technique's defaults, so "
          "knobs "
          "added later keep their defaults. `frame/Presets.h` loads it (`presetParams(technique, name)`, "
          "`applyPreset`; `$GI_PRESETS` overrides the path); `gi-render --preset NAME` applies one before "
          "any "
          "`--param`; they are the steps gi-server's adaptive quality moves between "
          "(`docs/interactive.md`).\n\n"
          "| technique | preset | parameters | mean frame ms | geometric-mean "
       << metricName() << " |\n|---|---|---|---|---|\n";
    for (const auto& p : presets)
        md << "| " << p.technique << " | " << p.name << " | " << p.changes << " | " << fmt(p.timeMs) << " | "
           << fmt(p.error, 4) << " |\n";
    md << "\n";
    if (presetFile.contains("default_technique"))
        md << "**Default technique** (gi-server without `--technique`): `"
           << presetFile["default_technique"]["name"].get<std::string>()
           << "`: " << presetFile["default_technique"]["reason"].get<std::string>() << ".\n\n";

    // The seed papers' tables.
    const std::string first = d.scenes.front();
    const int W = d.width, H = d.height;
    md << "## The seed papers' tables, as this renderer measures them\n\n"
       << "Measured with `gi-bench sweep --paper-tables` on " << first
       << " (the papers' scenes, resolutions and "
       << "GPUs differ: compare ratios and trends, not absolute numbers). Paper numbers are quoted from the "
          "papers.\n\n";

    // 001 Table 1.
    md << "### 001 Table 1: multiresolution splatting against stencil gathering (256 VPLs)\n\n";
    const json* gat = findRow(d, first, "multires_gather", W, H, {{"vpl_grid", 16}});
    const json* spl = findRow(d, first, "multires_splat", W, H, {{"vpl_grid", 16}});
    if (gat && spl) {
        std::vector<std::string> names;
        for (const json* r : {gat, spl})
            for (const auto& p : (*r)["passes"])
                if (std::find(names.begin(), names.end(), p["name"]) == names.end())
                    names.push_back(p["name"]);
        md << "| pass (ms, " << W << "x" << H << ") | multires_gather | multires_splat |\n|---|---|---|\n";
        for (const auto& n : names)
            md << "| " << n << " | " << fmt(passMs(*gat, n)) << " | " << fmt(passMs(*spl, n)) << " |\n";
        md << "| **total of passes** | **" << fmt((*gat)["gpu_ms"]) << "** | **" << fmt((*spl)["gpu_ms"])
           << "** |\n\n";
        const double stageG = passMs(*gat, "vpl_gather"), stageS = passMs(*spl, "subsplat_splat");
        md << "| ratio splat / gather | this renderer | 001 (Cornell Box, GPU) |\n|---|---|---|\n"
           << "| total | "
           << fmt((*spl)["gpu_ms"].get<double>() / std::max((*gat)["gpu_ms"].get<double>(), 1e-9), 2)
           << "x | 6.35x (52.1 ms / 8.2 ms) |\n"
           << "| light stage (subsplat_splat / vpl_gather) | "
           << (stageG > 0 ? fmt(stageS / stageG, 2) + "x" : std::string("-"))
           << " | 18.3x (45.8 ms / 2.5 ms) |\n\n";
    } else {
        md << "Not measured (run the sweep with `--paper-tables` and both techniques).\n\n";
    }

    // 003 Table 1.
    md << "### 003 Table 1: positive and negative indirect lights\n\n";
    {
        const std::vector<std::tuple<int, int, double>> paper = {{100, 50, 26.5},  {150, 0, 32.6},
                                                                 {200, 100, 15.6}, {300, 0, 19.2},
                                                                 {300, 150, 11.0}, {450, 0, 13.6}};
        bool any = false;
        std::ostringstream t;
        t << "| positive | negative | frame ms | fps | rel. RMSE | 003 fps (640x480) | 003 ms "
             "|\n|---|---|---|---|---|---|---|\n";
        for (auto [p, n, fps] : paper) {
            const json* r =
                findRow(d, first, "second_order", W, H, {{"positive_count", p}, {"negative_count", n}});
            any |= r != nullptr;
            t << "| " << p << " | " << n << " | " << (r ? fmt((*r)["frame_ms"]) : "-") << " | "
              << (r ? fmt(1000.0 / (*r)["frame_ms"].get<double>()) : "-") << " | "
              << (r && (*r)["error"].is_object() ? fmt((*r)["error"]["relative_rmse"], 4) : "-") << " | "
              << fmt(fps) << " | " << fmt(1000.0 / fps) << " |\n";
        }
        md << (any ? t.str() : std::string("Not measured (run the sweep with `--paper-tables`).\n")) << "\n";
    }

    // 003 Table 2.
    md << "### 003 Table 2: low-resolution share against error and time\n\n";
    {
        std::vector<const json*> rows;
        for (const auto& r : d.rows)
            if (r["scene"] == first && r["technique"] == "second_order" &&
                r.contains("baseline_relative_rmse"))
                rows.push_back(&r);
        std::sort(rows.begin(), rows.end(), [](const json* a, const json* b) {
            return (*a)["counts"].value("lowres_fraction", 0.0) >
                   (*b)["counts"].value("lowres_fraction", 0.0);
        });
        if (!rows.empty()) {
            md << "| configuration | low-res share | RMS vs full resolution | rel. RMSE vs reference | frame "
                  "ms | fps |\n"
                  "|---|---|---|---|---|---|\n";
            for (const json* r : rows) {
                const double share = (*r)["params"].value("lowres_factor", 2) == 1
                                         ? 0.0
                                         : (*r)["counts"].value("lowres_fraction", 0.0);
                md << "| " << changesOf(*r) << " | " << fmt(100 * share) << " % | "
                   << fmt(100 * (*r)["baseline_relative_rmse"].get<double>(), 4) << " % | "
                   << ((*r)["error"].is_object() ? fmt((*r)["error"]["relative_rmse"], 4) : "-") << " | "
                   << fmt((*r)["frame_ms"]) << " | " << fmt(1000.0 / (*r)["frame_ms"].get<double>())
                   << " |\n";
            }
            md << "\n003's own numbers (640x480): 100 % low-res: 1.5082 % RMS, 42.5 fps; 87.5 %: 0.1688 %, "
                  "26.5 fps; "
                  "50 %: 0.0885 %, 15.4 fps; 0 %: 0 %, 12.6 fps. \"RMS vs full resolution\" here is the "
                  "relative RMSE "
                  "against the same configuration with `lowres_factor=1` (003's \"unoptimized render\").\n\n";
        } else {
            md << "Not measured (run the sweep with `--paper-tables`).\n\n";
        }
    }

    // 000 Table 1.
    md << "### 000 Table 1: per-VPL subsplats against indirect resolution and VPL count\n\n";
    {
        const std::vector<int> sizes = {32, 64, 128, 256}, grids = {4, 8, 16};
        bool any = false;
        std::ostringstream t;
        t << "`multires_splat` with `refinement=illumination` (subsplats refined separately for each VPL). "
             "Each cell: "
             "subsplats in total, subsplats per VPL (and as a share of the pixels), refinement pass ms, "
             "frame ms.\n\n"
             "| resolution |";
        for (int g : grids) t << " " << g << "^2 VPLs |";
        t << "\n|---|";
        for (size_t i = 0; i < grids.size(); ++i) t << "---|";
        t << "\n";
        for (int s : sizes) {
            t << "| " << s << "^2 |";
            for (int g : grids) {
                const json* r = findRow(d, first, "multires_splat", s, s,
                                        {{"refinement", "illumination"}, {"vpl_grid", g}});
                any |= r != nullptr;
                if (!r) {
                    t << " - |";
                    continue;
                }
                const auto& c = (*r)["counts"];
                const double per = c.value("subsplats_per_vpl", 0.0);
                t << " " << fmtG(c.value("subsplats_total", 0.0)) << ", " << fmt(per, 0) << "/VPL ("
                  << fmt(100 * per / (s * s)) << " %), " << fmt(passMs(*r, "subsplat_refine")) << " ms, "
                  << fmt((*r)["frame_ms"]) << " ms |";
            }
            t << "\n";
        }
        md << (any ? t.str() : std::string("Not measured (run the sweep with `--paper-tables`).\n"))
           << "\n000's Table 1 (Buddha, Phong, 16^2 VPLs): 32^2: 120.5K subsplats, 3.9 ms refinement, 65 "
              "fps; 64^2: "
              "220.4K, 11.7 ms, 52 fps; 128^2: 421.8K, 17.7 ms, 39 fps; 256^2: 852.0K, 35.3 ms, 27 fps. Per "
              "VPL that "
              "is 470.7, 860.9, 1647.7, 3328.1 subsplats: 46.0 %, 21.0 %, 10.1 %, 5.1 % of the pixels, "
              "growing about "
              "2x per resolution step rather than 4x.\n\n";
    }

    // 000 Table 2.
    md << "### 000 Table 2: frame time against indirect resolution\n\n";
    {
        bool any = false;
        std::ostringstream t;
        t << "| resolution | multires_splat frame ms | fps | 000 Simple Teapot fps |\n|---|---|---|---|\n";
        const std::map<int, std::string> paper = {{128, "68"}, {256, "50"}, {512, "33"}, {1024, "22"}};
        for (int s : {32, 64, 128, 256}) {
            const json* r = findRow(d, first, "multires_splat", s, s, json::object());
            any |= r != nullptr;
            t << "| " << s << "^2 | " << (r ? fmt((*r)["frame_ms"]) : "-") << " | "
              << (r ? fmt(1000.0 / (*r)["frame_ms"].get<double>()) : "-") << " | "
              << (paper.count(s) ? paper.at(s) : "-") << " |\n";
        }
        md << (any ? t.str() : std::string("Not measured (run the sweep with `--paper-tables`).\n"))
           << "\n000 (GeForce GTX 280): 512^2 33 fps, 1024^2 22 fps for the teapot; the cost grows far "
              "slower than "
              "the pixel count.\n\n";
    }

    // 002.
    md << "### 002: cost per bias-compensation iteration\n\n";
    {
        std::string tech;
        for (const auto& t : d.techniques)
            if (const ParamTable* tb = tableOf(t);
                tb && tb->find("ssbc_iterations") && (tech.empty() || t == "ssbc"))
                tech = t;
        std::ostringstream t;
        bool any = false;
        if (!tech.empty()) {
            const ParamSpec* spec = tableOf(tech)->find("ssbc_iterations");
            t << "`" << tech << "`, " << W << "x" << H
              << ".\n\n| ssbc_iterations | frame ms | compensation passes ms | rel. RMSE "
                 "|\n|---|---|---|---|\n";
            for (int k = static_cast<int>(spec->min); k <= static_cast<int>(spec->max); ++k) {
                const json* r = findRow(d, first, tech, W, H, {{"ssbc_iterations", k}});
                if (!r) continue;
                any = true;
                double comp = 0;
                for (const auto& p : (*r)["passes"])
                    if (p["name"].get<std::string>().rfind("ssbc_", 0) == 0) comp += p["ms"].get<double>();
                t << "| " << k << " | " << fmt((*r)["frame_ms"]) << " | " << fmt(comp) << " | "
                  << ((*r)["error"].is_object() ? fmt((*r)["error"]["relative_rmse"], 4) : "-") << " |\n";
            }
        }
        md << (any ? t.str()
                   : std::string(
                         "Not yet available: no measured technique has an `ssbc_iterations` parameter.\n"))
           << "\n002 (1024x768, GPU): \"each compensation step takes approximately 27 ms\"; three steps at "
              "the highest "
              "quality 550 ms.\n\n";
    }

    md << "## Files\n\n"
          "- `sweep.jsonl` (one JSON object per point: key, scene, size, technique, set, knob, value, "
          "params, "
          "frame_ms, gpu_ms, passes, counts, frames, over_budget, error, reference) and `sweep.csv` (the "
          "same "
          "without passes and counts) in the sweep's `--out` folder.\n"
          "- Plots and their gnuplot scripts: `"
       << rel(o.images, o.out) << "/accuracy_*.{png,gp}`.\n";

    // Sections that come from elsewhere are kept as they are: the list of reruns at other sizes and
    // the non-diffuse table (bench/nondiffuse/run.sh).
    std::string kept;
    {
        std::ifstream previous(o.out);
        const std::string text((std::istreambuf_iterator<char>(previous)), std::istreambuf_iterator<char>());
        for (const char* name : {"reruns", "nondiffuse"}) {
            const std::string begin = std::string("<!-- ") + name + ":begin -->";
            const std::string end = std::string("<!-- ") + name + ":end -->";
            const size_t b = text.find(begin), e = text.find(end);
            if (b != std::string::npos && e != std::string::npos && e > b)
                kept += "\n" + text.substr(b, e + end.size() - b) + "\n";
        }
    }
    fs::path op(o.out);
    if (op.has_parent_path()) fs::create_directories(op.parent_path());
    std::ofstream out(o.out);
    if (!out) throw InputError(o.out, "cannot open for writing");
    out << md.str() << kept;
    std::fprintf(stderr, "gi-bench: wrote %s, %s%s\n", o.out.c_str(), o.presets.c_str(),
                 plotter ? "" : " (plots skipped: gnuplot is not installed)");
    return 0;
}

} // namespace gis::bench
