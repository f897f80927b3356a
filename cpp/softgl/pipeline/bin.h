// Binning: each set-up primitive is listed in every screen tile it may cover, in draw order, so
// that tiles can be rasterised and shaded independently on worker threads while every pixel still
// sees its primitives in order (ES 3.0 §4: per-fragment operations happen in primitive order).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "softgl/core/capacity_bytes.h"
#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/setup.h"

namespace softgl {

inline constexpr int32_t kTileSize = 64;   // pixels; a multiple of kBlockSize

struct TileGrid {
    int32_t width = 0, height = 0, tiles_x = 0, tiles_y = 0;
    TileGrid() = default;
    TileGrid(int32_t width, int32_t height);
    size_t count() const { return size_t(tiles_x) * size_t(tiles_y); }
    TileRect rect(size_t tile) const;
};

class Bins {
public:
    // Empty lists for grid.count() tiles. Only the lists filled since the last reset are cleared
    // (a one-point draw fills one of 256 tiles).
    void reset(const TileGrid& grid);
    // Appends prims[first..] to the tiles their bounding box meets, skipping tiles that lie entirely
    // outside one of a primitive's edges. Indices refer to `prims`.
    void add(const std::vector<PrimitiveSetup>& prims, size_t first = 0);
    // The same for prims[0..count), listed as index_base + their position.
    void add(const PrimitiveSetup* prims, size_t count, uint32_t index_base);
    // Gathering parts[0..count) (consecutive runs of primitives binned separately, on several
    // threads): begin_gather resets to the tiles occupied in any part, then gather_tile(t, ...) for
    // each of those (in parallel, any order) makes t's list the concatenation of parts[i]'s lists
    // for t, each index plus index_base[i]: exactly the lists one add() over all of them gives.
    void begin_gather(const TileGrid& grid, const Bins* parts, size_t count);
    void gather_tile(size_t t, const Bins* parts, size_t count, const uint32_t* index_base);
    const std::vector<uint32_t>& tile(size_t t) const { return lists_[t]; }
    const TileGrid& grid() const { return grid_; }
    // The tiles with a non-empty list, in no particular order.
    const std::vector<uint32_t>& occupied() const { return occupied_; }
    // occupied() in checkerboard order, the order the tile pass hands them to the pool: first the
    // tiles with tx + ty even, then the odd ones, each in row order. Workers take neighbouring
    // indices at the same time, and two tiles side by side share the cache lines at their common
    // edge (the buffers are not 64-byte aligned, so a 64-pixel row starts mid-line): in row order
    // those lines bounced between the cores on every row (large depth-tested triangles: 1.3x
    // instead of 1.9x from 1 to 2 threads).
    void checkerboard_order(std::vector<uint32_t>& out) const;
    uint64_t tiles_skipped = 0;              // (primitive, tile) pairs rejected by the edge test
    // Sum over the added primitives of (bounding box width + 2) x (height + 2): at least the lanes
    // their 2x2 quads can shade (the draw's work estimate, pipeline/draw_rollback.h).
    uint64_t quad_pixels_bound = 0;

    // Heap bytes held (kept scratch charged to the ledger after every draw: pipeline/draw.cpp).
    // The tiles' lists are summed again only after one may have grown (a 1024² grid has 256
    // lists: summing them all cost ~2,000 instructions a draw, most draws grow none).
    uint64_t capacity_bytes() const {
        if (lists_changed_) lists_bytes_ = softgl::capacity_bytes(lists_), lists_changed_ = false;
        return lists_bytes_ + softgl::capacity_bytes(occupied_) + softgl::capacity_bytes(marks_);
    }

private:
    // A tile's first primitive: the list joins occupied_.
    void append(size_t t, uint32_t n) {
        std::vector<uint32_t>& list = lists_[t];
        if (list.empty()) occupied_.push_back(uint32_t(t));
        if (list.size() == list.capacity()) lists_changed_ = true;   // push_back reallocates
        list.push_back(n);
    }

    TileGrid grid_;
    std::vector<std::vector<uint32_t>> lists_;   // empty outside occupied_
    std::vector<uint32_t> occupied_;
    std::vector<uint8_t> marks_;                 // begin_gather: tiles already in occupied_
    // capacity_bytes' sum of lists_, and whether a list may have grown since (set by the single
    // thread that appends or resets; begin_gather sets it for the gather_tile calls that follow).
    mutable uint64_t lists_bytes_ = 0;
    mutable bool lists_changed_ = true;
};

}  // namespace softgl
