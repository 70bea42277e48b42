#include "gi/second_order/SecondOrder.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_inverse.hpp>

#include "gi/common/ParamSpecs.h"
#include "core/Error.h"
#include "gi/common/VplGrid.h"
#include "gi/second_order/Limits.h"
#include "gl/ShaderShared.h"

namespace gis {
namespace {

using second_order::kMaxNegative;
using second_order::kMaxPositive;
using second_order::kNoFixupThreshold;

// Candidate pixels examined per requested negative light: S_neg is zero on most of the image
// (surfaces with every light in front of them), so the first negative_count back-lit candidates in
// Halton order are kept out of this many. Fewer back-lit pixels give fewer negative lights, each
// still standing for its share of the frustum's solid angle (unbiased).
constexpr int kCandidatesPerNegative = 8;
constexpr int kMaxCandidates = kCandidatesPerNegative * kMaxNegative;
// A negative light's area is (solid angle) * d^2 / cos(view angle); the cosine is clamped here so a
// sample on a surface seen edge-on stands for at most 10x its perpendicular footprint.
constexpr float kMinCosView = 0.1f;

// Stats block of second_order.glsl: active VPL slots, clamped pixels, negatives placed, valid positives.
constexpr int kStatsWords = 4;

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

} // namespace

SecondOrder::SecondOrder() {
    const gl::ShaderStage fullscreen{GL_VERTEX_SHADER, "render/fullscreen.vert"};
    PlacePositiveProgram& pp = mPlacePositive;
    pp.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/second_order/place_positive.comp"}});
    pp.first = pp.program.location("uFirst");
    pp.count = pp.program.location("uCount");
    pp.light = pp.program.location("uLight");
    pp.rsmSize = pp.program.location("uRsmSize");
    pp.sampleMeasure = pp.program.location("uSampleMeasure");
    pp.position = pp.program.textureUnit("gRsmPosition");
    pp.normal = pp.program.textureUnit("gRsmNormal");
    pp.flux = pp.program.textureUnit("gRsmFlux");
    pp.vpls = pp.program.storageBlock("VplOut");
    pp.samples = pp.program.storageBlock("Samples");
    pp.stats = pp.program.optionalStorageBlock("SecondOrderStats");

    PlaceNegativeProgram& pn = mPlaceNegative;
    pn.program = gl::Program::build({{GL_COMPUTE_SHADER, "gi/second_order/place_negative.comp"}});
    pn.positiveCount = pn.program.location("uPositiveCount");
    pn.negativeCount = pn.program.location("uNegativeCount");
    pn.candidateCount = pn.program.location("uCandidateCount");
    pn.frustumSolidAngle = pn.program.location("uFrustumSolidAngle");
    pn.minDistance = pn.program.location("uMinDistance");
    pn.minCosView = pn.program.location("uMinCosView");
    pn.position = pn.program.textureUnit("gPosition");
    pn.normal = pn.program.textureUnit("gNormal");
    pn.vpls = pn.program.storageBlock("Vpls");
    pn.candidates = pn.program.storageBlock("Candidates");
    pn.stats = pn.program.optionalStorageBlock("SecondOrderStats");

    LowGeometryProgram& lg = mLowGeometry;
    lg.program =
        gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "gi/second_order/lowres_gbuffer.frag"}});
    lg.factor = lg.program.location("uFactor");
    lg.position = lg.program.textureUnit("gPosition");
    lg.normal = lg.program.textureUnit("gNormal");

    GatherProgram& g = mGather;
    g.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "gi/second_order/gather.frag"}},
                                   kernelDefines(VplKernel::Point, {}));
    g.minDistance = g.program.location("uMinDistance");
    g.vplCount = g.program.location("uVplCount");
    g.batchFirst = g.program.location("uBatchFirst");
    g.position = g.program.textureUnit("gPosition");
    g.normal = g.program.textureUnit("gNormal");
    g.stats = g.program.optionalStorageBlock("SecondOrderStats");
    g.transport = VplTransportHandles(g.program);

    DiscontinuityProgram& d = mDiscontinuity;
    d.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "gi/second_order/discontinuity.frag"}});
    d.factor = d.program.location("uFactor");
    d.lowSize = d.program.location("uLowSize");
    d.threshold = d.program.location("uThreshold");
    d.position = d.program.textureUnit("gPosition");
    d.normal = d.program.textureUnit("gNormal");
    d.lowPosition = d.program.textureUnit("gLowPosition");
    d.lowNormal = d.program.textureUnit("gLowNormal");

    ResolveProgram& r = mResolve;
    r.program = gl::Program::build({fullscreen, {GL_FRAGMENT_SHADER, "gi/second_order/resolve.frag"}});
    r.factor = r.program.location("uFactor");
    r.lowSize = r.program.location("uLowSize");
    r.fixup = r.program.location("uFixup");
    r.hasDirect = r.program.location("uHasDirect");
    r.position = r.program.textureUnit("gPosition");
    r.albedo = r.program.textureUnit("gAlbedo");
    r.direct = r.program.textureUnit("gDirect");
    r.flag = r.program.textureUnit("gFlag");
    r.fullIrradiance = r.program.textureUnit("gFullIrradiance");
    r.lowIrradiance = r.program.textureUnit("gLowIrradiance");
    r.lowPosition = r.program.textureUnit("gLowPosition");
    r.stats = r.program.optionalStorageBlock("SecondOrderStats");
    mEmptyVao = gl::VertexArray::create();
    mSamples = gl::Buffer::create(kMaxPositive * sizeof(glm::vec4));
    mCandidates = gl::Buffer::create(kMaxCandidates * sizeof(glm::ivec4));
    mVpls = gl::Buffer::create((kMaxPositive + kMaxNegative) * sizeof(shader::Vpl));
    mStats =
        gl::Buffer::create(kStatsWords * sizeof(GLuint), nullptr, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
    mFlaggedQuery = gl::Query::create(GL_SAMPLES_PASSED);
    mCoveredQuery = gl::Query::create(GL_SAMPLES_PASSED);
}

void SecondOrder::resize(int width, int height) {
    mLowPosition = gl::Texture::create2D(GL_RGBA32F, width, height);
    mLowNormal = gl::Texture::create2D(GL_RGBA16F, width, height);
    mLowIrradiance = gl::Texture::create2D(GL_RGBA32F, width, height);
    mFlag = gl::Texture::create2D(GL_R8, width, height);
    mStencil = gl::Texture::create2D(GL_DEPTH24_STENCIL8, width, height);
    mFullIrradiance = gl::Texture::create2D(GL_RGBA32F, width, height);
    mIndirect = gl::Texture::create2D(GL_RGBA32F, width, height);

    mLowGeometryFbo = gl::Framebuffer::of("second_order low-res G-buffer", {&mLowPosition, &mLowNormal});
    mLowIrradianceFbo = gl::Framebuffer::of("second_order low-res irradiance", {&mLowIrradiance});
    // The discontinuity pass marks the stencil that the fix-up gather then tests.
    mFlagFbo = gl::Framebuffer::of("second_order discontinuity", {&mFlag}, &mStencil);
    mFixupFbo = gl::Framebuffer::of("second_order fix-up", {&mFullIrradiance}, &mStencil);
    mResolveFbo = gl::Framebuffer::of("second_order indirect", {&mIndirect});
}

const halton::ConeSamples& SecondOrder::cone(ConeCache& cache, double cosHalfAngle, int count) {
    if (cache.cosHalfAngle != cosHalfAngle || cache.count != count) {
        cache.samples = halton::sampleCone(cosHalfAngle, count);
        cache.cosHalfAngle = cosHalfAngle;
        cache.count = count;
    }
    return cache.samples;
}

std::vector<int> splitPositiveSlots(int slots, const std::vector<double>& lightFlux) {
    std::vector<int> counts(lightFlux.size(), 0);
    if (slots <= 0 || lightFlux.empty()) return counts;
    if (lightFlux.size() == 1) {
        counts[0] = slots;
        return counts;
    }
    double total = 0.0;
    for (double f : lightFlux)
        if (std::isfinite(f) && f > 0.0) total += f;
    // Largest remainders: the counts sum to `slots` exactly; a light with flux gets at least one
    // slot while there are slots to give.
    std::vector<double> remainder(lightFlux.size(), 0.0);
    int given = 0;
    for (size_t i = 0; i < lightFlux.size(); ++i) {
        const double f = std::isfinite(lightFlux[i]) && lightFlux[i] > 0.0 ? lightFlux[i] : 0.0;
        const double share = total > 0.0 ? f / total : 1.0 / double(lightFlux.size());
        const double exact = share * slots;
        counts[i] = static_cast<int>(std::floor(exact));
        remainder[i] = exact - counts[i];
        if (counts[i] == 0 && share > 0.0) remainder[i] += 1.0; // first in line for a leftover slot
        given += counts[i];
    }
    while (given < slots) {
        const size_t best =
            static_cast<size_t>(std::max_element(remainder.begin(), remainder.end()) - remainder.begin());
        ++counts[best];
        remainder[best] = -1.0;
        ++given;
    }
    return counts;
}

int SecondOrder::placePositive(const FrameInputs& in, gl::PassTimer& timer, Counters& counters) {
    GIS_ASSERT(in.lights != nullptr);
    const shader::LightUniforms& lights = *in.lights;
    const int lightCount = lights.counts.x;
    const int requested = std::clamp(mPositiveSlots, 0, kMaxPositive);
    // Each light's share of the slots follows its reflected flux (the sum over its views).
    std::vector<double> lightFlux(static_cast<size_t>(lightCount), 1.0);
    if (!in.viewFlux.empty()) {
        for (int i = 0; i < lightCount; ++i) {
            double sum = 0.0;
            const int first = static_cast<int>(lights.lights[i].info.z),
                      views = static_cast<int>(lights.lights[i].info.w);
            for (int v = first; v < first + views && v < static_cast<int>(in.viewFlux.size()); ++v)
                sum += in.viewFlux[static_cast<size_t>(v)];
            lightFlux[static_cast<size_t>(i)] = sum;
        }
    }
    const std::vector<int> perLight = splitPositiveSlots(requested, lightFlux);
    if (mLightCones.size() < perLight.size()) mLightCones.resize(perLight.size());

    std::vector<glm::vec4> uv;
    struct Range {
        int first, count, light;
        float measure;
    };
    std::vector<Range> ranges;
    double draws = 0;
    bool capped = false;
    constexpr double kPi = 3.14159265358979323846;
    for (int i = 0; i < lightCount; ++i) {
        const int n = perLight[static_cast<size_t>(i)];
        if (n <= 0) continue;
        const shader::GpuLight& light = lights.lights[i];
        const int type = static_cast<int>(light.info.x + 0.5f);
        const int firstView = static_cast<int>(light.info.z + 0.5f);
        const int first = static_cast<int>(uv.size());
        float measure = 0.0f;
        if (type == GIS_LIGHT_DIRECTIONAL) {
            // The lit square of the orthographic view: 2D Halton points (bases 2, 3), each standing for
            // an equal share of its area.
            const shader::LightView& view = lights.views[firstView];
            for (int k = 0; k < n; ++k) {
                const auto index = static_cast<std::uint32_t>(k + 1);
                uv.emplace_back(halton::radicalInverse(index, 2), halton::radicalInverse(index, 3), 1.0f,
                                static_cast<float>(firstView));
            }
            const double side = 2.0 * view.info.y;
            measure = static_cast<float>(side * side / n);
        } else {
            // The spot's cone around its axis, or the whole sphere of a point light (its cube face
            // by the direction's major axis). The cone's axis is the spot direction, so the accepted
            // set turns with the light: lights move smoothly under rotation instead of popping in and
            // out at the cone's edge.
            const bool point = type == GIS_LIGHT_POINT;
            const double cosOuter =
                point ? -1.0 : std::clamp(static_cast<double>(light.direction.w), -1.0, 1.0);
            const halton::ConeSamples& samples = cone(mLightCones[static_cast<size_t>(i)], cosOuter, n);
            draws += samples.draws;
            capped = capped || samples.capped;
            const halton::Frame frame = halton::frameAround(glm::vec3(light.direction));
            const glm::vec3 origin(light.position);
            const int count = static_cast<int>(samples.directions.size());
            for (int k = 0; k < count; ++k) {
                const glm::vec3 d = frame.toWorld(samples.directions[static_cast<size_t>(k)]);
                int view = firstView;
                if (point) {
                    const glm::vec3 a = glm::abs(d);
                    const int face = (a.x >= a.y && a.x >= a.z) ? (d.x >= 0.0f ? 0 : 1)
                                     : (a.y >= a.z)             ? (d.y >= 0.0f ? 2 : 3)
                                                                : (d.z >= 0.0f ? 4 : 5);
                    view += face;
                }
                glm::vec4 sample(0.0f, 0.0f, 0.0f, static_cast<float>(view));
                const glm::vec4 clip = lights.views[view].viewProj * glm::vec4(origin + d, 1.0f);
                if (clip.w > 1e-6f) { // behind the light: no image point
                    glm::vec2 ndc = glm::vec2(clip) / clip.w;
                    if (point) ndc = glm::clamp(ndc, glm::vec2(-1.0f), glm::vec2(1.0f)); // face seams
                    if (std::abs(ndc.x) <= 1.0f && std::abs(ndc.y) <= 1.0f) // inside the RSM frustum
                        sample = glm::vec4(ndc * 0.5f + 0.5f, 1.0f, static_cast<float>(view));
                }
                uv.push_back(sample);
            }
            if (count > 0) measure = static_cast<float>(2.0 * kPi * (1.0 - cosOuter) / count);
        }
        const int count = static_cast<int>(uv.size()) - first;
        if (count > 0) ranges.push_back({first, count, i, measure});
    }
    counters["halton_draws"] = draws;
    counters["cone_capped"] = capped ? 1 : 0;
    const int total = static_cast<int>(uv.size());
    counters["positive_count"] = total;
    if (total == 0) return 0;
    mSamples.upload(0, static_cast<GLsizeiptr>(uv.size() * sizeof(glm::vec4)), uv.data());

    {
        gl::Pass pass(timer, "vpl_place");
        const PlacePositiveProgram& p = mPlacePositive;
        pass.use(p.program).set(p.rsmSize, in.rsmSize);
        pass.texture(p.position, in.get("lights.rsm.position"))
            .texture(p.normal, in.get("lights.rsm.normal"))
            .texture(p.flux, in.get("lights.rsm.flux"));
        pass.buffer(p.vpls, mVpls).buffer(p.samples, mSamples).buffer(p.stats, mStats);
        for (const Range& r : ranges) {
            pass.set(p.first, r.first)
                .set(p.count, r.count)
                .set(p.light, r.light)
                .set(p.sampleMeasure, r.measure);
            // Each dispatch adds to the counts the previous one wrote.
            pass.dispatch(1).barrier(GL_SHADER_STORAGE_BARRIER_BIT);
        }
        pass.barrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    }
    return total;
}

int SecondOrder::placeNegative(const FrameInputs& in, const ParamSet& params, int positiveCount,
                               gl::PassTimer& timer, Counters& counters) {
    const shader::FrameUniforms& f = *in.frame;
    const int target = std::min(mNegativeSlots * kCandidatesPerNegative, kMaxCandidates);
    counters["negative_candidates"] = 0;
    if (target <= 0 || positiveCount <= 0) return 0;

    // The camera's frustum: the axis, the four corner directions (their spherical quadrilateral is
    // the frustum's solid angle) and the cone that encloses them. Directions only (digest S.4 case
    // 17): the eye projects to x = y = w = 0, so viewProj's rows x, y and w map a direction d to the
    // clip coordinates of eye + d, and their inverse maps an image point back to its direction.
    // Unprojecting near-plane points or projecting eye + d instead lost the directions to fp32
    // rounding far from the origin (a 1 mm ulp at 1e4 m against a 5 cm near plane): the candidates,
    // and with them the negative lights, moved.
    glm::dmat3 rows; // rows[c]: column c of viewProj's rows x, y, w
    for (int c = 0; c < 3; ++c) rows[c] = glm::dvec3(f.viewProj[c][0], f.viewProj[c][1], f.viewProj[c][3]);
    const double det = glm::determinant(rows);
    if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return 0;
    const glm::dmat3 inverseRows = glm::inverse(rows);
    bool ok = true;
    const glm::vec3 centre(inverseRows * glm::dvec3(0.0, 0.0, 1.0));
    const glm::vec2 cornerNdc[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    glm::dvec3 corners[4];
    for (int i = 0; i < 4; ++i) {
        const glm::vec3 c(inverseRows * glm::dvec3(cornerNdc[i], 1.0));
        const float len = glm::length(c);
        ok = ok && finite(c) && len > 1e-20f;
        corners[i] = ok ? glm::dvec3(c / len) : glm::dvec3(0, 0, 1);
    }
    const float centreLen = glm::length(centre);
    if (!ok || !finite(centre) || !(centreLen > 1e-20f)) return 0;
    const glm::dvec3 axis = glm::dvec3(centre / centreLen);
    double cosCorner = 1.0;
    for (const auto& c : corners) cosCorner = std::min(cosCorner, glm::dot(axis, c));
    cosCorner = std::clamp(cosCorner - 1e-4, -1.0, 1.0); // margin: corner rays stay inside the cone
    const double frustumSolidAngle = halton::frustumSolidAngle(corners);

    // About 2/pi of an enclosing cone lies inside a square frustum, less for wide images: twice the
    // target leaves room for aspect ratios up to about 3:1.
    const halton::ConeSamples& samples = cone(mCameraCone, cosCorner, 2 * target);
    const halton::Frame frame = halton::frameAround(glm::vec3(axis));
    std::vector<glm::ivec4> pixels;
    pixels.reserve(static_cast<size_t>(target));
    for (const glm::vec3& local : samples.directions) {
        if (static_cast<int>(pixels.size()) >= target) break;
        const glm::dvec3 xyw = rows * glm::dvec3(frame.toWorld(local));
        if (!(xyw.z > 1e-6)) continue;
        const glm::vec2 ndc(xyw.x / xyw.z, xyw.y / xyw.z);
        if (!(std::abs(ndc.x) <= 1.0f && std::abs(ndc.y) <= 1.0f)) continue;
        const int x = std::clamp(static_cast<int>((ndc.x * 0.5f + 0.5f) * static_cast<float>(in.width)), 0,
                                 in.width - 1);
        const int y = std::clamp(static_cast<int>((ndc.y * 0.5f + 0.5f) * static_cast<float>(in.height)), 0,
                                 in.height - 1);
        pixels.emplace_back(x, y, 1, 0);
    }
    const int candidates = static_cast<int>(pixels.size());
    counters["negative_candidates"] = candidates;
    if (candidates == 0) return 0;
    mCandidates.upload(0, static_cast<GLsizeiptr>(pixels.size() * sizeof(glm::ivec4)), pixels.data());

    {
        gl::Pass pass(timer, "negative_place");
        const PlaceNegativeProgram& p = mPlaceNegative;
        pass.use(p.program)
            .set(p.positiveCount, positiveCount)
            .set(p.negativeCount, mNegativeSlots)
            .set(p.candidateCount, candidates)
            .set(p.frustumSolidAngle, static_cast<float>(frustumSolidAngle))
            .set(p.minDistance, vplMinDistance(params, in.sceneSize))
            .set(p.minCosView, kMinCosView);
        pass.texture(p.position, in.get("gbuffer.position")).texture(p.normal, in.get("gbuffer.normal"));
        pass.buffer(p.vpls, mVpls).buffer(p.candidates, mCandidates).buffer(p.stats, mStats);
        pass.dispatch(1).barrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    }
    return mNegativeSlots;
}

void SecondOrder::gather(gl::Pass& pass, const gl::Texture& position, const gl::Texture& normal,
                         const ParamSet& params, float sceneSize, int slots, Counters& counters) {
    const GatherProgram& g = mGather;
    pass.use(g.program).set(g.minDistance, vplMinDistance(params, sceneSize));
    g.transport.set(pass, params, sceneSize, false, 0.0f, nullptr);
    pass.texture(g.position, position).texture(g.normal, normal).buffer(g.stats, mStats);
    pass.blendAdd(); // signed sums: negative lights carry negative flux
    counters["vpl_batches"] = mBatches.forEach(mVpls, slots, [&](int count, int first) {
        pass.set(g.vplCount, count).set(g.batchFirst, first).drawFullscreen(mEmptyVao);
    });
}

void SecondOrder::execute(const FrameInputs& in, const ParamSet& params, gl::PassTimer& timer,
                          Counters& counters) {
    const float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(mResolveFbo.id(), GL_COLOR, 0, zero);
    for (const char* name : {"positive_count", "positive_valid", "halton_draws", "cone_capped",
                             "negative_candidates", "negative_count", "vpl_count", "vpl_batches",
                             "covered_pixels", "fixup_pixels", "negative_clamped_fraction"})
        counters[name] = 0;
    counters["lowres_fraction"] = 1;

    mPositiveSlots = in.lightEnabled ? params.getInt("positive_count") : 0;
    mNegativeSlots = std::clamp(params.getInt("negative_count"), 0, kMaxNegative);
    if (!in.frame || !in.find("gbuffer.position") || !in.find("gbuffer.normal") ||
        !in.find("gbuffer.albedo") || !in.find("lights.rsm.position") || in.rsmSize <= 0 ||
        in.lightViews <= 0 || !in.lights || in.width <= 0 || in.height <= 0)
        mPositiveSlots = 0;
    if (mPositiveSlots <= 0) {
        mPositiveSlots = mNegativeSlots = 0;
        return; // no light: the indirect term is exactly 0
    }

    const GLuint clearStats[kStatsWords] = {};
    mStats.upload(0, sizeof clearStats, clearStats);
    mPositiveSlots = placePositive(in, timer, counters);
    if (mPositiveSlots == 0) {
        mNegativeSlots = 0;
        return;
    }
    mNegativeSlots = placeNegative(in, params, mPositiveSlots, timer, counters);
    const int slots = mPositiveSlots + mNegativeSlots;
    const int factor = std::clamp(params.getInt("lowres_factor"), 1, 8);
    const int lowW = (in.width + factor - 1) / factor, lowH = (in.height + factor - 1) / factor;
    const double threshold = params.getFloat("discontinuity_threshold");
    const bool fixup = threshold < kNoFixupThreshold;
    // Threshold 0 flags every covered pixel (discontinuity.frag), so no low-res value is ever used.
    const bool lowres = threshold > 0.0;
    const gl::Texture& position = in.get("gbuffer.position");
    const gl::Texture& normal = in.get("gbuffer.normal");

    if (lowres) {
        {
            gl::Pass pass(timer, "lowres_gbuffer");
            const LowGeometryProgram& lg = mLowGeometry;
            pass.target(mLowGeometryFbo, lowW, lowH).use(lg.program).set(lg.factor, factor);
            pass.texture(lg.position, position).texture(lg.normal, normal).drawFullscreen(mEmptyVao);
        }
        gl::Pass pass(timer, "lowres_gather");
        pass.target(mLowIrradianceFbo, lowW, lowH).clearColor(1);
        gather(pass, mLowPosition, mLowNormal, params, in.sceneSize, slots, counters);
    }

    GLuint flagged = 0;
    if (fixup) {
        {
            gl::Pass pass(timer, "discontinuity");
            const DiscontinuityProgram& d = mDiscontinuity;
            pass.target(mFlagFbo, in.width, in.height).clearColor(1).clearDepthStencil(1.0f, 0);
            pass.use(d.program)
                .set(d.factor, factor)
                .set(d.lowSize, glm::ivec2(lowW, lowH))
                .set(d.threshold, static_cast<float>(threshold));
            pass.texture(d.position, position)
                .texture(d.normal, normal)
                .texture(d.lowPosition, mLowPosition)
                .texture(d.lowNormal, mLowNormal);
            pass.stencilTest(true).stencilFunc(GL_ALWAYS, 1);
            glBeginQuery(GL_SAMPLES_PASSED, mFlaggedQuery.id());
            pass.drawFullscreen(mEmptyVao);
            glEndQuery(GL_SAMPLES_PASSED);
        }
        gl::Pass pass(timer, "fixup_gather");
        pass.target(mFixupFbo, in.width, in.height).clearColor(1);
        pass.stencilTest(false).stencilFunc(GL_EQUAL, 1);
        gather(pass, position, normal, params, in.sceneSize, slots, counters);
    }

    {
        gl::Pass pass(timer, "resolve");
        const ResolveProgram& r = mResolve;
        const gl::Texture* direct = in.find("direct");
        pass.target(mResolveFbo, in.width, in.height).use(r.program);
        pass.set(r.factor, factor)
            .set(r.lowSize, glm::ivec2(lowW, lowH))
            .set(r.fixup, fixup ? 1 : 0)
            .set(r.hasDirect, direct ? 1 : 0);
        pass.texture(r.position, position)
            .texture(r.albedo, in.get("gbuffer.albedo"))
            .texture(r.direct, direct ? *direct : in.get("gbuffer.albedo"))
            .texture(r.flag, mFlag)
            .texture(r.fullIrradiance, mFullIrradiance)
            .texture(r.lowIrradiance, mLowIrradiance)
            .texture(r.lowPosition, mLowPosition)
            .buffer(r.stats, mStats);
        glBeginQuery(GL_SAMPLES_PASSED, mCoveredQuery.id());
        pass.drawFullscreen(mEmptyVao);
        glEndQuery(GL_SAMPLES_PASSED);
        pass.barrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    }

    // Counters: waits for the frame's last pass (the composite reads its output next anyway).
    GLuint covered = 0;
    glGetQueryObjectuiv(mCoveredQuery.id(), GL_QUERY_RESULT, &covered);
    if (fixup) glGetQueryObjectuiv(mFlaggedQuery.id(), GL_QUERY_RESULT, &flagged);
    GLuint stats[kStatsWords] = {};
    glGetNamedBufferSubData(mStats.id(), 0, sizeof stats, stats);
    const double coveredD = static_cast<double>(covered);
    counters["covered_pixels"] = covered;
    counters["fixup_pixels"] = flagged;
    counters["lowres_fraction"] = covered > 0 ? 1.0 - static_cast<double>(flagged) / coveredD : 1.0;
    counters["negative_clamped_fraction"] = covered > 0 ? static_cast<double>(stats[1]) / coveredD : 0.0;
    counters["vpl_count"] = stats[0];
    counters["negative_count"] = stats[2];
    counters["positive_valid"] = stats[3];
    mSsbc.apply(in, params, mIndirect, timer, counters);
}

std::vector<shader::Vpl> SecondOrder::readVpls(int* positiveCount) const {
    if (positiveCount) *positiveCount = mPositiveSlots;
    std::vector<shader::Vpl> vpls(static_cast<size_t>(mPositiveSlots + mNegativeSlots));
    if (!vpls.empty())
        glGetNamedBufferSubData(mVpls.id(), 0, static_cast<GLsizeiptr>(vpls.size() * sizeof(shader::Vpl)),
                                vpls.data());
    return vpls;
}

} // namespace gis
