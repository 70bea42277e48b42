// The light-space VPL tree shared by isr and hier_isr (001 §3.4-3.5, digest S.2 "RSM pyramid / VPL
// tree"). std140 (uniforms) / std430 (nodes); C++ sees it through gl/ShaderShared.h (static_asserts).
//
// 001 stores the tree as "an implicit mipmap in one flat texture". The GL 4.5 form here is one
// shader storage buffer of LightNode records: level-major, row-major inside each level. Level 0 is
// the RSM itself (R x R nodes, R = rsm_size); level l is ceil(R / 2^l) per side, down to 1 x 1, and
// starts at node index level[l].x. The parent of node (x, y) on level l is (x / 2, y / 2) on level
// l + 1, so odd sizes keep their last row and column (those nodes cover fewer texels).
#ifndef GIS_SHARED_LIGHT_TREE_H
#define GIS_SHARED_LIGHT_TREE_H

#define GIS_UBO_LIGHT_TREE 4
#define GIS_SSBO_LIGHT_NODES 2
// The same nodes as RGBA32F texels, five per LightNode, for the traversal's reads (light_tree.glsl).
#define GIS_TEXTURE_LIGHT_NODES 14
#define GIS_MAX_LIGHT_LEVELS                                                                                 \
    13 // a mosaic of light views at most 2.5 x 1024 texels wide gives at most 13 levels

// One node: the clustered light patch over the RSM texels under it. The first three members have
// the layout of Vpl (shared/FrameData.h), so a selected node becomes a VPL by copying them.
struct LightNode {
    vec4 position; // xyz: flux-luminance-weighted mean position (m); w: 1 holds geometry, 0 empty
    vec4 normal;   // xyz: unit mean normal (weights as position); w: disk area A = sum omega |V|^2 (m^2)
    vec4 flux;     // rgb: summed reflected flux of the valid texels; w: valid texel count
    vec4 lo;       // xyz: per-component normal minimum; w: min light distance |p - light| (m)
    vec4 hi;       // xyz: per-component normal maximum; w: max light distance (m; 001 Eq. 8's |V_j|max)
};

struct LightTreeUniforms {
    ivec4
        level[GIS_MAX_LIGHT_LEVELS]; // x: first node index; y: nodes per side; z: texels per node side (2^l)
    ivec4 info;                      // x: level count; y: RSM size R; z: total node count; w: unused
};

#endif
