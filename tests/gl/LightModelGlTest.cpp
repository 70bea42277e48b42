// One light model (frame/LightModel.h) for the C++ side and the shaders: the cone attenuation
// LightModel::spotFactor() and spotFactor() of shaders/common.glsl, fed the frame uniforms exactly as
// the renderer writes them (writeLightUniforms), agree for every light type, cone and direction.
#include <algorithm>
#include <cmath>

#include "../common/ShaderProbe.h"
#include "GlTestSupport.h"
#include "frame/LightModel.h"
#include "gl/Shader.h"
#include "gl/ShaderShared.h"

namespace gis::test {
namespace {

const char* kProbe = R"(#version 450 core
#include "common.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer Directions { vec4 gDirections[]; };
layout(std430, binding = 1) writeonly buffer Results { float gResults[]; };
void main() {
    gResults[gl_WorkGroupID.x] = spotFactor(normalize(gDirections[gl_WorkGroupID.x].xyz));
}
)";

/// spotFactor() of common.glsl for each unit direction, with `light` in the frame block.
std::vector<float> shaderSpotFactors(const LightModel& light, const std::vector<glm::vec4>& directions) {
    sharedContext();
    static gl::Program program;
    if (!program) program = buildComputeProbe("spot", kProbe);
    shader::FrameUniforms u{};
    writeLightUniforms(light, u);
    gl::Buffer frame = gl::Buffer::create(sizeof u, &u);
    gl::Buffer in =
        gl::Buffer::create(static_cast<GLsizeiptr>(directions.size() * sizeof(glm::vec4)), directions.data());
    gl::Buffer out = gl::Buffer::create(static_cast<GLsizeiptr>(directions.size() * sizeof(float)));
    glUseProgram(program.id());
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_FRAME, frame.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
    glDispatchCompute(static_cast<GLuint>(directions.size()), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> r(directions.size());
    glGetNamedBufferSubData(out.id(), 0, static_cast<GLsizeiptr>(r.size() * sizeof(float)), r.data());
    return r;
}

TEST(LightModel, ShaderAndCppConeAttenuationAgree) {
    // Directions on a cone sweep around the axis, from on-axis to behind the light.
    const glm::vec3 axis = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
    const glm::vec3 side = glm::normalize(glm::cross(axis, glm::vec3(0, 0, 1)));
    std::vector<glm::vec4> directions;
    for (int i = 0; i <= 90; ++i) {
        const float angle = 3.14159265f * static_cast<float>(i) / 90.0f;
        directions.emplace_back(std::cos(angle) * axis + std::sin(angle) * side, 0.0f);
    }
    struct Cone {
        float inner, outer;
    };
    for (const Cone cone : {Cone{0.3f, 0.5f}, Cone{0.0f, 0.785f}, Cone{0.5f, 0.5001f}, Cone{1.2f, 1.5f}}) {
        FrameState state;
        state.light.type = LightType::Spot;
        state.light.position = {0, 2, 0};
        state.light.direction = axis * 3.0f; // not unit: the model normalises
        state.light.innerConeAngle = cone.inner;
        state.light.outerConeAngle = cone.outer;
        state.light.intensity = 5.0f;
        const LightModel light = makeLightModel(state, Bounds{{-1, -1, -1}, {1, 1, 1}});
        const std::vector<float> gpu = shaderSpotFactors(light, directions);
        // Both sides compute the cosine in float; the slope of the falloff, 2 / (cosInner - cosOuter),
        // magnifies its last bits near a narrow cone's edge.
        const float tolerance = 1e-6f + 4e-7f / std::max(light.cosInner - light.cosOuter, 1e-4f);
        int inside = 0, outside = 0;
        for (std::size_t i = 0; i < directions.size(); ++i) {
            const float cpu = light.spotFactor(glm::normalize(glm::vec3(directions[i])));
            EXPECT_NEAR(gpu[i], cpu, tolerance)
                << "cone " << cone.inner << "/" << cone.outer << ", direction " << i;
            inside += cpu == 1.0f;
            outside += cpu == 0.0f;
        }
        EXPECT_GT(outside, 0) << "the sweep reaches outside the cone";
        if (cone.inner > 0.05f) {
            EXPECT_GT(inside, 0) << "and inside the inner cone";
        }
    }
    // Point and directional lights are not attenuated by a cone on the C++ side; the shaders never
    // call spotFactor for them (the pipeline renders spot lights only so far).
    FrameState point;
    point.light.type = LightType::Point;
    point.light.intensity = 1.0f;
    EXPECT_EQ(makeLightModel(point, Bounds{}).spotFactor({0, 1, 0}), 1.0f);
}

TEST(LightModel, OffWhenDisabledDarkOrNotFinite) {
    FrameState s;
    s.light.intensity = 3.0f;
    EXPECT_TRUE(makeLightModel(s, Bounds{}).on);
    EXPECT_EQ(makeLightModel(s, Bounds{}).intensity, 3.0f);
    s.lightEnabled = false;
    EXPECT_FALSE(makeLightModel(s, Bounds{}).on);
    s.lightEnabled = true;
    s.light.position.x = std::nanf("");
    EXPECT_FALSE(makeLightModel(s, Bounds{}).on);
    EXPECT_EQ(makeLightModel(s, Bounds{}).intensity, 0.0f)
        << "an off light writes intensity 0 to the shaders";
    s.light.position.x = 0.0f;
    s.light.color = {-1.0f, 0.5f, INFINITY};
    EXPECT_EQ(makeLightModel(s, Bounds{}).color, glm::vec3(0.0f)) << "a non-finite colour is black";
}

} // namespace
} // namespace gis::test
