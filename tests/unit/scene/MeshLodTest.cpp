#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include "scene/MeshLod.h"

namespace gis {
namespace {

/// A closed UV sphere of `segments` x `rings` quads (poles included as degenerate rows).
Mesh sphere(float radius, int segments, int rings) {
    Mesh mesh;
    for (int j = 0; j <= rings; ++j)
        for (int i = 0; i < segments; ++i) {
            const float theta = glm::pi<float>() * static_cast<float>(j) / static_cast<float>(rings);
            const float phi = glm::two_pi<float>() * static_cast<float>(i) / static_cast<float>(segments);
            mesh.positions.emplace_back(radius * std::sin(theta) * std::cos(phi), radius * std::cos(theta),
                                        radius * std::sin(theta) * std::sin(phi));
        }
    const auto seg = static_cast<std::uint32_t>(segments);
    for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(rings); ++j)
        for (std::uint32_t i = 0; i < seg; ++i) {
            const std::uint32_t a = j * seg + i, b = j * seg + (i + 1) % seg, c = a + seg, d = b + seg;
            mesh.indices.insert(mesh.indices.end(), {a, d, b, a, c, d});
        }
    return mesh;
}

/// A flat n x n grid of quads in the XZ plane, `size` metres across.
Mesh grid(int n, float size) {
    Mesh mesh;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            mesh.positions.emplace_back(size * static_cast<float>(i) / static_cast<float>(n), 0.0f,
                                        size * static_cast<float>(j) / static_cast<float>(n));
    const auto row = static_cast<std::uint32_t>(n + 1);
    for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(n); ++j)
        for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(n); ++i) {
            const std::uint32_t a = j * row + i, b = a + 1, c = a + row, d = c + 1;
            mesh.indices.insert(mesh.indices.end(), {a, c, b, b, c, d});
        }
    return mesh;
}

/// Distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
float pointTriangleDistance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    const glm::vec3 ab = b - a, ac = c - a, ap = p - a;
    const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0f && d2 <= 0.0f) return glm::length(p - a);
    const glm::vec3 bp = p - b;
    const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0f && d4 <= d3) return glm::length(p - b);
    const float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
    const glm::vec3 cp = p - c;
    const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0f && d5 <= d6) return glm::length(p - c);
    const float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
    const float va = d3 * d6 - d5 * d4;
    if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f)
        return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    const float denom = va + vb + vc;
    if (!(std::abs(denom) > 0.0f)) return glm::length(p - a); // a degenerate triangle
    const float v = vb / denom, w = vc / denom;
    return glm::length(p - (a + ab * v + ac * w));
}

/// The farthest any vertex of the full mesh lies from the level's surface.
float farthestVertex(const Mesh& mesh, const std::vector<std::uint32_t>& level) {
    float farthest = 0.0f;
    for (const glm::vec3& p : mesh.positions) {
        float nearest = std::numeric_limits<float>::max();
        for (std::size_t t = 0; t + 2 < level.size(); t += 3)
            nearest = std::min(nearest, pointTriangleDistance(p, mesh.positions[level[t]],
                                                              mesh.positions[level[t + 1]],
                                                              mesh.positions[level[t + 2]]));
        farthest = std::max(farthest, nearest);
    }
    return farthest;
}

TEST(MeshLod, SmallMeshesGetNoLevels) {
    EXPECT_TRUE(buildLodLevels(sphere(1.0f, 32, 16)).empty()); // 1,024 triangles
    Mesh empty;
    EXPECT_TRUE(buildLodLevels(empty).empty());
}

TEST(MeshLod, InvalidIndicesOrPositionsGetNoLevels) {
    Mesh badIndex = sphere(1.0f, 96, 48);
    badIndex.indices[7] = static_cast<std::uint32_t>(badIndex.positions.size());
    EXPECT_TRUE(buildLodLevels(badIndex).empty());
    Mesh badPosition = sphere(1.0f, 96, 48);
    badPosition.positions[3].y = std::nanf("");
    EXPECT_TRUE(buildLodLevels(badPosition).empty());
}

TEST(MeshLod, LevelsShrinkAndTheirErrorsGrowAndBoundTheSurface) {
    const Mesh mesh = sphere(2.0f, 96, 48); // 9,216 triangles, extent 4 m
    const std::vector<LodLevel> levels = buildLodLevels(mesh);
    ASSERT_GE(levels.size(), 2u);
    std::size_t previous = mesh.indices.size();
    float previousError = 0.0f;
    for (const LodLevel& level : levels) {
        ASSERT_EQ(level.indices.size() % 3, 0u);
        EXPECT_LT(static_cast<double>(level.indices.size()), 0.7 * static_cast<double>(previous));
        EXPECT_GE(level.error, previousError);
        EXPECT_LE(level.error, 0.1f * 4.0f + 1e-4f); // LodOptions::maxError of the extent
        for (std::uint32_t v : level.indices) ASSERT_LT(v, mesh.positions.size());
        previous = level.indices.size();
        previousError = level.error;
    }
    // A curved surface cannot lose triangles for free.
    EXPECT_GT(levels.front().error, 0.0f);
    // The error says how far the level strays: every vertex of the full sphere lies within about it of
    // the level's surface (the simplifier's quadric error is an estimate, hence the margin).
    for (std::size_t l : {std::size_t{0}, levels.size() - 1}) {
        const float farthest = farthestVertex(mesh, levels[l].indices);
        EXPECT_LE(farthest, 2.0f * levels[l].error + 1e-4f) << "level " << l;
        EXPECT_GT(farthest, 0.25f * levels[l].error) << "level " << l << ": the error is not a loose guess";
    }
}

TEST(MeshLod, AFlatGridCollapsesAtNoCost) {
    const Mesh mesh = grid(64, 10.0f); // 8,192 triangles
    const std::vector<LodLevel> levels = buildLodLevels(mesh);
    ASSERT_FALSE(levels.empty());
    EXPECT_LE(levels.back().indices.size() / 3, 8192u / 32u);
    for (const LodLevel& level : levels) EXPECT_LE(level.error, 1e-4f);
    // The coarsest level still covers the whole grid: its edges stayed where they were.
    EXPECT_LE(farthestVertex(mesh, levels.back().indices), 1e-3f);
}

} // namespace
} // namespace gis
#include <chrono>
#include "scene/SceneLoader.h"
TEST(MeshLodTiming, Atrium) {
    const gis::Scene scene = gis::loadScene("builtin:atrium");
    const auto t0 = std::chrono::steady_clock::now();
    std::size_t tris = 0;
    for (const gis::Mesh& m : scene.meshes) for (const auto& l : gis::buildLodLevels(m)) tris += l.indices.size() / 3;
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[timing] atrium LOD %.1f ms, %zu triangles\n", ms, tris);
}
