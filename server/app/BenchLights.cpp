// gi-bench lights: frame time against light count at a fixed total VPL budget, per technique, side
// by side in one run (frames of every count interleaved), as issue [lights] asks: only the shadow-map
// and RSM passes (and the flux measurement) are per light, so 8 lights should cost at most twice one.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>

#include "BenchCommon.h"
#include "core/Error.h"
#include "core/Log.h"
#include "gl/Platform.h"
#include "scene/SceneLoader.h"

namespace gis::bench {
namespace {

/// `count` spot lights on a ring under the ceiling of the scene's bounds, pointing down and slightly
/// outwards, with the first light's colour and cone and 1 / count of its intensity each, so the total
/// power (and the image's brightness) stays the same at every count.
std::vector<FrameLight> ringOfLights(const Scene& scene, const FrameState& base, int count) {
    const Light first = base.lights.empty() ? Light{} : base.lights.front().light;
    const glm::vec3 lo = scene.bounds.min, hi = scene.bounds.max;
    const glm::vec3 centre = 0.5f * (lo + hi);
    const float radius = 0.3f * std::min(hi.x - lo.x, hi.z - lo.z);
    const float height = lo.y + 0.95f * (hi.y - lo.y);
    std::vector<FrameLight> out;
    for (int i = 0; i < count; ++i) {
        Light l = first;
        l.type = LightType::Spot;
        const float a = 6.2831853f * static_cast<float>(i) / static_cast<float>(count);
        const glm::vec3 offset =
            count == 1 ? glm::vec3(0.0f) : radius * glm::vec3(std::cos(a), 0.0f, std::sin(a));
        l.position = glm::vec3(centre.x, height, centre.z) + offset;
        l.direction = glm::normalize(glm::vec3(0.0f, -1.0f, 0.0f) + 0.2f * offset);
        l.intensity = first.intensity / static_cast<float>(count);
        l.name = "bench light " + std::to_string(i);
        out.push_back({"light" + std::to_string(i), l, true});
    }
    return out;
}

// Shadow-map, RSM and flux-measurement time of a frame's median stats: the per-light passes.
double perLightMs(const nlohmann::json& stats) {
    double ms = 0;
    for (const auto& p : stats["passes"]) {
        const std::string name = p["name"].get<std::string>();
        if (name == "shadow_map" || name == "rsm" || name == "rsm_flux") ms += p["gpu_ms"].get<double>();
    }
    return ms;
}

} // namespace

int lights(const std::vector<std::string>& args) {
    RunOptions o;
    o.frames = 3;
    std::vector<int> counts = {1, 2, 4, 8, 16};
    cli::OptionTable options;
    addRunOptions(options, o, "every technique");
    options.value("--counts", "N,N,...", "light counts, each 1..64 (default 1,2,4,8,16)",
                  [&](const std::string& v) {
                      counts.clear();
                      for (const std::string& n : splitList(v))
                          counts.push_back(cli::parseInteger("--counts", n, 1, 64));
                  });
    if (printedHelp(
            args,
            "usage: gi-bench lights [options]\n\n"
            "Frame time against light count: for each technique, N spot lights on a ring under the ceiling "
            "sharing the first light's power, at the technique's default (total) VPL budget; frames of every "
            "N interleaved; prints the median frame time, the ratio of each N to one light and the "
            "per-light passes (shadow_map, rsm, rsm_flux) at the largest N.",
            options))
        return 0;
    options.parse(args);
    auto& [sceneName, width, height, frames, configs, jsonPath, gl, timerQueries] = o;
    if (configs.empty())
        for (const char* t : {"none", "rsm_gather", "ssbc", "multires_splat", "multires_gather", "isr",
                              "hier_isr", "second_order"})
            configs.push_back(parseConfig(t));

    auto scene = std::make_shared<Scene>(loadScene(sceneName));
    auto backend = gl.empty() ? gl::defaultBackend() : gl::parseBackend(gl);
    auto context = gl::createContext(backend);
    std::printf("scene %s, %dx%d, GL %s (%s), timing %s; N spot lights sharing the first light's power, "
                "each technique at its default VPL budget (the total, split across lights); median of %d "
                "frames, the counts interleaved\n\n",
                sceneName.c_str(), width, height, context->info().backend.c_str(),
                context->info().renderer.c_str(), timerQueries ? "timer queries" : "glFinish per pass",
                frames);
    std::printf("| technique |");
    for (int n : counts) std::printf(" %d light%s (ms) |", n, n == 1 ? "" : "s");
    for (size_t k = 1; k < counts.size(); ++k) std::printf(" %d / 1 |", counts[k]);
    std::printf(" per-light passes at %d (ms) |\n|---|", counts.back());
    for (size_t k = 0; k < 2 * counts.size(); ++k) std::printf("---|");
    std::printf("\n");

    nlohmann::json rows = nlohmann::json::array();
    for (const Config& config : configs) {
        const FrameState base = makeStates(*scene, {config}, width, height).front();
        // One renderer per count, so none reallocates its light arrays between interleaved frames.
        std::vector<std::unique_ptr<FrameRenderer>> renderers;
        std::vector<FrameState> states;
        for (int n : counts) {
            FrameState s = base;
            s.frameParams.set("max_lights", std::max(n, 1));
            s.lights = ringOfLights(*scene, base, n);
            states.push_back(s);
            renderers.push_back(std::make_unique<FrameRenderer>(timerQueries));
            renderers.back()->setScene(scene);
            (void)renderers.back()->render(s, false); // warm-up
        }
        std::vector<std::vector<nlohmann::json>> stats(counts.size());
        for (int f = 0; f < frames; ++f)
            for (size_t k = 0; k < counts.size(); ++k)
                stats[k].push_back(renderers[k]->render(states[k], false).stats);
        nlohmann::json row = {{"config", config.label}, {"counts", counts}};
        std::vector<double> ms;
        for (size_t k = 0; k < counts.size(); ++k) {
            const nlohmann::json median = medianStats(stats[k]);
            ms.push_back(median["frame_ms"].get<double>());
            row["frame_ms"].push_back(ms.back());
            row["per_light_ms"].push_back(perLightMs(median));
            row["vpl_count"].push_back(median["counts"].value("vpl_count", 0.0));
        }
        std::printf("| %s |", config.label.c_str());
        for (double m : ms) std::printf(" %.1f |", m);
        for (size_t k = 1; k < ms.size(); ++k) {
            row["ratio"].push_back(ms[k] / std::max(ms[0], 1e-9));
            std::printf(" %.2f |", ms[k] / std::max(ms[0], 1e-9));
        }
        std::printf(" %.1f |\n", row["per_light_ms"].back().get<double>());
        std::fflush(stdout);
        rows.push_back(row);
    }
    if (!jsonPath.empty()) {
        std::ofstream f(jsonPath);
        if (!f) throw InputError(jsonPath, "cannot open for writing");
        f << nlohmann::json(
                 {{"scene", sceneName}, {"size", {width, height}}, {"frames", frames}, {"rows", rows}})
                 .dump(2)
          << "\n";
    }
    return 0;
}

} // namespace gis::bench
