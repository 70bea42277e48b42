// The numerical-stability harness (digest S.4, issue #10): one GL context and FrameRenderer per
// technique (so switching cases never recompiles a technique), frame read-back of every buffer the
// test can reach without widening FrameRenderer's API, the per-frame assertions every S.4 case
// shares, and the results table written by the run (docs/stability.md).
//
// What a frame check reads: the final linear radiance (FrameOutput), the technique's indirect()
// texture, and, by name from the renderer's frame resources (gl/FrameResources.h), the G-buffer, the
// RSM and the direct-light target. With `deep` set it
// also reads back every floating-point texture level alive in that context (eye-hierarchy atlases,
// SSBC mip chains, low-resolution buffers), which is how NaN in a mip chain is caught.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gl/GlApi.h"
#include "render/FrameRenderer.h"
#include "scene/Scene.h"

namespace gis::stability {

/// RGBA float copy of one texture level (any colour or depth format; depth lands in .r).
struct Image {
    int width = 0, height = 0, layers = 1;
    GLenum format = 0;
    std::vector<float> rgba;
    bool empty() const { return rgba.empty(); }
    float at(int x, int y, int c) const { return rgba[(static_cast<size_t>(y) * width + x) * 4 + c]; }
};

/// Reads level `level` of `texture` (rows bottom to top, as GL stores them).
Image readTexture(GLuint texture, int level = 0);

struct RenderSpec {
    std::shared_ptr<const Scene> scene;
    std::string technique = "rsm_gather";
    int width = 64, height = 64;
    /// Frame and technique parameters on top of the suite's defaults (kFastFrameParams).
    nlohmann::json params = nlohmann::json::object();
    std::optional<Camera> camera; ///< default: the scene's first camera
    std::optional<Light> light;   ///< default: the scene's first spot light
    bool deep = false;            ///< also read every float texture of the context
};

/// One rendered frame and everything read back from it. Images are top-to-bottom like FrameOutput
/// except the raw GL ones (gPosition ...), which are bottom-to-top; use pixel() helpers.
struct Frame {
    RenderSpec spec;
    FrameOutput out;
    Image gPosition, gNormal, gAlbedo; ///< G-buffer (empty when it could not be identified)
    Image rsmPosition, rsmNormal, rsmFlux;
    Image direct;   ///< the direct-light target (empty when ambiguous)
    Image indirect; ///< technique()->indirect(); empty for `none`
    double wallMs = 0;
    int deepTextures = 0; ///< textures read by the deep check
    int glErrors = 0;     ///< GL errors the driver reported during the frame (KHR_debug)
    std::string glErrorText;

    // Measures (filled by measure()).
    double rsmFluxSum[3] = {0, 0, 0};    ///< total reflected flux the RSM carries, per channel
    double indirectPower[3] = {0, 0, 0}; ///< sum over visible pixels of E_ind * pixel area, per channel
    double energyRatio = 0;              ///< max over channels of indirectPower / rsmFluxSum (0 when no flux)
    double indirectMax = 0;              ///< largest indirect radiance component
    double indirectMean = 0;             ///< mean indirect radiance (mean of RGB) over covered pixels
    int coveredPixels = 0;

    double counter(const std::string& name, double fallback = -1) const;
    /// Final linear radiance, top-left origin.
    float finalAt(int x, int y, int c) const {
        return out.linear[(static_cast<size_t>(y) * out.width + x) * 4 + c];
    }
    /// Indirect radiance at top-left pixel (x, y), 0 when there is no indirect texture.
    float indirectAt(int x, int y, int c) const;
    bool coveredAt(int x, int y) const;
};

/// Energy bound factor: the one-bounce indirect power received by the visible surfaces may not
/// exceed this multiple of the flux the RSM reflects (energy conservation: a Lambertian VPL of flux
/// Phi delivers at most Phi to all surfaces together; the factor covers the screen-space area
/// estimate). Techniques that add multi-bounce compensation (SSBC with ssbc_input=illumination) are
/// bounded by the geometric series Phi / (1 - rho_max) instead; cases pass their own bound.
constexpr double kOneBounceEnergyBound = 1.05;
/// Generous per-frame wall-clock bound on llvmpipe: no runaway refinement or traversal.
constexpr double kMaxFrameMs = 20000.0;

/// How much slower a frame may be in the sanitizer build: there llvmpipe's own allocations go through
/// AddressSanitizer's allocator, whose fresh pages made C20's splat frame 54 s alone against 7.9 s
/// (60% of its samples page faults under __asan::Allocator::Allocate).
#if defined(__SANITIZE_ADDRESS__)
constexpr double kSanitizerSlowdown = 3.0;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr double kSanitizerSlowdown = 3.0;
#else
constexpr double kSanitizerSlowdown = 1.0;
#endif
#else
constexpr double kSanitizerSlowdown = 1.0;
#endif

struct FrameBounds {
    double energy = kOneBounceEnergyBound; ///< < 0: not checked (the case checks energy itself)
    bool background = true;                ///< background pixels: indirect and final exactly 0
    /// Wall-clock bound of this frame (ms), times kSanitizerSlowdown in the sanitizer build. Only
    /// C20's 4M-subsplat frame raises it: 7.9-14 s alone on llvmpipe; in the sanitizer build 54 s
    /// alone and 65 s with two test processes sharing the cores.
    double maxFrameMs = kMaxFrameMs;
    /// Non-empty: GL errors in this frame are a known, reported bug (knownFailure) instead of a
    /// test failure; the text names the cause.
    std::string knownGlError;
};

/// Renders, reads back and checks the shared S.4 assertions with EXPECTs naming the frame:
/// no NaN/Inf in any buffer read back, no negative radiance (final and, except second_order's
/// signed indirect, indirect; second_order: indirect >= -direct), energy <= bound x RSM flux,
/// frame time <= kMaxFrameMs, background exactly 0. Records the frame into the current table cell.
Frame render(const RenderSpec& spec, const FrameBounds& bounds = {});
/// Renders without the shared checks (reference frames of comparisons).
Frame renderRaw(const RenderSpec& spec);

/// The renderer and context of `technique` (made current), for tests that drive a technique
/// directly (NaN injection).
FrameRenderer& rendererFor(const std::string& technique);

/// GL names of the renderer's targets after its last frame, read from its frame resources by name
/// (gl/FrameResources.h); 0 where the frame did not publish one.
struct FrameTextures {
    GLuint gPosition = 0, gNormal = 0, gAlbedo = 0;
    GLuint rsmPosition = 0, rsmNormal = 0, rsmFlux = 0;
    GLuint direct = 0;
};
FrameTextures frameTextures(const FrameRenderer& renderer);

/// Reads every float texture level of the current context except `exclude`; returns the number of
/// non-finite values and describes the first offender in `first`.
size_t countNonFiniteTextures(const std::vector<GLuint>& exclude, std::string* first = nullptr);

/// Every registered technique name, registry order.
std::vector<std::string> allTechniques();
/// Techniques with VPLs (all but `none`).
std::vector<std::string> vplTechniques();
bool usesEyeHierarchy(const std::string& technique);

/// Relative RMSE of b against a over all pixels and RGB: sqrt(sum (b-a)^2 / sum a^2).
double relativeRmse(const std::vector<float>& a, const std::vector<float>& b);
double sumRgb(const std::vector<float>& rgba);

// ---- results table ------------------------------------------------------------------------------

/// A measured violation of an S.4 assertion whose cause is diagnosed and reported but lies in code
/// this suite does not change: the cell shows "KNOWN" with the reason instead of failing the run.
/// GIS_STABILITY_STRICT=1 turns known failures into test failures.
void knownFailure(const std::string& what, const std::string& reason);

/// Adds a measured value to the current (case, technique) cell, shown in the detail table.
void note(const std::string& key, double value);
void note(const std::string& key, const std::string& value);

/// Fixture for the S.4 cases: the parameter is the technique; SetUp opens a table cell named after
/// the test (C<nn>_...), TearDown closes it with pass / FAIL / n/a.
class CaseTest : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override;
    void TearDown() override;
    const std::string& technique() const { return GetParam(); }
    /// Skips (n/a in the table) unless the technique is one of `names`.
    bool appliesTo(const std::vector<std::string>& names);
};

/// Opens / closes a cell by hand (tests outside CaseTest: kernel probes, temporal, sanitising).
void beginCell(const std::string& caseId, const std::string& column);
void endCell(bool failed, bool skipped);

/// Writes the tables (markdown + JSON) to the build directory; with GIS_UPDATE_STABILITY_DOC=1
/// also splices the markdown into docs/stability.md between its generated-table markers.
void writeReport();

} // namespace gis::stability
