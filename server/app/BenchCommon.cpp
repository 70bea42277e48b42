#include "app/BenchCommon.h"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "analysis/Accuracy.h"
#include "core/Error.h"

namespace gis::bench {

bool parseTiming(const std::string& text) {
    if (text == "query") return true;
    if (text == "finish") return false;
    throw UsageError("--timing must be query or finish, got '" + text + "'");
}

Config parseConfig(const std::string& spec) {
    Config c;
    c.label = spec;
    auto colon = spec.find(':');
    c.technique = spec.substr(0, colon);
    if (colon == std::string::npos) return c;
    std::stringstream rest(spec.substr(colon + 1));
    std::string kv;
    while (std::getline(rest, kv, ',')) {
        auto eq = kv.find('=');
        if (eq == std::string::npos || eq == 0)
            throw UsageError("--config: expected name=value, got '" + kv + "'");
        c.params.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
    }
    return c;
}

void addRunOptions(cli::OptionTable& table, RunOptions& o, const std::string& configsDefault) {
    table
        .value("--scene", "NAME", "builtin:NAME or a .gltf/.glb file (default " + o.scene + ")",
               [&o](const std::string& v) { o.scene = v; })
        .value("--size", "WxH",
               "frame size, 16..4096 each (default " + std::to_string(o.width) + "x" +
                   std::to_string(o.height) + ")",
               [&o](const std::string& v) { cli::parseSize("--size", v, 4096, o.width, o.height); })
        .value("--config", "SPEC", "technique[:name=value,...], repeatable (default: " + configsDefault + ")",
               [&o](const std::string& v) { o.configs.push_back(parseConfig(v)); })
        .integer("--frames", "N", "timed GL frames per configuration, after a warm-up", 1, 1000, o.frames)
        .value("--json", "FILE", "also write the rows as JSON", [&o](const std::string& v) { o.json = v; })
        .value("--gl", "egl|osmesa", "headless GL backend (default: $GI_GL, else egl)",
               [&o](const std::string& v) { o.gl = v; })
        .value(
            "--timing", "query|finish",
            "GPU timer queries, or glFinish around each pass (default finish: llvmpipe's queries attribute "
            "deferred work to later passes)",
            [&o](const std::string& v) { o.timerQueries = parseTiming(v); });
}

bool printedHelp(const std::vector<std::string>& args, const std::string& what,
                 const cli::OptionTable& options) {
    if (!cli::OptionTable::asksForHelp(args)) return false;
    std::cout << what << "\n\n" << options.usage();
    return true;
}

std::vector<FrameState> makeStates(const Scene& scene, const std::vector<Config>& configs, int width,
                                   int height) {
    std::vector<FrameState> states;
    for (const auto& c : configs) {
        try {
            FrameState s = makeFrameState(scene, c.technique);
            for (const auto& [k, v] : c.params) setParamFromString(s, k, v, "--config " + c.label);
            s.width = width;
            s.height = height;
            states.push_back(std::move(s));
        } catch (const InputError& e) {
            throw UsageError(e.what());
        }
    }
    return states;
}

Measurement measure(FrameRenderer& renderer, const FrameState& state, int frames, double maxFrameMs) {
    Measurement m;
    // The direct pass is read back with the warm-up (it may be the only frame) and the last frame, for
    // the indirect-only error; one read-back barely moves the median.
    m.last = renderer.render(state, true, true); // warm-up
    std::vector<nlohmann::json> stats;
    if (maxFrameMs > 0 && m.last.stats.value("frame_ms", 0.0) > maxFrameMs) {
        m.overBudget = true;
        stats.push_back(m.last.stats);
    } else {
        for (int k = 0; k < frames; ++k) {
            m.last = renderer.render(state, true, k + 1 == frames);
            stats.push_back(m.last.stats);
        }
    }
    m.frames = static_cast<int>(stats.size());
    m.stats = medianStats(stats);
    return m;
}

nlohmann::json referenceNoiseJson(const ReferenceImage& reference, const ReferenceImage& direct) {
    const ImageView view(reference.rgb, reference.width, reference.height, 3);
    const PixelMask mask = maskFromNonZero(view);
    auto orNull = [](double noise) { return noise < 0 ? nlohmann::json(nullptr) : nlohmann::json(noise); };
    nlohmann::json out = {{"image", orNull(relativeNoise(view, reference.variance, mask))},
                          {"indirect", nullptr}};
    if (direct.rgb.size() == reference.rgb.size() && !reference.variance.empty() &&
        direct.variance.size() == reference.variance.size()) {
        const std::vector<float> indirect =
            differenceRgb(view, ImageView(direct.rgb, direct.width, direct.height, 3));
        std::vector<float> variance(reference.variance);
        for (size_t i = 0; i < variance.size(); ++i) variance[i] += direct.variance[i];
        out["indirect"] =
            orNull(relativeNoise(ImageView(indirect, reference.width, reference.height, 3), variance, mask));
    }
    return out;
}

double sumPassMs(const nlohmann::json& stats) {
    double total = 0;
    for (const auto& p : stats["passes"]) total += p["gpu_ms"].get<double>();
    return total;
}

} // namespace gis::bench
