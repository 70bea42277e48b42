#include "gl/Pass.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <string>

#include "core/Log.h"

namespace gis::gl {
namespace {

std::atomic<long> gPassErrors{0};

} // namespace

bool passChecksEnabled() {
    static const bool enabled = [] {
        const char* v = std::getenv("GI_GL_CHECK_PASSES");
        if (v) return std::string(v) == "1";
#ifdef NDEBUG
        return false;
#else
        return true;
#endif
    }();
    return enabled;
}

long passCheckErrors() {
    return gPassErrors.load();
}

Pass::Pass(PassTimer& timer, std::string name) : mTimer(&timer), mName(std::move(name)) {
    mTimer->begin(mName);
}

Pass::Pass(std::string name) : mTimer(nullptr), mName(std::move(name)) {}

Pass::~Pass() {
    if (mPolygonOffset) glDisable(GL_POLYGON_OFFSET_FILL);
    if (mDepthTest) glDisable(GL_DEPTH_TEST);
    if (mBlend) glDisable(GL_BLEND);
    if (mCull) glDisable(GL_CULL_FACE);
    if (mColorMasked) glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    if (mScissor) glDisable(GL_SCISSOR_TEST);
    if (mStencil) {
        glDisable(GL_STENCIL_TEST);
        glStencilMask(0xFF);
    }
    if (mFrontFace) glFrontFace(GL_CCW);
    for (GLenum i = 0; i < 8; ++i)
        if (mClipDistances & (1u << i)) glDisable(GL_CLIP_DISTANCE0 + i);
    for (const BlockBinding& b : mBoundBlocks) glBindBufferBase(b.target, b.index, 0);
    if (mTimer) mTimer->end();
    if (passChecksEnabled()) {
        for (GLenum e = glGetError(); e != GL_NO_ERROR; e = glGetError()) {
            ++gPassErrors;
            logError("gl: pass '" + mName + "': GL error 0x" + [&] {
                static const char* hex = "0123456789abcdef";
                std::string out;
                for (int s = 12; s >= 0; s -= 4) out += hex[(e >> s) & 15];
                return out;
            }());
        }
    }
}

Pass& Pass::target(const Framebuffer& fbo, int width, int height) {
    mFbo = fbo.id();
    glBindFramebuffer(GL_FRAMEBUFFER, mFbo);
    glViewport(0, 0, width, height);
    mViewport[0] = 0;
    mViewport[1] = 0;
    mViewport[2] = width;
    mViewport[3] = height;
    return *this;
}

Pass& Pass::clearColor(int count) {
    const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < count; ++i) glClearNamedFramebufferfv(mFbo, GL_COLOR, i, zero);
    return *this;
}

Pass& Pass::clearDepth(float depth) {
    glClearNamedFramebufferfv(mFbo, GL_DEPTH, 0, &depth);
    return *this;
}

Pass& Pass::clearDepthStencil(float depth, int stencil) {
    glClearNamedFramebufferfi(mFbo, GL_DEPTH_STENCIL, 0, depth, stencil);
    return *this;
}

Pass& Pass::depthTest(GLenum func) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(func);
    mDepthTest = true;
    return *this;
}

Pass& Pass::polygonOffset(float factor, float units) {
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(factor, units);
    mPolygonOffset = true;
    return *this;
}

Pass& Pass::viewport(int x, int y, int width, int height) {
    glViewport(x, y, width, height);
    mViewport[0] = x;
    mViewport[1] = y;
    mViewport[2] = width;
    mViewport[3] = height;
    return *this;
}

Pass& Pass::scissor(int x, int y, int width, int height) {
    glEnable(GL_SCISSOR_TEST);
    glScissor(x, y, std::max(width, 0), std::max(height, 0));
    mScissor = true;
    return *this;
}

Pass& Pass::blend(GLenum srcRgb, GLenum dstRgb, GLenum srcAlpha, GLenum dstAlpha) {
    glEnable(GL_BLEND);
    glBlendFuncSeparate(srcRgb, dstRgb, srcAlpha, dstAlpha);
    mBlend = true;
    return *this;
}

Pass& Pass::noColorWrites() {
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    mColorMasked = true;
    return *this;
}

Pass& Pass::textureBarrier() {
    glTextureBarrier();
    return *this;
}

Pass& Pass::blendAdd() {
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    mBlend = true;
    return *this;
}

Pass& Pass::cullFace(GLenum face) {
    glEnable(GL_CULL_FACE);
    glCullFace(face);
    mCull = true;
    return *this;
}

Pass& Pass::stencilTest(bool write) {
    glEnable(GL_STENCIL_TEST);
    glStencilMask(write ? 0xFF : 0x00);
    glStencilOp(GL_KEEP, GL_KEEP, write ? GL_REPLACE : GL_KEEP);
    mStencil = true;
    return *this;
}

Pass& Pass::stencilFunc(GLenum func, GLint ref) {
    glStencilFunc(func, ref, 0xFF);
    return *this;
}

Pass& Pass::clipDistance(int index) {
    glEnable(GL_CLIP_DISTANCE0 + static_cast<GLenum>(index));
    mClipDistances |= 1u << index;
    return *this;
}

Pass& Pass::frontFace(GLenum mode) {
    glFrontFace(mode);
    mFrontFace = true;
    return *this;
}

Pass& Pass::use(const Program& program) {
    glUseProgram(program.id());
    return *this;
}

Pass& Pass::texture(TextureUnit unit, const Texture& texture) {
    if (unit.unit != kNoUnit) glBindTextureUnit(unit.unit, texture.id());
    return *this;
}

Pass& Pass::texture(TextureUnit unit, const Texture* texture) {
    if (unit.unit != kNoUnit) glBindTextureUnit(unit.unit, texture ? texture->id() : 0);
    return *this;
}

Pass& Pass::image(ImageUnit unit, const Texture& texture, GLenum access, GLenum format, int level) {
    glBindImageTexture(unit.unit, texture.id(), level, GL_FALSE, 0, access, format);
    return *this;
}

Pass& Pass::imageLayered(ImageUnit unit, const Texture& texture, GLenum access, GLenum format, int level) {
    glBindImageTexture(unit.unit, texture.id(), level, GL_TRUE, 0, access, format);
    return *this;
}

void Pass::rememberBlock(BlockBinding block) {
    // A loop rebinding one block (ping-pong lists) unbinds it once at the end.
    const bool known = std::any_of(mBoundBlocks.begin(), mBoundBlocks.end(), [&](const BlockBinding& b) {
        return b.target == block.target && b.index == block.index;
    });
    if (!known) mBoundBlocks.push_back(block);
}

Pass& Pass::buffer(BlockBinding block, const Buffer& buffer) {
    if (block.index == kNoUnit) return *this;
    glBindBufferBase(block.target, block.index, buffer.id());
    rememberBlock(block);
    return *this;
}

Pass& Pass::buffer(BlockBinding block, const Buffer& buffer, GLintptr offset, GLsizeiptr bytes) {
    if (block.index == kNoUnit) return *this;
    glBindBufferRange(block.target, block.index, buffer.id(), offset, bytes);
    rememberBlock(block);
    return *this;
}

Pass& Pass::set(UniformLocation u, const glm::vec2& value) {
    glUniform2f(u.location, value.x, value.y);
    return *this;
}

Pass& Pass::set(UniformLocation u, const glm::vec3& value) {
    glUniform3f(u.location, value.x, value.y, value.z);
    return *this;
}

Pass& Pass::set(UniformLocation u, const glm::vec4& value) {
    glUniform4f(u.location, value.x, value.y, value.z, value.w);
    return *this;
}

Pass& Pass::set(UniformLocation u, const glm::ivec2& value) {
    glUniform2i(u.location, value.x, value.y);
    return *this;
}

Pass& Pass::set(UniformLocation u, const glm::ivec3& value) {
    glUniform3i(u.location, value.x, value.y, value.z);
    return *this;
}

Pass& Pass::set(UniformLocation u, std::span<const glm::vec3> values) {
    if (!values.empty()) glUniform3fv(u.location, static_cast<GLsizei>(values.size()), &values[0].x);
    return *this;
}

Pass& Pass::set(UniformLocation u, const glm::mat4& value) {
    glUniformMatrix4fv(u.location, 1, GL_FALSE, &value[0][0]);
    return *this;
}

Pass& Pass::dispatch(int groupsX, int groupsY, int groupsZ) {
    glDispatchCompute(static_cast<GLuint>(std::max(groupsX, 0)), static_cast<GLuint>(std::max(groupsY, 0)),
                      static_cast<GLuint>(std::max(groupsZ, 0)));
    return *this;
}

Pass& Pass::barrier(GLbitfield bits) {
    glMemoryBarrier(bits);
    return *this;
}

Pass& Pass::set(UniformLocation u, unsigned value) {
    glUniform1ui(u.location, value);
    return *this;
}

Pass& Pass::dispatchIndirect(const Buffer& commands, GLintptr offset) {
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, commands.id());
    glDispatchComputeIndirect(offset);
    return *this;
}

Pass& Pass::set(UniformLocation u, int value) {
    glUniform1i(u.location, value);
    return *this;
}

Pass& Pass::set(UniformLocation u, float value) {
    glUniform1f(u.location, value);
    return *this;
}

void Pass::drawFullscreen(const VertexArray& emptyVao) {
    glBindVertexArray(emptyVao.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

bool Pass::drawFullscreenInBands(const VertexArray& emptyVao, const std::function<bool()>& stop, int bands) {
    const auto [x, y, width, height] = mViewport;
    // Rows per band: llvmpipe rasterizes the target in 64 x 64 bins, one per thread at a time, so
    // bands of whole bin rows keep its threads as busy as one draw would; a target of a single bin
    // row (a small refinement tile, one thread's work either way) goes in multiples of 16 rows.
    constexpr int kBinRows = 64, kSmallBandRows = 16;
    const int step = height > kBinRows ? kBinRows : kSmallBandRows;
    const int wanted = (height + std::max(bands, 1) - 1) / std::max(bands, 1);
    const int rows = (wanted + step - 1) / step * step;
    if (!stop || height <= rows) {
        drawFullscreen(emptyVao);
        return true;
    }
    glEnable(GL_SCISSOR_TEST);
    bool goOn = true;
    for (int top = 0; top < height && goOn; top += rows) {
        glScissor(x, y + top, width, std::min(rows, height - top));
        drawFullscreen(emptyVao);
        if (top + rows >= height) break;
        goOn = !stop();
    }
    glDisable(GL_SCISSOR_TEST);
    return goOn;
}

bool Pass::drawFullscreenAnySamples(const VertexArray& emptyVao, const Query& anySamples) {
    glBeginQuery(GL_ANY_SAMPLES_PASSED, anySamples.id());
    drawFullscreen(emptyVao);
    glEndQuery(GL_ANY_SAMPLES_PASSED);
    GLuint any = 0;
    glGetQueryObjectuiv(anySamples.id(), GL_QUERY_RESULT, &any);
    return any != 0;
}

void Pass::drawFullscreenCounted(const VertexArray& emptyVao, const Query& samplesPassed) {
    glBeginQuery(GL_SAMPLES_PASSED, samplesPassed.id());
    drawFullscreen(emptyVao);
    glEndQuery(GL_SAMPLES_PASSED);
}

} // namespace gis::gl
