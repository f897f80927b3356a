// Binning: each set-up primitive is listed in every screen tile it may cover, in draw order, so
// that tiles can be rasterised and shaded independently on worker threads while every pixel still
// sees its primitives in order (ES 3.0 §4: per-fragment operations happen in primitive order).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

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
    void reset(const TileGrid& grid);        // empty lists for grid.count() tiles
    // Appends prims[first..] to the tiles their bounding box meets, skipping tiles that lie entirely
    // outside one of a primitive's edges. Indices refer to `prims`.
    void add(const std::vector<PrimitiveSetup>& prims, size_t first = 0);
    // The same for prims[0..count), listed as index_base + their position.
    void add(const PrimitiveSetup* prims, size_t count, uint32_t index_base);
    // Tile t's list becomes the concatenation of parts[i]'s lists for t (i < count), each index
    // plus index_base[i]. Binning consecutive runs of primitives separately (on several threads) and
    // gathering them in order gives exactly the lists one add() over all of them gives.
    void gather_tile(size_t t, const Bins* parts, size_t count, const uint32_t* index_base);
    const std::vector<uint32_t>& tile(size_t t) const { return lists_[t]; }
    const TileGrid& grid() const { return grid_; }
    uint64_t tiles_skipped = 0;              // (primitive, tile) pairs rejected by the edge test

private:
    TileGrid grid_;
    std::vector<std::vector<uint32_t>> lists_;
};

}  // namespace softgl
