// Reference light transport: the estimators behind the modes documented in ReferenceRenderer.h.
//
// All modes share one receiver and one direct-light evaluation, so a difference between two modes is
// exactly the indirect term. Surfaces reflect with scene/Brdf.h (the GL pipeline's model): direct light
// is f(l, wo) E_d with the whole f (diffuse + the specular lobe, GGX or Phong by the frame parameter
// specular_lobe). Indirect estimators at a Lambertian vertex cosine-sample the hemisphere
// (pdf = cos(theta_x) / pi), which cancels the cosine and the 1/pi: a sample's value is rho_x times the
// radiance arriving along the sampled direction (bit for bit the estimator of the Lambertian-only
// renderer). At a vertex with a specular lobe they sample the BRDF (Sampling.h sampleBrdf(): diffuse or
// specular lobe picked by their estimated albedos, weighed by the combined density), so a sample's value
// is f cos / pdf times that radiance.
#include "reference/ReferenceRenderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <glm/gtc/matrix_inverse.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/Error.h"
#include "frame/LightModel.h"
#include "reference/ContentHash.h"
#include "reference/RayScene.h"
#include "reference/Sampling.h"

namespace gis {
namespace {

using reference::kInvPi;
using reference::RawHit;
using reference::RayScene;
using reference::Rng;
using reference::SurfaceHit;

enum class Mode { Direct, OneBounceUnoccluded, OneBounce, Path };

constexpr int kTile = 16;
constexpr int kMaxPassSamples = 64;
constexpr int kMinNoiseSamples = 32; // samples before the noise target may stop a render
constexpr int kMaxImageSide = 16384;
constexpr int kRouletteDepth = 3; // vertices before Russian roulette starts

Mode parseMode(const std::string& name) {
    if (name == "direct") return Mode::Direct;
    if (name == "one-bounce-unoccluded") return Mode::OneBounceUnoccluded;
    if (name == "one-bounce") return Mode::OneBounce;
    if (name == "path") return Mode::Path;
    std::string known;
    for (const std::string& m : referenceModes()) known += (known.empty() ? "" : ", ") + m;
    throw InputError("mode", "unknown reference mode '" + name + "' (known: " + known + ")");
}

glm::vec3 unitOr(const glm::vec3& v, const glm::vec3& fallback) {
    const float len2 = glm::dot(v, v);
    return len2 > 1e-24f && std::isfinite(len2) ? v / std::sqrt(len2) : fallback;
}

glm::vec3 facing(const glm::vec3& n, const glm::vec3& towards) {
    return glm::dot(n, towards) < 0.0f ? -n : n;
}

/// A receiver or bounce vertex: the hit plus the normals turned to the side being shaded.
struct Vertex {
    SurfaceHit hit;
    glm::vec3 n{0.0f};  ///< shading normal on the shaded side
    glm::vec3 ng{0.0f}; ///< geometric normal on the same side (ray offsets, leaving-the-surface test)
    glm::vec3 wo{0.0f}; ///< unit direction towards the previous vertex (the camera for a receiver)
};

/// `wo` is the unit direction from the hit back along the ray that found it.
Vertex orient(const SurfaceHit& hit, const glm::vec3& wo) {
    Vertex v;
    v.hit = hit;
    v.n = facing(hit.shadingNormal, wo);
    v.ng = facing(hit.geometricNormal, wo);
    v.wo = wo;
    return v;
}

/// How the frame parameters shape the reflection model (FrameState built without the frame table, as
/// the unit tests do, gets the defaults: GGX, specular on).
struct ShadingModel {
    brdf::Lobe lobe = brdf::Lobe::Ggx;
    /// effect_specular: the GL direct pass adds the specular lobe unless it is off (auto turns it on
    /// exactly when some material has a specular lobe, and brdf::specular() is 0 for the others, so
    /// auto and on shade alike). Off drops the specular lobe at every vertex here: the reference then
    /// renders the scene with each surface's diffuse lobe rho_d only.
    bool specular = true;

    explicit ShadingModel(const FrameState& state) {
        const ParamSet& fp = state.frameParams;
        if (fp.has("specular_lobe") && fp.getEnum("specular_lobe") == "phong") lobe = brdf::Lobe::Phong;
        if (fp.has("effect_specular") && fp.getEnum("effect_specular") == "off") specular = false;
    }
};

// Lights a reference sample evaluates exactly, one by one; a set larger than this is sampled at
// path vertices: one light chosen with probability proportional to its power into the scene
// (LightModel::sceneFlux), weighted by 1 / that probability (unbiased). Primary vertices always sum
// every light, so a direct-mode render stays exact.
constexpr size_t kExactLights = 4;

class Integrator {
public:
    Integrator(const RayScene& rays, const LightSetModel& lights, float sceneRadius,
               const ShadingModel& shading, Mode mode, int maxDepth, float causticMinRoughness)
        : mRays(rays), mLights(lights), mShading(shading), mMode(mode), mMaxDepth(maxDepth),
          mEps(rays.epsilon()),
          // alpha of that roughness; 0 keeps every caustic (alpha >= kMinAlpha > 0 is never below it)
          mCausticMinAlpha(causticMinRoughness > 0.0f ? brdf::alphaFrom(causticMinRoughness) : 0.0f) {
        double total = 0.0;
        for (const LightModel& l : lights.lights) {
            total += std::max(l.sceneFlux(sceneRadius), 0.0);
            mCdf.push_back(total);
        }
        if (!(total > 0.0)) // no measurable power: uniform selection
            for (size_t i = 0; i < mCdf.size(); ++i) mCdf[i] = static_cast<double>(i + 1);
        const double last = mCdf.empty() ? 1.0 : mCdf.back();
        for (double& c : mCdf) c /= last;
    }

    bool anyLight() const { return !mLights.lights.empty(); }

    /// E_d of light `light` at p for the side of unit normal n: its irradiance on a surface facing it
    /// (LightModel::incidence: I c f window / d^2, or E c) times max(0, n.l) and a hard shadow ray.
    /// `lOut` receives the unit direction to the light. Zero where the direction is undefined (p at
    /// the light's position: digest S.4 case 1).
    glm::vec3 directIrradiance(const LightModel& light, const glm::vec3& p, const glm::vec3& n,
                               const glm::vec3& ngRaw, glm::vec3* lOut = nullptr) const {
        glm::vec3 l, irradiance;
        float dist = 0.0f;
        if (!light.incidence(p, l, dist, irradiance)) return glm::vec3(0.0f);
        if (lOut) *lOut = l;
        const float cosTheta = glm::dot(n, l);
        if (!(cosTheta > 0.0f)) return glm::vec3(0.0f);
        const glm::vec3 e = irradiance * cosTheta;
        if (!(e.x > 0.0f || e.y > 0.0f || e.z > 0.0f)) return glm::vec3(0.0f);
        // Leave from the light's side of the geometric surface so the ray cannot re-hit its own triangle.
        const glm::vec3 origin = p + facing(ngRaw, l) * mEps;
        float tfar = std::numeric_limits<float>::infinity();
        if (std::isfinite(dist)) tfar = glm::length(light.position - origin) - mEps;
        if (tfar > mEps && mRays.occluded(origin, l, 0.0f, tfar)) return glm::vec3(0.0f);
        return e;
    }

    /// Calls `each(light, weight)` for the lights a vertex evaluates: all of them (weight 1) when
    /// `rng` is null or the set is small, else one chosen by power with weight 1 / its probability.
    template <class F> void forLights(Rng* rng, F&& each) const {
        if (!rng || mLights.lights.size() <= kExactLights) {
            for (const LightModel& l : mLights.lights) each(l, 1.0f);
            return;
        }
        const double u = rng->uniform();
        size_t i = static_cast<size_t>(std::lower_bound(mCdf.begin(), mCdf.end(), u) - mCdf.begin());
        i = std::min(i, mCdf.size() - 1);
        const double pmf = mCdf[i] - (i > 0 ? mCdf[i - 1] : 0.0);
        if (pmf > 0.0) each(mLights.lights[i], static_cast<float>(1.0 / pmf));
    }

    /// True when vertex v reflects through a specular lobe (its material has one and effect_specular is
    /// not off).
    bool specularAt(const Vertex& v) const { return mShading.specular && v.hit.surface.hasSpecular(); }

    /// Outgoing radiance of vertex v towards v.wo due to direct light: f(l, wo) E_d, i.e. rho_d / pi E_d
    /// (the Lambertian term, evaluated as before) plus the specular lobe's f_s(l, wo) E_d, as
    /// spotReflected() in shaders/render/lighting.glsl.
    /// `reachedAlpha`: the widest lobe (GGX alpha; 1 for a diffuse lobe) sampled on the path before v, 0
    /// at the receiver. With causticMinRoughness > 0, v's specular lobe is left out when it is smoother
    /// than that roughness AND narrower than reachedAlpha: a sharp lobe found by sampling a wider one
    /// (a caustic, or a glossy-to-sharper-glossy path) is what a path tracer finds only by chance.
    glm::vec3 reflectedDirect(const Vertex& v, float reachedAlpha = 0.0f, Rng* rng = nullptr) const {
        glm::vec3 radiance(0.0f);
        const bool caustic = v.hit.surface.alpha < std::min(mCausticMinAlpha, reachedAlpha);
        const bool specular = specularAt(v) && !caustic;
        forLights(rng, [&](const LightModel& light, float weight) {
            glm::vec3 l(0.0f);
            const glm::vec3 e =
                weight * directIrradiance(light, v.hit.position, v.n, v.hit.geometricNormal, &l);
            if (!(e.x > 0.0f || e.y > 0.0f || e.z > 0.0f)) return;
            radiance += v.hit.albedo * kInvPi * e;
            if (specular) radiance += brdf::specular(v.hit.surface, mShading.lobe, v.n, l, v.wo) * e;
        });
        return radiance;
    }

    /// One sample of the pixel's radiance for the camera ray (origin, dir, tfar).
    glm::vec3 sample(const glm::vec3& origin, const glm::vec3& dir, float tfar, Rng& rng,
                     std::vector<RawHit>& scratch) const {
        SurfaceHit hit;
        if (!mRays.intersectFromCamera(origin, dir, 0.0f, tfar, hit)) return glm::vec3(0.0f); // background
        const Vertex x = orient(hit, -dir); // camera-facing, like the G-buffer normal
        glm::vec3 radiance = x.hit.emission + reflectedDirect(x);
        switch (mMode) {
        case Mode::Direct:
            break;
        case Mode::OneBounce:
            radiance += oneBounce(x, rng);
            break;
        case Mode::OneBounceUnoccluded:
            radiance += oneBounceUnoccluded(x, rng, scratch);
            break;
        case Mode::Path:
            radiance += pathIndirect(x, rng);
            break;
        }
        return radiance;
    }

private:
    /// A bounce direction w leaving x on its shaded side and the sample's weight f cos / pdf (for a
    /// Lambertian vertex exactly rho_d). False when the path ends here (nothing sampled, or zero weight).
    ///
    /// Lambertian vertex: cosine-distributed direction around the shading normal. Where shading and
    /// geometric normals differ (smooth-shaded meshes) the lobe can dip below the geometric surface by
    /// the angle a between them; such a direction is mirrored back above it rather than dropped, so no
    /// energy is lost (the directional bias covers a probability of about a^2 / 4). False only for a
    /// direction in the surface plane.
    ///
    /// Vertex with a specular lobe: Sampling.h sampleBrdf() (the density must stay exact there, so a
    /// direction below the geometric surface is dropped instead: it loses a probability of about a^2 / 4
    /// of the diffuse lobe and, for the specular lobe, the part of it past the geometric horizon).
    bool sampleBounce(const Vertex& x, Rng& rng, glm::vec3& w, glm::vec3& weight,
                      float* lobeAlpha = nullptr) const {
        if (lobeAlpha) *lobeAlpha = 1.0f; // the diffuse lobe
        if (specularAt(x)) {
            const float uPick = rng.uniform();
            const float u1 = rng.uniform();
            const float u2 = rng.uniform();
            reference::BrdfSample bs;
            if (!reference::sampleBrdf(x.hit.surface, mShading.lobe, x.n, x.wo, uPick, u1, u2, bs))
                return false;
            w = bs.wi;
            weight = bs.weight;
            if (lobeAlpha && bs.specular) *lobeAlpha = x.hit.surface.alpha;
            return glm::dot(w, x.ng) > 0.0f && (weight.x > 0.0f || weight.y > 0.0f || weight.z > 0.0f);
        }
        const float u1 = rng.uniform();
        const float u2 = rng.uniform();
        w = unitOr(reference::sampleCosine(x.n, u1, u2), x.n);
        const float below = glm::dot(w, x.ng);
        if (below < 0.0f) w = unitOr(w - 2.0f * below * x.ng, x.ng);
        weight = x.hit.albedo;
        return glm::dot(w, x.ng) > 0.0f;
    }

    // L_1 with visibility: the first surface y along w, seen from its x-facing side, reflects its direct
    // light through its whole BRDF towards x. Estimate: (f_x cos / pdf) * L_r(y) (rho_x * L_r(y) for a
    // Lambertian x).
    glm::vec3 oneBounce(const Vertex& x, Rng& rng) const {
        glm::vec3 w, weight;
        float lobeAlpha = 1.0f;
        if (!sampleBounce(x, rng, w, weight, &lobeAlpha)) return glm::vec3(0.0f);
        SurfaceHit hit;
        if (!mRays.intersect(x.hit.position + x.ng * mEps, w, 0.0f, std::numeric_limits<float>::infinity(),
                             hit))
            return glm::vec3(0.0f);
        return weight * reflectedDirect(orient(hit, -w), lobeAlpha, &rng);
    }

    // L_1 without visibility between x and y. Changing the area integral to directions at x turns
    // dA_y cos(theta_y) / |x - y|^2 into d(omega) for EVERY surface the line crosses, so one cosine
    // sample sums L_r(y) over all crossings y whose light-facing side faces x (cos(theta_y) > 0); the
    // ratio of y's shading to geometric cosine is taken as 1 (exact for flat-shaded meshes). Each y
    // still needs its own shadow ray to the light (it must be in the RSM). No 1/d^2 appears, so there
    // is no singularity where y approaches x.
    // Specular surfaces: y reflects diffusely only (rho_y / pi E_d: the RSM's flux is the diffusely
    // reflected flux, the VPL a diffuse emitter), while x gathers through its whole BRDF (a sample
    // weighs f_x cos / pdf instead of rho_x), i.e. what the VPL gather converges to with the receiver's
    // specular lobe and without the VPLs' own glossy lobes.
    glm::vec3 oneBounceUnoccluded(const Vertex& x, Rng& rng, std::vector<RawHit>& hits) const {
        glm::vec3 w, weight;
        if (!sampleBounce(x, rng, w, weight) || !anyLight()) return glm::vec3(0.0f);
        const glm::vec3 origin = x.hit.position + x.ng * mEps;
        mRays.intersectAll(origin, w, 0.0f, std::numeric_limits<float>::infinity(), hits);
        glm::vec3 sum(0.0f);
        for (const RawHit& raw : hits) {
            const SurfaceHit y = mRays.resolve(raw, origin, w);
            forLights(&rng, [&](const LightModel& light, float lightWeight) {
                glm::vec3 l, irradiance;
                float dist = 0.0f;
                if (!light.incidence(y.position, l, dist, irradiance)) return;
                const glm::vec3 nLight = facing(y.shadingNormal, l); // the RSM's light-facing normal
                if (!(glm::dot(nLight, -w) > 0.0f)) return;          // x behind y's lit side
                sum += lightWeight * y.albedo * kInvPi *
                       directIrradiance(light, y.position, nLight, y.geometricNormal);
            });
        }
        return weight * sum;
    }

    // Multi-bounce path: next-event estimation to the delta light at every vertex (the only way to reach
    // it), emission where a bounce ray hits an emissive surface (reached by BRDF sampling only, so no
    // MIS weight is needed), Russian roulette from vertex kRouletteDepth on with survival probability
    // min(max weight, 0.95), the weight being this vertex's f cos / pdf (rho for a Lambertian vertex).
    glm::vec3 pathIndirect(const Vertex& first, Rng& rng) const {
        glm::vec3 radiance(0.0f);
        glm::vec3 throughput(1.0f);
        Vertex v = first;
        float reachedAlpha = 0.0f; // widest lobe sampled so far
        for (int depth = 1; depth < mMaxDepth; ++depth) {
            glm::vec3 w, weight;
            float lobeAlpha = 1.0f;
            if (!sampleBounce(v, rng, w, weight, &lobeAlpha)) break;
            reachedAlpha = std::max(reachedAlpha, lobeAlpha);
            throughput *= weight;
            if (depth >= kRouletteDepth) {
                // Survival follows this vertex's sample weight (not the accumulated throughput), so on
                // grey surfaces the weight of a surviving path stays constant instead of jumping by 1/q.
                const glm::vec3& a = weight;
                const float survive = std::min(std::max({a.x, a.y, a.z}), 0.95f);
                if (!(survive > 0.0f) || rng.uniform() >= survive) break;
                throughput /= survive;
            }
            SurfaceHit hit;
            if (!mRays.intersect(v.hit.position + v.ng * mEps, w, 0.0f,
                                 std::numeric_limits<float>::infinity(), hit))
                break;
            v = orient(hit, -w);
            radiance += throughput * (v.hit.emission + reflectedDirect(v, reachedAlpha, &rng));
        }
        return radiance;
    }

    const RayScene& mRays;
    const LightSetModel& mLights;
    std::vector<double> mCdf; ///< cumulative selection probabilities, by power
    const ShadingModel& mShading;
    Mode mMode;
    int mMaxDepth;
    float mEps;
    float mCausticMinAlpha;
};

// Sums of each pixel's samples and of their squares (the squares give the pixel mean's variance).
void addSanitized(double* acc, double* accSquares, const glm::vec3& c) {
    for (int i = 0; i < 3; ++i)
        if (std::isfinite(c[i]) && c[i] > 0.0f) {
            const auto v = static_cast<double>(c[i]);
            acc[i] += v;
            accSquares[i] += v * v;
        }
}

// Variance of the mean of n samples from their sum and sum of squares (unbiased; 0 against rounding).
double varianceOfMean(double sum, double sumSquares, int n) {
    if (n < 2) return 0.0;
    const double dn = n;
    return std::max(0.0, (sumSquares - sum * sum / dn) / (dn * (dn - 1.0)));
}

} // namespace

std::vector<std::string> referenceModes() {
    return {"direct", "one-bounce-unoccluded", "one-bounce", "path"};
}

void validateReferenceOptions(const ReferenceOptions& options) {
    parseMode(options.mode);
    if (options.spp <= 0) throw InputError("spp", "must be at least 1, got " + std::to_string(options.spp));
    if (!std::isfinite(options.timeBudgetSeconds) || options.timeBudgetSeconds < 0)
        throw InputError("time_budget", "must be a finite number of seconds >= 0 (0 = none)");
    if (options.maxDepth < 1 || options.maxDepth > 1024)
        throw InputError("max_depth", "must be in [1, 1024], got " + std::to_string(options.maxDepth));
    if (options.threads < 0) throw InputError("threads", "must be >= 0 (0 = all hardware threads)");
    if (!(options.causticMinRoughness >= 0.0f && options.causticMinRoughness <= 1.0f))
        throw InputError("caustic_min_roughness", "must be in [0, 1] (0 = every caustic)");
    if (!std::isfinite(options.noiseTarget) || options.noiseTarget < 0 || options.noiseTarget >= 1)
        throw InputError("noise_target", "must be a relative noise in [0, 1) (0 = none, 0.01 = 1%)");
}

ReferenceRenderer::ReferenceRenderer(const Scene& scene)
    : mRays(std::make_unique<reference::RayScene>(scene)), mSceneDigest(reference::sceneDigest(scene)),
      mBounds(scene.bounds) {}

ReferenceRenderer::~ReferenceRenderer() = default;

ReferenceImage ReferenceRenderer::render(const FrameState& state, const ReferenceOptions& options,
                                         const std::function<void(int, double)>& progress) {
    validateReferenceOptions(options);
    const Mode mode = parseMode(options.mode);
    const int w = state.width, h = state.height;
    if (w <= 0 || w > kMaxImageSide)
        throw InputError("width", "must be in [1, 16384], got " + std::to_string(w));
    if (h <= 0 || h > kMaxImageSide)
        throw InputError("height", "must be in [1, 16384], got " + std::to_string(h));

    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };

    // Rays through the pipeline's own projection: unproject NDC at the near (z = -1) and far (z = 1)
    // planes, so the reference sees exactly the GL frustum, clipping included. Double precision keeps
    // the inverse accurate for large far/near ratios.
    const glm::dmat4 invViewProj = glm::inverse(glm::dmat4(cameraViewProj(state.camera, w, h)));
    // The lights exactly as the GL pipeline sees them (frame/LightModel.h).
    const LightSetModel lights = makeLightSet(state, mBounds);
    const ShadingModel shading(state);
    const Integrator integrator(*mRays, lights, std::max(mBounds.radius(), 1e-6f), shading, mode,
                                options.maxDepth, options.causticMinRoughness);

    // A pixel-centre direct render has no random decision: one sample is the exact answer.
    const int target = (mode == Mode::Direct && !options.jitter) ? 1 : options.spp;
    const size_t pixels = static_cast<size_t>(w) * static_cast<size_t>(h);
    std::vector<double> accum(pixels * 3, 0.0), accumSquares(pixels * 3, 0.0);
    const int tilesX = (w + kTile - 1) / kTile, tilesY = (h + kTile - 1) / kTile;

    auto renderPass = [&](int firstSample, int count) {
        tbb::parallel_for(
            tbb::blocked_range<int>(0, tilesX * tilesY, 1), [&](const tbb::blocked_range<int>& r) {
                std::vector<RawHit> scratch;
                for (int tile = r.begin(); tile != r.end(); ++tile) {
                    const int x0 = (tile % tilesX) * kTile, y0 = (tile / tilesX) * kTile;
                    for (int py = y0; py < std::min(y0 + kTile, h); ++py)
                        for (int px = x0; px < std::min(x0 + kTile, w); ++px) {
                            const size_t index =
                                static_cast<size_t>(py) * static_cast<size_t>(w) + static_cast<size_t>(px);
                            for (int s = firstSample; s < firstSample + count; ++s) {
                                Rng rng(options.seed, index, static_cast<std::uint64_t>(s));
                                const float ox = options.jitter ? rng.uniform() : 0.5f;
                                const float oy = options.jitter ? rng.uniform() : 0.5f;
                                // Rows run top to bottom; NDC y runs bottom to top.
                                const double nx = 2.0 * (px + ox) / w - 1.0;
                                const double ny = 1.0 - 2.0 * (py + oy) / h;
                                glm::dvec4 nearP = invViewProj * glm::dvec4(nx, ny, -1.0, 1.0);
                                glm::dvec4 farP = invViewProj * glm::dvec4(nx, ny, 1.0, 1.0);
                                if (!(std::abs(nearP.w) > 1e-300) || !(std::abs(farP.w) > 1e-300)) continue;
                                const glm::dvec3 a = glm::dvec3(nearP) / nearP.w,
                                                 b = glm::dvec3(farP) / farP.w;
                                const double len = glm::length(b - a);
                                if (!(len > 0.0) || !std::isfinite(len)) continue;
                                const glm::vec3 dir(glm::normalize(b - a));
                                addSanitized(&accum[index * 3], &accumSquares[index * 3],
                                             integrator.sample(glm::vec3(a), dir, static_cast<float>(len),
                                                               rng, scratch));
                            }
                        }
                }
            });
    };

    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);

    // The noise target's signal: the image itself, or (noiseOfIndirect) the image less its direct light,
    // taken from a pixel-centre direct render (exact for one light; the scale of the signal otherwise).
    std::vector<float> directForNoise;
    if (options.noiseTarget > 0 && options.noiseOfIndirect && mode != Mode::Direct) {
        ReferenceOptions direct = options;
        direct.mode = "direct";
        direct.jitter = false;
        direct.noiseTarget = 0;
        direct.timeBudgetSeconds = 0;
        directForNoise = render(state, direct).rgb;
    }
    // Relative noise of the current mean over the pixels it covers: sqrt(mean variance of the mean) over
    // the signal's RMS. +infinity while the signal is 0 (nothing to measure against yet).
    auto currentNoise = [&](int n) {
        double variance = 0, signal = 0;
        size_t covered = 0;
        for (size_t p = 0; p < pixels; ++p) {
            const double* a = &accum[p * 3];
            if (!(a[0] > 0 || a[1] > 0 || a[2] > 0)) continue;
            ++covered;
            for (int c = 0; c < 3; ++c) {
                variance += varianceOfMean(a[c], accumSquares[p * 3 + c], n);
                double v = a[c] / n;
                if (!directForNoise.empty()) v = std::max(0.0, v - directForNoise[p * 3 + c]);
                signal += v * v;
            }
        }
        if (covered == 0 || !(signal > 0)) return std::numeric_limits<double>::infinity();
        return std::sqrt(variance / signal);
    };

    int done = 0;
    int passSize = 1;
    while (done < target) {
        int count = std::min(passSize, target - done);
        if (options.timeBudgetSeconds > 0 && done > 0) {
            // Size the pass to what is likely to fit the remaining time, so the budget is not overrun
            // by a long pass; at least one sample per pass keeps making progress.
            const double perSample = elapsed() / done;
            const double remaining = options.timeBudgetSeconds - elapsed();
            if (perSample > 0) count = std::max(1, std::min(count, static_cast<int>(remaining / perSample)));
        }
        arena.execute([&] { renderPass(done, count); });
        done += count;
        if (progress) progress(done, elapsed());
        if (options.timeBudgetSeconds > 0 && elapsed() >= options.timeBudgetSeconds) break;
        // Few samples underestimate the variance of rare bright paths: the target is trusted from
        // kMinNoiseSamples on.
        if (options.noiseTarget > 0 && done >= kMinNoiseSamples && currentNoise(done) <= options.noiseTarget)
            break;
        passSize = std::min(passSize * 2, kMaxPassSamples);
    }

    ReferenceImage image;
    image.width = w;
    image.height = h;
    image.spp = done;
    image.mode = options.mode;
    image.key = reference::requestKey(mSceneDigest, state, options);
    image.rgb.resize(pixels * 3);
    const double inv = 1.0 / std::max(done, 1);
    for (size_t i = 0; i < pixels * 3; ++i) {
        const auto v = static_cast<float>(accum[i] * inv);
        image.rgb[i] = std::isfinite(v) && v > 0.0f ? v : 0.0f;
    }
    // A deterministic render is exact (variance 0); one sample of a random one says nothing about its
    // spread (left empty: unknown).
    if (target == 1 && mode == Mode::Direct && !options.jitter) {
        image.variance.assign(pixels * 3, 0.0f);
    } else if (done >= 2) {
        image.variance.resize(pixels * 3);
        for (size_t i = 0; i < pixels * 3; ++i) {
            const auto v = static_cast<float>(varianceOfMean(accum[i], accumSquares[i], done));
            image.variance[i] = std::isfinite(v) ? v : 0.0f;
        }
    }
    image.seconds = elapsed();
    return image;
}

} // namespace gis
