// The light-space VPL tree shared by isr and hier_isr (digest S.3 P4 C and D; 001 §3.4-3.5): an
// implicit mip pyramid of the RSM from R x R (R = rsm_size) down to 1 x 1, every node holding the
// exact sums (flux, disk area, valid texels), the flux-weighted mean position and normal, and the
// min-max light distance and normal components of the texels under it.
//
// 001 keeps the tree "in one flat texture" with Haar-like clustering. The GL 4.5 form is one shader
// storage buffer of LightNode records, level-major and row-major per level (shared/LightTree.h), plus
// a uniform block with the level offsets: a traversal reads any node with one index computation, and
// a level is contiguous for the per-level build and selection passes. hier_isr's traversal reads the
// same buffer through a buffer texture, five RGBA32F texels a node (light_tree.glsl: llvmpipe loads a
// storage buffer's element float by float per lane, a texel fetch a vec4 at once; 3x faster).
//
// Several light views: level 0 is a mosaic of the views' RSM layers, lightTreeTiles(views) per row
// (empty tiles past the last view), so one tree spans every light's texels and isr's and hier_isr's
// cuts choose among all lights' patches at once.
//
// Build: one compute dispatch per level from level 1 up (level 1's also writes level 0 from the RSM
// textures), each node reducing its 2x2 children; about 4/3 R^2 nodes of 80 bytes (7 MB at
// R = 1024). Compute writes the SSBO directly; the fragment + glTextureBarrier route that suits the
// eye hierarchy's textures would need five render targets and a texture-to-buffer copy for the
// traversal. 3.3 ms at R = 256 on llvmpipe (2 cores).
#pragma once

#include <vector>

#include "gi/Technique.h"
#include "gl/Background.h"
#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"
#include "gl/ShaderShared.h"

namespace gis {

struct LightLevel {
    int offset = 0; ///< index of the level's first node in the flat buffer
    int side = 0;   ///< nodes per side, ceil(R / 2^l)
};

/// Levels of the tree over an R x R RSM: level 0 is R x R, level l is ceil(R / 2^l) per side, the
/// last one 1 x 1. Pure, so tests can check it without GL.
std::vector<LightLevel> lightTreeLayout(int rsmSize);
/// Tiles per row of level 0's mosaic of `views` light views: ceil(sqrt(views)).
int lightTreeTiles(int views);
/// The finest level whose side does not exceed `resolution` (patches per side): the level a
/// "16^2 light patches" style parameter names. Clamps to the tree (R when resolution >= R).
int lightLevelForResolution(const std::vector<LightLevel>& levels, int resolution);

/// A level of the tree built where input may stop the frame goes in dispatches of at most this many
/// nodes, input asked between them (LightTree::build): a quarter of level 1 over a 1024 RSM, about
/// 7 ms on llvmpipe; the default 256 RSM's whole level 1 (16,384 nodes) stays one.
inline constexpr int kBuildChunkNodes = 65536;
/// The largest node buffer a light tree keeps for a smaller tree (LightTree::ensureLayout): a 1024
/// RSM's tree of one view, 112 MB; or what the asked RSM side's tree needs
/// (FrameInputs::rsmSizeAsked), whose still view builds it again.
inline constexpr long long kKeptTreeBytes = 128ll << 20;
/// Bytes of the nodes of a tree over a level 0 of `rsmSize` texels a side. Pure.
long long lightTreeBytes(int rsmSize);

class LightTree {
public:
    LightTree();
    /// Builds every level from the RSM (pass "light_tree"); nothing when the light is off (valid()
    /// then reports false). Writes the counters vpl_tree_levels and vpl_tree_nodes. Light views the
    /// frame reuses (FrameInputs::lightViewsReused) keep the last build: no pass, and the counter
    /// vpl_tree_reused. With an interrupt check (FrameInputs::interruptCheck) a big level goes in
    /// chunks of kBuildChunkNodes with input asked between them; a stop leaves the tree not valid.
    void build(const FrameInputs& in, gl::PassTimer& timer, Counters& counters);
    bool valid() const { return mValid; }
    const std::vector<LightLevel>& levels() const { return mLevels; }
    /// Side of level 0 (texels): tiles() x the RSM side of one view.
    int rsmSize() const { return mRsmSize; }
    /// Views per mosaic row of level 0 (view v at tile (v % tiles, v / tiles)).
    int tiles() const { return mTiles; }
    const gl::Buffer& nodes() const { return mNodes; }
    /// Binds the nodes at GIS_SSBO_LIGHT_NODES and as texels at GIS_TEXTURE_LIGHT_NODES, and the level
    /// table at GIS_UBO_LIGHT_TREE.
    void bind() const;

    /// Test hooks: the nodes read back (synchronises), and the inputs of the last build (the
    /// renderer's RSM textures; valid until the renderer reallocates them).
    std::vector<shader::LightNode> readNodes() const;
    /// Test hook: keep node buffers up to `bytes` for smaller trees instead of kKeptTreeBytes.
    void setKeptBytes(long long bytes) { mKeptBytes = bytes; }
    /// Node buffers started in the background so far.
    int backgroundStarts() const { return mMaker.starts(); }
    const FrameInputs& lastInputs() const { return mLastInputs; }

private:
    /// `keptSize`: the level 0 side whose tree's buffer is kept beyond kKeptTreeBytes. False when
    /// input stopped the frame while a new buffer was made (the layout is then unchanged).
    bool ensureLayout(int rsmSize, int keptSize, const FrameInputs& in);
    /// A node buffer of `bytes`; empty when input stopped the frame while it was made.
    gl::Buffer makeNodeBuffer(GLsizeiptr bytes, const FrameInputs& in);

    struct BuildProgram {
        gl::Program program;
        gl::UniformLocation level, tiles, viewSide, firstNode;
        gl::TextureUnit position, normal, flux;
    } mBuild;
    gl::Buffer mNodes, mUbo;
    GLsizeiptr mNodeBytes = 0;     ///< of mNodes, the tree's (the buffer may be larger: ensureLayout)
    gl::BufferTexture mNodeTexels; ///< mNodes as RGBA32F texels (light_tree.glsl, lightNodeTexel)
    int mMaxTexels = 0;            ///< GL_MAX_TEXTURE_BUFFER_SIZE
    bool mWarnedTexels = false;
    std::vector<LightLevel> mLevels;
    int mRsmSize = 0; ///< side of level 0: the mosaic of every view's RSM
    int mTiles = 1;
    bool mValid = false;
    FrameInputs mLastInputs;
    long long mKeptBytes = kKeptTreeBytes;                                  ///< setKeptBytes
    gl::BackgroundMaker<GLsizeiptr, gl::Buffer> mMaker{"light tree nodes"}; ///< makeNodeBuffer
};

} // namespace gis
