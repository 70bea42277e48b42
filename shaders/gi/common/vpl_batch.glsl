// The gathers' current batch of VPLs (VplBatches, server/gi/common/VplGrid.h): a buffer texture of
// RGBA32F texels, three per VPL in shader::Vpl's order (position, normal, flux). Not a uniform block:
// llvmpipe (Mesa 22.3) loads a block's array element at a loop index float by float and lane by
// lane, each load with a bounds test, where a texel fetch loads each lane's vec4 at once; the loads
// were most of a gather's time (docs/multires.md, "VPLs as texels").
layout(binding = GIS_TEXTURE_VPLS) uniform samplerBuffer uBatchVpls;

Vpl batchVpl(int i) { return vplFromTexels(uBatchVpls, 3 * i); }

// sum += TERM(i) for i = 0, 1, ..., count - 1, in that order (so the sum is the plain loop's, bit for
// bit), four terms per iteration: llvmpipe pays a loop's per-iteration lane-mask work once per four
// VPLs instead of once per VPL. TERM is a function or function-like macro of the index.
#define GIS_SUM_OVER_BATCH(sum, count, TERM)                                                              \
    {                                                                                                     \
        int gisBatchI = 0;                                                                                \
        for (; gisBatchI + 3 < (count); gisBatchI += 4) {                                                 \
            sum += TERM(gisBatchI);                                                                       \
            sum += TERM(gisBatchI + 1);                                                                   \
            sum += TERM(gisBatchI + 2);                                                                   \
            sum += TERM(gisBatchI + 3);                                                                   \
        }                                                                                                 \
        for (; gisBatchI < (count); ++gisBatchI) sum += TERM(gisBatchI);                                  \
    }
