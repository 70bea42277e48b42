// Subsplat lists of multires_splat (000 §3 step 5), shared by C++ and GLSL (std430).
// A list item is a uvec2: x = VPL index (per-VPL refinement; 0 otherwise), y = packed patch
// (level << 28 | y << 14 | x), so levels < 16 and level sizes < 16384 texels.
#ifndef GIS_SHARED_SUBSPLAT_H
#define GIS_SHARED_SUBSPLAT_H

#define GIS_SUBSPLAT_GROUP 64
// Work groups per dispatch dimension: GL guarantees GL_MAX_COMPUTE_WORK_GROUP_COUNT >= 65535 in each.
// Larger lists are dispatched in 2D (x up to this, y rows); shaders flatten with gl_NumWorkGroups.x.
#define GIS_SUBSPLAT_MAX_GROUPS_X 65535u

struct SubsplatCounters {
    uvec4 dispatch; // xyz: work groups of the next refinement pass (glDispatchComputeIndirect, 2D)
    uvec4 draw;     // DrawArraysIndirectCommand: count, instanceCount, first, baseInstance
    uvec4 counts;   // x: items in the input list; y: items in the next list; z: splat items;
                    // w: items the list cap kept from refining (splatted coarser instead)
    uvec4 perLevel[4]; // splat items per level, level l at perLevel[l / 4][l % 4]
};

#endif
