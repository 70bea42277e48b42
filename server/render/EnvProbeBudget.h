// How many environment probes to render, and at what face size, within a time budget
// (env_budget_ms; docs/nondiffuse.md, "Probe budget"). No GL: EnvProbe feeds the model the time
// its probe passes took and asks for a plan whenever it has to render its cubes again.
//
// Cost model: one probe (six faces, their mip chain and the prefilter) costs a + b * size^2 ms. A
// face size's cost is the median of its last kEnvCostSamples measurements (one slow frame on a shared
// machine does not move it). With two or more face sizes measured, a and b come from the two nearest to the
// size asked about (b >= 0, a >= 0); with one, half of its cost is taken as fixed (the scene's draws) and
// half as growing with the texels; with none there is no prediction and, under a budget, the room probe
// alone renders at kPreferredMinSize (or env_size when smaller) so that it is measured. Plan, first
// that fits: every probe at the largest size from env_size down to kPreferredMinSize; then fewer local probes
// (the smallest objects go first) at the largest size that fits; then the room probe alone down to kMinSize.
// When nothing fits, the room probe alone at the smallest size.
#pragma once

#include <deque>
#include <map>
#include <string>

namespace gis {

class EnvProbeCostModel {
public:
    /// Measured: `probes` probes at `size` texels per face took `ms` together.
    void record(int size, int probes, double ms);
    /// Predicted ms for one probe at `size`; negative when nothing was measured yet.
    double probeMs(int size) const;
    bool empty() const { return mSamples.empty(); }
    void clear() { mSamples.clear(); }

private:
    double measuredMs(int size) const;          ///< the median at a measured size
    std::map<int, std::deque<double>> mSamples; ///< face size -> the last ms per probe
};

struct EnvProbePlan {
    int size = 0;            ///< texels per face
    int probes = 0;          ///< the room probe plus local probes
    double predictedMs = -1; ///< for `probes` at `size`; negative when not predicted
    std::string reason;      ///< the choice in words, for the frame's stats
};

/// Face sizes the plan does not go below: kPreferredMinSize while local probes can still be dropped
/// instead, kMinSize for the room probe alone (an env_size below either is kept as asked).
inline constexpr int kEnvPreferredMinSize = 32;
inline constexpr int kEnvMinSize = 16;
/// Measurements kept per face size.
inline constexpr int kEnvCostSamples = 5;

/// The plan for `requestedSize` texels and `wantedProbes` probes (>= 1) under `budgetMs` (<= 0: no
/// budget) with the costs `model` predicts.
EnvProbePlan planEnvProbes(int requestedSize, int wantedProbes, double budgetMs,
                           const EnvProbeCostModel& model);

} // namespace gis
