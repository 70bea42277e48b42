// Files made by another tool (Blender's glTF exporter, tests/data/corpus/generate.py) render lit and
// finite through the whole pipeline: none of them has a light the renderer shows, so each gets the
// default key light (frame/DefaultLighting.h) and says so in the stats.
#include <string>

#include <gtest/gtest.h>

#include "GlTestSupport.h"

using namespace gis;
using gis::test::renderScene;

namespace {

struct CorpusFile {
    const char* name;
    const char* noteContains;
};

// Mean linear radiance over the RGB channels of covered and uncovered pixels alike.
double meanRadiance(const FrameOutput& f) {
    double sum = 0;
    for (size_t i = 0; i + 3 < f.linear.size(); i += 4)
        sum += f.linear[i] + f.linear[i + 1] + f.linear[i + 2];
    return f.linear.empty() ? 0.0 : sum / (3.0 * static_cast<double>(f.linear.size() / 4));
}

} // namespace

TEST(Corpus, BlenderExportsRenderLitWithTheDefaultKeyLight) {
    const CorpusFile files[] = {{"suzanne", "no lights"},
                                {"textured_box", "no lights"},
                                {"millimetres", "no lights"},
                                {"point_lamps", "2 point, 1 directional"}};
    for (const CorpusFile& file : files) {
        for (const char* technique : {"none", "rsm_gather"}) {
            SCOPED_TRACE(std::string(file.name) + " / " + technique);
            const std::string path = std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/" + file.name + ".glb";
            const FrameOutput f = renderScene(path, technique, 64, 64);
            EXPECT_EQ(gis::test::badValues(f), 0u);
            ASSERT_TRUE(f.stats.contains("lighting"));
            EXPECT_EQ(f.stats["lighting"]["source"], "default");
            EXPECT_NE(f.stats["lighting"]["note"].get<std::string>().find(file.noteContains),
                      std::string::npos)
                << f.stats["lighting"].dump();
            // Black before the default light: the direct light alone must now show the model.
            EXPECT_GT(meanRadiance(f), 1e-3) << "the frame is black";
        }
    }
}
