// The eye-space multiresolution hierarchy shared by multires_splat, multires_gather, isr and hier_isr
// (digest S.3 P3/P5/P7). std140; C++ sees it through gl/ShaderShared.h (static_asserts there).
//
// Atlas ("flattened multiresolution buffer", 001 §3.2.1, whose figure is missing from the paper):
// level 0 (full resolution W x H) at the origin; levels 1..C stacked in one column to its right.
// Level l is ceil(W / 2^l) x ceil(H / 2^l), so odd sizes keep their last row and column; the parent
// of texel t on level l is t / 2 on level l + 1. Texels outside every level are padding.
#ifndef GIS_SHARED_EYE_HIERARCHY_H
#define GIS_SHARED_EYE_HIERARCHY_H

#define GIS_UBO_EYE 2
#define GIS_MAX_EYE_LEVELS 16

// Bits of EyeHierarchyUniforms.info.w (refinement options).
#define GIS_EYE_DIAGONAL 1        // 000 §5.2: a discontinuity in a diagonal neighbour also refines
#define GIS_EYE_DEPTH_DERIVATIVE 2 // depth test on the derivative max-mip instead of min-max depth
#define GIS_EYE_CURVATURE 4       // normal test on the curvature max-mip (000 Eq. 1) instead of min-max

// Bits of the per-texel refinement flags (R8UI atlas).
#define GIS_EYE_FLAG_REFINE 1u  // this patch must be subdivided
#define GIS_EYE_FLAG_COVERED 2u // at least one pixel of the patch sees geometry
#define GIS_EYE_FLAG_DISCONTINUOUS 4u // the patch itself holds a discontinuity (before the diagonal rule)
#define GIS_EYE_FLAG_SUBDIVIDED 8u // this patch and every ancestor refine: its children are visited

// The receiver list (std430): the stencil pass appends each receiver's atlas texel, packed
// y << 16 | x (atlas sides < 65536), and the gathers run one compute invocation per item
// (eye_receiver_list.glsl). On llvmpipe a stencilled full-screen pass shades the receivers in
// 8-pixel groups, most of whose lanes are dead along the thin level-0 edges; a packed list keeps
// every lane busy.
#define GIS_SSBO_EYE_RECEIVERS 6
#define GIS_IMAGE_EYE_ILLUMINATION 0
#define GIS_EYE_RECEIVER_GROUP 64
// GL guarantees GL_MAX_COMPUTE_WORK_GROUP_COUNT >= 65535 per dimension: longer lists run in 2D.
#define GIS_EYE_RECEIVER_MAX_GROUPS_X 65535u

struct EyeReceiverListHeader {
    uvec4 dispatch; // xyz: work groups of the receiver passes (glDispatchComputeIndirect); w: unused
    uvec4 counts;   // x: receivers appended; yzw: unused
};

struct EyeHierarchyUniforms {
    ivec4 level[GIS_MAX_EYE_LEVELS]; // xy: atlas offset (texels); zw: level size (texels)
    ivec4 info;                      // x: level count C + 1; y, z: full-resolution W, H; w: option bits
    vec4 thresholds; // x: depth range / min depth; y: depth derivative (relative, per pixel);
                     // z: normal component range [0, 2]; w: curvature 2 sin(angle / 2) [0, 2]
};

#endif
