// Helpers shared by gi-bench's subcommands (gi_bench.cpp, BenchSweep.cpp, BenchReport.cpp).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/CommandLine.h"
#include "render/FrameRenderer.h"
#include "frame/FrameState.h"
#include "scene/Scene.h"
#include "reference/ReferenceRenderer.h"

namespace gis::bench {

using cli::joinList;
using cli::splitList;
using cli::UsageError;
/// "query" (timer queries) or "finish" (glFinish around each pass).
bool parseTiming(const std::string& text);


/// technique[:name=value,...] as given to --config.
struct Config {
    std::string technique;
    std::vector<std::pair<std::string, std::string>> params;
    std::string label;
};
Config parseConfig(const std::string& spec);

/// The options gi-bench's GL commands share (table, passes, lights).
struct RunOptions {
    std::string scene = "builtin:cornell";
    int width = 512, height = 512;
    int frames = 5;
    std::vector<Config> configs; ///< empty: the command's own list
    std::string json, gl;
    bool timerQueries = false;
};
/// Declares --scene, --size, --config, --frames, --json, --gl and --timing into `o`, their defaults
/// taken from `o` as it is; `configsDefault` says what runs without --config.
void addRunOptions(cli::OptionTable& table, RunOptions& o, const std::string& configsDefault);
/// A command's --help: `what` (its description), then its options.
bool printedHelp(const std::vector<std::string>& args, const std::string& what,
                 const cli::OptionTable& options);
std::vector<FrameState> makeStates(const Scene& scene, const std::vector<Config>& configs, int width,
                                   int height);

/// One warm-up frame, then up to `frames` timed ones. With maxFrameMs > 0 a configuration whose warm-up
/// frame already took longer is timed by that frame alone (`overBudget`), which bounds the cost of a
/// slow point to one frame.
struct Measurement {
    nlohmann::json stats; ///< medianStats of the timed frames
    FrameOutput last;     ///< the last frame, with linear radiance and its direct pass
    int frames = 0;
    bool overBudget = false;
};
Measurement measure(FrameRenderer& renderer, const FrameState& state, int frames, double maxFrameMs = 0);
/// {"image": the reference's relative noise over the pixels it covers, "indirect": the same for its
/// indirect light (less `direct`, the pixel-centre direct render)}; null where the variance is unknown.
nlohmann::json referenceNoiseJson(const ReferenceImage& reference, const ReferenceImage& direct);
/// Sum of the stats' per-pass GPU milliseconds.
double sumPassMs(const nlohmann::json& stats);

int sweep(const std::vector<std::string>& args);
int lights(const std::vector<std::string>& args);
int pointShadows(const std::vector<std::string>& args);
int report(const std::vector<std::string>& args);

} // namespace gis::bench
