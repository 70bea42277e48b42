#include "gi/rsm_gather/RsmGather.h"

#include <algorithm>

#include "gl/ShaderShared.h"

namespace gis {

TechniqueInfo RsmGather::info() {
    return {"rsm_gather", "full-resolution gather from VPLs on a regular RSM grid", "000 §3, Eq. 2",
            ParamTable({
                {.name = "vpl_grid", .type = ParamType::Int, .defaultValue = 16, .min = 1, .max = 256,
                 .unit = "VPLs per side", .help = "VPLs on a regular RSM grid, vpl_grid^2 in total (<= rsm_size)",
                 .source = "000 §3.1; 001 Table 1 uses 256 VPLs"},
                {.name = "min_distance", .type = ParamType::Float, .defaultValue = 0.1, .min = 0.0, .max = 1.0,
                 .unit = "m", .help = "distance clamp of the VPL 1/d^2 falloff (bounds the r->0 singularity)",
                 .source = "000 Fig. 13 (value not given; chosen)"},
            })};
}

RsmGather::RsmGather() {
    mExtract = gl::Program::build({{GL_COMPUTE_SHADER, "gi/rsm_gather/vpl_extract.comp"}});
    mGather = gl::Program::build({{GL_VERTEX_SHADER, "render/fullscreen.vert"},
                                  {GL_FRAGMENT_SHADER, "gi/rsm_gather/gather.frag"}});
    mEmptyVao = gl::VertexArray::create();
}

void RsmGather::resize(int width, int height) {
    mIndirect = gl::Texture::create2D(GL_RGBA32F, width, height);
    mTarget = gl::Framebuffer::create();
    mTarget.attachColor(0, mIndirect);
    mTarget.finish(1, "rsm_gather indirect");
}

void RsmGather::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer, Counters& counters) {
    const int grid = std::clamp(params.getInt("vpl_grid"), 1, std::max(in.rsmSize, 1));
    const int vplCount = in.lightEnabled ? grid * grid : 0;
    counters["vpl_count"] = vplCount;

    const GLsizeiptr bytes = static_cast<GLsizeiptr>(std::max(vplCount, 1)) * sizeof(shader::Vpl);
    if (mVpls.size() < bytes) mVpls = gl::Buffer::create(bytes);

    if (vplCount > 0) {
        timer.begin("vpl_extract");
        glUseProgram(mExtract.id());
        glUniform1i(mExtract.uniform("uGrid"), grid);
        glUniform1i(mExtract.uniform("uRsmSize"), in.rsmSize);
        glBindTextureUnit(0, in.rsmPosition->id());
        glBindTextureUnit(1, in.rsmNormal->id());
        glBindTextureUnit(2, in.rsmFlux->id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, mVpls.id());
        glDispatchCompute(static_cast<GLuint>((vplCount + 63) / 64), 1, 1);
        glMemoryBarrier(GL_UNIFORM_BARRIER_BIT);
        timer.end();
    }

    timer.begin("vpl_gather");
    glBindFramebuffer(GL_FRAMEBUFFER, mTarget.id());
    glViewport(0, 0, in.width, in.height);
    const float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(mTarget.id(), GL_COLOR, 0, zero);
    if (vplCount > 0) {
        glUseProgram(mGather.id());
        glUniform1f(mGather.uniform("uMinDistance"), static_cast<float>(params.getFloat("min_distance")));
        glBindTextureUnit(0, in.gPosition->id());
        glBindTextureUnit(1, in.gNormal->id());
        glBindTextureUnit(2, in.gAlbedo->id());
        glBindVertexArray(mEmptyVao.id());
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE);
        for (int first = 0; first < vplCount; first += GIS_MAX_VPLS_PER_BATCH) {
            const int count = std::min(GIS_MAX_VPLS_PER_BATCH, vplCount - first);
            glBindBufferRange(GL_UNIFORM_BUFFER, GIS_UBO_VPLS, mVpls.id(),
                              static_cast<GLintptr>(first) * static_cast<GLintptr>(sizeof(shader::Vpl)),
                              static_cast<GLsizeiptr>(count) * static_cast<GLsizeiptr>(sizeof(shader::Vpl)));
            glUniform1i(mGather.uniform("uVplCount"), count);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        }
        glDisable(GL_BLEND);
        counters["vpl_batches"] = (vplCount + GIS_MAX_VPLS_PER_BATCH - 1) / GIS_MAX_VPLS_PER_BATCH;
    }
    timer.end();
}

} // namespace gis
