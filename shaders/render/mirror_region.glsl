// Planar mirrors (render/PlanarMirrors.cpp): which pixels belong to one mirrored view. A view at
// level k is the chain of mirrors m1..mk (eye -> m1 -> ... -> mk); its pixels are those where the eye
// G-buffer shows m1, the level-1 view shows m2, ..., the level-(k-1) view shows mk. Ids are mirror
// index + 1 (0: no mirror), stored as exact small integers in float channels.
#ifndef GIS_MIRROR_REGION_GLSL
#define GIS_MIRROR_REGION_GLSL

layout(binding = 1) uniform sampler2D gMirrorIdEye; // eye G-buffer normal: w = mirror id
layout(binding = 2) uniform sampler2D gMirrorId1;   // level-1 views: r = mirror id
layout(binding = 3) uniform sampler2D gMirrorId2;   // level-2 views: r = mirror id

uniform int uLevel;     // k, 1..3
uniform ivec3 uChain;   // mirror ids (index + 1) of the chain m1, m2, m3

bool sameId(float stored, int id) { return abs(stored - float(id)) < 0.25; }

bool inRegion(ivec2 px) {
    if (!sameId(texelFetch(gMirrorIdEye, px, 0).w, uChain.x)) return false;
    if (uLevel >= 2 && !sameId(texelFetch(gMirrorId1, px, 0).r, uChain.y)) return false;
    if (uLevel >= 3 && !sameId(texelFetch(gMirrorId2, px, 0).r, uChain.z)) return false;
    return true;
}

#endif
