// Coarser versions of a mesh's triangles for distant or small views (level of detail), built on the
// CPU with meshoptimizer's edge-collapse simplifier. Each level keeps the mesh's vertices (its
// indices name a subset of them, so texture coordinates and normals are the mesh's own) and says
// how far its surface may stray from the full mesh: a view draws the coarsest level whose error,
// projected at the mesh's nearest point, stays under its pixel tolerance (render/SceneGpu.h).
#pragma once

#include <cstdint>
#include <vector>

#include "scene/Scene.h"

namespace gis {

struct LodLevel {
    std::vector<std::uint32_t> indices; ///< triangle list into the mesh's vertices
    /// How far the level's surface may lie from the full mesh's, in the mesh's own units (metres for
    /// a world-space mesh): the simplifier's error bound (meshopt_simplify's result error, which is
    /// relative to the mesh's extent, times that extent).
    float error = 0.0f;
};

struct LodOptions {
    /// Meshes with fewer triangles get no levels: a few thousand triangles cost llvmpipe less than
    /// the per-draw work a level adds.
    std::size_t minTriangles = 4096;
    double ratio = 0.25;   ///< each level aims at this share of the one before
    int maxLevels = 4;     ///< coarser levels besides the full mesh
    float maxError = 0.1f; ///< of the mesh's extent, all steps together: coarser is not worth keeping
    /// A level that removes less than this share of the level before ends the chain.
    double minReduction = 0.3;
};

/// The mesh's coarser levels, finest first, each with fewer triangles and no smaller error than the
/// one before; empty for a small mesh, one whose indices are not all valid, or one the simplifier
/// cannot reduce. Each level is simplified from the one before (the second and later with their open
/// borders locked); its error is the sum of the steps' errors, a bound against the full mesh.
std::vector<LodLevel> buildLodLevels(const Mesh& mesh, const LodOptions& options = {});

} // namespace gis
