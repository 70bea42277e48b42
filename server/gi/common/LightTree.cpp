#include "gi/common/LightTree.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include "core/Error.h"
#include "core/Log.h"
#include "gl/Pass.h"

namespace gis {

std::vector<LightLevel> lightTreeLayout(int rsmSize) {
    GIS_ASSERT(rsmSize > 0);
    std::vector<LightLevel> levels;
    int offset = 0;
    for (int side = rsmSize;; side = (side + 1) / 2) {
        levels.push_back({offset, side});
        offset += side * side;
        if (side == 1) break;
    }
    GIS_ASSERT(levels.size() <= GIS_MAX_LIGHT_LEVELS);
    return levels;
}

int lightLevelForResolution(const std::vector<LightLevel>& levels, int resolution) {
    for (size_t l = 0; l < levels.size(); ++l)
        if (levels[l].side <= resolution) return static_cast<int>(l);
    return static_cast<int>(levels.size()) - 1; // resolution < 1: the 1 x 1 root
}

LightTree::LightTree() {
    gl::Program p = gl::Program::build({{GL_COMPUTE_SHADER, "gi/common/light_tree_build.comp"}});
    mBuild = {{},
              p.location("uLevel"),
              p.location("uTiles"),
              p.location("uViewSide"),
              p.location("uFirstNode"),
              p.textureUnit("uRsmPosition"),
              p.textureUnit("uRsmNormal"),
              p.textureUnit("uRsmFlux")};
    mBuild.program = std::move(p);
    mUbo = gl::Buffer::create(sizeof(shader::LightTreeUniforms));
    mNodeTexels = gl::BufferTexture::create();
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &mMaxTexels);
}

long long lightTreeBytes(int rsmSize) {
    const std::vector<LightLevel> levels = lightTreeLayout(rsmSize);
    const LightLevel& last = levels.back();
    return (static_cast<long long>(last.offset) + static_cast<long long>(last.side) * last.side) *
           static_cast<long long>(sizeof(shader::LightNode));
}

bool LightTree::ensureLayout(int rsmSize, int keptSize, const FrameInputs& in) {
    if (rsmSize == mRsmSize && mNodes) return true;
    std::vector<LightLevel> levels = lightTreeLayout(rsmSize);
    const LightLevel& last = levels.back();
    const int nodeCount = last.offset + last.side * last.side;
    const GLsizeiptr nodeBytes =
        static_cast<GLsizeiptr>(nodeCount) * static_cast<GLsizeiptr>(sizeof(shader::LightNode));
    // A larger buffer serves a smaller tree: a live view whose drag draws 256 RSMs and whose
    // refinement draws the asked 1024 alternates between the two, and creating the 1024's 112 MB
    // buffer took about 60 ms each time, input waiting. Kept up to kKeptTreeBytes, or up to what
    // the asked side's tree needs while a drag's capped maps ask for a smaller one (13 point-lamp
    // views at rsm_size 1024, 512 each in the mosaic: 447 MB, created again in each refinement after
    // a drag, about 230 ms); a larger one goes when a smaller tree is asked for (docs/interactive.md,
    // "The light tree in refinement").
    const bool fits = mNodes && mNodes.size() >= nodeBytes;
    const long long kept = std::max(mKeptBytes, keptSize > rsmSize ? lightTreeBytes(keptSize) : 0ll);
    if (!fits || (mNodes.size() > nodeBytes && mNodes.size() > kept)) {
        gl::Buffer made = makeNodeBuffer(nodeBytes, in);
        if (!made) return false;
        mNodes = std::move(made);
        mNodeTexels.view(mNodes, GL_RGBA32F, 0, mNodes.size());
    }
    mLevels = std::move(levels);
    mNodeBytes = nodeBytes;
    shader::LightTreeUniforms u{};
    for (size_t l = 0; l < mLevels.size(); ++l)
        u.level[l] = glm::ivec4(mLevels[l].offset, mLevels[l].side, 1 << l, 0);
    u.info = glm::ivec4(static_cast<int>(mLevels.size()), rsmSize, nodeCount, 0);
    mUbo.upload(0, sizeof u, &u);
    mRsmSize = rsmSize;
    return true;
}

gl::Buffer LightTree::makeNodeBuffer(GLsizeiptr bytes, const FrameInputs& in) {
    // Where input may stop the frame, large storage is made on a helper thread and input is asked
    // while it is made (gl/Background.h): llvmpipe zeroes it in one call, 60 ms for a 1024 RSM's
    // tree of one view (112 MB), 240 ms for 13 point-lamp views' (447 MB). A stop leaves it being
    // made: the next frame that asks for the same size takes it.
    std::optional<gl::Buffer> made = mMaker.make(
        bytes, static_cast<double>(bytes), in.backgroundBytes,
        in.interruptCheck ? std::function<bool()>([&] { return in.interrupted(); }) : std::function<bool()>(),
        [bytes] { return gl::Buffer::create(bytes); });
    return made ? std::move(*made) : gl::Buffer{};
}

void LightTree::bind() const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, GIS_SSBO_LIGHT_NODES, mNodes.id());
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_LIGHT_TREE, mUbo.id());
    glBindTextureUnit(GIS_TEXTURE_LIGHT_NODES, mNodeTexels.id());
}

int lightTreeTiles(int views) {
    int tiles = 1;
    while (tiles * tiles < views) ++tiles;
    return tiles;
}

void LightTree::build(const FrameInputs& in, gl::PassTimer& timer, Counters& counters) {
    const int tiles = lightTreeTiles(std::max(in.lightViews, 1));
    // The nodes depend on the RSMs alone: unchanged light views (an orbit, the tiles and VPL parts
    // of a refinement step) keep the last build, which was whole (GL finishes queued work).
    if (mValid && in.lightViewsReused && in.lightEnabled && in.lightViews > 0 && tiles == mTiles &&
        tiles * in.rsmSize == mRsmSize && in.find("lights.rsm.position")) {
        mLastInputs = in;
        mLastInputs.lights = nullptr;
        counters["vpl_tree_levels"] = static_cast<double>(mLevels.size());
        counters["vpl_tree_nodes"] = static_cast<double>(mLevels.back().offset + 1);
        counters["vpl_tree_reused"] = 1;
        return;
    }
    mLastInputs = in;
    mLastInputs.lights = nullptr; // the renderer's per-frame copy: gone after the frame
    mValid = false;
    if (in.rsmSize <= 0 || !in.find("lights.rsm.position")) return;
    // Input asked while the nodes' storage was made stops the frame here (the tree is not valid).
    if (!ensureLayout(tiles * in.rsmSize, tiles * std::max(in.rsmSizeAsked, in.rsmSize), in)) return;
    mTiles = tiles;
    counters["vpl_tree_levels"] = static_cast<double>(mLevels.size());
    counters["vpl_tree_nodes"] = static_cast<double>(mLevels.back().offset + 1);
    // The traversal reads the nodes as texels (five each); a GL whose texel buffers are smaller than
    // the tree gets no tree (and so no indirect light from it) rather than nodes read as zeros.
    if (static_cast<long long>(mLevels.back().offset + 1) * 5 > mMaxTexels) {
        if (!mWarnedTexels)
            logWarn("light tree: " + std::to_string(mLevels.back().offset + 1) +
                    " nodes need more than this GL's " + std::to_string(mMaxTexels) +
                    " texels per buffer texture; lower rsm_size");
        mWarnedTexels = true;
        return;
    }
    if (!in.lightEnabled || in.lightViews <= 0) return;

    {
        gl::Pass pass(timer, "light_tree");
        pass.use(mBuild.program).set(mBuild.tiles, tiles).set(mBuild.viewSide, in.rsmSize);
        bind();
        pass.texture(mBuild.position, in.get("lights.rsm.position"))
            .texture(mBuild.normal, in.get("lights.rsm.normal"))
            .texture(mBuild.flux, in.get("lights.rsm.flux"));
        // Level 1's dispatch writes level 0 too (light_tree_build.comp); then one dispatch per level.
        // Where input may stop the frame (refinement), a level of more than kBuildChunkNodes nodes
        // goes in chunks with input asked between them: over a 1024 RSM the tree took 38 ms, most of
        // it level 1's one dispatch, which a camera move waited for. A stopped build is not valid:
        // the next frame builds it again.
        for (size_t l = 1; l < mLevels.size(); ++l) {
            if (l > 1) pass.barrier(GL_SHADER_STORAGE_BARRIER_BIT); // level l - 1 is complete
            const int count = mLevels[l].side * mLevels[l].side;
            const int chunk = in.interruptCheck ? kBuildChunkNodes : count;
            pass.set(mBuild.level, static_cast<int>(l));
            for (int first = 0; first < count; first += chunk) {
                if (first > 0 && in.interrupted()) return;
                pass.set(mBuild.firstNode, first).dispatch((std::min(chunk, count - first) + 63) / 64);
            }
        }
        pass.barrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_UNIFORM_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                     GL_BUFFER_UPDATE_BARRIER_BIT);
    }
    mValid = true;
}

std::vector<shader::LightNode> LightTree::readNodes() const {
    std::vector<shader::LightNode> nodes;
    if (!mNodes) return nodes;
    nodes.resize(static_cast<size_t>(mNodeBytes) / sizeof(shader::LightNode));
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(mNodes.id(), 0, mNodeBytes, nodes.data());
    return nodes;
}

} // namespace gis
