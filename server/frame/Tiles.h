// Tiled refinement: a refinement step of the live view is rendered as a sequence of tiles that each
// fit one slice of time (session/Session.cpp), so input waits for at most the tile in progress.
// A tile is an ordinary frame (FrameState::window) whose projection is the full image's cropped to
// its pixels, widened by a guard band for the screen-space steps near its edges (the eye hierarchy,
// bias compensation); the inner part is pasted into the full image (docs/interactive.md).
#pragma once

#include <cstdint>
#include <vector>

#include "frame/FrameState.h"

namespace gis {

/// Pixels of the full image, top-left origin; a tile may reach past the image's right and bottom
/// edges (its outside part is rendered, never pasted), so every tile of a band has one size.
struct TileRect {
    int x = 0, y = 0, width = 0, height = 0;
};

/// Guard band in pixels on each side of a tile of `full`: 0 for per-pixel techniques, the eye
/// hierarchy's coarsest patch (at most 64 px) where the technique builds one, 32 px where bias
/// compensation integrates screen-space neighbours.
int tileGuardPx(const FrameState& full);

/// The state that renders `rect` of `full` with `guard` px around it: the window, the rendered size
/// and, for an eye hierarchy, `coarsest_size` scaled so that the coarsest patches keep their size in
/// pixels (the hierarchy over the tile then matches the full image's, up to its cell boundaries).
FrameState tileState(const FrameState& full, const TileRect& rect, int guard);

/// Copies the part of a rendered tile (RGBA8, rows top to bottom, `guard` px around `rect`) that lies
/// inside the full image into `canvas` (fullWidth x fullHeight RGBA8).
void pasteTile(std::vector<std::uint8_t>& canvas, int fullWidth, int fullHeight,
               const std::vector<std::uint8_t>& tile, int tileWidth, int tileHeight, const TileRect& rect,
               int guard);

/// Bilinear resize of an RGBA8 image (the interactive frame stretched to full size as the canvas a
/// refinement step starts from), within one 8-bit level of the exact value; an invalid source
/// gives black.
std::vector<std::uint8_t> resizeRgba8(const std::vector<std::uint8_t>& src, int srcWidth, int srcHeight,
                                      int width, int height);
/// Rows [rowBegin, rowEnd) of the same into `out` (width x height RGBA8, sized by the caller): a
/// resize in bands that a caller can stop between.
void resizeRgba8Rows(const std::vector<std::uint8_t>& src, int srcWidth, int srcHeight,
                     std::vector<std::uint8_t>& out, int width, int height, int rowBegin, int rowEnd);

/// The part of `rect` inside a width x height image (empty when none is).
TileRect clipToImage(const TileRect& rect, int width, int height);
/// The smallest rectangle holding both (an empty one adds nothing).
TileRect unite(const TileRect& a, const TileRect& b);
/// The pixels of `rect` (inside the image) copied out of `canvas` (width x height RGBA8): the region
/// of the image a patch frame sends.
std::vector<std::uint8_t> cropRgba8(const std::vector<std::uint8_t>& canvas, int width, int height,
                                    const TileRect& rect);

/// The order and sizes of one step's tiles: square tiles in reading order, each at the first cell
/// (align x align px) not yet covered. Each next() asks for about `pixels` pixels (from measured
/// slice times); the side is kept while the request stays within a factor 1.6 of its area, since
/// every new size reallocates the renderer's targets. A tile may overlap cells a larger tile of an
/// earlier row covered: such pixels are rendered twice, none is missed.
class TilePlan {
public:
    TilePlan(int fullWidth, int fullHeight, int align = 16, int minSide = 32);
    bool done() const { return mNextCell >= static_cast<int>(mCovered.size()); }
    TileRect next(double pixels);
    /// Fraction of the image's cells covered by the tiles handed out, [0, 1].
    double shareDone() const;
    int tilesDone() const { return mTiles; }
    int fullWidth() const { return mFullWidth; }
    int fullHeight() const { return mFullHeight; }

private:
    int sideFor(double pixels, int limit) const;
    int mFullWidth, mFullHeight, mAlign, mMinSide;
    int mCellsX = 0, mCellsY = 0;
    std::vector<std::uint8_t> mCovered; ///< per cell, row-major
    int mNextCell = 0;                  ///< the first cell not covered
    int mSide = 0;                      ///< the current tile side
    long long mCoveredCells = 0;
    int mTiles = 0;
};

} // namespace gis
