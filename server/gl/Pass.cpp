#include "gl/Pass.h"

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

Pass::Pass(PassTimer& timer, const char* name) : mTimer(timer), mName(name) {
    mTimer.begin(name);
}

Pass::~Pass() {
    if (mPolygonOffset) glDisable(GL_POLYGON_OFFSET_FILL);
    if (mDepthTest) glDisable(GL_DEPTH_TEST);
    mTimer.end();
    if (passChecksEnabled()) {
        for (GLenum e = glGetError(); e != GL_NO_ERROR; e = glGetError()) {
            ++gPassErrors;
            logError("gl: pass '" + std::string(mName) + "': GL error 0x" + [&] {
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

Pass& Pass::use(const Program& program) {
    glUseProgram(program.id());
    return *this;
}

Pass& Pass::texture(TextureUnit unit, const Texture& texture) {
    glBindTextureUnit(unit.unit, texture.id());
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

} // namespace gis::gl
