#include "frame/Tiles.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/Error.h"
#include "gi/Catalog.h"

namespace gis {

int tileGuardPx(const FrameState& full) {
    const TechniqueInfo& info = findTechniqueInfo(full.technique);
    const ParamSet& p = full.techniqueParams;
    int guard = 0;
    if (info.eyeHierarchy && p.has("coarsest_size")) {
        const int longer = std::max(full.width, full.height);
        const int coarsest = std::max(1, p.getInt("coarsest_size"));
        guard = std::min(64, (longer + coarsest - 1) / coarsest);
    }
    if (info.biasCompensation && p.has("ssbc_iterations") && p.getInt("ssbc_iterations") > 0)
        guard = std::max(guard, 32);
    return guard;
}

FrameState tileState(const FrameState& full, const TileRect& rect, int guard) {
    GIS_ASSERT(rect.width > 0 && rect.height > 0 && guard >= 0);
    GIS_ASSERT(!full.window.active());
    FrameState tile = full;
    tile.width = rect.width + 2 * guard;
    tile.height = rect.height + 2 * guard;
    tile.window = {rect.x - guard, rect.y - guard, full.width, full.height};
    const TechniqueInfo& info = findTechniqueInfo(full.technique);
    if (info.eyeHierarchy && tile.techniqueParams.has("coarsest_size")) {
        const double ratio = static_cast<double>(std::max(tile.width, tile.height)) /
                             static_cast<double>(std::max({full.width, full.height, 1}));
        const ParamSpec* spec = tile.techniqueParams.table().find("coarsest_size");
        const int maxSize = spec ? static_cast<int>(spec->max) : 256;
        const int scaled =
            static_cast<int>(std::lround(full.techniqueParams.getInt("coarsest_size") * ratio));
        tile.techniqueParams.set("coarsest_size", std::clamp(scaled, 1, maxSize));
    }
    return tile;
}

void pasteTile(std::vector<std::uint8_t>& canvas, int fullWidth, int fullHeight,
               const std::vector<std::uint8_t>& tile, int tileWidth, int tileHeight, const TileRect& rect,
               int guard) {
    GIS_ASSERT(canvas.size() == static_cast<std::size_t>(fullWidth) * fullHeight * 4);
    GIS_ASSERT(tile.size() == static_cast<std::size_t>(tileWidth) * tileHeight * 4);
    const int x0 = std::max(rect.x, 0), x1 = std::min(rect.x + rect.width, fullWidth);
    const int y0 = std::max(rect.y, 0), y1 = std::min(rect.y + rect.height, fullHeight);
    if (x1 <= x0) return;
    for (int y = y0; y < y1; ++y) {
        const int ty = y - rect.y + guard, tx = x0 - rect.x + guard;
        if (ty < 0 || ty >= tileHeight || tx < 0 || tx + (x1 - x0) > tileWidth) continue;
        std::memcpy(canvas.data() + (static_cast<std::size_t>(y) * fullWidth + x0) * 4,
                    tile.data() + (static_cast<std::size_t>(ty) * tileWidth + tx) * 4,
                    static_cast<std::size_t>(x1 - x0) * 4);
    }
}

TileRect clipToImage(const TileRect& rect, int width, int height) {
    const int x0 = std::clamp(rect.x, 0, std::max(0, width)), y0 = std::clamp(rect.y, 0, std::max(0, height));
    const int x1 = std::clamp(rect.x + std::max(0, rect.width), x0, std::max(0, width));
    const int y1 = std::clamp(rect.y + std::max(0, rect.height), y0, std::max(0, height));
    return {x0, y0, x1 - x0, y1 - y0};
}

TileRect unite(const TileRect& a, const TileRect& b) {
    const bool aEmpty = a.width <= 0 || a.height <= 0, bEmpty = b.width <= 0 || b.height <= 0;
    if (aEmpty) return b;
    if (bEmpty) return a;
    const int x0 = std::min(a.x, b.x), y0 = std::min(a.y, b.y);
    const int x1 = std::max(a.x + a.width, b.x + b.width), y1 = std::max(a.y + a.height, b.y + b.height);
    return {x0, y0, x1 - x0, y1 - y0};
}

std::vector<std::uint8_t> cropRgba8(const std::vector<std::uint8_t>& canvas, int width, int height,
                                    const TileRect& rect) {
    const TileRect r = clipToImage(rect, width, height);
    std::vector<std::uint8_t> out(static_cast<std::size_t>(r.width) * r.height * 4);
    if (canvas.size() < static_cast<std::size_t>(width) * height * 4) return {};
    for (int y = 0; y < r.height; ++y)
        std::copy_n(canvas.begin() + ((static_cast<std::ptrdiff_t>(r.y) + y) * width + r.x) * 4,
                    static_cast<std::ptrdiff_t>(r.width) * 4,
                    out.begin() + static_cast<std::ptrdiff_t>(y) * r.width * 4);
    return out;
}

std::vector<std::uint8_t> resizeRgba8(const std::vector<std::uint8_t>& src, int srcWidth, int srcHeight,
                                      int width, int height) {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(width) * height * 4, 0);
    if (srcWidth <= 0 || srcHeight <= 0 || src.size() < static_cast<std::size_t>(srcWidth) * srcHeight * 4)
        return out;
    const double sx = static_cast<double>(srcWidth) / width, sy = static_cast<double>(srcHeight) / height;
    for (int y = 0; y < height; ++y) {
        // Pixel centres map to pixel centres; samples outside the source clamp to its edge.
        const double fy = std::clamp((y + 0.5) * sy - 0.5, 0.0, srcHeight - 1.0);
        const int y0 = static_cast<int>(fy), y1 = std::min(y0 + 1, srcHeight - 1);
        const double wy = fy - y0;
        for (int x = 0; x < width; ++x) {
            const double fx = std::clamp((x + 0.5) * sx - 0.5, 0.0, srcWidth - 1.0);
            const int x0 = static_cast<int>(fx), x1 = std::min(x0 + 1, srcWidth - 1);
            const double wx = fx - x0;
            for (int c = 0; c < 4; ++c) {
                auto at = [&](int px, int py) {
                    return static_cast<double>(src[(static_cast<std::size_t>(py) * srcWidth + px) * 4 + c]);
                };
                const double v = (at(x0, y0) * (1 - wx) + at(x1, y0) * wx) * (1 - wy) +
                                 (at(x0, y1) * (1 - wx) + at(x1, y1) * wx) * wy;
                out[(static_cast<std::size_t>(y) * width + x) * 4 + c] =
                    static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
            }
        }
    }
    return out;
}

TilePlan::TilePlan(int fullWidth, int fullHeight, int align, int minSide)
    : mFullWidth(std::max(fullWidth, 1)), mFullHeight(std::max(fullHeight, 1)), mAlign(std::max(align, 1)),
      mMinSide(std::max(minSide, 1)) {
    mCellsX = (mFullWidth + mAlign - 1) / mAlign;
    mCellsY = (mFullHeight + mAlign - 1) / mAlign;
    mCovered.assign(static_cast<std::size_t>(mCellsX) * mCellsY, 0);
}

int TilePlan::sideFor(double pixels, int limit) const {
    // Rounded down to the alignment (a tile must not take longer than asked: rounding 19 px up to 32
    // would nearly triple it), at least minSide, at most the image's (aligned) extent.
    const double side = std::sqrt(std::max(pixels, 1.0));
    const int s = static_cast<int>(std::floor(side / mAlign)) * mAlign;
    const int cap = ((limit + mAlign - 1) / mAlign) * mAlign;
    return std::clamp(s, std::min(mMinSide, cap), cap);
}

TileRect TilePlan::next(double pixels) {
    GIS_ASSERT(!done());
    pixels = std::max(pixels, 1.0);
    // Square tiles; the side is kept while the request stays within a factor 1.6 of its area.
    const double current = static_cast<double>(mSide) * mSide;
    if (mSide == 0 || pixels < current / 1.6 || pixels > current * 1.6)
        mSide = sideFor(pixels, std::max(mFullWidth, mFullHeight));
    while (mCovered[static_cast<std::size_t>(mNextCell)]) ++mNextCell;
    const int cx = mNextCell % mCellsX, cy = mNextCell / mCellsX;
    const int cells = mSide / mAlign;
    // The tile starts at the first cell not yet covered; it may reach over cells covered by a larger
    // tile of an earlier row (rendered twice, never missed) and past the image's edges.
    long long newly = 0;
    for (int y = cy; y < std::min(cy + cells, mCellsY); ++y)
        for (int x = cx; x < std::min(cx + cells, mCellsX); ++x) {
            auto& c = mCovered[static_cast<std::size_t>(y) * mCellsX + x];
            if (!c) {
                c = 1;
                ++newly;
            }
        }
    mCoveredCells += newly;
    ++mTiles;
    while (mNextCell < static_cast<int>(mCovered.size()) && mCovered[static_cast<std::size_t>(mNextCell)])
        ++mNextCell;
    return TileRect{cx * mAlign, cy * mAlign, mSide, mSide};
}

double TilePlan::shareDone() const {
    return std::clamp(static_cast<double>(mCoveredCells) / static_cast<double>(mCovered.size()), 0.0, 1.0);
}

} // namespace gis
