// Every technique on every built-in scene renders the bytes recorded in tests/data/frame_hashes.json:
// the guard that a restructuring of the frame pipeline (issue #18) changes no pixel. Each backend
// keeps its own table, tied to the GL renderer string it was recorded with (llvmpipe's code depends on
// the CPU and the LLVM version); on another renderer the test is skipped with a message, never
// silently passed. Regenerate with GIS_UPDATE_FRAME_HASHES=1 (once per backend: GI_GL=egl, osmesa).
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "GlTestSupport.h"
#include "gi/Technique.h"
#include "gl/Pass.h"

namespace gis::test {
namespace {

constexpr int kSize = 32; // small: 8 techniques x 6 scenes per backend in a few seconds

std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t h = 1469598103934665603ull) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

std::string hex(std::uint64_t v) {
    static const char* digits = "0123456789abcdef";
    std::string out(16, '0');
    for (int i = 15; i >= 0; --i, v >>= 4) out[static_cast<std::size_t>(i)] = digits[v & 15];
    return out;
}

const std::string kTable = std::string(GIS_SOURCE_DIR) + "/tests/data/frame_hashes.json";

TEST(FrameHashes, EveryTechniqueAndBuiltinSceneRendersTheRecordedBytes) {
    const gl::ContextInfo& gl = sharedContext().info();
    nlohmann::json table = nlohmann::json::object();
    if (std::ifstream in(kTable); in) table = nlohmann::json::parse(in, nullptr, false);
    if (!table.is_object()) table = nlohmann::json::object();

    nlohmann::json hashes = nlohmann::json::object();
    const long glErrorsBefore = gl::passCheckErrors();
    for (const auto& scene : builtinSceneNames())
        for (const auto& entry : techniqueRegistry()) {
            const FrameOutput out = renderScene("builtin:" + scene, entry.info.name, kSize, kSize);
            std::uint64_t h = fnv1a(out.rgba8.data(), out.rgba8.size());
            h = fnv1a(out.linear.data(), out.linear.size() * sizeof(float), h);
            hashes[scene + "/" + entry.info.name] = hex(h);
        }

    if (gl::passChecksEnabled()) {
        EXPECT_EQ(gl::passCheckErrors() - glErrorsBefore, 0)
            << "GL errors in the passes (the log names them)";
    }

    if (std::getenv("GIS_UPDATE_FRAME_HASHES")) {
        table[gl.backend] = {{"renderer", gl.renderer}, {"size", kSize}, {"hashes", hashes}};
        std::ofstream(kTable) << table.dump(2) << "\n";
        GTEST_SKIP() << "recorded " << hashes.size() << " frame hashes for " << gl.backend << " in "
                     << kTable;
    }
    const nlohmann::json& recorded = table.value(gl.backend, nlohmann::json::object());
    if (recorded.value("renderer", "") != gl.renderer)
        GTEST_SKIP() << kTable << " holds no hashes for " << gl.backend << " on '" << gl.renderer
                     << "' (recorded on '" << recorded.value("renderer", "nothing")
                     << "'): record them with GIS_UPDATE_FRAME_HASHES=1 before changing the pipeline";
    int differing = 0;
    for (const auto& [key, value] : hashes.items()) {
        const std::string expected = recorded["hashes"].value(key, "");
        if (expected != value.get<std::string>()) {
            ++differing;
            ADD_FAILURE() << key << ": frame hash " << value.get<std::string>() << ", recorded "
                          << (expected.empty() ? "none" : expected);
        }
    }
    EXPECT_EQ(differing, 0) << "of " << hashes.size() << " frames";
    EXPECT_EQ(recorded["hashes"].size(), hashes.size()) << "techniques or scenes were added or removed";
}

} // namespace
} // namespace gis::test
