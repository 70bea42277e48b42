#include "render/EnvProbeBudget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace gis {
namespace {

std::string msText(double ms) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f ms", ms);
    return text;
}

std::string probesText(int size, int probes) {
    return "env_size " + std::to_string(size) + ", " + std::to_string(probes) +
           (probes == 1 ? " probe" : " probes");
}

} // namespace

void EnvProbeCostModel::record(int size, int probes, double ms) {
    if (size <= 0 || probes <= 0 || !std::isfinite(ms) || ms < 0.0) return;
    std::deque<double>& samples = mSamples[size];
    samples.push_back(ms / probes);
    if (samples.size() > static_cast<size_t>(kEnvCostSamples)) samples.pop_front();
}

double EnvProbeCostModel::measuredMs(int size) const {
    std::vector<double> v(mSamples.at(size).begin(), mSamples.at(size).end());
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double EnvProbeCostModel::probeMs(int size) const {
    if (mSamples.empty() || size <= 0) return -1.0;
    if (mSamples.count(size)) return measuredMs(size);
    const double s2 = static_cast<double>(size) * size;
    if (mSamples.size() == 1) {
        const int s0 = mSamples.begin()->first;
        return measuredMs(s0) * (0.5 + 0.5 * s2 / (static_cast<double>(s0) * s0));
    }
    // The two measured sizes nearest on a log scale.
    std::vector<std::pair<double, std::pair<int, double>>> byDistance;
    for (const auto& entry : mSamples) {
        const int s = entry.first;
        byDistance.push_back({std::abs(std::log(static_cast<double>(s) / size)), {s, measuredMs(s)}});
    }
    std::sort(byDistance.begin(), byDistance.end());
    auto [lo, hi] = std::minmax(byDistance[0].second, byDistance[1].second);
    const double lo2 = static_cast<double>(lo.first) * lo.first,
                 hi2 = static_cast<double>(hi.first) * hi.first;
    // Sizes are distinct map keys, so hi2 > lo2. Costs that fall with size are noise: the nearest
    // measurement stands for every size.
    const double perTexel = (hi.second - lo.second) / (hi2 - lo2);
    if (!(perTexel > 0.0)) return byDistance[0].second.second;
    const double fixed = std::max(0.0, lo.second - perTexel * lo2);
    return fixed + perTexel * s2;
}

EnvProbePlan planEnvProbes(int requestedSize, int wantedProbes, double budgetMs,
                           const EnvProbeCostModel& model) {
    const int requested = std::max(requestedSize, 1);
    const int wanted = std::max(wantedProbes, 1);
    EnvProbePlan plan{requested, wanted, -1.0, ""};
    if (!(budgetMs > 0.0)) {
        plan.reason = probesText(requested, wanted) + " as asked: no budget (env_budget_ms=0)";
        return plan;
    }
    if (model.empty()) {
        // Nothing measured on this scene at these samples: one probe at env_size 512 with 256 samples
        // takes seconds on a CPU, as one stage, so the first render is the cheapest plan the budget
        // would keep, and the next plans from what it measured.
        plan.size = std::min(requested, kEnvPreferredMinSize);
        plan.probes = 1;
        plan.reason = probesText(plan.size, 1) +
                      ": their cost is not measured yet, so the smallest first (asked: " +
                      probesText(requested, wanted) + ")";
        return plan;
    }
    auto predict = [&](int size, int probes) { return probes * model.probeMs(size); };
    const double asked = predict(requested, wanted);
    auto choose = [&](int size, int probes, bool fits) {
        plan = {size, probes, predict(size, probes), ""};
        const std::string budget = msText(budgetMs) + " budget";
        if (size == requested && probes == wanted)
            plan.reason = probesText(size, probes) + ": predicted " + msText(plan.predictedMs) +
                          " within the " + budget;
        else
            plan.reason = probesText(size, probes) +
                          (fits ? ": predicted " : ", over budget at the smallest: predicted ") +
                          msText(plan.predictedMs) + " against the " + budget +
                          " (asked: " + probesText(requested, wanted) + ", predicted " + msText(asked) + ")";
        return plan;
    };

    std::vector<int> sizes{requested}; // env_size, halved down to kEnvPreferredMinSize
    while (sizes.back() / 2 >= kEnvPreferredMinSize) sizes.push_back(sizes.back() / 2);
    for (int probes = wanted; probes >= 1; --probes)
        for (int size : sizes)
            if (predict(size, probes) <= budgetMs) return choose(size, probes, true);
    int size = sizes.back();
    while (size / 2 >= kEnvMinSize) {
        size /= 2;
        if (predict(size, 1) <= budgetMs) return choose(size, 1, true);
    }
    return choose(size, 1, false);
}

} // namespace gis
