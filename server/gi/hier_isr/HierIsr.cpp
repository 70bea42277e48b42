#include "gi/hier_isr/HierIsr.h"

#include <algorithm>
#include <cmath>

#include "gi/Catalog.h"
#include "gi/common/VplGrid.h"

namespace gis {

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
    // A full traversal reaches the same leaves from any start level: start no coarser than a root
    // whose subtree fits one invocation's loop budget (kFullTraversalMaxDepth).
    if (s.mode == LightRefine::Always)
        s.startLevel = std::min(s.startLevel, s.leafLevel + kFullTraversalMaxDepth);
    return s;
}

int fullTraversalRanges(int roots, int depth) {
    if (roots <= 1) return 1;
    // Nodes of a root's subtree down `depth` levels (each node 4 children at most), plus the root
    // loop's own iteration.
    double perRoot = 1.0;
    double level = 1.0; // nodes of one level of the subtree: 4^d (a double: no overflow at any depth)
    for (int d = 0; d < std::max(depth, 0); ++d) perRoot += (level *= 4.0);
    const double iterations = static_cast<double>(roots) * (perRoot + 1.0);
    // Clamped as a double: a deep subtree's count is past any int.
    return static_cast<int>(
        std::clamp(std::ceil(iterations / kTraversalLoopBudget), 1.0, static_cast<double>(roots)));
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
    g.rootFirst = g.program.location("uRootFirst");
    g.rootEnd = g.program.location("uRootEnd");
    g.stats = g.program.storageBlock("CutStats");
    g.transport = VplTransportHandles(g.program);
    g.eye = EyeReceiverPassHandles(g.program);
    mStats = gl::Buffer::create(6 * sizeof(GLuint), nullptr, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
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

    const GLuint zero[6] = {};
    mStats.upload(0, sizeof zero, zero);
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
            const int rootSide = mTree.levels()[static_cast<size_t>(s.startLevel)].side;
            const int roots = rootSide * rootSide;
            // A full traversal: the roots in ranges within llvmpipe's loop budget and, in refinement,
            // small enough for input to stop between (traversalRanges); every receiver in each.
            int ranges = 1;
            if (s.mode == LightRefine::Always) {
                ranges = fullTraversalRanges(roots, s.startLevel - s.leafLevel);
                if (in.interruptCheck) {
                    const int leafSide = mTree.levels()[static_cast<size_t>(s.leafLevel)].side;
                    ranges =
                        std::max(ranges, traversalRanges(static_cast<double>(mEye.readReceiverCount()),
                                                         static_cast<double>(leafSide) * leafSide, roots));
                }
            }
            if (ranges > 1) {
                const int perRange = (roots + ranges - 1) / ranges;
                counters["traversal_ranges"] = (roots + perRange - 1) / perRange;
                for (int first = 0; first < roots; first += perRange) {
                    pass.set(g.rootFirst, first).set(g.rootEnd, std::min(first + perRange, roots));
                    mEye.dispatchReceivers(pass, g.eye);
                    if (first + perRange < roots && in.interrupted()) return;
                }
            } else {
                // In refinement the receivers go in chunks that input can stop between (one
                // dispatch: gatherCut of one batch).
                pass.set(g.rootFirst, 0).set(g.rootEnd, roots);
                if (!mEye.dispatchReceivers(pass, g.eye, in.interruptCheck, gatherCut(1).cutsPerBatch))
                    return;
            }
        }
    }

    mEye.reconstruct(in, params, true, mIndirect.framebuffer, timer);
    mEye.countReceivers(counters);

    GLuint stats[6] = {};
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(mStats.id(), 0, sizeof stats, stats);
    const double receivers = counters["receivers_total"];
    const double visited = static_cast<double>(stats[0]) + 4294967296.0 * static_cast<double>(stats[1]);
    const double cut = static_cast<double>(stats[3]) + 4294967296.0 * static_cast<double>(stats[4]);
    counters["nodes_visited_mean"] = receivers > 0 ? visited / receivers : 0.0;
    counters["nodes_visited_max"] = stats[2];
    counters["cut_size_mean"] = receivers > 0 ? cut / receivers : 0.0;
    counters["cut_size_max"] = stats[5];
    mSsbc.apply(in, params, mIndirect.texture, timer, counters);
}

} // namespace gis
