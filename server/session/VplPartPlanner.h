// Refinement's VPL parts: into how many parts a tile's VPLs are split, and how large the tile is, so
// that one part fits a slice without repeating the part's fixed work more often than it must.
//
// Model, per tile size (a ladder of halvings from the largest tile), for a tile split into P parts:
//   ms(P) = fixedMs + vplMs / P
// fixedMs: what every part repeats whatever its VPLs (G-buffer, direct light, the eye hierarchy,
// composite, read-back); vplMs: the tile's whole VPL work, shared among its parts. Each part count keeps
// an exponential mean of its parts; two or more counts give a least-squares fit. With one count
// measured the cost counts as all VPLs, so an overrun asks for more parts (which certainly helps if it
// is VPL work) and the next tiles tell the two apart. Where fixed work alone fills most of the target
// the tile shrinks a rung, unless the smaller tile's fixed work turned out no smaller (costs per pass,
// not per pixel). Counting fixed work as VPL work was how multires_gather's tiles came to 154 parts
// of 0.04 ms gather and 8 ms fixed work each.
#pragma once

#include <map>

namespace gis {

struct VplPartPlan {
    double pixels = 0; ///< rendered pixels of the tile (guard band included)
    int parts = 1;
};

class VplPartPlanner {
public:
    struct Limits {
        double targetMs = 14;       ///< a part's cost aimed at (a share of the slice, ms)
        double tilePixels = 4096;   ///< the largest tile's rendered pixels
        double minTilePixels = 256; ///< smallest tile
        int maxParts = 4096;
    };
    explicit VplPartPlanner(Limits limits);

    /// The next tile's size and parts. `allVplRate`: before anything ran, ms per pixel of a tile's
    /// VPLs unsplit (a prediction).
    VplPartPlan plan(long vpls, double allVplRate);
    /// One rendered part of a tile of `pixels` split in `parts`, which took `ms`.
    void record(double pixels, int parts, double ms);

    /// The fitted costs (ms) of the tile size `plan` would use now; false while fewer than two part
    /// counts were measured at it.
    bool fitted(double& fixedMs, double& vplMs) const;

    /// What a step learned, for the next step with the same tiles: per tile size with a fit, its fixed
    /// ms and its VPL ms per VPL (the next step may have another VPL count), and whether smaller tiles
    /// proved no cheaper.
    struct Memory {
        std::map<int, std::pair<double, double>> fixedAndPerVpl; ///< by rung
        bool shrinkFutile = false;
        bool empty() const { return fixedAndPerVpl.empty(); }
    };
    /// This planner's fits, for steps of `vpls` VPLs.
    Memory remember(long vpls) const;
    /// Starts (before any record) from an earlier step's fits, scaled to this step's `vpls`, so its
    /// first tiles are not sized from a prediction again; this step's own parts then take over.
    void recall(const Memory& memory, long vpls);

private:
    struct Mean {
        double ms = 0;
        int samples = 0;
    };
    struct Rung {
        std::map<int, Mean> byParts;
        int lastParts = 0;
    };
    double rungPixels(int rung) const;
    int rungOf(double pixels) const;
    bool fit(int rung, double& fixedMs, double& vplMs) const;

    Limits mLimits;
    int mLowestRung = 0;
    int mRung = 0;
    bool mShrinkFutile = false;
    std::map<int, Rung> mRungs;
};

} // namespace gis
