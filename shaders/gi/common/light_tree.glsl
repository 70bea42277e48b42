// Light-space VPL tree access shared by its build pass, isr's selection and hier_isr's traversal
// (layout: shared/LightTree.h). The including pass declares the node buffer's access qualifier by
// defining GIS_LIGHT_NODES_QUALIFIER (readonly by default).
#include "shared/LightTree.h"

layout(std140, binding = GIS_UBO_LIGHT_TREE) uniform LightTreeBlock {
    LightTreeUniforms gLightTree;
};

#ifndef GIS_LIGHT_NODES_QUALIFIER
#define GIS_LIGHT_NODES_QUALIFIER readonly
#endif
layout(std430, binding = GIS_SSBO_LIGHT_NODES) GIS_LIGHT_NODES_QUALIFIER buffer LightNodes {
    LightNode gLightNodes[];
};

// The nodes as texels of a buffer texture over the same buffer (LightTree::bind), for passes that
// only read them in a loop: llvmpipe (Mesa 22.3) loads a storage buffer's element float by float and
// lane by lane, a texel fetch each lane's vec4 at once (hier_isr's traversal 3x faster,
// docs/multires.md). The lo member is not read: no reader needs it.
layout(binding = GIS_TEXTURE_LIGHT_NODES) uniform samplerBuffer uLightNodeTexels;
LightNode lightNodeTexel(int index) {
    Vpl v = vplFromTexels(uLightNodeTexels, 5 * index); // a node starts with a Vpl's layout
    LightNode node;
    node.position = v.position;
    node.normal = v.normal;
    node.flux = v.flux;
    node.lo = vec4(0.0);
    node.hi = texelFetch(uLightNodeTexels, 5 * index + 4);
    return node;
}

int lightLevelCount() { return gLightTree.info.x; }
int lightLevelSide(int level) { return gLightTree.level[level].y; }
int lightNodeIndex(int level, ivec2 t) { return gLightTree.level[level].x + t.y * gLightTree.level[level].y + t.x; }

// The level holding flat node index `index` (and the node within it), or -1 past the last node.
int lightLevelOf(int index, out ivec2 t) {
    for (int l = 0; l < gLightTree.info.x; ++l) {
        int side = gLightTree.level[l].y;
        int local = index - gLightTree.level[l].x;
        if (local >= 0 && local < side * side) {
            t = ivec2(local % side, local / side);
            return l;
        }
    }
    t = ivec2(-1);
    return -1;
}

// RSM texels under node t of `level` (fewer on the last row/column of odd sizes).
int lightFootprintTexels(int level, ivec2 t) {
    int s = gLightTree.level[level].z;
    ivec2 lo = t * s;
    ivec2 hi = min(lo + s, ivec2(gLightTree.info.y));
    ivec2 n = max(hi - lo, ivec2(0));
    return n.x * n.y;
}

float lightLuminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
