#include "softgl/pipeline/whole_rect.h"

#include <algorithm>

#include "softgl/pipeline/viewport.h"

namespace softgl {
namespace {

// Pixels [x0, x1) x [y0, y1) (x0, y0 not necessarily even).
struct Part {
    int32_t x0, y0, x1, y1;
    bool empty() const { return x0 >= x1 || y0 >= y1; }
};

// Whether every pixel of the (not empty) part has sample 0 of `sp` inside every edge. Edges are
// linear: their minimum over the samples' rectangle is at a corner (raster's exact block accept).
bool covers(const PrimitiveSetup& p, const SamplePattern& sp, const Part& r) {
    const int64_t X0 = int64_t(r.x0) * kSubPixel + sp.x[0], X1 = int64_t(r.x1 - 1) * kSubPixel + sp.x[0];
    const int64_t Y0 = int64_t(r.y0) * kSubPixel + sp.y[0], Y1 = int64_t(r.y1 - 1) * kSubPixel + sp.y[0];
    for (int i = 0; i < p.edge_count; ++i)
        if (std::min(p.a[i] * X0, p.a[i] * X1) + std::min(p.b[i] * Y0, p.b[i] * Y1) + p.c[i] < 0) return false;
    return true;
}

// Blends a covered part in place and counts what rasterizing and blending it would: every 8x8
// block it touches accepted, every quad it touches emitted (each has a covered pixel), four lanes
// shaded per quad, every pixel written and blended.
void blend_part(SimdLevel level, const BlendTable& table, uint8_t* color, size_t pitch, const Part& r,
                RasterStats& raster, DrawStats& stats) {
    apply_blend_table_to_rect_at(level, table, PixelRect{color, pitch, r.x0, r.y0, r.x1, r.y1});
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

}  // namespace

void blend_covered_part(SimdLevel level, const PrimitiveSetup& p, const TileRect& tile, const SamplePattern& sp,
                        const BlendTable& table, uint8_t* color, size_t pitch, std::vector<Quad>& quads,
                        RasterStats& raster, DrawStats& stats) {
    const Part part{std::max(p.x0, tile.x0), std::max(p.y0, tile.y0), std::min(p.x1, tile.x1), std::min(p.y1, tile.y1)};
    if (part.empty()) return;
    if (covers(p, sp, part)) return blend_part(level, table, color, pitch, part, raster, stats);
    // Rows of blocks pay off only where a part holds whole blocks (a small primitive: one raster).
    if (part.x1 - part.x0 < 2 * kBlockSize || part.y1 - part.y0 < 2 * kBlockSize)
        return rasterize_at(level, p, tile, sp, quads, raster);
    for (int32_t by = part.y0 & ~(kBlockSize - 1); by < part.y1; by += kBlockSize) {
        const int32_t y0 = std::max(by, part.y0), y1 = std::min(by + kBlockSize, part.y1);
        // The covered blocks of this row from the first one on, [xa, xb): one run, as a primitive
        // is convex (a gap would only leave more to rasterize).
        int32_t xa = part.x1, xb = part.x1;
        for (int32_t bx = part.x0 & ~(kBlockSize - 1); bx < part.x1; bx += kBlockSize) {
            const Part block{std::max(bx, part.x0), y0, std::min(bx + kBlockSize, part.x1), y1};
            const bool covered = covers(p, sp, block);
            if (covered && xa == part.x1) xa = block.x0;
            if (!covered && xa != part.x1) {
                xb = block.x0;
                break;
            }
        }
        // The rest of the row as quads, in raster's order (left to right); rasterize clips to p's
        // bounding box, and xa, xb lie on block edges or the part's, so the blocks are raster's.
        const int32_t ty0 = std::max(by, tile.y0), ty1 = std::min(by + kBlockSize, tile.y1);
        rasterize_at(level, p, TileRect{tile.x0, ty0, xa, ty1}, sp, quads, raster);
        if (xa < xb) blend_part(level, table, color, pitch, Part{xa, y0, xb, y1}, raster, stats);
        if (xb < part.x1) rasterize_at(level, p, TileRect{xb, ty0, tile.x1, ty1}, sp, quads, raster);
    }
}

void depth_covered_part(SimdLevel level, const PrimitiveSetup& p, const TileRect& tile, const SamplePattern& sp,
                        const EarlyDepth& test, std::vector<Quad>& quads, RasterStats& raster, DrawStats& stats) {
    const Part part{std::max(p.x0, tile.x0), std::max(p.y0, tile.y0), std::min(p.x1, tile.x1), std::min(p.y1, tile.y1)};
    if (part.x1 - part.x0 < kBlockSize || part.y1 - part.y0 < kBlockSize)   // no whole block
        return rasterize_at(level, p, tile, sp, quads, raster);
    EarlyDepth t = test;
    t.prim = &p;
    // Rows of blocks with no covered block, from rows_y0 on, are rasterized together: a raster
    // call per row costs more than one for them all (many primitives cover no whole block).
    int32_t rows_y0 = -1;
    const auto rasterize_rows = [&](int32_t y1) {
        if (rows_y0 >= 0) rasterize_at(level, p, TileRect{tile.x0, rows_y0, tile.x1, y1}, sp, quads, raster);
        rows_y0 = -1;
    };
    for (int32_t by = part.y0 & ~(kBlockSize - 1); by < part.y1; by += kBlockSize) {
        const int32_t ty0 = std::max(by, tile.y0), ty1 = std::min(by + kBlockSize, tile.y1);
        // Blocks wholly inside the part (and so the tile) only: their quads are raster's.
        int32_t xa = part.x1, xb = part.x1;
        if (by >= part.y0 && by + kBlockSize <= part.y1) {
            // The covered blocks of this row from the first one on, [xa, xb): one run, as a
            // primitive is convex (a gap would only leave more to rasterize).
            for (int32_t bx = (part.x0 + kBlockSize - 1) & ~(kBlockSize - 1); bx + kBlockSize <= part.x1; bx += kBlockSize) {
                const bool covered = covers(p, sp, Part{bx, by, bx + kBlockSize, by + kBlockSize});
                if (covered && xa == part.x1) xa = bx;
                if (covered) xb = bx + kBlockSize;
                else if (xa != part.x1) break;
            }
        }
        if (xa == part.x1) {   // none: the row as raster's quads, with the next ones if they have none
            if (rows_y0 < 0) rows_y0 = ty0;
            continue;
        }
        rasterize_rows(ty0);
        rasterize_at(level, p, TileRect{tile.x0, ty0, xa, ty1}, sp, quads, raster);
        uint64_t passed = 0;
        stats.fragments_killed_early += early_depth_rect_at(level, t, xa, by, xb, by + kBlockSize, passed);
        stats.quads += passed;
        const uint64_t blocks = uint64_t((xb - xa) / kBlockSize);
        raster.blocks_accepted += blocks;
        stats.blocks_depth_in_place += blocks;
        raster.quads += blocks * (kBlockSize / 2) * (kBlockSize / 2);
        rasterize_at(level, p, TileRect{xb, ty0, tile.x1, ty1}, sp, quads, raster);
    }
    rasterize_rows(tile.y1);
}

}  // namespace softgl
