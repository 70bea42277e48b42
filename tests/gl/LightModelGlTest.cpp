// One light model (frame/LightModel.h) for the C++ side and the shaders: the cone attenuation, the
// range window and the irradiance of LightModel and of lightIncidence() in shaders/common.glsl, fed
// the light block exactly as the renderer writes it (writeLightUniforms), agree for every light type,
// cone, range and point; and the light views of each type cover what they must.
#include <algorithm>
#include <cmath>
#include <memory>

#include "../common/ShaderProbe.h"
#include "GlTestSupport.h"
#include "frame/LightModel.h"
#include "gl/Shader.h"
#include "gl/ShaderShared.h"
#include "render/FrameRenderer.h"
#include "scene/SceneLoader.h"

namespace gis::test {
namespace {

const char* kProbe = R"(#version 450 core
#include "common.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer Points { vec4 gPoints[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 gResults[]; };
void main() {
    vec4 q = gPoints[gl_WorkGroupID.x];
    vec3 l, irradiance;
    float dist;
    bool defined = lightIncidence(0, q.xyz, l, dist, irradiance);
    // x: spot factor towards the point; y: range window at its distance; z: irradiance (red); w: defined
    vec3 fromLight = normalize(q.xyz - gLights.lights[0].position.xyz);
    gResults[gl_WorkGroupID.x] = vec4(spotFactor(0, fromLight), rangeWindow(0, length(q.xyz - gLights.lights[0].position.xyz)),
                                      irradiance.r, defined ? 1.0 : 0.0);
}
)";

FrameState stateWith(const Light& light) {
    FrameState s;
    s.lights = {{"light0", light, true}};
    return s;
}

/// The probe's results for `points` with `light` as the block's only light.
std::vector<glm::vec4> shaderProbe(const Light& light, const std::vector<glm::vec4>& points) {
    sharedContext();
    static gl::Program program;
    if (!program) program = buildComputeProbe("light", kProbe);
    const LightSetModel set = makeLightSet(stateWith(light), Bounds{{-3, -3, -3}, {3, 3, 3}});
    auto u = std::make_unique<shader::LightUniforms>();
    writeLightUniforms(set, *u);
    gl::Buffer block = gl::Buffer::create(sizeof *u, u.get());
    gl::Buffer in =
        gl::Buffer::create(static_cast<GLsizeiptr>(points.size() * sizeof(glm::vec4)), points.data());
    gl::Buffer out = gl::Buffer::create(static_cast<GLsizeiptr>(points.size() * sizeof(glm::vec4)));
    glUseProgram(program.id());
    glBindBufferBase(GL_UNIFORM_BUFFER, GIS_UBO_LIGHTS, block.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
    glDispatchCompute(static_cast<GLuint>(points.size()), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<glm::vec4> r(points.size());
    glGetNamedBufferSubData(out.id(), 0, static_cast<GLsizeiptr>(r.size() * sizeof(glm::vec4)), r.data());
    return r;
}

TEST(LightModel, ShaderAndCppConeAttenuationAgree) {
    // Points on a cone sweep around the axis, from on-axis to behind the light.
    const glm::vec3 axis = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
    const glm::vec3 side = glm::normalize(glm::cross(axis, glm::vec3(0, 0, 1)));
    const glm::vec3 position(0, 2, 0);
    std::vector<glm::vec4> points;
    for (int i = 0; i <= 90; ++i) {
        const float angle = 3.14159265f * static_cast<float>(i) / 90.0f;
        points.emplace_back(position + 1.5f * (std::cos(angle) * axis + std::sin(angle) * side), 0.0f);
    }
    struct Cone {
        float inner, outer;
    };
    for (const Cone cone : {Cone{0.3f, 0.5f}, Cone{0.0f, 0.785f}, Cone{0.5f, 0.5001f}, Cone{1.2f, 1.5f}}) {
        Light l;
        l.type = LightType::Spot;
        l.position = position;
        l.direction = axis * 3.0f; // not unit: the model normalises
        l.innerConeAngle = cone.inner;
        l.outerConeAngle = cone.outer;
        l.intensity = 5.0f;
        const LightModel light = makeLightModel({"light0", l, true}, Bounds{{-1, -1, -1}, {1, 1, 1}});
        const std::vector<glm::vec4> gpu = shaderProbe(l, points);
        // Both sides compute the cosine in float; the slope of the falloff, 2 / (cosInner - cosOuter),
        // magnifies its last bits near a narrow cone's edge.
        const float tolerance = 1e-6f + 4e-7f / std::max(light.cosInner - light.cosOuter, 1e-4f);
        int inside = 0, outside = 0;
        for (std::size_t i = 0; i < points.size(); ++i) {
            const float cpu = light.spotFactor(glm::normalize(glm::vec3(points[i]) - position));
            EXPECT_NEAR(gpu[i].x, cpu, tolerance)
                << "cone " << cone.inner << "/" << cone.outer << ", point " << i;
            inside += cpu == 1.0f;
            outside += cpu == 0.0f;
        }
        EXPECT_GT(outside, 0) << "the sweep reaches outside the cone";
        if (cone.inner > 0.05f) {
            EXPECT_GT(inside, 0) << "and inside the inner cone";
        }
    }
}

TEST(LightModel, ShaderAndCppIrradianceAgreeForEveryType) {
    std::vector<glm::vec4> points;
    for (int i = 0; i < 40; ++i) {
        const float t = static_cast<float>(i) / 39.0f;
        points.emplace_back(glm::vec3(-2.0f + 4.0f * t, -1.0f + 0.5f * std::sin(7.0f * t), 0.3f - t), 0.0f);
    }
    for (const LightType type : {LightType::Spot, LightType::Point, LightType::Directional}) {
        for (const float range : {0.0f, 2.5f}) {
            Light l;
            l.type = type;
            l.position = {0.2f, 1.5f, -0.1f};
            l.direction = glm::normalize(glm::vec3(0.1f, -1.0f, 0.05f));
            l.outerConeAngle = 1.0f;
            l.innerConeAngle = 0.6f;
            l.intensity = 7.0f;
            l.color = {0.9f, 0.5f, 0.25f};
            l.range = range;
            const LightModel light = makeLightModel({"light0", l, true}, Bounds{});
            const std::vector<glm::vec4> gpu = shaderProbe(l, points);
            for (std::size_t i = 0; i < points.size(); ++i) {
                glm::vec3 toLight, irradiance;
                float dist = 0.0f;
                const bool defined = light.incidence(glm::vec3(points[i]), toLight, dist, irradiance);
                EXPECT_EQ(gpu[i].w > 0.5f, defined);
                EXPECT_NEAR(gpu[i].z, irradiance.r, 1e-5f + 1e-5f * irradiance.r)
                    << "type " << int(type) << " range " << range << " point " << i;
                if (type != LightType::Directional) {
                    EXPECT_NEAR(gpu[i].y, light.rangeWindow(dist), 1e-5f);
                }
            }
        }
    }
}

TEST(LightModel, OffWhenDisabledDarkOrNotFinite) {
    Light l;
    l.intensity = 3.0f;
    FrameLight fl{"light0", l, true};
    EXPECT_TRUE(makeLightModel(fl, Bounds{}).on);
    EXPECT_EQ(makeLightModel(fl, Bounds{}).intensity, 3.0f);
    fl.enabled = false;
    EXPECT_FALSE(makeLightModel(fl, Bounds{}).on);
    fl.enabled = true;
    fl.light.position.x = std::nanf("");
    EXPECT_FALSE(makeLightModel(fl, Bounds{}).on);
    EXPECT_EQ(makeLightModel(fl, Bounds{}).intensity, 0.0f)
        << "an off light writes intensity 0 to the shaders";
    fl.light.position.x = 0.0f;
    fl.light.color = {-1.0f, 0.5f, INFINITY};
    EXPECT_EQ(makeLightModel(fl, Bounds{}).color, glm::vec3(0.0f)) << "a non-finite colour is black";
    EXPECT_FALSE(makeLightModel(fl, Bounds{}).on) << "a black light is off";
}

TEST(LightModel, ViewsOfEachTypeSeeTheWholeScene) {
    const Bounds bounds{{-1, 0, -1}, {1, 2, 1}};
    // Every corner of the bounds lands inside some view of each light (inside the clip volume).
    auto seen = [](const LightSetModel& set, const glm::vec3& p) {
        for (const LightViewModel& v : set.views) {
            const glm::vec4 c = v.viewProj * glm::vec4(p, 1.0f);
            if (!(c.w > 0.0f)) continue;
            const glm::vec3 ndc = glm::vec3(c) / c.w;
            if (std::abs(ndc.x) <= 1.0001f && std::abs(ndc.y) <= 1.0001f && std::abs(ndc.z) <= 1.0001f)
                return true;
        }
        return false;
    };
    Light point;
    point.type = LightType::Point;
    point.position = {0.1f, 1.2f, 0.3f}; // inside the bounds
    Light sun;
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(glm::vec3(0.4f, -1.0f, 0.25f));
    for (const Light& l : {point, sun}) {
        const LightSetModel set = makeLightSet(stateWith(l), bounds);
        ASSERT_EQ(set.lights.size(), 1u);
        EXPECT_EQ(set.views.size(), l.type == LightType::Point ? 6u : 1u);
        for (int i = 0; i < 27; ++i) {
            const glm::vec3 f(i % 3, (i / 3) % 3, i / 9);
            const glm::vec3 p = bounds.min + (bounds.max - bounds.min) * (f * 0.5f) * 0.999f + 0.0005f;
            EXPECT_TRUE(seen(set, p))
                << "type " << int(l.type) << " misses " << p.x << " " << p.y << " " << p.z;
        }
    }
}

TEST(LightModel, SetSkipsWithReasonsAndCapsViewTexels) {
    FrameState s = makeFrameState(loadScene("builtin:cornell"), "none");
    const Light base = s.lights.at(0).light;
    Light far = base;
    far.type = LightType::Point;
    far.position = {100.0f, 0.0f, 0.0f};
    far.range = 5.0f;
    Light dark = base;
    dark.intensity = 0.0f;
    s.lights = {{"a", base, true}, {"b", base, false}, {"c", dark, true}, {"d", far, true}};
    const LightSetModel set = makeLightSet(s, Bounds{{-1, 0, -1}, {1, 2, 1}});
    ASSERT_EQ(set.lights.size(), 1u);
    ASSERT_EQ(set.skipped.size(), 3u);
    EXPECT_NE(set.skipped[0].find("disabled"), std::string::npos);
    EXPECT_NE(set.skipped[1].find("no intensity"), std::string::npos);
    EXPECT_NE(set.skipped[2].find("range"), std::string::npos) << set.skipped[2];
    s.frameParams.set("max_lights", 2);
    s.lights.clear();
    for (const char* id : {"l0", "l1", "l2", "l3", "l4"}) s.lights.push_back({id, base, true});
    const LightSetModel capped = makeLightSet(s, Bounds{{-1, 0, -1}, {1, 2, 1}});
    EXPECT_EQ(capped.lights.size(), 2u);
    EXPECT_EQ(capped.skipped.size(), 3u);
    EXPECT_NE(capped.skipped[0].find("max_lights"), std::string::npos);
    // View sides: at the default size, full size up to sixteen views, then halved; above it, four
    // full-size maps.
    EXPECT_EQ(lightViewSide(1024, 1024, 1, 64), 1024);
    EXPECT_EQ(lightViewSide(1024, 1024, 16, 64), 1024);
    EXPECT_EQ(lightViewSide(1024, 1024, 17, 64), 512);
    EXPECT_EQ(lightViewSide(4096, 1024, 4, 64), 4096);
    EXPECT_EQ(lightViewSide(4096, 1024, 6, 64), 2048);
    EXPECT_EQ(lightViewSide(256, 256, 384, 16), 32);
    EXPECT_EQ(lightViewSide(256, 256, 100000, 16), 16) << "not below the floor";
}

TEST(LightModel, CappedSidesAndWhichKeptMapsServe) {
    const KeptLightViews none{};
    // No cap: the asked sides, and kept maps only of exactly those.
    LightViewSides s = lightViewSides(2048, 512, 0, 0, true, none);
    EXPECT_EQ(s.shadow, 2048);
    EXPECT_EQ(s.rsm, 512);
    EXPECT_FALSE(s.keep);
    EXPECT_TRUE(lightViewSides(2048, 512, 0, 0, true, {true, 2048, 512}).keep);
    EXPECT_FALSE(lightViewSides(2048, 512, 0, 0, true, {true, 1024, 512}).keep);
    EXPECT_FALSE(lightViewSides(2048, 512, 0, 0, true, {false, 2048, 512}).keep) << "other lights";
    // A cap: drawn at it, and kept maps between it and the asked serve (at their own sides).
    s = lightViewSides(2048, 512, 1024, 128, true, none);
    EXPECT_EQ(s.shadow, 1024);
    EXPECT_EQ(s.rsm, 128);
    s = lightViewSides(2048, 512, 1024, 128, true, {true, 2048, 256});
    EXPECT_TRUE(s.keep);
    EXPECT_EQ(s.shadow, 2048);
    EXPECT_EQ(s.rsm, 256);
    EXPECT_FALSE(lightViewSides(2048, 512, 1024, 128, true, {true, 512, 128}).keep) << "below the cap";
    EXPECT_FALSE(lightViewSides(2048, 512, 1024, 128, true, {true, 4096, 128}).keep) << "above the asked";
    // Without RSMs read, their side does not decide; a cap above the asked side is the asked side.
    EXPECT_TRUE(lightViewSides(2048, 512, 1024, 128, false, {true, 1024, 16}).keep);
    s = lightViewSides(1024, 256, 4096, 1024, true, none);
    EXPECT_EQ(s.shadow, 1024);
    EXPECT_EQ(s.rsm, 256);
}

} // namespace
} // namespace gis::test
