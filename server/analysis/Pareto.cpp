#include "analysis/Pareto.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace gis {

std::vector<std::size_t> paretoFront(const std::vector<TradeoffPoint>& points) {
    std::vector<std::size_t> order(points.size());
    std::iota(order.begin(), order.end(), 0);
    // Stable: equal (time, error) keep input order, so the first duplicate wins.
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        if (points[a].timeMs != points[b].timeMs) return points[a].timeMs < points[b].timeMs;
        return points[a].error < points[b].error;
    });
    std::vector<std::size_t> front;
    double best = INFINITY;
    for (std::size_t i : order) {
        if (points[i].error < best) {
            front.push_back(i);
            best = points[i].error;
        }
    }
    return front;
}

std::size_t kneeOfFront(const std::vector<TradeoffPoint>& front) {
    if (front.size() <= 2) return front.empty() ? 0 : front.size() - 1;
    auto lx = [](double v) { return std::log(std::max(v, 1e-12)); };
    const double x0 = lx(front.front().timeMs), y0 = lx(front.front().error);
    const double x1 = lx(front.back().timeMs), y1 = lx(front.back().error);
    const double dx = x1 - x0, dy = y1 - y0, len = std::hypot(dx, dy);
    std::size_t best = front.size() - 1;
    double bestDistance = 0;
    for (std::size_t i = 1; i + 1 < front.size(); ++i) {
        // Signed distance below the chord (towards lower error and time).
        const double d =
            len > 0 ? ((lx(front[i].timeMs) - x0) * dy - (lx(front[i].error) - y0) * dx) / len : 0.0;
        if (d > bestDistance) {
            bestDistance = d;
            best = i;
        }
    }
    return best;
}

PresetChoice choosePresets(const std::vector<TradeoffPoint>& front, double budgetMs, double errorTolerance,
                           double finalBudgetMs) {
    PresetChoice c;
    if (front.empty()) return c;
    const double tolerance = std::isfinite(errorTolerance) ? std::max(errorTolerance, 0.0) : 0.0;
    // The fastest point up to `last` (front order: time up, error down) within the tolerance of it.
    auto fastestEqualTo = [&](std::size_t last) {
        for (std::size_t i = 0; i <= last; ++i)
            if (front[i].error <= front[last].error + tolerance) return i;
        return last;
    };
    // The most accurate point the final budget affords (the fastest point when none fits).
    std::size_t mostAccurate = front.size() - 1;
    if (finalBudgetMs > 0) {
        mostAccurate = 0;
        for (std::size_t i = 0; i < front.size(); ++i)
            if (front[i].timeMs <= finalBudgetMs) mostAccurate = i;
    }
    c.final = fastestEqualTo(mostAccurate);
    c.interactive = 0;
    for (std::size_t i = 0; i < front.size(); ++i)
        if (front[i].timeMs <= budgetMs) c.interactive = i;
    c.interactive = std::min(fastestEqualTo(c.interactive), c.final); // never past final: steps only go up
    c.balanced = std::clamp(kneeOfFront(front), c.interactive, c.final);
    return c;
}

int chooseDefaultTechnique(const std::vector<TechniquePresets>& techniques, double budgetMs,
                           double errorTolerance) {
    int best = -1;
    for (int i = 0; i < static_cast<int>(techniques.size()); ++i) {
        const TechniquePresets& p = techniques[static_cast<std::size_t>(i)];
        if (p.interactive.timeMs > budgetMs) continue;
        if (best < 0) {
            best = i;
            continue;
        }
        const TechniquePresets& b = techniques[static_cast<std::size_t>(best)];
        if (p.interactive.error + errorTolerance < b.interactive.error) {
            best = i;
        } else if (p.interactive.error <= b.interactive.error + errorTolerance) {
            const bool moreAccurateFinal = p.final.error + errorTolerance < b.final.error;
            const bool equalFinal = p.final.error <= b.final.error + errorTolerance;
            if (moreAccurateFinal || (equalFinal && p.interactive.timeMs < b.interactive.timeMs)) best = i;
        }
    }
    return best;
}

} // namespace gis
