// Screen-space bias compensation (002; server/gi/common/BiasCompensation.h): the layout every SSBC
// pass shares. Mip level l of each chain is (padded W >> l) x (padded H >> l); the padded size is a
// multiple of 2^(levels - 1), so every texel has exactly 4 children and odd images keep their last
// row and column (digest S.4 case 18). Texels outside the image hold area 0 and contribute nothing.
//   geo:    xyz area-weighted mean position (m); w summed faded footprint area A (m^2), 0 = empty
//   normal: xyz area-weighted mean unit normal; w 1 where the sample spans a discontinuity
//   illum:  rgb area-weighted mean outgoing radiance of the step's input
#define GIS_SSBC_GROUP 8

// Per-workgroup sums for the counters: x energy (mean RGB, summed over pixels); y samples visited;
// z max samples visited by one pixel; w covered pixels.
layout(std430, binding = 0) buffer SsbcSums {
    vec4 gSsbcSums[];
};

shared vec4 sSsbcPartial[GIS_SSBC_GROUP * GIS_SSBC_GROUP];

// Every invocation must reach this (no early return before it): writes the group's sum at `slot`.
void ssbcGroupSum(vec4 mine, int slot) {
    uint i = gl_LocalInvocationIndex;
    sSsbcPartial[i] = mine;
    barrier();
    if (i == 0u) {
        vec4 s = vec4(0.0);
        for (int k = 0; k < GIS_SSBC_GROUP * GIS_SSBC_GROUP; ++k) {
            vec4 p = sSsbcPartial[k];
            s.xyw += p.xyw;
            s.z = max(s.z, p.z);
        }
        uint groups = gl_NumWorkGroups.x;
        gSsbcSums[slot * int(gl_NumWorkGroups.x * gl_NumWorkGroups.y) + int(gl_WorkGroupID.y * groups + gl_WorkGroupID.x)] = s;
    }
}

// Edge-stopping weight between two covered surface points (ssbc_blur and the half-resolution
// upsampling): Gaussian falloffs in the normal chord |n_p - n_q| and in the relative eye distance,
// with the discontinuity scales of ssbc_reduce.comp (chord 0.3, relative distance 0.1), so a 90-degree
// crease (chord 1.41) or a depth step gets a weight below 1e-9. Symmetric in p and q, which the
// energy-conserving blur needs. `eye` is the camera position.
float ssbcEdgeWeight(vec3 posP, vec3 nP, vec3 posQ, vec3 nQ, vec3 eye) {
    float chord = length(nP - nQ) / 0.3;
    float dP = length(posP - eye), dQ = length(posQ - eye);
    float rel = abs(dP - dQ) / max(0.1 * 0.5 * (dP + dQ), 1e-12);
    float w = exp(-chord * chord - rel * rel);
    return isBad(w) ? 0.0 : w;
}
