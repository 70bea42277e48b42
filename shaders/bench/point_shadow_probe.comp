#version 450 core
// gi-bench point-shadows: shadow lookups of a cube map and of a dual-paraboloid map at sample
// points, each in its own depth measure (planar depth along the face axis, radial distance), with the
// same relative bias. Writes x: cube visible, y: paraboloid visible (0 or 1).
layout(local_size_x = 64) in;
layout(binding = 0) uniform sampler2DArray uCube;       // 6 layers, depth in [0, 1]
layout(binding = 1) uniform sampler2DArray uParaboloid; // 2 layers
layout(std430, binding = 0) readonly buffer Points { vec4 gPoints[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 gResults[]; };
uniform int uCount;
layout(std430, binding = 2) readonly buffer Faces { mat4 gFaceViewProj[6]; };
uniform vec2 uCubeDepth;   // near, far of the faces' perspectives
uniform mat4 uLightView;
uniform vec2 uParaboloidDepth;
uniform vec3 uLight;
uniform float uBias;       // relative depth tolerance

float linearDepth(float z01, vec2 nf) { return nf.x * nf.y / max(nf.y - z01 * (nf.y - nf.x), 1e-20); }

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= uCount) return;
    vec3 p = gPoints[i].xyz;
    vec3 d = p - uLight;
    vec3 a = abs(d);
    int face = (a.x >= a.y && a.x >= a.z) ? (d.x >= 0.0 ? 0 : 1) : (a.y >= a.z) ? (d.y >= 0.0 ? 2 : 3) : (d.z >= 0.0 ? 4 : 5);
    vec4 clip = gFaceViewProj[face] * vec4(p, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    vec2 uv = clamp(ndc.xy * 0.5 + 0.5, 0.0, 1.0);
    float stored = linearDepth(texture(uCube, vec3(uv, face)).r, uCubeDepth);
    float own = clip.w; // planar depth along the face axis
    float cube = own <= stored * (1.0 + uBias) ? 1.0 : 0.0;

    vec3 v = (uLightView * vec4(p, 1.0)).xyz;
    int hemisphere = v.z <= 0.0 ? 0 : 1;
    vec3 vh = vec3(v.xy, hemisphere == 0 ? v.z : -v.z);
    float dist = length(vh);
    vec3 n = vh / max(dist, 1e-20);
    vec2 puv = clamp(n.xy / (1.0 - n.z) * 0.5 + 0.5, 0.0, 1.0);
    float pStored = uParaboloidDepth.x + texture(uParaboloid, vec3(puv, hemisphere)).r * (uParaboloidDepth.y - uParaboloidDepth.x);
    float paraboloid = dist <= pStored * (1.0 + uBias) ? 1.0 : 0.0;
    gResults[i] = vec4(cube, paraboloid, 0.0, 0.0);
}
