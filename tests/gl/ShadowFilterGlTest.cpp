// The shadow lookup's filter (pcfFiltered in shaders/render/lighting.glsl) takes (r + 1)^2 bilinear
// compare taps for what was (2r + 1)^2 taps at whole-texel offsets: the probe evaluates both on a
// shadow map of random depths (every texel an edge, the hardest case for a filter) at random points,
// the edges included, and they must agree for every radius the parameter allows.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "../common/ShaderProbe.h"
#include "GlTestSupport.h"
#include "gl/Objects.h"
#include "gl/Shader.h"

namespace gis::test {
namespace {

const char* kProbe = R"(#version 450 core
#include "common.glsl"
#include "render/lighting.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer Points { vec4 gPoints[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 gResults[]; };
uniform int uRadius;
uniform float uSide;
// The kernel as it was written before: one hardware 2x2 compare tap per whole-texel offset.
float pcfEveryOffset(vec3 uvz, float layer, int r) {
    float sum = 0.0;
    for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x)
            sum += texture(gShadowMap, vec4(uvz.xy + vec2(x, y) / uSide, layer, uvz.z));
    float taps = float(2 * r + 1);
    return sum / (taps * taps);
}
void main() {
    vec4 q = gPoints[gl_WorkGroupID.x]; // xy: uv; z: depth; w: layer
    gResults[gl_WorkGroupID.x] = vec4(pcfFiltered(q.xyz, q.w, uRadius, uSide), pcfEveryOffset(q.xyz, q.w, uRadius), 0, 0);
}
)";

TEST(ShadowFilter, PairedTapsEqualEveryOffsetsTap) {
    sharedContext();
    const gl::Program program = buildComputeProbe("shadow_filter", kProbe);
    constexpr int kSide = 64;
    constexpr int kLayers = 2;
    std::mt19937 rng(20261204);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<float> depths(static_cast<size_t>(kSide) * kSide * kLayers);
    for (float& d : depths) d = unit(rng);
    gl::Texture map = gl::Texture::create2DArray(GL_DEPTH_COMPONENT32F, kSide, kSide, kLayers);
    glTextureSubImage3D(map.id(), 0, 0, 0, 0, kSide, kSide, kLayers, GL_DEPTH_COMPONENT, GL_FLOAT,
                        depths.data());
    // As FrameRenderer sets the shadow maps up.
    map.setFilter(GL_LINEAR, GL_LINEAR);
    glTextureParameteri(map.id(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTextureParameteri(map.id(), GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);

    // Points over the whole map and just outside it (the taps clamp to the edge), plus texel centres
    // and corners, where a pair's weights reach 0 or 1.
    std::vector<glm::vec4> points;
    std::uniform_real_distribution<float> around(-0.05f, 1.05f);
    for (int i = 0; i < 400; ++i)
        points.emplace_back(around(rng), around(rng), unit(rng), static_cast<float>(i % kLayers));
    for (int i = 0; i < 40; ++i) {
        const float centre = (static_cast<float>(i) + 0.5f) / kSide;
        const float corner = static_cast<float>(i) / kSide;
        points.emplace_back(centre, corner, unit(rng), 0.0f);
        points.emplace_back(corner, centre, unit(rng), 1.0f);
    }
    gl::Buffer in =
        gl::Buffer::create(static_cast<GLsizeiptr>(points.size() * sizeof(glm::vec4)), points.data());
    gl::Buffer out = gl::Buffer::create(static_cast<GLsizeiptr>(points.size() * sizeof(glm::vec4)));

    for (int r = 0; r <= 3; ++r) {
        glUseProgram(program.id());
        glUniform1i(program.location("uRadius").location, r);
        glUniform1f(program.location("uSide").location, static_cast<float>(kSide));
        glBindTextureUnit(4, map.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
        glDispatchCompute(static_cast<GLuint>(points.size()), 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        std::vector<glm::vec4> results(points.size());
        glGetNamedBufferSubData(out.id(), 0, static_cast<GLsizeiptr>(results.size() * sizeof(glm::vec4)),
                                results.data());
        float worst = 0.0f;
        int varied = 0; // points whose kernel straddles lit and shadowed texels
        for (size_t i = 0; i < points.size(); ++i) {
            const float paired = results[i].x, every = results[i].y;
            ASSERT_TRUE(paired >= 0.0f && paired <= 1.0f) << "r " << r << " point " << i << ": " << paired;
            worst = std::max(worst, std::abs(paired - every));
            if (every > 0.0f && every < 1.0f) ++varied;
            // The filter's rounding: bilinear weights are interpolated at the sampler's precision,
            // and a tap's fraction comes back from a coordinate scaled by the map's side.
            EXPECT_NEAR(paired, every, 2e-3f) << "r " << r << " at uv (" << points[i].x << ", " << points[i].y
                                              << "), depth " << points[i].z;
        }
        EXPECT_GT(varied, static_cast<int>(points.size()) / 3) << "r " << r << ": the kernels must see edges";
        RecordProperty("max_difference_r" + std::to_string(r), std::to_string(worst));
    }
}

} // namespace
} // namespace gis::test
