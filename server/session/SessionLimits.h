// What a server allows each session, and how fast its live view must answer (gi-server's options,
// net/ServerOptions.h; protocol/PROTOCOL.md, "Adaptive quality").
#pragma once

namespace gis {

struct SessionLimits {
    int maxWidth = 2048, maxHeight = 2048; ///< px; larger requests are scaled down, aspect kept
    long maxVpls = 65536;                  ///< upper bound on VPLs a parameter set may ask for
    /// (0, 1]: the largest size factor of interactive frames (with frameTargetMs 0: the factor).
    double interactiveScale = 1.0;
    /// px: interactive frames draw big meshes at the coarsest level of detail whose error spans at most
    /// this many of their pixels (frame parameter lod_pixels, unless the client set it); the
    /// refinement steps draw every triangle. Above 0, every adaptive step (snapshots aside) also draws
    /// the light views within kLiveLightLodTexels (light_lod_texels). 0: every triangle always.
    double interactiveLodPixels = 1.0;
    /// ms of render and encode an interactive frame should take: the frame budget picks its size and
    /// VPL cap from measured costs (session/FrameBudget.h); a client may ask for its own in `hello` or
    /// `quality`. 0 = no budget: interactive frames at interactiveScale with their preset.
    int frameTargetMs = 80;
    /// ms one tile of a refinement step should take (tiles are sized from measured slice times), so an
    /// input waits for at most about this much before its own frame starts rendering.
    int sliceMs = 20;
    int settleMs = 250; ///< ms without input before refinement starts
    /// ms; a refinement step whose predicted total time exceeds this is skipped (and the client told
    /// so): from the measured tiles of its kind, or before the first one, from the previous step scaled
    /// by pixels and VPLs. Steps are rendered in tiles that input interrupts, so this bounds the work,
    /// not the wait. 0 = no limit.
    int refineBudgetMs = 30000;
};

} // namespace gis
