// CPU ground-truth renderer (DESIGN.md §4 "Reference"): Monte Carlo light transport on Embree ray
// queries, seeing exactly the scene, camera and lights the GL pipeline sees, so that a GL image
// and a reference image differ only by the light transport.
//
// Notation: x a receiver (first hit of the camera ray through a pixel centre), n_x its shading normal
// turned towards the camera, rho the diffuse albedo rho_d of scene/Brdf.h, L_e emission, and for the light
// (position p_l, intensity I in cd, colour c, spot factor f = t^2 with t = clamp((cos - cosOuter) /
// max(cosInner - cosOuter, 1e-4), 0, 1), f = 1 for point lights) the direct irradiance
//     E_d(x) = I c f(x) max(0, n_x . l) / |p_l - x|^2 * V(x, p_l)       (0 when |p_l - x|^2 == 0).
// Modes (the integral each estimates per pixel; L is outgoing radiance towards the camera):
//  - "direct":                L = L_e(x) + rho_x / pi * E_d(x)
//  - "one-bounce-unoccluded": direct + L_1 with
//        L_1(x) = rho_x / pi * Integral_A L_r(y) cos(theta_x) cos(theta_y) / |x - y|^2 dA_y,
//        L_r(y) = rho_y / pi * E_d(y), over every light-visible surface point y, WITHOUT the visibility
//        between x and y; cos(theta_y) uses y's light-facing normal and is 0 when x lies behind y's lit
//        side. This is what RSM/VPL gathering without indirect shadows and without a distance clamp
//        converges to (rsm_gather with one VPL per RSM texel and min_distance 0).
//  - "one-bounce":            direct + L_1 with the visibility V(x, y) inside the integral (the rendering
//        equation truncated after one diffuse bounce of the light's direct illumination).
//  - "path":                  the rendering equation, paths of up to maxDepth
//        surface vertices (1 = direct only), Russian roulette after vertex 3, next-event estimation
//        to the (delta) light at every vertex, emission added where a path hits an emissive surface.
// The one-bounce modes bounce the light source only: emissive surfaces are seen directly but do not
// light other surfaces (as in the GL pipeline, whose VPLs come from the lights' RSMs).
//
// Non-diffuse surfaces: every rho / pi above stands for the whole BRDF f(l, wo) of scene/Brdf.h (lobe
// and specular switch from the frame parameters specular_lobe and effect_specular), and bounces sample
// that BRDF (ReferenceRenderer.cpp, README.md); for Lambertian materials everything is as written.
//
// Sampling: one camera ray through each pixel centre per sample (GL's single raster sample), or a
// uniformly jittered point in the pixel with `jitter` (box filter). Estimators are in README.md.
//
// Determinism: each (seed, pixel, sample) has its own random stream and each pixel sums its samples in
// order, so an image depends on the options and not on the thread count or schedule. With a time
// budget the sample count reached depends on the machine; the image for a given count does not.
//
// Threading: render() runs on TBB worker threads; one ReferenceRenderer may be used from one thread at a
// time. The renderer copies what it needs from the scene.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "frame/FrameState.h"
#include "scene/Scene.h"

namespace gis {

namespace reference {
class RayScene;
}

struct ReferenceOptions {
    std::string mode = "one-bounce";
    int spp = 64; ///< samples per pixel to stop at, >= 1
    double timeBudgetSeconds =
        0;            ///< also stop once this much time has passed (checked between passes); 0 = none
    int maxDepth = 8; ///< path mode: surface vertices per path, >= 1
    std::uint64_t seed = 1;
    bool jitter = false; ///< box-filtered jitter inside each pixel instead of the pixel centre
    int threads = 0;     ///< 0 = all hardware threads
    /// Caustic regularisation (perceptual roughness, [0, 1]; 0 = none, the unbiased default): at a bounce
    /// vertex, the lights' reflection through a specular lobe smoother than this is left out when the
    /// path found the vertex by sampling a wider lobe (diffuse, or a rougher specular one): paths
    /// light -> sharp lobe -> wider lobe ... -> camera, e.g. caustics. A path tracer finds those for a
    /// point light only by chance and they dominate its noise (README.md "Non-diffuse surfaces"); the
    /// GL pipeline renders them only from lobes at least glossy_split rough (glossy VPLs), so glossy_split
    /// is the matching value. Lobes seen from the camera, or through sharper ones (a mirror), keep their
    /// highlights.
    float causticMinRoughness = 0.0f;
    /// Also stop once the image's relative noise (sqrt of the mean variance of the pixel means over the
    /// signal's RMS, over the pixels it covers) is at most this, checked between passes from 32 samples
    /// on; 0 = none. `spp` stays the upper bound.
    double noiseTarget = 0;
    /// Measure the noise target against the image less its direct light (what a GI comparison
    /// measures), not the whole image.
    bool noiseOfIndirect = false;
};

struct ReferenceImage {
    int width = 0;
    int height = 0;
    std::vector<float> rgb; ///< linear radiance, 3 floats per pixel, rows top to bottom; finite and >= 0
    int spp = 0;            ///< samples per pixel actually taken
    /// Per pixel and channel, the variance of the pixel's mean (its noise squared, from the samples'
    /// spread); zeros for a deterministic render, empty when unknown (one sample of a random estimator,
    /// or an EXR from elsewhere).
    std::vector<float> variance;
    double seconds = 0; ///< wall-clock render time (0 for a cache hit's load)
    std::string mode;
    std::string key; ///< referenceCacheKey() of the request (may be empty for images read from elsewhere)
};

class ReferenceRenderer {
public:
    /// Builds the ray-tracing acceleration structure (seconds for millions of triangles).
    explicit ReferenceRenderer(const Scene& scene);
    ~ReferenceRenderer();
    ReferenceRenderer(const ReferenceRenderer&) = delete;
    ReferenceRenderer& operator=(const ReferenceRenderer&) = delete;

    /// Renders `state` (camera, lights, width, height, and the frame parameters max_lights, specular_lobe
    /// and effect_specular; the rest of the parameter tables is ignored).
    /// `progress` is called after each pass with the samples per pixel and seconds so far.
    /// Throws InputError naming the option for bad options or sizes.
    /// "direct" without jitter is deterministic, so it stops after one sample (reported spp = 1).
    ReferenceImage render(const FrameState& state, const ReferenceOptions& options,
                          const std::function<void(int spp, double seconds)>& progress = {});

private:
    std::unique_ptr<reference::RayScene> mRays;
    std::string mSceneDigest; // scene part of the cache key, hashed once
    Bounds mBounds;
};

/// "direct", "one-bounce-unoccluded", "one-bounce", "path".
std::vector<std::string> referenceModes();

/// Throws InputError(option name, ...) when an option is out of range.
void validateReferenceOptions(const ReferenceOptions& options);

/// Content hash (hex, 32 digits) of everything the image depends on: geometry, materials, textures,
/// camera, light, size, specular_lobe, effect_specular (off or not), mode, spp, time budget, seed, depth,
/// jitter, causticMinRoughness, noiseTarget and noiseOfIndirect (not the thread count).
std::string referenceCacheKey(const Scene& scene, const FrameState& state, const ReferenceOptions& options);

/// Writes a float EXR with channels R, G, B and, when the image has them, variance.R/G/B (the pixel
/// means' variance), and metadata gis:mode, gis:spp, gis:seconds, gis:key (atomic: temp + rename).
/// Throws gis::Error on I/O failure.
void writeReferenceExr(const std::string& path, const ReferenceImage& image);
/// Reads an EXR written by writeReferenceExr (other RGB(A) EXRs load with empty metadata).
/// Throws InputError(path, ...) when the file is missing or unreadable.
ReferenceImage readReferenceExr(const std::string& path);

/// Returns the cached image for the request's key from cacheDir if present (and whole), else renders,
/// writes it there and returns it. cacheDir is created if missing.
ReferenceImage renderReferenceCached(const Scene& scene, const FrameState& state,
                                     const ReferenceOptions& options, const std::string& cacheDir,
                                     bool* cacheHit = nullptr);

} // namespace gis
