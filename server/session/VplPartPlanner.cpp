#include "session/VplPartPlanner.h"

#include <algorithm>
#include <cmath>

namespace gis {
namespace {

// Share of the target a part's fixed work may take before the tile shrinks a rung: the rest is left
// for VPLs (below it, parts would multiply to fit their VPL work into a sliver).
constexpr double kFixedShareBeforeShrink = 0.7;
// A part's VPL work where fixed work alone overruns the target and no smaller tile helps (share of
// the target).
constexpr double kVplShareOverFixedWork = 0.3;
// A smaller rung whose fixed work is above this share of the larger one's saved too little to be
// worth its extra tiles.
constexpr double kShrinkWorthIt = 0.85;
// The fewest and most parts measured must differ by this factor for a fit.
constexpr double kDistinctCounts = 1.25;
// Weight of a new part in its count's mean (parts of one tile vary by a few ms on a busy machine).
constexpr double kMeanWeight = 0.3;

int clampParts(double parts, int maxParts) {
    if (!(parts >= 1.0)) return 1; // NaN included
    return static_cast<int>(std::min(parts, static_cast<double>(maxParts)));
}

} // namespace

VplPartPlanner::VplPartPlanner(Limits limits) : mLimits(limits) {
    mLimits.tilePixels = std::max(mLimits.tilePixels, 1.0);
    mLimits.minTilePixels = std::clamp(mLimits.minTilePixels, 1.0, mLimits.tilePixels);
    mLowestRung = static_cast<int>(std::ceil(std::log2(mLimits.tilePixels / mLimits.minTilePixels) - 1e-9));
}

double VplPartPlanner::rungPixels(int rung) const {
    return std::max(mLimits.minTilePixels, mLimits.tilePixels / std::exp2(rung));
}

int VplPartPlanner::rungOf(double pixels) const {
    const double steps = std::round(std::log2(mLimits.tilePixels / std::max(pixels, 1.0)));
    return static_cast<int>(std::clamp(steps, 0.0, static_cast<double>(mLowestRung)));
}

bool VplPartPlanner::fit(int rung, double& fixedMs, double& vplMs) const {
    const auto found = mRungs.find(rung);
    if (found == mRungs.end() || found->second.byParts.size() < 2) return false;
    // Part counts too close together cannot tell fixed work from VPL work.
    const auto& counts = found->second.byParts;
    if (counts.rbegin()->first < kDistinctCounts * counts.begin()->first) return false;
    // Weighted least squares of ms = fixed + vpl x with x = 1 / parts; weights cap at 8 samples so that
    // one long-used count does not drown a newly tried one.
    double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const auto& [parts, mean] : found->second.byParts) {
        const double weight = std::min(mean.samples, 8);
        const double x = 1.0 / parts;
        sw += weight;
        sx += weight * x;
        sy += weight * mean.ms;
        sxx += weight * x * x;
        sxy += weight * x * mean.ms;
    }
    const double det = sw * sxx - sx * sx;
    if (!(det > 1e-12 * sw * sw)) return false;
    vplMs = (sw * sxy - sx * sy) / det;
    fixedMs = (sy - vplMs * sx) / sw;
    if (vplMs < 0.0) { // parts cost the same whatever their VPLs: all fixed
        vplMs = 0.0;
        fixedMs = sy / sw;
    } else if (fixedMs < 0.0) { // noise below the origin: all VPLs
        fixedMs = 0.0;
        vplMs = sxx > 0.0 ? sxy / sxx : 0.0;
    }
    return std::isfinite(fixedMs) && std::isfinite(vplMs);
}

bool VplPartPlanner::fitted(double& fixedMs, double& vplMs) const {
    return fit(mRung, fixedMs, vplMs);
}

VplPartPlan VplPartPlanner::plan(long vpls, double allVplRate) {
    const int maxParts =
        static_cast<int>(std::clamp(vpls, 1L, static_cast<long>(std::max(1, mLimits.maxParts))));
    const double target = std::max(mLimits.targetMs, 1e-3);
    auto partsFor = [&](double fixedMs, double vplMs) {
        const double headroom = std::max(target - fixedMs, kVplShareOverFixedWork * target);
        return clampParts(std::ceil(vplMs / headroom), maxParts);
    };
    VplPartPlan out;
    double fixedMs = 0, vplMs = 0;
    if (fit(mRung, fixedMs, vplMs)) {
        if (fixedMs > kFixedShareBeforeShrink * target && mRung < mLowestRung && !mShrinkFutile) {
            // A rung down: its own fit if it has one, else this one's scaled by the pixels.
            const double scale = rungPixels(mRung + 1) / rungPixels(mRung);
            ++mRung;
            out.pixels = rungPixels(mRung);
            double lowerFixed = 0, lowerVpl = 0;
            out.parts = fit(mRung, lowerFixed, lowerVpl) ? partsFor(lowerFixed, lowerVpl)
                                                         : partsFor(fixedMs * scale, vplMs * scale);
            return out;
        }
        out.pixels = rungPixels(mRung);
        out.parts = partsFor(fixedMs, vplMs);
        return out;
    }
    out.pixels = rungPixels(mRung);
    const auto found = mRungs.find(mRung);
    if (found != mRungs.end() && !found->second.byParts.empty()) {
        // One count measured: as if all of it were VPL work (pessimistic for fewer parts, optimistic
        // for more, which the next tile's measurement corrects).
        const Rung& rung = found->second;
        const auto last = rung.byParts.find(rung.lastParts);
        const auto& [parts, mean] = last != rung.byParts.end() ? *last : *rung.byParts.begin();
        out.parts = clampParts(std::ceil(parts * mean.ms / target), maxParts);
        return out;
    }
    out.parts = clampParts(std::ceil(std::max(allVplRate, 0.0) * out.pixels / target), maxParts);
    return out;
}

VplPartPlanner::Memory VplPartPlanner::remember(long vpls) const {
    Memory m;
    const double count = static_cast<double>(std::max(vpls, 1L));
    for (const auto& [rung, data] : mRungs) {
        double fixedMs = 0, vplMs = 0;
        if (fit(rung, fixedMs, vplMs)) m.fixedAndPerVpl[rung] = {fixedMs, vplMs / count};
    }
    m.shrinkFutile = mShrinkFutile;
    return m;
}

void VplPartPlanner::recall(const Memory& memory, long vpls) {
    const double count = static_cast<double>(std::max(vpls, 1L));
    // Two part counts far enough apart that fit() reproduces the remembered costs, each worth one
    // sample: this step's measurements outweigh them from its first tiles on.
    constexpr int kFew = 1, kMany = 16;
    for (const auto& [rung, costs] : memory.fixedAndPerVpl) {
        if (rung < 0 || rung > mLowestRung || !std::isfinite(costs.first) || !std::isfinite(costs.second))
            continue;
        const double vplMs = costs.second * count;
        Rung& r = mRungs[rung];
        r.byParts[kFew] = {costs.first + vplMs / kFew, 1};
        r.byParts[kMany] = {costs.first + vplMs / kMany, 1};
        r.lastParts = kMany;
    }
    // The tile size is chosen again from the largest: the last step may have shrunk its tiles for a
    // VPL count this one does not have (plan() steps down while fixed work fills the target).
    mShrinkFutile = memory.shrinkFutile;
}

void VplPartPlanner::record(double pixels, int parts, double ms) {
    if (!(pixels > 0.0) || parts < 1 || !std::isfinite(ms) || ms < 0.0) return;
    const int rungIndex = rungOf(pixels);
    Rung& rung = mRungs[rungIndex];
    Mean& mean = rung.byParts[parts];
    mean.ms = mean.samples == 0 ? ms : (1.0 - kMeanWeight) * mean.ms + kMeanWeight * ms;
    ++mean.samples;
    rung.lastParts = parts;
    // A smaller tile whose fixed work is hardly smaller: its costs are per pass, not per pixel, so
    // the larger tile does the same work in fewer tiles.
    double fixedHere = 0, vplHere = 0, fixedAbove = 0, vplAbove = 0;
    if (rungIndex > 0 && rungIndex == mRung && fit(rungIndex, fixedHere, vplHere) &&
        fit(rungIndex - 1, fixedAbove, vplAbove) && fixedHere > kShrinkWorthIt * fixedAbove) {
        mShrinkFutile = true;
        mRung = rungIndex - 1;
    }
}

} // namespace gis
