#include "gi/hier_isr/HierIsr.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/Error.h"
#include "gi/Catalog.h"
#include "gi/common/VplGrid.h"

namespace gis {
namespace {
/// gather.comp's CutStats, in order.
enum CutStat {
    kVisitedLo,
    kVisitedHi,
    kVisitedMax,
    kCutLo,
    kCutHi,
    kCutMax,
    kCutShort,
    kLeafVisitedLo,
    kLeafVisitedHi,
    kCutStats
};
} // namespace

LightCutSettings lightCutSettings(const std::vector<LightLevel>& levels, int coarsestResolution,
                                  int maxDepthResolution, double tau) {
    LightCutSettings s;
    s.leafLevel = lightLevelForResolution(levels, maxDepthResolution);
    s.startLevel = std::max(s.leafLevel, lightLevelForResolution(levels, coarsestResolution));
    // Decided on the float the shader sees: a tau that rounds to 0 must not reach the division.
    s.tau = static_cast<float>(tau);
    if (!(s.tau > 0.0f))
        s.mode = LightRefine::Always;
    else if (s.tau >= 1.0f)
        s.mode = LightRefine::Never;
    return s;
}

TraversalSplit traversalSplit(const std::vector<LightLevel>& levels, const LightCutSettings& s,
                              double loopBudget) {
    GIS_ASSERT(s.startLevel >= s.leafLevel && s.startLevel < static_cast<int>(levels.size()));
    const double budget = std::max(loopBudget, 1.0);
    // One root's worst case: the ancestors' loop, its subtree's nodes (every one refined, but for
    // Never: the root alone), the roots' loop itself. Doubles: a deep subtree is past any int.
    const auto iterationsPerRoot = [&](int rootLevel) {
        double subtree = 1.0;
        if (s.mode != LightRefine::Never) {
            double level = 1.0;
            for (int d = 0; d < rootLevel - s.leafLevel; ++d) subtree += (level *= 4.0);
        }
        return static_cast<double>(s.startLevel - rootLevel) + subtree + 1.0;
    };
    TraversalSplit split;
    split.rootLevel = std::min(s.startLevel, s.leafLevel + kFullTraversalMaxDepth);
    while (split.rootLevel > s.leafLevel && iterationsPerRoot(split.rootLevel) > budget) --split.rootLevel;
    const double side = levels[static_cast<size_t>(split.rootLevel)].side;
    split.roots = static_cast<int>(side * side);
    // Clamped as a double before converting: a tiny budget's count is past any int.
    split.ranges =
        static_cast<int>(std::clamp(std::ceil(side * side * iterationsPerRoot(split.rootLevel) / budget), 1.0,
                                    std::max(side * side, 1.0)));
    return split;
}

int traversalRanges(double receivers, double leavesPerReceiver, int roots) {
    if (roots <= 1) return 1;
    double ranges = kGatherPieces;
    const double pairs = receivers * leavesPerReceiver;
    if (std::isfinite(pairs) && pairs > 0.0)
        ranges = std::max(ranges, std::ceil(pairs / kTraversalPairsPerRange));
    ranges = std::min({ranges, static_cast<double>(kMaxTraversalRanges), static_cast<double>(roots)});
    return static_cast<int>(ranges);
}

TraversalPieces fullTraversalPieces(double receivers, double leavesPerReceiver, int roots, int minRanges) {
    TraversalPieces pieces;
    const int wanted = traversalRanges(receivers, leavesPerReceiver, kMaxTraversalRanges);
    const int rootCount = std::max(roots, 1);
    const int asked =
        std::clamp(std::max(traversalRanges(receivers, leavesPerReceiver, roots), minRanges), 1, rootCount);
    // What the loop over the roots dispatches: whole roots a range.
    const int perRange = (rootCount + asked - 1) / asked;
    pieces.ranges = (rootCount + perRange - 1) / perRange;
    pieces.chunks = std::max(1, (wanted + pieces.ranges - 1) / pieces.ranges);
    return pieces;
}

std::vector<int> lightCutCpu(const std::vector<shader::LightNode>& nodes,
                             const std::vector<LightLevel>& levels, const LightCutSettings& s,
                             float tanHalfFov, glm::vec3 receiver) {
    std::vector<int> cut;
    const float t2 = tanHalfFov * tanHalfFov;
    const float omega = 4.0f * std::asin(std::clamp(t2 / (1.0f + t2), 0.0f, 1.0f));
    const float scale = s.mode == LightRefine::Test
                            ? omega * (1.0f - s.tau) / (3.14159265358979f * std::max(s.tau, 1e-30f))
                            : 0.0f;
    const auto index = [&](int level, int x, int y) {
        const LightLevel& l = levels[static_cast<size_t>(level)];
        return l.offset + y * l.side + x;
    };
    struct Item {
        int level, x, y;
    };
    std::vector<Item> stack;
    const int rootSide = levels[static_cast<size_t>(s.startLevel)].side;
    for (int r = 0; r < rootSide * rootSide; ++r) {
        stack.push_back({s.startLevel, r % rootSide, r / rootSide});
        while (!stack.empty()) {
            const Item it = stack.back();
            stack.pop_back();
            const int i = index(it.level, it.x, it.y);
            const shader::LightNode& node = nodes[static_cast<size_t>(i)];
            if (node.position.w < 0.5f) continue;
            bool refine = false;
            if (it.level > s.leafLevel) {
                if (s.mode == LightRefine::Always) {
                    refine = true;
                } else if (s.mode == LightRefine::Test) {
                    const glm::vec3 v = glm::vec3(node.position) - receiver;
                    const float side = static_cast<float>(levels[static_cast<size_t>(it.level)].side);
                    refine = glm::dot(v, v) * side * side <= scale * node.hi.w * node.hi.w;
                }
            }
            if (!refine) {
                cut.push_back(i);
                continue;
            }
            const int childSide = levels[static_cast<size_t>(it.level - 1)].side;
            for (int k = 3; k >= 0; --k) {
                const int cx = it.x * 2 + (k & 1), cy = it.y * 2 + (k >> 1);
                if (cx < childSide && cy < childSide) stack.push_back({it.level - 1, cx, cy});
            }
        }
    }
    return cut;
}

HierIsr::HierIsr() {
    GatherProgram& g = mGather;
    g.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/hier_isr/gather.comp"}});
    g.startLevel = g.program.location("uStartLevel");
    g.leafLevel = g.program.location("uLeafLevel");
    g.refineMode = g.program.location("uRefineMode");
    g.tau = g.program.location("uTau");
    g.rootLevel = g.program.location("uRootLevel");
    g.rootFirst = g.program.location("uRootFirst");
    g.rootEnd = g.program.location("uRootEnd");
    g.stats = g.program.storageBlock("CutStats");
    g.transport = VplTransportHandles(g.program);
    g.eye = EyeReceiverPassHandles(g.program);
    mStats =
        gl::Buffer::create(kCutStats * sizeof(GLuint), nullptr, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
}

void HierIsr::resize(int width, int height) {
    mIndirect.resize(width, height, "hier_isr indirect");
}

void HierIsr::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                      Counters& counters) {
    mTree.build(in, timer, counters);
    mEye.build(in, params, timer);
    // The eye hierarchy is whole (a later part of the same image keeps it): input may stop the frame.
    if (in.interrupted()) return;
    // The receiver work cap (gi/Catalog.h): a view with more receivers than its share traverses to a
    // shallower max_depth, its leaves cut by the cost exponent's root.
    ParamSet traversal = params;
    if (mTree.valid())
        mEye.capVplsToReceivers(
            in, findTechniqueInfo("hier_isr"), traversal,
            [&](const ParamSet& p) { return squared(std::min<long>(in.rsmSize, p.getInt("max_depth"))); },
            counters);

    const GLuint zero[kCutStats] = {};
    mStats.upload(0, sizeof zero, zero);
    GLuint stats[kCutStats] = {};
    {
        gl::Pass pass(timer, "vpl_gather");
        if (mTree.valid()) {
            const LightCutSettings s =
                lightCutSettings(mTree.levels(), traversal.getInt("hier_coarsest"),
                                 traversal.getInt("max_depth"), traversal.getFloat("tau"));
            const GatherProgram& g = mGather;
            pass.use(g.program);
            g.transport.set(pass, params, in.sceneSize, false, in.glossyMinRoughness, nullptr);
            pass.set(g.startLevel, s.startLevel)
                .set(g.leafLevel, s.leafLevel)
                .set(g.refineMode, static_cast<int>(s.mode))
                .set(g.tau, s.tau);
            mTree.bind();
            pass.buffer(g.stats, mStats);
            mEye.beginReceiverPass(pass, g.eye, in);
            // One traversal in ranges of roots; false when input stopped it.
            const auto gather = [&](const TraversalSplit& split) {
                pass.set(g.rootLevel, split.rootLevel);
                if (split.rootLevel < s.startLevel)
                    counters["traversal_split_levels"] = s.startLevel - split.rootLevel;
                int ranges = split.ranges;
                // In refinement a full traversal's pieces are also small enough for input to stop
                // between (fullTraversalPieces); a traversal by the test goes in receiver chunks
                // (its work is not known beforehand), in each range.
                int chunks = 1;
                if (in.interruptCheck) {
                    if (s.mode == LightRefine::Always) {
                        const int leafSide = mTree.levels()[static_cast<size_t>(s.leafLevel)].side;
                        const TraversalPieces pieces = fullTraversalPieces(
                            static_cast<double>(mEye.readReceiverCount()),
                            static_cast<double>(leafSide) * leafSide, split.roots, ranges);
                        ranges = pieces.ranges;
                        chunks = pieces.chunks;
                        if (chunks > 1) counters["traversal_receiver_chunks"] = chunks;
                    } else {
                        chunks = gatherCut(1).cutsPerBatch;
                    }
                }
                const int perRange = (split.roots + ranges - 1) / ranges;
                if (ranges > 1) counters["traversal_ranges"] = (split.roots + perRange - 1) / perRange;
                for (int first = 0; first < split.roots; first += perRange) {
                    pass.set(g.rootFirst, first).set(g.rootEnd, std::min(first + perRange, split.roots));
                    if (!mEye.dispatchReceivers(pass, g.eye, in.interruptCheck, chunks)) return false;
                    if (first + perRange < split.roots && in.interrupted()) return false;
                }
                glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
                glGetNamedBufferSubData(mStats.id(), 0, sizeof stats, stats);
                return true;
            };
            // The split that no loop limit can stop (its worst case: every node refined) is the
            // traversal's own work for a full traversal or none; a traversal by the test is mostly
            // far cheaper, and its worst-case split cost 3-31 % more gather time in measurement
            // (docs/multires.md): it goes whole, and split only once a loop limit stopped receivers
            // short (gather.comp counts them exactly), from then on while its settings stay.
            const TraversalSplit safe = traversalSplit(mTree.levels(), s, mLoopBudget);
            const int startSide = mTree.levels()[static_cast<size_t>(s.startLevel)].side;
            const TraversalSplit whole{s.startLevel, startSide * startSide, 1};
            const std::array<double, 4> key{s.tau, static_cast<double>(s.startLevel),
                                            static_cast<double>(s.leafLevel),
                                            static_cast<double>(mTree.levels().size())};
            const bool splitFirst = s.mode != LightRefine::Test || mLoopBudgetSet || mSplitSettings == key;
            if (!gather(splitFirst ? safe : whole)) return;
            if (!splitFirst && stats[kCutShort] > 0 && (safe.ranges > 1 || safe.rootLevel < s.startLevel)) {
                counters["traversal_cut_short_whole"] = stats[kCutShort];
                mSplitSettings = key;
                mEye.clearIllumination();
                mStats.upload(0, sizeof zero, zero);
                if (!gather(safe)) return;
            }
        }
    }

    mEye.reconstruct(in, params, true, mIndirect.framebuffer, timer);
    mEye.countReceivers(counters);

    const double receivers = counters["receivers_total"];
    const auto sum64 = [&stats](CutStat lo, CutStat hi) {
        return static_cast<double>(stats[lo]) + 4294967296.0 * static_cast<double>(stats[hi]);
    };
    const double visited = sum64(kVisitedLo, kVisitedHi);
    const double cut = sum64(kCutLo, kCutHi);
    counters["nodes_visited_mean"] = receivers > 0 ? visited / receivers : 0.0;
    counters["nodes_visited_max"] = stats[kVisitedMax];
    counters["cut_size_mean"] = receivers > 0 ? cut / receivers : 0.0;
    counters["cut_size_max"] = stats[kCutMax];
    counters["traversal_cut_short"] = stats[kCutShort];
    counters["nodes_visited_leaf_mean"] =
        receivers > 0 ? sum64(kLeafVisitedLo, kLeafVisitedHi) / receivers : 0.0;
    mSsbc.apply(in, params, mIndirect.texture, timer, counters);
}

} // namespace gis
