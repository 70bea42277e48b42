// Shared fixture for tests that need a GL context: one context per test process, backend from GI_GL
// (CTest runs the same binary once per backend).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gl/Platform.h"
#include "render/FrameRenderer.h"
#include "scene/SceneLoader.h"

namespace gis::test {

gl::Context& sharedContext();

/// The renderer renderScene() uses (tests inspect its technique after a frame).
FrameRenderer& sharedRenderer();

/// Renders `scene` with `technique` and optional parameter overrides at w x h, with the linear frame;
/// `edit` may change the frame state (lights, camera) last.
FrameOutput renderScene(const std::string& scene, const std::string& technique, int w, int h,
                        const nlohmann::json& params = nlohmann::json::object(),
                        const std::function<void(FrameState&)>& edit = {});
/// The same for a scene the test built (uploaded to the shared renderer for this frame); with
/// `wantDirect` the frame's direct pass too (FrameOutput::linearDirect).
FrameOutput renderScene(const Scene& scene, const std::string& technique, int w, int h,
                        const nlohmann::json& params = nlohmann::json::object(),
                        const std::function<void(FrameState&)>& edit = {}, bool wantDirect = false);

/// Each side's indirect light (its total minus its own direct term), GL frames (RGBA) against
/// reference images (RGB), as interleaved RGB; `glSum` and `refSum` receive their sums.
struct IndirectPair {
    std::vector<float> gl, reference;
    double glSum = 0, refSum = 0;
};
IndirectPair indirectOnly(const FrameOutput& gl, const FrameOutput& glDirect, const std::vector<float>& ref,
                          const std::vector<float>& refDirect);

/// Pixel (x, y), top-left origin, where world point p lands in the scene's default camera.
glm::ivec2 projectToPixel(const Scene& scene, glm::vec3 p, int w, int h);

/// Relative RMSE (analysis/Metrics.h: over the RGB channels, relative to the reference's RMS value) of
/// `test` against `reference`, interleaved linear images of `pixels` pixels with 3 or 4 channels.
double relativeRmseOf(const std::vector<float>& test, int testChannels, const std::vector<float>& reference,
                      int referenceChannels, std::size_t pixels);
/// The same for two frames' linear outputs (RGBA).
double relativeRmseOf(const FrameOutput& test, const FrameOutput& reference);
/// Linear output values that are NaN, infinite or negative.
std::size_t badValues(const FrameOutput& f);
/// A frame's stats counter (stats.counts.NAME), 0 when absent.
double counter(const FrameOutput& f, const std::string& name);
/// Whether the frame's stats list a pass of that name.
bool hasPass(const FrameOutput& f, const std::string& name);

bool readPng(const std::string& path, int& w, int& h, std::vector<std::uint8_t>& rgb);
bool writePng(const std::string& path, int w, int h, const std::vector<std::uint8_t>& rgba);

} // namespace gis::test
