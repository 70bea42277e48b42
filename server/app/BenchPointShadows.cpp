// gi-bench point-shadows: a point light's shadow map as a cube (six 90-degree perspective faces, what
// the renderer uses) or as a dual paraboloid (two hemispheres), at the same number of texels: the
// time to render each on this GL, and how often each disagrees with exact ray-traced visibility at
// points spread over the scene's surfaces. docs/lights.md records the figures and the choice.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "BenchCommon.h"
#include "core/Error.h"
#include "frame/LightModel.h"
#include "gl/Pass.h"
#include "gl/Platform.h"
#include "reference/RayScene.h"
#include "render/SceneGpu.h"
#include "scene/SceneLoader.h"

namespace gis::bench {
namespace {

// Points uniformly by area over the scene's triangles, each with its geometric normal.
void samplePoints(const Scene& scene, int count, std::vector<glm::vec4>& points,
                  std::vector<glm::vec3>& normals) {
    std::vector<double> cdf;
    std::vector<std::pair<int, int>> tris;
    double total = 0;
    for (int m = 0; m < static_cast<int>(scene.meshes.size()); ++m) {
        const Mesh& mesh = scene.meshes[static_cast<size_t>(m)];
        for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
            const glm::vec3 a = mesh.positions[mesh.indices[t]], b = mesh.positions[mesh.indices[t + 1]],
                            c = mesh.positions[mesh.indices[t + 2]];
            total += 0.5 * glm::length(glm::cross(b - a, c - a));
            cdf.push_back(total);
            tris.emplace_back(m, static_cast<int>(t));
        }
    }
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < count; ++i) {
        const size_t k =
            static_cast<size_t>(std::lower_bound(cdf.begin(), cdf.end(), u(rng) * total) - cdf.begin());
        const auto [m, t] = tris[std::min(k, tris.size() - 1)];
        const Mesh& mesh = scene.meshes[static_cast<size_t>(m)];
        const glm::vec3 a = mesh.positions[mesh.indices[static_cast<size_t>(t)]],
                        b = mesh.positions[mesh.indices[static_cast<size_t>(t) + 1]],
                        c = mesh.positions[mesh.indices[static_cast<size_t>(t) + 2]];
        double s = u(rng), r = u(rng);
        if (s + r > 1.0) s = 1.0 - s, r = 1.0 - r;
        points.emplace_back(a + float(s) * (b - a) + float(r) * (c - a), 1.0f);
        normals.push_back(glm::normalize(glm::cross(b - a, c - a)));
    }
}

double medianMs(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

} // namespace

int pointShadows(const std::vector<std::string>& args) {
    std::string sceneName = "builtin:cornell-point", gl;
    int side = 512, repeats = 15, samples = 20000;
    cli::OptionTable options;
    options
        .value("--scene", "NAME", "a scene with a point light (default builtin:cornell-point)",
               [&](const std::string& v) { sceneName = v; })
        .integer("--side", "N", "cube face side (the paraboloids get sqrt(3) N)", 16, 4096, side)
        .integer("--samples", "N", "surface points", 100, 10000000, samples)
        .integer("--repeats", "N", "timed renders of each", 1, 1000, repeats)
        .value("--gl", "egl|osmesa", "headless GL backend (default: $GI_GL, else egl)",
               [&](const std::string& v) { gl = v; });
    if (printedHelp(
            args,
            "usage: gi-bench point-shadows [options]\n\n"
            "A point light's shadow map as a cube (the renderer's six faces) and as a dual paraboloid with "
            "the same texel count: render time (median of --repeats, glFinish) and the share of surface "
            "points whose visibility disagrees with a ray (docs/lights.md).",
            options))
        return 0;
    options.parse(args);
    const Scene scene = loadScene(sceneName);
    FrameState state = makeFrameState(scene, "none");
    const LightSetModel set = makeLightSet(state, scene.bounds);
    auto point = std::find_if(set.lights.begin(), set.lights.end(),
                              [](const LightModel& l) { return l.type == LightType::Point; });
    if (point == set.lights.end())
        throw InputError(sceneName, "has no point light to compare the shadow maps with");
    const glm::vec3 light = point->position;
    const int paraboloidSide = static_cast<int>(std::lround(side * std::sqrt(3.0))); // 2 D^2 = 6 S^2 texels

    auto context = gl::createContext(gl.empty() ? gl::defaultBackend() : gl::parseBackend(gl));
    SceneGpu gpu(scene);
    gl::VertexArray vao = gl::VertexArray::create();
    const gl::Program faceProgram = gl::Program::build(
        {{GL_VERTEX_SHADER, "bench/face.vert"}, {GL_FRAGMENT_SHADER, "render/shadow.frag"}});
    const gl::UniformLocation faceViewProj = faceProgram.location("uViewProj");
    const gl::Program dpProgram = gl::Program::build(
        {{GL_VERTEX_SHADER, "bench/paraboloid.vert"}, {GL_FRAGMENT_SHADER, "render/shadow.frag"}});
    const gl::UniformLocation dpView = dpProgram.location("uLightView"),
                              dpHemisphere = dpProgram.location("uHemisphere"),
                              dpRange = dpProgram.location("uDepthRange");
    gl::Texture cube = gl::Texture::create2DArray(GL_DEPTH_COMPONENT32F, side, side, 6);
    gl::Texture dp = gl::Texture::create2DArray(GL_DEPTH_COMPONENT32F, paraboloidSide, paraboloidSide, 2);
    std::vector<gl::Framebuffer> cubeFbos, dpFbos;
    for (int f = 0; f < 6; ++f) cubeFbos.push_back(gl::Framebuffer::ofLayer("cube face", {}, &cube, f));
    for (int h = 0; h < 2; ++h) dpFbos.push_back(gl::Framebuffer::ofLayer("paraboloid", {}, &dp, h));

    // The renderer's own cube faces, and a paraboloid pair with the same depth range.
    std::vector<glm::mat4> faces;
    for (int v = point->firstView; v < point->firstView + point->viewCount; ++v)
        faces.push_back(set.views[static_cast<size_t>(v)].viewProj);
    const glm::vec3 lo = scene.bounds.min, hi = scene.bounds.max;
    float farthest = 0;
    for (int i = 0; i < 8; ++i)
        farthest = std::max(
            farthest,
            glm::length(glm::vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z) - light));
    const glm::vec2 range(1e-3f * farthest, farthest * 1.05f);
    // The cube faces' own near and far (LightModel's perspectiveDepthRange): read back from the matrix.
    const glm::mat4& p0 = faces[0];
    const glm::mat4 proj =
        p0 * glm::inverse(glm::lookAt(light, light + glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)));
    const float a = proj[2][2], b = proj[3][2];
    const glm::vec2 cubeDepth(b / (a - 1.0f), b / (a + 1.0f));
    const glm::mat4 lightView = glm::lookAt(light, light + glm::vec3(0, -1, 0), glm::vec3(0, 0, 1));

    auto renderCube = [&] {
        for (int f = 0; f < 6; ++f) {
            gl::Pass pass("cube face");
            pass.target(cubeFbos[static_cast<size_t>(f)], side, side)
                .depthTest(GL_LESS)
                .clearDepth()
                .polygonOffset(2.0f, 4.0f);
            pass.use(faceProgram).set(faceViewProj, faces[static_cast<size_t>(f)]);
            gpu.draw(faceProgram, nullptr);
        }
    };
    auto renderParaboloid = [&] {
        for (int h = 0; h < 2; ++h) {
            gl::Pass pass("paraboloid");
            pass.target(dpFbos[static_cast<size_t>(h)], paraboloidSide, paraboloidSide)
                .depthTest(GL_LESS)
                .clearDepth()
                .clipDistance(0)
                .polygonOffset(2.0f, 4.0f);
            pass.use(dpProgram)
                .set(dpView, lightView)
                .set(dpHemisphere, h == 0 ? 1.0f : -1.0f)
                .set(dpRange, range);
            gpu.draw(dpProgram, nullptr);
        }
    };
    std::vector<double> cubeMs, dpMs;
    renderCube();
    renderParaboloid();
    glFinish();
    for (int r = 0; r < repeats; ++r) {
        for (int which = 0; which < 2; ++which) {
            const auto t0 = std::chrono::steady_clock::now();
            which == 0 ? renderCube() : renderParaboloid();
            glFinish();
            (which == 0 ? cubeMs : dpMs)
                .push_back(
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        }
    }

    // Visibility at points over the surfaces, against rays.
    std::vector<glm::vec4> points;
    std::vector<glm::vec3> normals;
    samplePoints(flattenInstances(scene), samples, points, normals); // world-space triangles
    const reference::RayScene rays(scene);
    const float eps = rays.epsilon();
    std::vector<int> exact(points.size());
    int facing = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        const glm::vec3 p(points[i]);
        const glm::vec3 d = light - p;
        const float dist = glm::length(d);
        const glm::vec3 l = d / std::max(dist, 1e-20f);
        glm::vec3 n = normals[i];
        if (glm::dot(n, l) < 0.0f) n = -n;
        exact[i] = rays.occluded(p + n * eps, l, 0.0f, dist - 2.0f * eps) ? 0 : 1;
        facing += 1;
    }
    const gl::Program probe = gl::Program::build({{GL_COMPUTE_SHADER, "bench/point_shadow_probe.comp"}});
    gl::Buffer in =
        gl::Buffer::create(static_cast<GLsizeiptr>(points.size() * sizeof(glm::vec4)), points.data());
    gl::Buffer out = gl::Buffer::create(static_cast<GLsizeiptr>(points.size() * sizeof(glm::vec4)));
    gl::Buffer faceBuffer =
        gl::Buffer::create(static_cast<GLsizeiptr>(faces.size() * sizeof(glm::mat4)), faces.data());
    cube.setFilter(GL_NEAREST, GL_NEAREST);
    dp.setFilter(GL_NEAREST, GL_NEAREST);
    {
        gl::Pass pass("probe");
        pass.use(probe)
            .set(probe.location("uCount"), static_cast<int>(points.size()))
            .set(probe.location("uCubeDepth"), cubeDepth)
            .set(probe.location("uLightView"), lightView)
            .set(probe.location("uParaboloidDepth"), range)
            .set(probe.location("uLight"), light)
            .set(probe.location("uBias"), 0.01f);
        pass.texture(probe.textureUnit("uCube"), cube).texture(probe.textureUnit("uParaboloid"), dp);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, faceBuffer.id());
        pass.dispatch((static_cast<int>(points.size()) + 63) / 64).barrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    }
    std::vector<glm::vec4> results(points.size());
    glGetNamedBufferSubData(out.id(), 0, static_cast<GLsizeiptr>(results.size() * sizeof(glm::vec4)),
                            results.data());
    int cubeWrong = 0, dpWrong = 0, lit = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        lit += exact[i];
        cubeWrong += (results[i].x > 0.5f ? 1 : 0) != exact[i];
        dpWrong += (results[i].y > 0.5f ? 1 : 0) != exact[i];
    }
    std::printf("scene %s, point light at (%.2f, %.2f, %.2f), GL %s (%s)\n", sceneName.c_str(), light.x,
                light.y, light.z, context->info().backend.c_str(), context->info().renderer.c_str());
    std::printf("%d surface points (%d lit by rays), relative depth bias 1%%, nearest-texel lookups\n\n",
                facing, lit);
    std::printf("| map | texels | render (ms, median of %d) | visibility wrong |\n|---|---|---|---|\n",
                repeats);
    std::printf("| cube, 6 x %d^2 | %d | %.2f | %.2f%% |\n", side, 6 * side * side, medianMs(cubeMs),
                100.0 * cubeWrong / facing);
    std::printf("| dual paraboloid, 2 x %d^2 | %d | %.2f | %.2f%% |\n", paraboloidSide,
                2 * paraboloidSide * paraboloidSide, medianMs(dpMs), 100.0 * dpWrong / facing);
    return 0;
}

} // namespace gis::bench
