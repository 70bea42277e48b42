// Reference renderer against closed-form answers: a Lambertian plane under a point or spot light, a
// closed sphere lit from its centre (one bounce, and all bounces as a geometric series).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <glm/gtc/matrix_inverse.hpp>
#include <gtest/gtest.h>

#include "ReferenceTestScenes.h"
#include "frame/LightModel.h"
#include "reference/ReferenceRenderer.h"

using namespace gis;
using namespace gis::test;

namespace {

// The camera ray through pixel (px, py)'s centre, built independently of the renderer.
void pixelRay(const Camera& cam, int w, int h, int px, int py, glm::dvec3& origin, glm::dvec3& dir) {
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cameraViewProj(cam, w, h)));
    const double nx = 2.0 * (px + 0.5) / w - 1.0, ny = 1.0 - 2.0 * (py + 0.5) / h;
    const glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0), b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
    origin = glm::dvec3(a) / a.w;
    dir = glm::normalize(glm::dvec3(b) / b.w - origin);
}

Scene makePlaneScene(float rho) {
    Scene scene;
    scene.name = "test:plane";
    scene.materials.push_back(diffuse(glm::vec3(rho)));
    scene.meshes.push_back(makeQuadY(0.0f, -5.0f, 5.0f, -5.0f, 5.0f, 0));
    finalizeScene(scene, "plane");
    return scene;
}

// Radiance of the plane y = 0 at p: rho / pi * I * colour * factor * cos / d^2.
glm::dvec3 planeRadiance(const glm::dvec3& p, double rho, const Light& light, double factor) {
    const glm::dvec3 toLight = glm::dvec3(light.position) - p;
    const double d2 = glm::dot(toLight, toLight);
    const double cosTheta = toLight.y / std::sqrt(d2);
    return rho / M_PI * light.intensity * glm::dvec3(light.color) * factor * std::max(cosTheta, 0.0) / d2;
}

// Pixels of the plane y = 0 seen by `cam` (away from its edges) with their points.
template <class F> int forPlanePixels(const Camera& cam, int w, int h, F&& each) {
    int n = 0;
    for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px) {
            glm::dvec3 o, d;
            pixelRay(cam, w, h, px, py, o, d);
            if (d.y >= -1e-3) continue;
            const glm::dvec3 p = o + d * (-o.y / d.y);
            if (std::abs(p.x) > 4.9 || std::abs(p.z) > 4.9) continue;
            each(static_cast<size_t>(py) * w + px, p);
            ++n;
        }
    return n;
}

} // namespace

TEST(ReferenceAnalytic, PlaneUnderPointLightMatchesInverseSquareCosine) {
    const float rho = 0.6f;
    const Scene scene = makePlaneScene(rho);
    const Camera cam = lookAt({0.5f, 2.5f, 3.0f}, {0.0f, 0.0f, 0.0f});
    const Light light = pointLight({0.3f, 1.0f, -0.2f}, 2.5f, {1.0f, 0.5f, 0.25f});
    const int w = 24, h = 24;
    ReferenceRenderer renderer(scene);
    const ReferenceImage img = renderer.render(frameFor(cam, light, w, h), {.mode = "direct", .spp = 1});
    ASSERT_EQ(img.rgb.size(), static_cast<size_t>(w * h * 3));
    const int checked = forPlanePixels(cam, w, h, [&](size_t i, const glm::dvec3& p) {
        const glm::dvec3 expected = planeRadiance(p, rho, light, 1.0);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(img.rgb[i * 3 + c], expected[c], 0.005 * expected[c])
                << "pixel " << i % w << "," << i / w << " channel " << c;
    });
    EXPECT_GT(checked, w * h / 3);
}

TEST(ReferenceAnalytic, PlaneUnderSpotLightUsesGltfConeFalloff) {
    const float rho = 0.5f;
    const Scene scene = makePlaneScene(rho);
    const Camera cam = lookAt({0.0f, 3.0f, 2.0f}, {0.0f, 0.0f, 0.0f});
    Light spot = pointLight({0.1f, 1.5f, 0.0f}, 4.0f);
    spot.type = LightType::Spot;
    spot.direction = glm::normalize(glm::vec3(0.2f, -1.0f, 0.1f));
    spot.innerConeAngle = glm::radians(15.0f);
    spot.outerConeAngle = glm::radians(35.0f);
    const int w = 24, h = 24;
    ReferenceRenderer renderer(scene);
    const ReferenceImage img = renderer.render(frameFor(cam, spot, w, h), {.mode = "direct", .spp = 1});
    int inside = 0, penumbra = 0, outside = 0;
    for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px) {
            glm::dvec3 o, d;
            pixelRay(cam, w, h, px, py, o, d);
            if (d.y >= -1e-3) continue;
            const glm::dvec3 p = o + d * (-o.y / d.y);
            const glm::dvec3 fromLight = glm::normalize(p - glm::dvec3(spot.position));
            const double cd = glm::dot(glm::dvec3(spot.direction), fromLight);
            const double cosOuter = std::cos(double(spot.outerConeAngle)),
                         cosInner = std::cos(double(spot.innerConeAngle));
            const double t = std::clamp((cd - cosOuter) / std::max(cosInner - cosOuter, 1e-4), 0.0, 1.0);
            // Skip pixels right at the cone edges, where float rounding of cos decides in or out.
            if (std::abs(cd - cosOuter) < 1e-4 || std::abs(cd - cosInner) < 1e-4) continue;
            const double expected = planeRadiance(p, rho, spot, t * t).x;
            const double got = img.rgb[(static_cast<size_t>(py) * w + px) * 3];
            EXPECT_NEAR(got, expected, 0.005 * expected + 1e-7) << "pixel " << px << "," << py;
            (t >= 1.0 ? inside : t > 0.0 ? penumbra : outside)++;
        }
    EXPECT_GT(inside, 5);
    EXPECT_GT(penumbra, 5);
    EXPECT_GT(outside, 5);
}

// A wall in the plane z = z0 facing +z, spanning x in [-halfWidth, halfWidth] and y in [0, height].
Mesh makeWallZ(float z0, float halfWidth, float height, int material) {
    Mesh wall;
    wall.name = "wall";
    wall.positions = {
        {-halfWidth, 0, z0}, {halfWidth, 0, z0}, {halfWidth, height, z0}, {-halfWidth, height, z0}};
    wall.normals.assign(4, glm::vec3(0, 0, 1));
    wall.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    wall.indices = {0, 1, 2, 0, 2, 3};
    wall.material = material;
    return wall;
}

TEST(ReferenceAnalytic, PlaneUnderDirectionalLightIsUniformLuxTimesCosine) {
    const float rho = 0.4f;
    const Scene scene = makePlaneScene(rho);
    const Camera cam = lookAt({0.5f, 2.5f, 3.0f}, {0.0f, 0.0f, 0.0f});
    Light sun;
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.5f));
    sun.intensity = 3.0f; // lux
    sun.color = {1.0f, 0.8f, 0.6f};
    const int w = 20, h = 20;
    ReferenceRenderer renderer(scene);
    const ReferenceImage img = renderer.render(frameFor(cam, sun, w, h), {.mode = "direct", .spp = 1});
    // E = E_perp cos(theta), theta the angle between the normal (+y) and the direction to the sun.
    const double cosTheta = -double(sun.direction.y);
    const int n = forPlanePixels(cam, w, h, [&](size_t i, const glm::dvec3&) {
        for (int c = 0; c < 3; ++c) {
            const double expected = rho / M_PI * sun.intensity * sun.color[c] * cosTheta;
            EXPECT_NEAR(img.rgb[i * 3 + static_cast<size_t>(c)], expected, 1e-5 * expected);
        }
    });
    EXPECT_GT(n, w * h / 3);
}

TEST(ReferenceAnalytic, RangeWindowFollowsTheSpecsFalloff) {
    const float rho = 0.5f;
    const Scene scene = makePlaneScene(rho);
    const Camera cam = lookAt({0.0f, 4.0f, 2.5f}, {0.0f, 0.0f, 0.0f});
    Light light = pointLight({0.2f, 0.8f, 0.1f}, 3.0f);
    light.range = 2.0f;
    const int w = 24, h = 24;
    ReferenceRenderer renderer(scene);
    const ReferenceImage img = renderer.render(frameFor(cam, light, w, h), {.mode = "direct", .spp = 1});
    int zero = 0, windowed = 0;
    forPlanePixels(cam, w, h, [&](size_t i, const glm::dvec3& p) {
        const double d = glm::length(p - glm::dvec3(light.position));
        const double r = d / light.range;
        const double window = std::pow(std::clamp(1.0 - r * r * r * r, 0.0, 1.0), 2.0);
        const double expected = planeRadiance(p, rho, light, window).x;
        EXPECT_NEAR(img.rgb[i * 3], expected, 1e-4 * expected + 1e-9) << "distance " << d;
        (window == 0.0 ? zero : windowed)++;
    });
    EXPECT_GT(zero, 10) << "points beyond the range are unlit";
    EXPECT_GT(windowed, 10);
}

TEST(ReferenceAnalytic, TwoLightsEqualTheSumOfEachAlone) {
    // Direct and one bounce (the plane and a wall facing it), with a spot and a point light.
    Scene scene = makePlaneScene(0.6f);
    scene.materials.push_back(diffuse({0.8f, 0.3f, 0.2f}, "red"));
    scene.meshes.push_back(makeWallZ(-1.0f, 2.0f, 3.0f, 1));
    finalizeScene(scene, "plane and wall");
    const Camera cam = lookAt({0.3f, 1.5f, 3.0f}, {0.0f, 0.5f, -0.5f});
    Light a = pointLight({-0.6f, 1.2f, 0.4f}, 2.0f, {1.0f, 0.9f, 0.7f});
    Light b = pointLight({0.7f, 0.9f, -0.3f}, 1.5f, {0.4f, 0.6f, 1.0f});
    b.type = LightType::Spot;
    b.direction = glm::normalize(glm::vec3(-0.2f, -1.0f, -0.4f));
    b.innerConeAngle = 0.4f;
    b.outerConeAngle = 0.8f;
    const int w = 16, h = 16;
    ReferenceRenderer renderer(scene);
    for (const char* mode : {"direct", "one-bounce"}) {
        const ReferenceOptions options{.mode = mode, .spp = std::string(mode) == "direct" ? 1 : 256};
        FrameState both = frameFor(cam, a, w, h);
        both.lights.push_back({"light1", b, true});
        const ReferenceImage ab = renderer.render(both, options);
        const ReferenceImage ia = renderer.render(frameFor(cam, a, w, h), options);
        const ReferenceImage ib = renderer.render(frameFor(cam, b, w, h), options);
        double diff = 0, norm = 0;
        for (size_t i = 0; i < ab.rgb.size(); ++i) {
            const double sum = double(ia.rgb[i]) + double(ib.rgb[i]);
            diff += (ab.rgb[i] - sum) * (ab.rgb[i] - sum);
            norm += sum * sum;
        }
        const double rel = std::sqrt(diff / std::max(norm, 1e-30));
        std::printf("superposition (%s): relative RMS difference %.2e\n", mode, rel);
        // Both modes sum up to four lights exactly at every vertex, and the bounce directions do not
        // depend on the lights: what remains is float rounding (measured: 1e-8).
        EXPECT_LT(rel, 1e-5) << mode;
    }
}

TEST(ReferenceAnalytic, ManyLightsAreSampledByPowerWithoutBias) {
    // Eight point lights (more than the exact-sum limit): a path vertex picks one by power. The one-bounce
    // image converges to the sum of the lights' one-bounce images.
    Scene scene = makePlaneScene(0.7f);
    scene.meshes.push_back(makeWallZ(-1.0f, 3.0f, 3.0f, 0));
    finalizeScene(scene, "plane and wall");
    const Camera cam = lookAt({0.0f, 1.2f, 3.0f}, {0.0f, 0.6f, -0.5f});
    const int w = 12, h = 12;
    ReferenceRenderer renderer(scene);
    FrameState many = frameFor(cam, pointLight({-1.5f, 1.0f, 0.0f}, 0.5f), w, h);
    for (int i = 1; i < 8; ++i)
        many.lights.push_back(
            {"light" + std::to_string(i),
             pointLight({-1.5f + 0.4f * float(i), 0.5f + 0.15f * float(i), 0.3f}, 0.5f + 0.4f * float(i)),
             true});
    const ReferenceOptions options{.mode = "one-bounce", .spp = 512};
    const ReferenceImage sampled = renderer.render(many, options);
    std::vector<double> sum(sampled.rgb.size(), 0.0);
    for (const FrameLight& l : many.lights) {
        const ReferenceImage one = renderer.render(frameFor(cam, l.light, w, h), options);
        for (size_t i = 0; i < sum.size(); ++i) sum[i] += one.rgb[i];
    }
    double diff = 0, norm = 0, meanSampled = 0, meanSum = 0;
    for (size_t i = 0; i < sum.size(); ++i) {
        diff += (sampled.rgb[i] - sum[i]) * (sampled.rgb[i] - sum[i]);
        norm += sum[i] * sum[i];
        meanSampled += sampled.rgb[i];
        meanSum += sum[i];
    }
    std::printf("8 lights sampled by power: relative RMS difference %.3f, mean ratio %.4f\n",
                std::sqrt(diff / norm), meanSampled / meanSum);
    EXPECT_NEAR(meanSampled / meanSum, 1.0, 0.02) << "no bias in the mean";
    EXPECT_LT(std::sqrt(diff / norm), 0.15);
}

TEST(ReferenceAnalytic, OccluderCastsHardShadow) {
    const float rho = 0.5f;
    Scene scene;
    scene.name = "test:shadow";
    scene.materials.push_back(diffuse(glm::vec3(rho)));
    scene.meshes.push_back(makeQuadY(0.0f, -5.0f, 5.0f, -5.0f, 5.0f, 0));
    scene.meshes.push_back(makeQuadY(0.5f, -0.25f, 0.25f, -0.25f, 0.25f, 0)); // blocker half way up
    finalizeScene(scene, "shadow");
    const Light light = pointLight({0.0f, 1.0f, 0.0f}, 1.0f);
    const Camera cam = lookAt({0.0f, 1.2f, 2.5f}, {0.0f, 0.0f, -0.3f});
    const int w = 32, h = 32;
    ReferenceRenderer renderer(scene);
    const ReferenceImage img = renderer.render(frameFor(cam, light, w, h), {.mode = "direct", .spp = 1});
    int shadowed = 0, lit = 0;
    for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px) {
            glm::dvec3 o, d;
            pixelRay(cam, w, h, px, py, o, d);
            if (d.y >= -1e-3) continue;
            // Pixels that see the blocker itself are not about the shadow.
            const glm::dvec3 q = o + d * ((0.5 - o.y) / d.y);
            if (std::abs(q.x) < 0.3 && std::abs(q.z) < 0.3) continue;
            const glm::dvec3 p = o + d * (-o.y / d.y);
            if (std::abs(p.x) > 4.9 || std::abs(p.z) > 4.9) continue; // off the plane
            // The shadow is the blocker projected from the light onto y = 0: the square |x|,|z| < 0.5.
            const double edge = std::max(std::abs(p.x), std::abs(p.z));
            if (std::abs(edge - 0.5) < 0.05) continue; // pixel footprints straddling the edge
            const double got = img.rgb[(static_cast<size_t>(py) * w + px) * 3];
            if (edge < 0.5) {
                EXPECT_EQ(got, 0.0) << "pixel " << px << "," << py;
                ++shadowed;
            } else {
                const double expected = planeRadiance(p, rho, light, 1.0).x;
                EXPECT_NEAR(got, expected, 0.005 * expected) << "pixel " << px << "," << py;
                ++lit;
            }
        }
    EXPECT_GT(shadowed, 10);
    EXPECT_GT(lit, 10);
}

// Closed sphere, point light of intensity I at the centre. Every point of the (ideal) sphere gets the
// direct irradiance E0 = I / R^2 and reflects radiosity B0 = rho E0 uniformly. Inside a closed surface of
// uniform radiosity B the whole hemisphere above any point shows radiance B / pi, so the irradiance is
// Integral (B / pi) cos dw = B: the first bounce gives E1 = rho I / R^2 everywhere and
//     L1 = rho / pi * E1 = rho^2 I / (pi R^2)
// for both one-bounce modes (the sphere is convex: nothing occludes x from y, and every y is lit).
// Discretisation: the mesh's vertices lie on the sphere and its faces are inscribed chords, so y lies at
// distances in [R cos(a), R] with a about half a face's angular size (pi / segments): with 128 segments
// cos(a)^-2 - 1 < 6e-4, the bias in E at any y is below 0.06%, far inside the 1% bound.
TEST(ReferenceAnalytic, ClosedSphereOneBounceIsUniform) {
    const float radius = 2.0f, rho = 0.6f, intensity = 3.0f;
    const Scene scene = makeSphereFurnace(radius, rho, 128);
    const FrameState state = frameFor(scene.cameras.front(), pointLight({0, 0, 0}, intensity), 12, 12);
    ReferenceRenderer renderer(scene);
    const ReferenceImage direct = renderer.render(state, {.mode = "direct", .spp = 1});
    const double expected = double(rho) * rho * intensity / (M_PI * radius * radius);
    for (const std::string mode : {"one-bounce-unoccluded", "one-bounce"}) {
        const ReferenceImage img = renderer.render(state, {.mode = mode, .spp = 64});
        double sum = 0;
        for (size_t i = 0; i < img.rgb.size(); ++i) {
            const double l1 = double(img.rgb[i]) - direct.rgb[i];
            EXPECT_NEAR(l1, expected, 0.01 * expected) << mode << " value " << i;
            sum += l1;
        }
        const double meanL1 = sum / static_cast<double>(img.rgb.size());
        std::printf("%s: mean L1 %.6f, expected %.6f (rel. error %.2e)\n", mode.c_str(), meanL1, expected,
                    meanL1 / expected - 1.0);
        EXPECT_NEAR(meanL1, expected, 0.003 * expected) << mode;
    }
}

// Furnace: the same sphere with all bounces. With E_0 = I / R^2 and the argument above applied to each
// bounce (radiosity B_k = rho E_k uniform => E_{k+1} = B_k = rho E_k), E_k = rho^k E_0 and the total
// irradiance is E = E_0 * sum_k rho^k = E_0 / (1 - rho). The radiance is rho / pi * E:
//     L = rho I / (pi R^2 (1 - rho)),   indirect part L - L_direct = rho^2 I / (pi R^2 (1 - rho)).
// With rho = 0.5 paths of 64 vertices truncate the series at rho^63 (negligible).
TEST(ReferenceAnalytic, ClosedSpherePathTracingSumsTheGeometricSeries) {
    const float radius = 1.0f, rho = 0.5f, intensity = 2.0f;
    const Scene scene = makeSphereFurnace(radius, rho, 128);
    const FrameState state = frameFor(scene.cameras.front(), pointLight({0, 0, 0}, intensity), 8, 8);
    ReferenceRenderer renderer(scene);
    const ReferenceImage direct = renderer.render(state, {.mode = "direct", .spp = 1});
    const ReferenceImage path = renderer.render(state, {.mode = "path", .spp = 1024, .maxDepth = 64});
    const double e0 = intensity / (radius * radius);
    const double expectedTotal = rho * e0 / (M_PI * (1.0 - rho));
    const double expectedIndirect = double(rho) * rho * e0 / (M_PI * (1.0 - rho));
    const double total = mean(path.rgb), indirect = total - mean(direct.rgb);
    std::printf(
        "path: mean total %.6f (expected %.6f, rel. %.2e), indirect %.6f (expected %.6f, rel. %.2e)\n", total,
        expectedTotal, total / expectedTotal - 1.0, indirect, expectedIndirect,
        indirect / expectedIndirect - 1.0);
    EXPECT_NEAR(total, expectedTotal, 0.01 * expectedTotal);
    EXPECT_NEAR(indirect, expectedIndirect, 0.015 * expectedIndirect);
    for (size_t i = 0; i < path.rgb.size(); ++i)
        EXPECT_NEAR(path.rgb[i], expectedTotal, 0.05 * expectedTotal) << i;
}
