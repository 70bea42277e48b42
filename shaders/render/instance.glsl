// The placement of the mesh being drawn (render/SceneGpu.h, scene Mesh::instances): per-instance
// attributes, one object -> world matrix per placement (or per draw command, in passes that draw
// instanced for their own reasons). World-space meshes are drawn with the identity, which leaves
// every position, normal and tangent bit for bit as it was.
layout(location = 5) in mat4 inToWorld;       // object -> world (locations 5-8)
layout(location = 9) in mat3 inNormalToWorld; // its linear part's inverse transpose (locations 9-11)

vec3 placedPosition(vec3 p) {
    return (inToWorld * vec4(p, 1.0)).xyz;
}
// Not unit length under scaling: the fragment stages normalise (safeNormal, materialNormal).
vec3 placedNormal(vec3 n) {
    return inNormalToWorld * n;
}
// Placements have a positive determinant (the loader flattens mirrored ones), so w holds.
vec4 placedTangent(vec4 t) {
    return vec4(mat3(inToWorld) * t.xyz, t.w);
}
