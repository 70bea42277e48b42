// The gathers read their VPLs through VplBatches (server/gi/common/VplGrid.h) and
// shaders/gi/common/vpl_batch.glsl: each batch a buffer-texture view of the VPL buffer, three texels per
// shader::Vpl. A probe reads every VPL of a buffer spanning three batches through batchVpl() and must
// get back the bytes the buffer holds, each batch at its own offset; and GIS_SUM_OVER_BATCH, which
// takes four terms per iteration, must give the plain loop's sum bit for bit for every count.
#include <cstring>
#include <vector>

#include "../common/ShaderProbe.h"
#include "GlTestSupport.h"
#include "gi/common/VplGrid.h"
#include "gl/Objects.h"
#include "gl/ShaderShared.h"

namespace gis::test {
namespace {

const char* kProbe = R"(#version 450 core
#include "common.glsl"
#include "gi/common/vpl_batch.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = 0) writeonly buffer Read { Vpl gRead[]; };
layout(std430, binding = 1) writeonly buffer Sums { vec4 gSums[]; }; // per (batch, count): unrolled, plain
uniform int uFirst;
uniform int uCount;
uniform int uSumSlot;
// A term whose rounding depends on the order it is added in.
vec3 probeTerm(int i) { Vpl v = batchVpl(i); return v.flux.rgb * v.position.w + v.normal.xyz * 1e-3; }
void main() {
    for (int i = 0; i < uCount; ++i) gRead[uFirst + i] = batchVpl(i);
    for (int count = 0; count <= 9; ++count) {
        vec3 unrolled = vec3(0.0), plain = vec3(0.0);
        GIS_SUM_OVER_BATCH(unrolled, min(count, uCount), probeTerm)
        for (int i = 0; i < min(count, uCount); ++i) plain += probeTerm(i);
        gSums[uSumSlot * 10 + count] = vec4(unrolled.x, plain.x, unrolled.z, plain.z);
    }
}
)";

TEST(VplBatches, EveryBatchReadsItsOwnVplsAndTheUnrolledSumIsTheLoops) {
    sharedContext();
    const gl::Program program = buildComputeProbe("vpl_batch", kProbe);
    const int count = 2 * GIS_MAX_VPLS_PER_BATCH + 333; // two whole batches and a partial one
    std::vector<shader::Vpl> vpls(static_cast<size_t>(count));
    for (int i = 0; i < count; ++i) {
        const float f = static_cast<float>(i);
        vpls[static_cast<size_t>(i)] = {{f, f + 0.25f, -f, i % 2 ? 1.0f : 0.5f},
                                        {0.1f * f, 1.0f / (f + 1.0f), 0.3f, 0.01f * f},
                                        {1.0f + f / 7.0f, 3.0f / (f + 3.0f), 1e5f / (f + 1.0f), f + 0.5f}};
    }
    const GLsizeiptr bytes = static_cast<GLsizeiptr>(vpls.size() * sizeof(shader::Vpl));
    gl::Buffer source = gl::Buffer::create(bytes, vpls.data());
    gl::Buffer read = gl::Buffer::create(bytes);
    const int kSlots = 3;
    gl::Buffer sums = gl::Buffer::create(static_cast<GLsizeiptr>(kSlots * 10 * sizeof(glm::vec4)));

    VplBatches batches;
    std::vector<int> firsts;
    glUseProgram(program.id());
    const int n = batches.forEach(source, count, [&](int batchCount, int first) {
        firsts.push_back(first);
        glUniform1i(program.location("uFirst").location, first);
        glUniform1i(program.location("uCount").location, batchCount);
        glUniform1i(program.location("uSumSlot").location, static_cast<int>(firsts.size()) - 1);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, read.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, sums.id());
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    });
    ASSERT_EQ(n, kSlots);
    EXPECT_EQ(firsts, (std::vector<int>{0, GIS_MAX_VPLS_PER_BATCH, 2 * GIS_MAX_VPLS_PER_BATCH}));

    std::vector<shader::Vpl> back(vpls.size());
    glGetNamedBufferSubData(read.id(), 0, bytes, back.data());
    int wrong = 0;
    for (size_t i = 0; i < vpls.size(); ++i)
        if (std::memcmp(&back[i], &vpls[i], sizeof(shader::Vpl)) != 0 && ++wrong <= 5)
            ADD_FAILURE() << "VPL " << i << " read back as position (" << back[i].position.x << ", "
                          << back[i].position.y << ", " << back[i].position.z << ")";
    EXPECT_EQ(wrong, 0) << "VPLs read wrongly through their batches";

    std::vector<glm::vec4> s(static_cast<size_t>(kSlots * 10));
    glGetNamedBufferSubData(sums.id(), 0, static_cast<GLsizeiptr>(s.size() * sizeof(glm::vec4)), s.data());
    for (int slot = 0; slot < kSlots; ++slot)
        for (int c = 0; c <= 9; ++c) {
            const glm::vec4 v = s[static_cast<size_t>(slot * 10 + c)];
            EXPECT_EQ(v.x, v.y) << "batch " << slot << ", " << c << " terms: red";
            EXPECT_EQ(v.z, v.w) << "batch " << slot << ", " << c << " terms: blue";
            if (c > 0) {
                EXPECT_GT(v.x, 0.0f) << "batch " << slot << ", " << c << " terms";
            }
        }
}

} // namespace
} // namespace gis::test
