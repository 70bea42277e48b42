// Files made by another tool (Blender's glTF exporter, tests/data/corpus/generate.py) render lit and
// finite through the whole pipeline: those without lights get the default rig (frame/DefaultLighting.h)
// and say so in the stats; point_lamps.glb is lit by its own two point lamps and sun.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "GlTestSupport.h"

using namespace gis;
using gis::test::renderScene;

namespace {

struct CorpusFile {
    const char* name;
    const char* source;
    const char* noteContains;
    int rendered; ///< lights rendered
};

// Mean linear radiance over the RGB channels of covered and uncovered pixels alike.
double meanRadiance(const FrameOutput& f) {
    double sum = 0;
    for (size_t i = 0; i + 3 < f.linear.size(); i += 4)
        sum += f.linear[i] + f.linear[i + 1] + f.linear[i + 2];
    return f.linear.empty() ? 0.0 : sum / (3.0 * static_cast<double>(f.linear.size() / 4));
}

} // namespace

TEST(Corpus, BlenderExportsRenderLit) {
    const CorpusFile files[] = {{"suzanne", "default", "no lights", 2},
                                {"textured_box", "default", "no lights", 2},
                                {"millimetres", "default", "no lights", 2},
                                {"point_lamps", "scene", "3 lights", 3}};
    for (const CorpusFile& file : files) {
        for (const char* technique : {"none", "rsm_gather"}) {
            SCOPED_TRACE(std::string(file.name) + " / " + technique);
            const std::string path = std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/" + file.name + ".glb";
            const FrameOutput f = renderScene(path, technique, 64, 64);
            EXPECT_EQ(gis::test::badValues(f), 0u);
            ASSERT_TRUE(f.stats.contains("lighting"));
            const nlohmann::json& lighting = f.stats["lighting"];
            EXPECT_EQ(lighting["source"], file.source);
            EXPECT_NE(lighting["note"].get<std::string>().find(file.noteContains), std::string::npos)
                << lighting.dump();
            EXPECT_EQ(lighting["rendered"].size(), static_cast<size_t>(file.rendered)) << lighting.dump();
            EXPECT_TRUE(lighting["skipped"].empty()) << "no unexplained light: " << lighting.dump();
            EXPECT_FALSE(lighting.contains("warning")) << lighting.dump();
            // Black before the default light (and before point and sun lamps rendered): the direct
            // light alone must now show the model.
            EXPECT_GT(meanRadiance(f), 1e-3) << "the frame is black";
        }
    }
}

// Blender exports its lamps' watts as candela and its sun as lux, about ten stops above the built-in
// scenes: at EV 0 these files were a white frame. Metered (frame/Exposure.h), the model is neither
// black nor white; with metering off they are white again, which is what the meter fixes.
TEST(Corpus, BlenderLampsAreExposedToShowTheModel) {
    for (const char* name : {"point_lamps", "colonnade"}) {
        SCOPED_TRACE(name);
        const std::string path = std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/" + name + ".glb";
        // Share of covered pixels whose tone-mapped colour is clipped white, and their mean (0..255).
        auto look = [](const FrameOutput& f) {
            size_t covered = 0, white = 0;
            double sum = 0;
            for (size_t i = 0; i + 3 < f.rgba8.size(); i += 4) {
                if (f.linear[i] + f.linear[i + 1] + f.linear[i + 2] <= 0.0f) continue; // background
                ++covered;
                const int lo = std::min({f.rgba8[i], f.rgba8[i + 1], f.rgba8[i + 2]});
                if (lo >= 250) ++white;
                sum += (f.rgba8[i] + f.rgba8[i + 1] + f.rgba8[i + 2]) / 3.0;
            }
            return std::pair{covered ? static_cast<double>(white) / covered : 1.0,
                             covered ? sum / covered : 0.0};
        };
        const FrameOutput metered = renderScene(path, "multires_gather", 64, 64);
        ASSERT_TRUE(metered.stats["lighting"].contains("exposure"));
        const nlohmann::json& exposure = metered.stats["lighting"]["exposure"];
        EXPECT_EQ(exposure["source"], "metered") << exposure.dump();
        const auto [white, mean] = look(metered);
        EXPECT_LT(white, 0.05) << "clipped white: " << exposure.dump();
        EXPECT_GT(mean, 30.0) << "too dark: " << exposure.dump();
        EXPECT_LT(mean, 200.0) << "too bright: " << exposure.dump();
        const FrameOutput absolute = renderScene(path, "multires_gather", 64, 64, {{"metering", "off"}});
        EXPECT_EQ(absolute.stats["lighting"]["exposure"]["source"], "off");
        const auto [whiteBefore, meanBefore] = look(absolute);
        std::printf("%s: %s: %.0f%% clipped, mean %.0f / 255; metering off: %.0f%% clipped, mean %.0f\n",
                    name, exposure["note"].get<std::string>().c_str(), 100.0 * white, mean,
                    100.0 * whiteBefore, meanBefore);
        EXPECT_GT(whiteBefore, 0.5) << "without the meter the file's lamps clip the frame white";
    }
}

// The compressed copies (tests/data/corpus/compress.sh: glTF Transform's Draco, gltfpack's meshopt and
// quantization) render as their originals, up to the encoders' quantization.
TEST(Corpus, CompressedCopiesRenderAsTheirOriginals) {
    for (const char* name : {"suzanne", "textured_box"}) {
        const std::string dir = std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/";
        const FrameOutput original = renderScene(dir + name + ".glb", "rsm_gather", 64, 64);
        // _quantized: gltfpack's default output, whose texture coordinates are dequantized by
        // KHR_texture_transform (the box only).
        for (const char* kind : {"_draco", "_meshopt", "_quantized"}) {
            if (std::string(kind) == "_quantized" && std::string(name) != "textured_box") continue;
            SCOPED_TRACE(std::string(name) + kind);
            const FrameOutput compressed = renderScene(dir + name + kind + ".glb", "rsm_gather", 64, 64);
            ASSERT_EQ(compressed.linear.size(), original.linear.size());
            double squaredError = 0, squaredValue = 0;
            for (size_t i = 0; i < original.linear.size(); ++i) {
                if (i % 4 == 3) continue;
                const double d = compressed.linear[i] - original.linear[i];
                squaredError += d * d;
                squaredValue += double(original.linear[i]) * original.linear[i];
            }
            const double relativeRmse = std::sqrt(squaredError / std::max(squaredValue, 1e-30));
            std::printf("[corpus] %s%s against %s.glb: relative RMSE %.4f\n", name, kind, name, relativeRmse);
            EXPECT_EQ(gis::test::badValues(compressed), 0u);
            EXPECT_LT(relativeRmse, 0.05);
        }
    }
}

// Blender's linked duplicates (colonnade.glb: one column mesh placed by twelve nodes) load as one
// instanced mesh and render as their flattened copies do, with every technique family.
TEST(Corpus, LinkedDuplicatesStayInstancedAndRenderAsFlattened) {
    const Scene scene = loadScene(std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/colonnade.glb");
    const auto column = std::find_if(scene.meshes.begin(), scene.meshes.end(),
                                     [](const Mesh& m) { return m.instances.size() == 12; });
    ASSERT_NE(column, scene.meshes.end()) << "the column is not one mesh with twelve instances";
    EXPECT_EQ(scene.instanceCount(), 12u);
    EXPECT_LT(scene.storedTriangleCount() * 5, scene.triangleCount());
    const Scene flat = flattenInstances(scene);
    for (const char* technique : {"none", "rsm_gather", "hier_isr"}) {
        SCOPED_TRACE(technique);
        const FrameOutput a = renderScene(scene, technique, 96, 72, {{"exposure", -10}});
        const FrameOutput b = renderScene(flat, technique, 96, 72, {{"exposure", -10}});
        EXPECT_EQ(gis::test::badValues(a), 0u);
        EXPECT_GT(meanRadiance(a), 1e-3);
        EXPECT_EQ(gis::test::counter(a, "instances"), 12.0);
        // The floor, and the twelve columns as one instanced command.
        EXPECT_EQ(gis::test::counter(a, "draw_runs_gbuffer"), 2.0);
        const double error = gis::test::relativeRmseOf(a, b);
        std::printf("[corpus] colonnade %s instanced against flattened: relative RMSE %.5f\n", technique,
                    error);
        EXPECT_LT(error, 2e-3);
    }
}
