// Frame pipeline on a real GL context (llvmpipe in CI), once per backend.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <thread>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "GlTestSupport.h"
#include "core/Error.h"
#include "gl/Background.h"
#include "gl/Platform.h"
#include "gl/ShaderShared.h"
#include "scene/SceneLoader.h"
#include <unistd.h>

using namespace gis;
using gis::test::renderScene;

namespace {
constexpr int kGoldenSize = 128;

float luminance(const std::vector<float>& img, int w, int x, int y, int c) {
    return img[(static_cast<size_t>(y) * w + x) * 4 + c];
}

// Mean of channel c over a (2r+1)^2 window.
float windowMean(const FrameOutput& f, glm::ivec2 p, int c, int r = 2) {
    double sum = 0;
    int n = 0;
    for (int y = p.y - r; y <= p.y + r; ++y)
        for (int x = p.x - r; x <= p.x + r; ++x) {
            if (x < 0 || y < 0 || x >= f.width || y >= f.height) continue;
            sum += luminance(f.linear, f.width, x, y, c);
            ++n;
        }
    return n ? static_cast<float>(sum / n) : 0.0f;
}
} // namespace

TEST(Context, CreatesOpenGL45Core) {
    auto& ctx = test::sharedContext();
    EXPECT_NE(ctx.info().version.find("4.5"), std::string::npos) << ctx.info().version;
    EXPECT_FALSE(ctx.info().renderer.empty());
    std::printf("backend %s, renderer %s, %s\n", ctx.info().backend.c_str(), ctx.info().renderer.c_str(),
                ctx.info().version.c_str());
}

// Objects made on a helper thread in a shared context (gl/Background.h) serve the asking context:
// the size asked, data written and read back there, and the asking thread's context stays current.
// What is never taken is deleted by its owner; a making that fails says why.
TEST(Context, ObjectsMadeInTheBackgroundServeTheAskingContext) {
    auto& ctx = test::sharedContext();
    ASSERT_EQ(gl::Context::current(), &ctx);
    constexpr GLsizeiptr kBytes = 3 << 20;
    auto pending = gl::Background<gl::Buffer>::start([] { return gl::Buffer::create(kBytes); });
    EXPECT_TRUE(pending.started());
    for (int i = 0; i < 5000 && !pending.ready(); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    EXPECT_TRUE(pending.ready());
    EXPECT_EQ(gl::Context::current(), &ctx);
    std::optional<gl::Buffer> made = pending.take();
    EXPECT_FALSE(pending.started());
    EXPECT_TRUE(pending.error().empty()) << pending.error();
    ASSERT_TRUE(made && *made);
    gl::Buffer buffer = std::move(*made);
    EXPECT_EQ(buffer.size(), kBytes);
    GLint64 size = 0;
    glGetNamedBufferParameteri64v(buffer.id(), GL_BUFFER_SIZE, &size);
    EXPECT_EQ(size, kBytes);
    std::vector<std::uint32_t> written(1024);
    for (size_t i = 0; i < written.size(); ++i) written[i] = static_cast<std::uint32_t>(i * 2654435761u);
    const GLintptr offset = kBytes - static_cast<GLintptr>(written.size() * 4);
    buffer.upload(offset, static_cast<GLsizeiptr>(written.size() * 4), written.data());
    std::vector<std::uint32_t> read(written.size());
    glGetNamedBufferSubData(buffer.id(), offset, static_cast<GLsizeiptr>(read.size() * 4), read.data());
    EXPECT_EQ(read, written);

    // A texture array, sampled here after the helper made it.
    auto texture = gl::Background<gl::Texture>::start([] {
                       return gl::Texture::create2DArray(GL_RGBA32F, 64, 64, 3);
                   }).take();
    ASSERT_TRUE(texture && *texture);
    const float texel[4] = {0.25f, 0.5f, 0.75f, 1.0f};
    glTextureSubImage3D(texture->id(), 0, 5, 7, 2, 1, 1, 1, GL_RGBA, GL_FLOAT, texel);
    float back[4] = {};
    glGetTextureSubImage(texture->id(), 0, 5, 7, 2, 1, 1, 1, GL_RGBA, GL_FLOAT, sizeof back, back);
    EXPECT_EQ(std::vector<float>(back, back + 4), std::vector<float>(texel, texel + 4));

    // Dropped before it is taken (a renderer that goes while its storage is made), and replaced.
    {
        auto dropped = gl::Background<gl::Buffer>::start([] { return gl::Buffer::create(kBytes); });
    }
    auto replaced = gl::Background<gl::Buffer>::start([] { return gl::Buffer::create(kBytes); });
    replaced = gl::Background<gl::Buffer>::start([] { return gl::Buffer::create(kBytes / 2); });
    EXPECT_EQ(replaced.take()->size(), kBytes / 2);

    // A making that throws, or leaves a GL error, gives nothing and says why.
    auto thrown = gl::Background<gl::Buffer>::start([]() -> gl::Buffer { throw Error("no storage today"); });
    EXPECT_FALSE(thrown.take());
    EXPECT_EQ(thrown.error(), "no storage today");
    auto refused = gl::Background<gl::Texture>::start([] {
        gl::Texture t = gl::Texture::create2DArray(GL_RGBA32F, 64, 64, 1);
        glTextureParameteri(t.id(), GL_TEXTURE_MIN_FILTER, GL_RGBA); // not a filter
        return t;
    });
    EXPECT_FALSE(refused.take());
    EXPECT_NE(refused.error().find("GL_INVALID_ENUM"), std::string::npos) << refused.error();

    // The maker: made here without a stop; in the background with one, a stop leaving it going on
    // for the next call of the same key.
    gl::BackgroundMaker<int, gl::Buffer> maker("test buffers");
    const auto small = [] { return gl::Buffer::create(1024); };
    const auto large = [] { return gl::Buffer::create(kBytes); };
    const auto stop = [] { return true; };
    const auto goOn = [] { return false; };
    EXPECT_EQ(maker.make(1, 1024, 1, {}, small)->size(), 1024);
    EXPECT_EQ(maker.make(1, 1024, 2048, stop, small)->size(), 1024) << "under the background's size";
    EXPECT_EQ(maker.starts(), 0);
    EXPECT_FALSE(maker.make(2, kBytes, 1, stop, large));
    EXPECT_EQ(maker.starts(), 1);
    EXPECT_EQ(maker.make(2, kBytes, 1, goOn, large)->size(), kBytes);
    EXPECT_EQ(maker.starts(), 1) << "the making the stop left going on";
    EXPECT_EQ(maker.failures(), 0);

    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    EXPECT_EQ(gl::Context::current(), &ctx);
}

TEST(Context, SharedStructLayoutMatchesGlsl) {
    test::sharedContext();
    gl::Program p = gl::Program::build(
        {{GL_VERTEX_SHADER, "render/fullscreen.vert"}, {GL_FRAGMENT_SHADER, "render/direct.frag"}});
    struct Member {
        const char* name;
        size_t offset;
    };
    const Member members[] = {
        {"gFrame.viewProj", offsetof(shader::FrameUniforms, viewProj)},
        {"gFrame.cameraPos", offsetof(shader::FrameUniforms, cameraPos)},
        {"gFrame.viewport", offsetof(shader::FrameUniforms, viewport)},
        {"gFrame.rsmInfo", offsetof(shader::FrameUniforms, rsmInfo)},
        {"gFrame.toneInfo", offsetof(shader::FrameUniforms, toneInfo)},
    };
    for (const auto& m : members) {
        GLuint index = GL_INVALID_INDEX;
        const char* names[] = {m.name};
        glGetUniformIndices(p.id(), 1, names, &index);
        if (index == GL_INVALID_INDEX) continue; // optimised away in this program
        GLint offset = -1;
        glGetActiveUniformsiv(p.id(), 1, &index, GL_UNIFORM_OFFSET, &offset);
        EXPECT_EQ(static_cast<size_t>(offset), m.offset) << m.name;
    }
    GLuint block = glGetUniformBlockIndex(p.id(), "FrameBlock");
    ASSERT_NE(block, GL_INVALID_INDEX);
    GLint size = 0;
    glGetActiveUniformBlockiv(p.id(), block, GL_UNIFORM_BLOCK_DATA_SIZE, &size);
    EXPECT_EQ(static_cast<size_t>(size), sizeof(shader::FrameUniforms));
    // The light block: its members' offsets and its size as the C++ side lays them out.
    const Member lightMembers[] = {
        {"gLights.lights[0].position", offsetof(shader::LightUniforms, lights)},
        {"gLights.lights[0].info",
         offsetof(shader::LightUniforms, lights) + offsetof(shader::GpuLight, info)},
        {"gLights.views[0].viewProj", offsetof(shader::LightUniforms, views)},
        {"gLights.views[0].info", offsetof(shader::LightUniforms, views) + offsetof(shader::LightView, info)},
        {"gLights.counts", offsetof(shader::LightUniforms, counts)},
    };
    int found = 0;
    for (const auto& m : lightMembers) {
        GLuint index = GL_INVALID_INDEX;
        const char* names[] = {m.name};
        glGetUniformIndices(p.id(), 1, names, &index);
        if (index == GL_INVALID_INDEX) continue;
        ++found;
        GLint offset = -1;
        glGetActiveUniformsiv(p.id(), 1, &index, GL_UNIFORM_OFFSET, &offset);
        EXPECT_EQ(static_cast<size_t>(offset), m.offset) << m.name;
    }
    EXPECT_GT(found, 0) << "the direct pass reads the light block";
    GLuint lights = glGetUniformBlockIndex(p.id(), "LightBlock");
    ASSERT_NE(lights, GL_INVALID_INDEX);
    glGetActiveUniformBlockiv(p.id(), lights, GL_UNIFORM_BLOCK_DATA_SIZE, &size);
    EXPECT_EQ(static_cast<size_t>(size), sizeof(shader::LightUniforms));
}

TEST(Shaders, CompileErrorsNameFileAndLine) {
    test::sharedContext();
    auto dir = std::filesystem::temp_directory_path() / ("gis_shader_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir / "x");
    {
        std::FILE* f = std::fopen((dir / "x/main.frag").c_str(), "w");
        std::fputs(
            "#version 450 core\n#include \"x/inc.glsl\"\nout vec4 c;\nvoid main() { c = vec4(f()); }\n", f);
        std::fclose(f);
        f = std::fopen((dir / "x/inc.glsl").c_str(), "w");
        std::fputs("float f() {\n  return 1.0;\n  this is not glsl;\n}\n", f);
        std::fclose(f);
    }
    ::setenv("GI_SHADER_DIR", dir.c_str(), 1);
    try {
        gl::Program::build({{GL_FRAGMENT_SHADER, "x/main.frag"}});
        ADD_FAILURE() << "expected a compile error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("shaders/x/inc.glsl:3"), std::string::npos) << e.what();
    }
    ::unsetenv("GI_SHADER_DIR");
    std::filesystem::remove_all(dir);
}

TEST(Pipeline, DirectOnlyMatchesGolden) {
    FrameOutput f = renderScene("builtin:cornell", "none", kGoldenSize, kGoldenSize);
    const std::string golden = std::string(GIS_SOURCE_DIR) + "/tests/data/golden/cornell_none_128.png";
    if (const char* u = std::getenv("GIS_UPDATE_GOLDENS"); u && std::string(u) == "1") {
        ASSERT_TRUE(test::writePng(golden, f.width, f.height, f.rgba8));
        GTEST_SKIP() << "golden updated: " << golden;
    }
    int w = 0, h = 0;
    std::vector<std::uint8_t> expected;
    ASSERT_TRUE(test::readPng(golden, w, h, expected))
        << "missing golden " << golden << " (regenerate with GIS_UPDATE_GOLDENS=1)";
    ASSERT_EQ(w, f.width);
    ASSERT_EQ(h, f.height);
    // Tolerance: llvmpipe versions and EGL/OSMesa may differ in the last bit of rasterisation and
    // filtering. A pixel "fails" beyond 8/255 in any channel; at most 0.5% may fail (silhouette
    // pixels), and the mean difference must stay under 1/255.
    int failing = 0;
    double sumDiff = 0;
    for (int i = 0; i < w * h; ++i)
        for (int c = 0; c < 3; ++c) {
            int d = std::abs(int(f.rgba8[i * 4 + c]) - int(expected[i * 3 + c]));
            sumDiff += d;
            if (d > 8) {
                ++failing;
                break;
            }
        }
    double mean = sumDiff / (w * h * 3.0);
    if (failing > w * h / 200 || mean > 1.0) {
        test::writePng(::testing::TempDir() + "cornell_none_actual.png", f.width, f.height, f.rgba8);
        FAIL() << failing << " pixels differ by more than 8/255, mean difference " << mean
               << " (actual written to " << ::testing::TempDir() << "cornell_none_actual.png)";
    }
}

TEST(Pipeline, RsmGatherAddsRedBleedingNearTheRedWall) {
    auto scene = loadScene("builtin:cornell");
    const int s = 128;
    FrameOutput direct = renderScene("builtin:cornell", "none", s, s);
    FrameOutput gi = renderScene("builtin:cornell", "rsm_gather", s, s, {{"vpl_grid", 16}});
    // A floor point next to the red wall (x = -1), in front of the tall box.
    glm::ivec2 p = test::projectToPixel(scene, {-0.85f, 0.0f, 0.55f}, s, s);
    const float redDirect = windowMean(direct, p, 0), redGi = windowMean(gi, p, 0);
    const float greenDirect = windowMean(direct, p, 1), greenGi = windowMean(gi, p, 1);
    EXPECT_GT(redGi, redDirect * 1.05f) << "indirect light should add red at pixel " << p.x << "," << p.y;
    EXPECT_GT(redGi - redDirect, greenGi - greenDirect)
        << "the added light should be redder than it is green";
    // And the mirror image next to the green wall gets greener.
    glm::ivec2 q = test::projectToPixel(scene, {0.85f, 0.0f, 0.55f}, s, s);
    EXPECT_GT(windowMean(gi, q, 1) - windowMean(direct, q, 1),
              windowMean(gi, q, 0) - windowMean(direct, q, 0));
}

TEST(Pipeline, NoNanInfOrNegativeRadiance) {
    for (const char* technique : {"none", "rsm_gather"}) {
        for (glm::ivec2 size : {glm::ivec2(128, 128), glm::ivec2(97, 61)}) {
            nlohmann::json params = nlohmann::json::object();
            if (std::string(technique) == "rsm_gather") params["min_distance"] = 0.0; // no clamp at all
            FrameOutput f = renderScene("builtin:cornell", technique, size.x, size.y, params);
            size_t bad = 0;
            for (float v : f.linear)
                if (!std::isfinite(v) || v < 0.0f) ++bad;
            EXPECT_EQ(bad, 0u) << technique << " at " << size.x << "x" << size.y;
        }
    }
}

TEST(Pipeline, RenderingTwiceGivesIdenticalBytes) {
    FrameOutput a = renderScene("builtin:cornell", "rsm_gather", 96, 96);
    FrameOutput b = renderScene("builtin:cornell", "rsm_gather", 96, 96);
    EXPECT_TRUE(a.rgba8 == b.rgba8);
    EXPECT_TRUE(a.linear == b.linear);
}

TEST(Pipeline, StatsHaveTheDocumentedShape) {
    FrameOutput f = renderScene("builtin:cornell", "rsm_gather", 64, 48, {{"vpl_grid", 8}});
    const auto& s = f.stats;
    EXPECT_EQ(s["technique"], "rsm_gather");
    EXPECT_EQ(s["size"], nlohmann::json({64, 48}));
    EXPECT_GT(s["frame_ms"].get<double>(), 0.0);
    ASSERT_TRUE(s["passes"].is_array());
    std::vector<std::string> names;
    for (const auto& p : s["passes"]) {
        names.push_back(p["name"]);
        EXPECT_GE(p["gpu_ms"].get<double>(), 0.0);
        EXPECT_GE(p["cpu_ms"].get<double>(), 0.0);
    }
    EXPECT_NE(std::find(names.begin(), names.end(), "vpl_gather"), names.end());
    EXPECT_EQ(s["counts"]["vpl_count"], 64);
    EXPECT_EQ(s["params"]["vpl_grid"], 8);
}

TEST(Pipeline, TotalVplFluxEqualsRsmFlux) {
    // Grid VPLs carry their cell's summed flux: coarse and fine grids light a diffuse receiver far
    // from every VPL almost equally (the kernel varies little across a cell at that distance).
    FrameOutput coarse = renderScene("builtin:cornell-empty", "rsm_gather", 64, 64, {{"vpl_grid", 4}});
    FrameOutput fine = renderScene("builtin:cornell-empty", "rsm_gather", 64, 64, {{"vpl_grid", 64}});
    double sc = 0, sf = 0;
    for (size_t i = 0; i < coarse.linear.size(); i += 4) {
        sc += coarse.linear[i] + coarse.linear[i + 1] + coarse.linear[i + 2];
        sf += fine.linear[i] + fine.linear[i + 1] + fine.linear[i + 2];
    }
    EXPECT_NEAR(sc / sf, 1.0, 0.15);
}

// Consecutive runs that need the same state go out as one multi-draw (SceneGpu::draw): six quads of
// materials A A A B A A take three G-buffer draw calls, and what each draws is unchanged (the frame
// hashes of every built-in scene hold, FrameHashGlTest).
TEST(Pipeline, RunsOfOneStateAreOneDrawCall) {
    Scene scene = loadScene("builtin:cornell-empty");
    ASSERT_GE(scene.materials.size(), 2u);
    scene.meshes.clear();
    const int materialOf[6] = {0, 0, 0, 1, 0, 0};
    for (int i = 0; i < 6; ++i) {
        Mesh quad{.name = "quad" + std::to_string(i), .material = materialOf[i]};
        const float x = -0.75f + 0.3f * static_cast<float>(i);
        for (const glm::vec2 c :
             {glm::vec2(0, 0), glm::vec2(0.2f, 0), glm::vec2(0.2f, 0.2f), glm::vec2(0, 0.2f)}) {
            quad.positions.emplace_back(x + c.x, 0.9f + c.y, 0.5f);
            quad.normals.emplace_back(0.0f, 0.0f, 1.0f);
        }
        quad.indices = {0, 1, 2, 0, 2, 3};
        scene.meshes.push_back(quad);
    }
    scene.updateBounds();
    finalizeScene(scene, "test:quads");
    const FrameOutput f = renderScene(scene, "none", 64, 48);
    EXPECT_EQ(test::counter(f, "triangles_gbuffer"), 12.0);
    EXPECT_EQ(test::counter(f, "draw_runs_gbuffer"), 6.0);
    EXPECT_EQ(test::counter(f, "draw_calls_gbuffer"), 3.0);
    EXPECT_EQ(test::badValues(f), 0u);
}

// A mesh drawn through instance matrices (Mesh::instances) gives the image of its flattened copies,
// in every pass (shadow maps, RSMs, G-buffer, VPL gathers), and the stats say what was instanced.
TEST(Pipeline, InstancedMeshesDrawLikeTheirFlattenedCopies) {
    Scene instanced = loadScene("builtin:cornell");
    auto tall = std::find_if(instanced.meshes.begin(), instanced.meshes.end(),
                             [](const Mesh& m) { return m.name == "tall_box"; });
    ASSERT_NE(tall, instanced.meshes.end());
    // The box's own space is its world placement undone; a second, smaller copy stands by the wall.
    const glm::mat4 original = glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(-0.35f, 0.6f, -0.35f)),
                                           glm::radians(17.0f), glm::vec3(0, 1, 0));
    const glm::mat4 copy =
        glm::scale(glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(0.55f, 0.3f, -0.6f)),
                               glm::radians(-40.0f), glm::vec3(0, 1, 0)),
                   glm::vec3(0.5f));
    // A third copy far behind the camera, outside every view: culled on its own.
    const glm::mat4 behind = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, 40.0f)) * original;
    transformMesh(*tall, glm::inverse(original));
    tall->instances = {original, copy, behind};
    const std::size_t boxTriangles = tall->indices.size() / 3;
    instanced.updateBounds();
    const Scene flat = flattenInstances(instanced);
    ASSERT_EQ(flat.meshes.size(), instanced.meshes.size());

    for (const char* technique : {"none", "rsm_gather", "multires_gather"}) {
        SCOPED_TRACE(technique);
        // VPL shadow maps draw the scene instanced per VPL face: the placement must survive that.
        const nlohmann::json params = std::string(technique) == "rsm_gather"
                                          ? nlohmann::json{{"vpl_shadows", true}}
                                          : nlohmann::json::object();
        const FrameOutput a = renderScene(instanced, technique, 96, 72, params);
        const FrameOutput b = renderScene(flat, technique, 96, 72, params);
        EXPECT_EQ(test::badValues(a), 0u);
        EXPECT_EQ(test::counter(a, "instances"), 3.0);
        EXPECT_EQ(test::counter(a, "triangles"), test::counter(b, "triangles"));
        EXPECT_LT(test::counter(a, "triangles_stored"), test::counter(a, "triangles"));
        // The far copy is culled on its own (the flattened copies, one mesh, have one box that
        // holds the far one too: nothing of it is culled); the two in view go out as one command.
        EXPECT_EQ(test::counter(a, "triangles_gbuffer_culled"), static_cast<double>(boxTriangles));
        EXPECT_EQ(test::counter(b, "triangles_gbuffer_culled"), 0.0);
        EXPECT_EQ(test::counter(a, "draw_runs_gbuffer"), test::counter(b, "draw_runs_gbuffer"));
        // Float rounding of the placed positions only (the vertex stage against the CPU).
        EXPECT_LT(test::relativeRmseOf(a, b), 2e-3);
    }
    // The copy is really drawn: without it the image differs.
    Scene single = instanced;
    for (Mesh& m : single.meshes)
        if (m.name == "tall_box") m.instances.erase(m.instances.begin() + 1);
    EXPECT_GT(test::relativeRmseOf(renderScene(single, "none", 96, 72), renderScene(flat, "none", 96, 72)),
              0.02);
}
