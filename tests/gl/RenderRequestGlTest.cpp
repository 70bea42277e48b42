// executeRenderJob on GL: its PNG holds exactly the pixels of a direct FrameRenderer render of the
// same state (built here by hand, as a session would), its JPEG and WebP decode at the right size, its
// stats carry the encoding, and compare adds the reference metrics. Small frames, few VPLs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "GlTestSupport.h"
#include "core/Error.h"
#include "core/Base64.h"
#include "job/ApiRender.h"
#include "job/RenderRequest.h"

namespace {

constexpr int kW = 48, kH = 32;

std::shared_ptr<const gis::Scene> cornell() {
    static const auto scene = std::make_shared<const gis::Scene>(gis::loadScene("builtin:cornell"));
    return scene;
}

gis::RenderResult execute(const gis::RenderJob& job) {
    gis::test::sharedContext();
    return gis::executeRenderJob(gis::test::sharedRenderer(), job, [](const std::string& name) {
        EXPECT_EQ(name, "builtin:cornell");
        return cornell();
    });
}

gis::RenderJob smallJob(const std::string& format) {
    return gis::parseRenderRequest({{"scene", "builtin:cornell"},
                                    {"technique", "rsm_gather"},
                                    {"params", {{"vpl_grid", 4}}},
                                    {"size", {kW, kH}},
                                    {"format", format}});
}

/// Decodes with OpenImageIO through a per-process file (CTest runs the backends in parallel).
bool decode(const std::vector<std::uint8_t>& bytes, const std::string& name, int& w, int& h,
            std::vector<std::uint8_t>& rgb) {
    const auto path = std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "_" + name);
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    const bool ok = gis::test::readPng(path.string(), w, h, rgb); // any format OpenImageIO reads
    std::filesystem::remove(path);
    return ok;
}

TEST(RenderRequestGl, PngHoldsTheDirectRendersPixels) {
    nlohmann::json request = {
        {"scene", "builtin:cornell"},
        {"technique", "rsm_gather"},
        {"params", {{"vpl_grid", 4}, {"exposure", 0.5}}},
        {"size", {kW, kH}},
        {"camera", {{"position", {0.3, 1.1, 3.6}}, {"target", {0, 0.9, 0}}, {"fov_deg", 45}}},
        {"light", {{"intensity", 5}, {"cone_deg", 50}}}};
    const gis::RenderResult result = execute(gis::parseRenderRequest(request));
    EXPECT_EQ(result.mimeType, "image/png");

    // The same frame without the request layer.
    gis::FrameState state = gis::makeFrameState(*cornell(), "rsm_gather");
    gis::applyParams(state, {{"vpl_grid", 4}, {"exposure", 0.5}}, "test");
    state.width = kW;
    state.height = kH;
    state.camera.position = {0.3f, 1.1f, 3.6f};
    state.camera.target = {0.0f, 0.9f, 0.0f};
    state.camera.yfovRadians = 45.0f * 0.017453292519943295f;
    const float ratio = state.lights.at(0).light.innerConeAngle / state.lights.at(0).light.outerConeAngle;
    state.lights.at(0).light.intensity = 5.0f;
    state.lights.at(0).light.outerConeAngle = 50.0f * 0.017453292519943295f;
    state.lights.at(0).light.innerConeAngle =
        std::clamp(ratio, 0.0f, 0.99f) * state.lights.at(0).light.outerConeAngle;
    gis::FrameRenderer& renderer = gis::test::sharedRenderer();
    const gis::FrameOutput direct = renderer.render(state);

    int w = 0, h = 0;
    std::vector<std::uint8_t> rgb;
    ASSERT_TRUE(decode(result.image, "render_request.png", w, h, rgb));
    ASSERT_EQ(w, kW);
    ASSERT_EQ(h, kH);
    size_t differing = 0;
    for (size_t i = 0; i < static_cast<size_t>(kW) * kH; ++i)
        for (int c = 0; c < 3; ++c) differing += rgb[i * 3 + c] != direct.rgba8[i * 4 + c];
    EXPECT_EQ(differing, 0u);
    // And the encoder is the whole difference: re-encoding the direct frame gives the same bytes.
    EXPECT_EQ(result.image, gis::encodePng(direct.rgba8.data(), kW, kH,
                                           gis::renderImageMetadata("builtin:cornell", state)));

    const nlohmann::json& stats = result.stats;
    EXPECT_EQ(stats["codec"], "png");
    EXPECT_EQ(stats["bytes"].get<size_t>(), result.image.size());
    EXPECT_TRUE(stats["encode_ms"].is_number());
    EXPECT_EQ(stats["scene"], "builtin:cornell");
    EXPECT_EQ(stats["technique"], "rsm_gather");
    EXPECT_EQ(stats["size"], nlohmann::json({kW, kH}));
    EXPECT_EQ(stats["params"]["vpl_grid"], 4);
    EXPECT_EQ(stats["counts"]["vpl_count"].get<double>(), 16.0);
    EXPECT_FALSE(stats.contains("compare"));
}

TEST(RenderRequestGl, SameRequestSameBytes) {
    const gis::RenderJob job = smallJob("png");
    EXPECT_EQ(execute(job).image, execute(job).image);
}

TEST(RenderRequestGl, JpegAndWebpDecode) {
    for (const char* format : {"jpeg", "webp"}) {
        gis::RenderJob job = smallJob(format);
        job.quality = 80;
        const gis::RenderResult result = execute(job);
        ASSERT_GT(result.image.size(), 16u) << format;
        if (std::string(format) == "jpeg") {
            EXPECT_EQ(result.mimeType, "image/jpeg");
            EXPECT_EQ(result.image[0], 0xFF);
            EXPECT_EQ(result.image[1], 0xD8);
        } else {
            EXPECT_EQ(result.mimeType, "image/webp");
            EXPECT_EQ(std::string(result.image.begin(), result.image.begin() + 4), "RIFF");
            EXPECT_EQ(std::string(result.image.begin() + 8, result.image.begin() + 12), "WEBP");
        }
        EXPECT_EQ(result.stats["codec"], format);
        EXPECT_EQ(result.stats["bytes"].get<size_t>(), result.image.size());
        int w = 0, h = 0;
        std::vector<std::uint8_t> rgb;
        ASSERT_TRUE(decode(result.image, std::string("render_request.") + format, w, h, rgb)) << format;
        EXPECT_EQ(w, kW) << format;
        EXPECT_EQ(h, kH) << format;
    }
}

TEST(RenderRequestGl, CompareAddsMetrics) {
    if (!gis::renderJobsCanCompare()) GTEST_SKIP() << "built without the reference layer";
    gis::RenderJob job = gis::parseRenderRequest({{"scene", "builtin:cornell"},
                                                  {"technique", "none"},
                                                  {"size", {32, 32}},
                                                  {"compare", {{"mode", "direct"}, {"spp", 1}}}});
    const gis::RenderResult result = execute(job);
    ASSERT_TRUE(result.stats.contains("compare"));
    const nlohmann::json& compare = result.stats["compare"];
    for (const char* k : {"rmse", "relative_rmse", "psnr_db", "ssim", "flip", "pixels"})
        EXPECT_TRUE(compare.contains(k)) << k;
    EXPECT_EQ(compare["reference"]["mode"], "direct");
    EXPECT_EQ(compare["reference"]["cache_hit"], false);
    // The GL direct light against the CPU's: the same integral, so the error is small.
    EXPECT_LT(compare["relative_rmse"].get<double>(), 0.3);
    EXPECT_EQ(compare["reference_noise"], 0.0); // a pixel-centre direct render is exact
    EXPECT_FALSE(compare.contains("indirect")); // nothing to split off a direct reference
}

// A GI reference with a noise target: the noise is reported beside the error, and the indirect light
// and the direct pass are measured apart.
TEST(RenderRequestGl, CompareSplitsIndirectLightAndReportsTheNoise) {
    if (!gis::renderJobsCanCompare()) GTEST_SKIP() << "built without the reference layer";
    gis::RenderJob job =
        gis::parseRenderRequest({{"scene", "builtin:cornell"},
                                 {"technique", "rsm_gather"},
                                 {"params", {{"vpl_grid", 8}}},
                                 {"size", {32, 32}},
                                 {"compare", {{"mode", "one-bounce-unoccluded"}, {"noise_target", 0.1}}}});
    EXPECT_EQ(job.compare->spp, gis::RenderLimits{}.maxReferenceSpp); // the target decides, up to the cap
    const nlohmann::json compare = execute(job).stats["compare"];
    std::printf("%s\n", compare.dump().c_str());
    const nlohmann::json& indirect = compare["indirect"];
    EXPECT_GT(compare["reference"]["spp"].get<int>(), 1);
    EXPECT_EQ(compare["reference"]["noise_target"]["of"], "indirect");
    EXPECT_LE(indirect["reference_noise"].get<double>(), 0.1);
    EXPECT_GT(indirect["reference_noise"].get<double>(), compare["reference_noise"].get<double>());
    EXPECT_LE(indirect["relative_rmse_corrected"].get<double>(), indirect["relative_rmse"].get<double>());
    EXPECT_GT(indirect["relative_rmse"].get<double>(), 0.0);
    EXPECT_NEAR(indirect["mean_ratio"].get<double>(), 1.0, 0.35);
    EXPECT_EQ(compare["direct"]["reference"]["mode"], "direct");
    EXPECT_LT(compare["direct"]["relative_rmse"].get<double>(), 0.3);
}

TEST(RenderRequestGl, ResolverDecidesTheScene) {
    gis::test::sharedContext();
    const gis::RenderJob job = smallJob("png");
    try {
        gis::executeRenderJob(gis::test::sharedRenderer(), job, [](const std::string&) { return nullptr; });
        FAIL() << "a refused scene rendered";
    } catch (const gis::InputError& e) {
        EXPECT_EQ(e.where(), "/scene");
    }
}

// POST /api/render's reply, built beside the job: the image with its stats in a header, the same
// bytes in JSON as base64, the service's VPL cap and the resolver's refusals as 400s with a pointer.
TEST(RenderRequestGl, ApiRepliesCarryTheSameImageEitherWay) {
    gis::test::sharedContext();
    const gis::RenderJob job = smallJob("png");
    auto resolve = [](const std::string&) { return cornell(); };
    const gis::HttpReply image = gis::renderApiRequest(gis::test::sharedRenderer(), job, resolve, 65536, 1.5,
                                                       gis::ApiReplyForm::Image);
    ASSERT_EQ(image.status, 200u) << image.body;
    EXPECT_EQ(image.contentType, "image/png");
    ASSERT_EQ(image.headers.size(), 1u);
    EXPECT_EQ(image.headers[0].first, "x-gi-stats:");
    EXPECT_EQ(nlohmann::json::parse(image.headers[0].second)["queue_ms"], 1.5);
    const gis::HttpReply json =
        gis::renderApiRequest(gis::test::sharedRenderer(), job, resolve, 65536, 0.0, gis::ApiReplyForm::Json);
    ASSERT_EQ(json.status, 200u);
    const auto body = nlohmann::json::parse(json.body);
    EXPECT_EQ(gis::base64Decode(body["image_base64"].get<std::string>()).value_or(""), image.body)
        << "the same PNG";
    EXPECT_FALSE(body.contains("reference_base64")) << "no compare asked";

    const gis::HttpReply capped =
        gis::renderApiRequest(gis::test::sharedRenderer(), job, resolve, 8, 0.0, gis::ApiReplyForm::Image);
    EXPECT_EQ(capped.status, 400u);
    const auto cap = nlohmann::json::parse(capped.body);
    EXPECT_EQ(cap["error"], "invalid_request");
    EXPECT_EQ(cap["where"], "/params");
    EXPECT_NE(cap["message"].get<std::string>().find("the server allows 8"), std::string::npos);

    const gis::HttpReply refused = gis::renderApiRequest(
        gis::test::sharedRenderer(), job,
        [](const std::string&) -> std::shared_ptr<const gis::Scene> {
            throw gis::InputError("x", "not offered");
        },
        65536, 0.0, gis::ApiReplyForm::Image);
    EXPECT_EQ(refused.status, 400u);
    EXPECT_EQ(nlohmann::json::parse(refused.body)["where"], "/scene");
}

} // namespace
