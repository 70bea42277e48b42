// Render requests (render/RenderRequest.h) without GL: defaults, the JSON pointer and the advice of
// every kind of error, limits, and the FrameState a job builds.
#include <gtest/gtest.h>

#include <functional>

#include "core/Error.h"
#include "job/ApiRender.h"
#include "job/RenderRequest.h"
#include "scene/SceneLoader.h"

namespace {

struct Failure {
    std::string where = "(none)";
    std::string message;
};

Failure failureOf(const nlohmann::json& request, const gis::RenderLimits& limits = {}) {
    try {
        gis::parseRenderRequest(request, limits);
    } catch (const gis::InputError& e) {
        return {e.where(), e.reason()};
    }
    return {};
}

nlohmann::json withScene(nlohmann::json fields) {
    fields["scene"] = "builtin:cornell";
    return fields;
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

TEST(RenderRequest, SchemaIsEmbedded) {
    const nlohmann::json& schema = gis::renderRequestSchema();
    ASSERT_TRUE(schema.is_object());
    for (const char* k : {"scene", "technique", "preset", "params", "size", "format", "quality", "camera",
                          "light", "compare"})
        EXPECT_TRUE(schema["properties"].contains(k)) << k;
}

TEST(RenderRequest, OnlySceneIsRequired) {
    const gis::RenderJob job = gis::parseRenderRequest({{"scene", "builtin:cornell"}});
    EXPECT_EQ(job.scene, "builtin:cornell");
    EXPECT_EQ(job.technique, "rsm_gather");
    EXPECT_EQ(job.preset, "");
    EXPECT_TRUE(job.params.empty());
    EXPECT_EQ(job.width, 512);
    EXPECT_EQ(job.height, 512);
    EXPECT_EQ(job.codec, gis::ImageCodec::Png);
    EXPECT_EQ(job.quality, 90);
    EXPECT_FALSE(job.camera.has_value());
    EXPECT_FALSE(job.light.has_value());
    EXPECT_FALSE(job.compare.has_value());
    EXPECT_EQ(job.referenceCacheDir, "");
}

TEST(RenderRequest, ParsesEveryField) {
    const nlohmann::json camera = {{"position", {0, 1, 3}}, {"target", {0, 1, 0}}, {"fov_deg", 45}};
    const nlohmann::json light = {{"intensity", 4}, {"enabled", true}};
    const gis::RenderJob job = gis::parseRenderRequest(withScene({{"technique", "none"},
                                                                  {"params", {{"exposure", 0.5}}},
                                                                  {"size", {64, 48}},
                                                                  {"format", "webp"},
                                                                  {"quality", 75},
                                                                  {"camera", camera},
                                                                  {"light", light}}));
    EXPECT_EQ(job.technique, "none");
    EXPECT_EQ(job.params, nlohmann::json({{"exposure", 0.5}}));
    EXPECT_EQ(job.width, 64);
    EXPECT_EQ(job.height, 48);
    EXPECT_EQ(job.codec, gis::ImageCodec::Webp);
    EXPECT_EQ(job.quality, 75);
    ASSERT_TRUE(job.camera.has_value());
    EXPECT_EQ(*job.camera, camera);
    ASSERT_TRUE(job.light.has_value());
    EXPECT_EQ(*job.light, light);
}

TEST(RenderRequest, BadSizeNamesTheComponent) {
    Failure f = failureOf(withScene({{"size", {8, 64}}}));
    EXPECT_EQ(f.where, "/size/0");
    EXPECT_TRUE(contains(f.message, ">= 16")) << f.message;
    EXPECT_TRUE(contains(f.message, "[width, height]")) << f.message;
    f = failureOf(withScene({{"size", {64, 5000}}}));
    EXPECT_EQ(f.where, "/size/1");
    EXPECT_TRUE(contains(f.message, "limit of 2048")) << f.message;
    gis::RenderLimits small;
    small.maxWidth = 100;
    EXPECT_EQ(failureOf(withScene({{"size", {128, 64}}}), small).where, "/size/0");
    EXPECT_EQ(failureOf(withScene({{"size", {1e12, 64}}})).where, "/size/0"); // beyond int
    EXPECT_EQ(failureOf(withScene({{"size", {64}}})).where, "/size");
    EXPECT_EQ(failureOf(withScene({{"size", {64.5, 64}}})).where, "/size/0");
    EXPECT_EQ(failureOf(withScene({{"size", "64x64"}})).where, "/size");
}

TEST(RenderRequest, UnknownParamIsNamed) {
    const Failure f = failureOf(withScene({{"params", {{"vpl_gird", 4}}}}));
    EXPECT_EQ(f.where, "/params/vpl_gird");
    EXPECT_TRUE(contains(f.message, "unknown parameter 'vpl_gird'")) << f.message;
    EXPECT_TRUE(contains(f.message, "vpl_grid")) << f.message; // the known names, to fix the typo
}

TEST(RenderRequest, ParamOutOfRangeGivesTheRange) {
    Failure f = failureOf(withScene({{"params", {{"vpl_grid", 100000}}}}));
    EXPECT_EQ(f.where, "/params/vpl_grid");
    EXPECT_TRUE(contains(f.message, "[1, 256]")) << f.message;
    // Parameters are checked against the requested technique's table.
    f = failureOf(withScene({{"technique", "none"}, {"params", {{"vpl_grid", 4}}}}));
    EXPECT_EQ(f.where, "/params/vpl_grid");
    EXPECT_EQ(failureOf(withScene({{"params", {{"vpl_grid", {1, 2}}}}})).where, "/params/vpl_grid");
    EXPECT_EQ(failureOf(withScene({{"params", {1, 2}}})).where, "/params");
}

TEST(RenderRequest, BadFormatListsTheValidOnes) {
    for (const nlohmann::json& format : {nlohmann::json("gif"), nlohmann::json("jpg"), nlohmann::json(3)}) {
        const Failure f = failureOf(withScene({{"format", format}}));
        EXPECT_EQ(f.where, "/format") << format;
        for (const char* name : {"png", "jpeg", "webp"}) EXPECT_TRUE(contains(f.message, name)) << f.message;
    }
    EXPECT_EQ(gis::parseRenderRequest(withScene({{"format", "jpeg"}})).codec, gis::ImageCodec::Jpeg);
}

TEST(RenderRequest, QualityOutOfRange) {
    for (const nlohmann::json& q :
         {nlohmann::json(0), nlohmann::json(101), nlohmann::json(50.5), nlohmann::json("high")}) {
        const Failure f = failureOf(withScene({{"format", "jpeg"}, {"quality", q}}));
        EXPECT_EQ(f.where, "/quality") << q;
        EXPECT_TRUE(contains(f.message, "1 to 100")) << f.message;
    }
    EXPECT_EQ(gis::parseRenderRequest(withScene({{"format", "jpeg"}, {"quality", 1}})).quality, 1);
}

TEST(RenderRequest, UnknownTechnique) {
    const Failure f = failureOf(withScene({{"technique", "nope"}}));
    EXPECT_EQ(f.where, "/technique");
    EXPECT_TRUE(contains(f.message, "unknown technique 'nope'")) << f.message;
    EXPECT_TRUE(contains(f.message, "rsm_gather")) << f.message;
}

TEST(RenderRequest, StructuralErrors) {
    Failure f = failureOf({{"technique", "none"}});
    EXPECT_EQ(f.where, "");
    EXPECT_TRUE(contains(f.message, "missing required field 'scene'")) << f.message;
    f = failureOf(withScene({{"sise", {64, 64}}}));
    EXPECT_EQ(f.where, "/sise");
    EXPECT_TRUE(contains(f.message, "known fields: scene")) << f.message;
    EXPECT_EQ(failureOf(nlohmann::json::array()).where, "");
    EXPECT_EQ(failureOf({{"scene", ""}}).where, "/scene");
    EXPECT_EQ(failureOf(withScene({{"preset", "fastest"}})).where, "/preset");
}

TEST(RenderRequest, CameraAndLightErrors) {
    EXPECT_EQ(failureOf(withScene({{"camera", {{"position", {0, 1, 3}}, {"target", {0, 1, 3}}}}})).where,
              "/camera/target");
    EXPECT_EQ(failureOf(withScene({{"camera", {{"position", {0, 1, 3}}}}})).where, "/camera");
    EXPECT_EQ(
        failureOf(withScene({{"camera", {{"position", {0, 1, 3}}, {"target", {0, 1, 0}}, {"roll", 1}}}}))
            .where,
        "/camera/roll");
    EXPECT_EQ(failureOf(withScene({{"light", {{"direction", {0, 0, 0}}}}})).where, "/light/direction");
    EXPECT_EQ(failureOf(withScene({{"light", {{"intensity", -1}}}})).where, "/light/intensity");
}

TEST(RenderRequest, CompareOptionsAndLimits) {
    const nlohmann::json request = withScene({{"compare", {{"mode", "direct"}, {"spp", 4}}}});
    if (!gis::renderJobsCanCompare()) {
        EXPECT_EQ(failureOf(request).where, "/compare");
        return;
    }
    gis::RenderJob job = gis::parseRenderRequest(request);
    ASSERT_TRUE(job.compare.has_value());
    EXPECT_EQ(job.compare->mode, "direct");
    EXPECT_EQ(job.compare->spp, 4);
    EXPECT_EQ(job.compare->timeBudgetSeconds,
              gis::RenderLimits{}.maxReferenceSeconds); // the cap is the default

    gis::RenderLimits unlimited;
    unlimited.maxReferenceSeconds = 0;
    EXPECT_EQ(gis::parseRenderRequest(request, unlimited).compare->timeBudgetSeconds, 0.0);

    gis::RenderLimits noCompare;
    noCompare.allowCompare = false;
    EXPECT_EQ(failureOf(request, noCompare).where, "/compare");
    EXPECT_EQ(failureOf(withScene({{"compare", {{"mode", "raytrace"}}}})).where, "/compare/mode");
    EXPECT_EQ(failureOf(withScene({{"compare", {{"spp", 4}}}})).where, "/compare");
    EXPECT_EQ(failureOf(withScene({{"compare", {{"mode", "path"}, {"spp", 1000000}}}})).where,
              "/compare/spp");
    EXPECT_EQ(failureOf(withScene({{"compare", {{"mode", "path"}, {"spp", 1e12}}}})).where, "/compare/spp");
    EXPECT_EQ(failureOf(withScene({{"compare", {{"mode", "path"}, {"time_budget_s", 0}}}})).where,
              "/compare/time_budget_s");
    EXPECT_EQ(failureOf(withScene({{"compare", {{"mode", "path"}, {"time_budget_s", 3600}}}})).where,
              "/compare/time_budget_s");
    // A noise target: spp becomes the cap (the server's unless the request names fewer).
    const gis::RenderJob noisy = gis::parseRenderRequest(
        withScene({{"compare", {{"mode", "one-bounce"}, {"noise_target", 0.05}, {"noise_of", "image"}}}}));
    EXPECT_EQ(noisy.compare->noiseTarget, 0.05);
    EXPECT_FALSE(noisy.compare->noiseOfIndirect);
    EXPECT_EQ(noisy.compare->spp, gis::RenderLimits{}.maxReferenceSpp);
    EXPECT_EQ(gis::parseRenderRequest(
                  withScene({{"compare", {{"mode", "one-bounce"}, {"noise_target", 0.05}, {"spp", 16}}}}))
                  .compare->spp,
              16);
    EXPECT_EQ(failureOf(withScene({{"compare", {{"mode", "path"}, {"noise_target", 0.9}}}})).where,
              "/compare/noise_target");
    EXPECT_EQ(failureOf(withScene({{"compare", {{"mode", "path"}, {"noise_of", "pixels"}}}})).where,
              "/compare/noise_of");
}

TEST(RenderRequest, JobFrameStateLayersTheRequestOnTheScene) {
    const gis::Scene scene = gis::loadScene("builtin:cornell");
    const gis::RenderJob job =
        gis::parseRenderRequest(withScene({{"technique", "rsm_gather"},
                                           {"params", {{"vpl_grid", 4}, {"exposure", 1}}},
                                           {"size", {64, 48}},
                                           {"camera", {{"position", {0.5, 1, 3}}, {"target", {0, 1, 0}}}},
                                           {"light", {{"intensity", 2}}}}));
    const gis::FrameState state = gis::makeJobFrameState(scene, job);
    const gis::FrameState plain = gis::makeFrameState(scene, "rsm_gather");
    EXPECT_EQ(state.technique, "rsm_gather");
    EXPECT_EQ(state.width, 64);
    EXPECT_EQ(state.height, 48);
    EXPECT_EQ(state.techniqueParams.getInt("vpl_grid"), 4);
    EXPECT_EQ(state.frameParams.getFloat("exposure"), 1.0);
    EXPECT_EQ(state.camera.position, glm::vec3(0.5f, 1, 3));
    EXPECT_EQ(state.camera.up, plain.camera.up); // not in the request: the scene's
    EXPECT_EQ(state.lights.at(0).light.intensity, 2.0f);
    EXPECT_EQ(state.lights.at(0).light.position, plain.lights.at(0).light.position);

    // Without camera and light the scene's own are used.
    const gis::FrameState bare = gis::makeJobFrameState(scene, gis::parseRenderRequest(withScene({})));
    EXPECT_EQ(bare.camera.position, plain.camera.position);
    EXPECT_EQ(bare.lights.at(0).light.intensity, plain.lights.at(0).light.intensity);
    EXPECT_EQ(gis::paramsJson(bare), gis::paramsJson(plain));
}

TEST(RenderRequest, MetadataHoldsOnlyWhatTheImageDependsOn) {
    const gis::Scene scene = gis::loadScene("builtin:cornell");
    const gis::RenderJob job = gis::parseRenderRequest(withScene({{"params", {{"vpl_grid", 4}}}}));
    const gis::FrameState state = gis::makeJobFrameState(scene, job);
    const gis::ImageMetadata meta = gis::renderImageMetadata(job.scene, state);
    ASSERT_EQ(meta.size(), 3u);
    EXPECT_EQ(meta[0], std::make_pair(std::string("gi:technique"), std::string("rsm_gather")));
    EXPECT_EQ(meta[1], std::make_pair(std::string("gi:scene"), std::string("builtin:cornell")));
    EXPECT_EQ(meta[2].first, "gi:params");
    EXPECT_EQ(nlohmann::json::parse(meta[2].second), gis::paramsJson(state));
    EXPECT_EQ(meta, gis::renderImageMetadata(job.scene, gis::makeJobFrameState(scene, job)));
}

TEST(RenderRequest, EffectPlanRequestedByTheFrameParameters) {
    const gis::Scene scene = gis::loadScene("builtin:cornell");
    auto stateWith = [&](nlohmann::json params) {
        return gis::makeJobFrameState(scene, gis::parseRenderRequest(withScene({{"params", params}})));
    };
    EXPECT_FALSE(gis::effectPlanRequested(stateWith(nlohmann::json::object())));
    EXPECT_TRUE(gis::effectPlanRequested(stateWith({{"effects", "auto"}})));
    EXPECT_TRUE(gis::effectPlanRequested(stateWith({{"effect_indirect", "off"}})));
}

} // namespace

TEST(ApiRender, ReplyFormAndErrorBodies) {
    nlohmann::json request = {{"scene", "builtin:cornell"}, {"response", "json"}};
    EXPECT_EQ(gis::takeReplyForm(request), gis::ApiReplyForm::Json);
    EXPECT_FALSE(request.contains("response")) << "the field is the API's, not the job's";
    nlohmann::json plain = {{"scene", "builtin:cornell"}};
    EXPECT_EQ(gis::takeReplyForm(plain), gis::ApiReplyForm::Image);
    nlohmann::json bad = {{"scene", "builtin:cornell"}, {"response", "xml"}};
    try {
        gis::takeReplyForm(bad);
        FAIL() << "accepted response: xml";
    } catch (const gis::InputError& e) {
        EXPECT_EQ(e.where(), "/response");
    }
    const gis::HttpReply error = gis::errorReply(400, "invalid_request", "bad \xff byte", "/size/0");
    EXPECT_EQ(error.status, 400u);
    EXPECT_EQ(error.contentType, "application/json");
    const auto body = nlohmann::json::parse(error.body);
    EXPECT_EQ(body["error"], "invalid_request");
    EXPECT_EQ(body["where"], "/size/0");
    EXPECT_EQ(body["message"], "bad \\xFF byte") << "invalid UTF-8 is escaped, never thrown on";
}
