// One render or compute pass as a scope: the prologue every pass repeated (timer, target, viewport,
// clears, program, textures, uniforms, the empty VAO for a fullscreen triangle) written once, with
// textures bound by the shader's own binding names and uniforms by locations the program resolved
// when it was built (gl/Shader.h: Program::textureUnit, Program::location), so a misspelt name fails
// where the program is built instead of being ignored at draw time.
//
// At scope end the pass disables what it enabled (depth test, polygon offset, blending, face
// culling, stencil test, clip distances, colour masking; the front face goes back to GL_CCW and the stencil
// write mask to 0xFF), unbinds the storage blocks it bound, ends its timer slot (a pass built without a timer
// is a sub-step of a timed one) and, when pass checks are on (GI_GL_CHECK_PASSES=1, as the GL tests run, or a
// debug build), reads glGetError and logs the pass's name with the error; passCheckErrors() counts them.
// Passes never throw: they sit on the per-frame path.
#pragma once

#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <functional>

#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"

namespace gis::gl {

class Pass {
public:
    Pass(PassTimer& timer, std::string name);
    /// An untimed pass: a sub-step inside a timed pass (timer slots never nest).
    explicit Pass(std::string name);
    ~Pass();
    Pass(const Pass&) = delete;
    Pass& operator=(const Pass&) = delete;

    /// Binds `fbo` and sets the viewport to width x height.
    Pass& target(const Framebuffer& fbo, int width, int height);
    /// Clears colour attachments 0..count-1 of the bound target to 0 (the last `target`).
    Pass& clearColor(int count);
    Pass& clearDepth(float depth = 1.0f);
    /// Clears the depth-stencil attachment of the bound target (write masks at their defaults, which
    /// passes restore).
    Pass& clearDepthStencil(float depth = 1.0f, int stencil = 0);
    Pass& depthTest(GLenum func = GL_LESS);
    /// Slope-scaled depth offset for the pass's triangles (shadow maps against acne).
    Pass& polygonOffset(float factor, float units);
    /// A sub-rectangle of the target (an atlas level).
    Pass& viewport(int x, int y, int width, int height);
    /// Draws and clears touch only this rectangle of the target until the pass ends (a band of a
    /// light view drawn in pieces).
    Pass& scissor(int x, int y, int width, int height);
    /// Additive blending (ONE, ONE) for the pass's draws: accumulating lights or splats.
    Pass& blendAdd();
    /// Blending with separate colour and alpha factors.
    Pass& blend(GLenum srcRgb, GLenum dstRgb, GLenum srcAlpha, GLenum dstAlpha);
    /// Writes no colour (a stencil- or depth-only draw) until the pass ends.
    Pass& noColorWrites();
    /// Makes this pass's earlier writes to a texture visible to its later reads (glTextureBarrier).
    Pass& textureBarrier();
    Pass& cullFace(GLenum face = GL_BACK);
    /// Enables the stencil test. With `write`, fragments that pass replace the stored value with the
    /// reference (write mask 0xFF); without, the stencil buffer is only read (write mask 0). The test
    /// itself is stencilFunc's, set per draw.
    Pass& stencilTest(bool write);
    /// The stencil test of the following draws: `func` (GL_ALWAYS, GL_EQUAL, ...) of `ref` against the
    /// stored value, all 8 bits.
    Pass& stencilFunc(GLenum func, GLint ref);
    /// Enables the user clip distance gl_ClipDistance[index] (the vertex shader must write it).
    Pass& clipDistance(int index = 0);
    /// The winding of front faces for the following draws (GL_CW inside an odd number of mirrors).
    Pass& frontFace(GLenum mode);
    Pass& use(const Program& program);
    Pass& texture(TextureUnit unit, const Texture& texture);
    /// Binds `texture`, or unbinds the unit when it is null (an input the shader does not read then).
    Pass& texture(TextureUnit unit, const Texture* texture);
    /// Binds `level` of `texture` for image load/store (layer 0 of an array or cube).
    Pass& image(ImageUnit unit, const Texture& texture, GLenum access, GLenum format = GL_RGBA32F,
                int level = 0);
    /// Binds all layers (or cube faces) of `level` of `texture` for image load/store.
    Pass& imageLayered(ImageUnit unit, const Texture& texture, GLenum access, GLenum format, int level = 0);
    /// Binds all of `buffer` (or `bytes` from `offset`) at the block's binding point.
    Pass& buffer(BlockBinding block, const Buffer& buffer);
    Pass& buffer(BlockBinding block, const Buffer& buffer, GLintptr offset, GLsizeiptr bytes);
    Pass& set(UniformLocation u, int value);
    Pass& set(UniformLocation u, unsigned value);
    Pass& set(UniformLocation u, float value);
    Pass& set(UniformLocation u, const glm::vec2& value);
    Pass& set(UniformLocation u, const glm::vec3& value);
    Pass& set(UniformLocation u, const glm::vec4& value);
    Pass& set(UniformLocation u, const glm::ivec2& value);
    Pass& set(UniformLocation u, const glm::ivec3& value);
    Pass& set(UniformLocation u, const glm::mat4& value);
    /// A vec3 array uniform, from element 0 (Program::location of the array's name).
    Pass& set(UniformLocation u, std::span<const glm::vec3> values);
    /// A fullscreen triangle (shaders/render/fullscreen.vert) with `emptyVao` bound.
    void drawFullscreen(const VertexArray& emptyVao);
    /// drawFullscreen() in about `bands` horizontal bands of the viewport, `stop` asked after each
    /// band but the last (a `stop` that waits for the work queued, as the renderer's interrupt check
    /// does, makes each band a stage): at its first true the bands not yet drawn are left
    /// and false is returned. Refinement's long gathers use it so that input waits for one band
    /// rather than the whole pass; each pixel is shaded exactly as by one draw. Without `stop`, or for
    /// one band, it is drawFullscreen() (and true).
    bool drawFullscreenInBands(const VertexArray& emptyVao, const std::function<bool()>& stop, int bands);
    /// drawFullscreen() counted by `anySamples` (a GL_ANY_SAMPLES_PASSED query): waits for the result
    /// and returns whether any sample passed the tests.
    bool drawFullscreenAnySamples(const VertexArray& emptyVao, const Query& anySamples);
    /// drawFullscreen() counted by `samplesPassed` (a GL_SAMPLES_PASSED query); does not wait: read
    /// the result when it is needed.
    void drawFullscreenCounted(const VertexArray& emptyVao, const Query& samplesPassed);
    /// Dispatches groupsX x groupsY x groupsZ work groups of the compute program in use.
    Pass& dispatch(int groupsX, int groupsY = 1, int groupsZ = 1);
    /// Dispatches the work-group counts stored at `offset` in `commands`.
    Pass& dispatchIndirect(const Buffer& commands, GLintptr offset = 0);
    Pass& barrier(GLbitfield bits);

private:
    void rememberBlock(BlockBinding block);

    PassTimer* mTimer;
    std::string mName;
    GLuint mFbo = 0;
    int mViewport[4] = {0, 0, 0, 0}; ///< the last target() or viewport(): x, y, width, height
    bool mDepthTest = false;
    bool mPolygonOffset = false;
    bool mBlend = false;
    bool mCull = false;
    bool mStencil = false;
    bool mColorMasked = false;
    bool mScissor = false;
    bool mFrontFace = false;
    unsigned mClipDistances = 0; ///< bit i: GL_CLIP_DISTANCE0 + i enabled here
    std::vector<BlockBinding> mBoundBlocks;
};

/// Whether passes check glGetError at their end (GI_GL_CHECK_PASSES=1, or a build without NDEBUG).
bool passChecksEnabled();
/// GL errors the pass checks found since the process started (0 unless checks are on).
long passCheckErrors();

} // namespace gis::gl
