// A primitive that covers the whole of its part of a tile: the tile's pixels inside its bounding
// box all have their one sample inside every edge. draw.cpp then blends that part by table in one
// pass (fragment_ops.h apply_blend_table_to_rect), with no quads built, and counts what
// rasterize would have counted.
#pragma once
#include <algorithm>
#include <cstdint>

#include "softgl/pipeline/draw.h"
#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/viewport.h"

namespace softgl {

// The pixels of `tile` inside p's bounding box, [x0, x1) x [y0, y1) (x0, y0 not necessarily even).
struct PartRect {
    int32_t x0, y0, x1, y1;
    bool empty() const { return x0 >= x1 || y0 >= y1; }
};
inline PartRect part_in_tile(const PrimitiveSetup& p, const TileRect& tile) {
    return {std::max(p.x0, tile.x0), std::max(p.y0, tile.y0), std::min(p.x1, tile.x1), std::min(p.y1, tile.y1)};
}

// Whether every pixel of the (not empty) part has sample 0 of `sp` inside every edge (single
// sampling). Edges are linear: their minimum over the samples' rectangle is at a corner, the exact
// integer test of raster's block accept.
inline bool covers_part(const PrimitiveSetup& p, const SamplePattern& sp, const PartRect& r) {
    const int64_t X0 = int64_t(r.x0) * kSubPixel + sp.x[0], X1 = int64_t(r.x1 - 1) * kSubPixel + sp.x[0];
    const int64_t Y0 = int64_t(r.y0) * kSubPixel + sp.y[0], Y1 = int64_t(r.y1 - 1) * kSubPixel + sp.y[0];
    for (int i = 0; i < p.edge_count; ++i)
        if (std::min(p.a[i] * X0, p.a[i] * X1) + std::min(p.b[i] * Y0, p.b[i] * Y1) + p.c[i] < 0) return false;
    return true;
}

// What rasterizing and blending a covered part counts: every 8x8 block it touches accepted, every
// quad it touches emitted (each has a covered pixel), four lanes shaded per quad, every pixel
// written and blended.
inline void count_covered_part(const PartRect& r, RasterStats& raster, DrawStats& stats) {
    const uint64_t blocks = uint64_t((r.x1 - 1) / kBlockSize - r.x0 / kBlockSize + 1) *
                           uint64_t((r.y1 - 1) / kBlockSize - r.y0 / kBlockSize + 1);
    const uint64_t quads = uint64_t((r.x1 - (r.x0 & ~1) + 1) / 2) * uint64_t((r.y1 - (r.y0 & ~1) + 1) / 2);
    const uint64_t pixels = uint64_t(r.x1 - r.x0) * uint64_t(r.y1 - r.y0);
    raster.blocks_accepted += blocks;
    raster.quads += quads;
    stats.quads += quads;
    stats.fragments_shaded += 4 * quads;
    stats.samples_written += pixels;
    stats.samples_blended += pixels;
}

}  // namespace softgl
