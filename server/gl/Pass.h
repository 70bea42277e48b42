// One render or compute pass as a scope: the prologue every pass repeated (timer, target, viewport,
// clears, program, textures, uniforms, the empty VAO for a fullscreen triangle) written once, with
// textures bound by the shader's own binding names and uniforms by locations the program resolved
// when it was built (gl/Shader.h: Program::textureUnit, Program::location), so a misspelt name fails
// where the program is built instead of being ignored at draw time.
//
// At scope end the pass disables what it enabled (depth test, polygon offset, blending), ends its
// timer slot and, when pass checks are on (GI_GL_CHECK_PASSES=1, as the GL tests run, or a debug
// build), reads glGetError and logs the pass's name with the error; passCheckErrors() counts them.
// Passes never throw: they sit on the per-frame path.
#pragma once

#include <glm/glm.hpp>

#include "gl/Objects.h"
#include "gl/PassTimer.h"
#include "gl/Shader.h"

namespace gis::gl {

class Pass {
public:
    Pass(PassTimer& timer, const char* name);
    ~Pass();
    Pass(const Pass&) = delete;
    Pass& operator=(const Pass&) = delete;

    /// Binds `fbo` and sets the viewport to width x height.
    Pass& target(const Framebuffer& fbo, int width, int height);
    /// Clears colour attachments 0..count-1 of the bound target to 0 (the last `target`).
    Pass& clearColor(int count);
    Pass& clearDepth(float depth = 1.0f);
    Pass& depthTest(GLenum func = GL_LESS);
    /// Slope-scaled depth offset for the pass's triangles (shadow maps against acne).
    Pass& polygonOffset(float factor, float units);
    Pass& use(const Program& program);
    Pass& texture(TextureUnit unit, const Texture& texture);
    Pass& set(UniformLocation u, int value);
    Pass& set(UniformLocation u, float value);
    /// A fullscreen triangle (shaders/render/fullscreen.vert) with `emptyVao` bound.
    void drawFullscreen(const VertexArray& emptyVao);

private:
    PassTimer& mTimer;
    const char* mName;
    GLuint mFbo = 0;
    bool mDepthTest = false;
    bool mPolygonOffset = false;
};

/// Whether passes check glGetError at their end (GI_GL_CHECK_PASSES=1, or a build without NDEBUG).
bool passChecksEnabled();
/// GL errors the pass checks found since the process started (0 unless checks are on).
long passCheckErrors();

} // namespace gis::gl
