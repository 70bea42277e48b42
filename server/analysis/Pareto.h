// Error-versus-time trade-offs: the Pareto front of measured configurations and the presets picked
// from it (gi-bench report, presets/presets.json).
#pragma once

#include <cstddef>
#include <vector>

namespace gis {

struct TradeoffPoint {
    double timeMs = 0;
    double error = 0; ///< lower is better (relative RMSE)
};

/// Indices of the points that no other point dominates (no slower and no less accurate, and better in
/// one of the two), ordered by time ascending (error descending). Of exact duplicates the first index
/// is kept, so the result depends only on the input order.
std::vector<std::size_t> paretoFront(const std::vector<TradeoffPoint>& points);

/// Index into `front` (a front as paretoFront orders it) of its knee: the point farthest below the
/// chord from the fastest to the most accurate end in log(time)-log(error) space, where equal ratios
/// weigh the same at every scale. Fronts of one or two points return the last (most accurate) point
/// when two and 0 when one.
std::size_t kneeOfFront(const std::vector<TradeoffPoint>& front);

struct PresetChoice {
    std::size_t interactive = 0; ///< indices into the front
    std::size_t balanced = 0;
    std::size_t final = 0;
};

/// interactive: the most accurate front point with time <= budgetMs (the fastest point when none is
/// that fast); final: the most accurate point; balanced: the knee, moved into [interactive, final] so
/// the three never go backwards in time. Errors within `errorTolerance` (the measurement's noise, in
/// the error's units) of a more accurate point count as equal, and of equals the fastest is chosen: a
/// difference the reference cannot resolve never buys a slower preset. With finalBudgetMs > 0, final is
/// the most accurate point with time <= finalBudgetMs (what a service can afford to refine to; the
/// fastest point when none is that fast).
PresetChoice choosePresets(const std::vector<TradeoffPoint>& front, double budgetMs,
                           double errorTolerance = 0, double finalBudgetMs = 0);

/// One technique's interactive and final presets as measured (gi-bench report).
struct TechniquePresets {
    TradeoffPoint interactive, final;
};

/// The service's default technique: index into `techniques` of the most accurate interactive preset
/// with time <= budgetMs; -1 when none is that fast. Errors within `errorTolerance` count as equal; of
/// equals, the one whose final preset is more accurate beyond the tolerance wins (the frame budget
/// sizes either's live frames, and a still view shows the final step longest), then the faster.
int chooseDefaultTechnique(const std::vector<TechniquePresets>& techniques, double budgetMs,
                           double errorTolerance = 0);

} // namespace gis
