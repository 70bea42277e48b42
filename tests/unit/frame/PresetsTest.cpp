#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "core/Error.h"
#include "gi/Catalog.h"
#include "frame/FrameState.h"
#include "frame/Presets.h"
#include "scene/SceneLoader.h"

namespace {

std::string writeFile(const std::string& name, const std::string& text) {
    // CTest runs these tests in parallel processes: a shared file name would race.
    auto path = std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "_" + name);
    std::ofstream(path) << text;
    return path.string();
}

const char* kPresets = R"({"techniques": {"rsm_gather": {"interactive": {"vpl_grid": 8}, "balanced": {},
    "final": {"vpl_grid": 32, "kernel": "disk"}}, "broken": {"interactive": {"vpl_grid": 100000}}}})";

std::string what(const std::function<void()>& f) {
    try {
        f();
    } catch (const gis::InputError& e) {
        return e.what();
    }
    return {};
}

TEST(Presets, LoadsAndLooksUp) {
    auto presets = gis::loadPresets(writeFile("gis_presets_ok.json", kPresets));
    EXPECT_EQ(gis::presetParams(presets, "rsm_gather", "interactive"), nlohmann::json({{"vpl_grid", 8}}));
    EXPECT_TRUE(gis::presetParams(presets, "rsm_gather", "balanced").empty());
    EXPECT_EQ(gis::knownPresets().size(), 3u);
}

TEST(Presets, ErrorsNameThePreset) {
    auto presets = gis::loadPresets(writeFile("gis_presets_ok.json", kPresets));
    std::string e = what([&] { gis::presetParams(presets, "rsm_gather", "fastest"); });
    EXPECT_NE(e.find("preset 'fastest'"), std::string::npos) << e;
    EXPECT_NE(e.find("interactive, balanced, final"), std::string::npos) << e;
    e = what([&] { gis::presetParams(presets, "isr", "final"); });
    EXPECT_NE(e.find("no preset for technique 'isr'"), std::string::npos) << e;
    EXPECT_NE(what([] {
                  gis::loadPresets(writeFile("gis_presets_bad.json", "{\"techniques\": 3}"));
              }).find("techniques"),
              std::string::npos);
    EXPECT_NE(what([] { gis::loadPresets("/nonexistent/presets.json"); }).find("/nonexistent/presets.json"),
              std::string::npos);
}

TEST(Presets, AppliesThroughTheParameterValidation) {
    auto presets = gis::loadPresets(writeFile("gis_presets_ok.json", kPresets));
    gis::Scene scene = gis::loadScene("builtin:cornell");
    gis::FrameState state = gis::makeFrameState(scene, "rsm_gather");
    gis::applyPreset(state, presets, "final");
    EXPECT_EQ(state.techniqueParams.getInt("vpl_grid"), 32);
    EXPECT_EQ(state.techniqueParams.getEnum("kernel"), "disk");
    // A value out of range is rejected, names the preset, and changes nothing.
    presets["techniques"]["rsm_gather"]["interactive"] = {{"vpl_grid", 100000}};
    std::string e = what([&] { gis::applyPreset(state, presets, "interactive"); });
    EXPECT_NE(e.find("preset 'interactive'"), std::string::npos) << e;
    EXPECT_EQ(state.techniqueParams.getInt("vpl_grid"), 32);
}

TEST(Presets, CommittedFileAppliesToEveryTechniqueItNames) {
    const std::string path = std::string(GIS_SOURCE_DIR) + "/presets/presets.json";
    ASSERT_TRUE(std::filesystem::exists(path)) << path << " is committed with the accuracy report";
    auto presets = gis::loadPresets(path);
    gis::Scene scene = gis::loadScene("builtin:cornell");
    for (const auto& [technique, byName] : presets["techniques"].items()) {
        bool registered = false;
        for (const auto& info : gis::techniqueCatalog()) registered |= info.name == technique;
        if (!registered) continue;
        for (const auto& name : gis::knownPresets()) {
            gis::FrameState state = gis::makeFrameState(scene, technique);
            EXPECT_NO_THROW(gis::applyPreset(state, presets, name)) << technique << " " << name;
        }
    }
}

} // namespace
