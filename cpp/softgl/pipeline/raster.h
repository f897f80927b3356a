// Coverage: which samples of which pixels a set-up primitive covers, within one screen tile.
//
// Hierarchical: the tile ∩ bounding box is walked in 8x8-pixel blocks; a block that lies entirely
// outside one edge is skipped, a block entirely inside all edges is emitted with full coverage and
// no per-sample test (docs/architecture.md, "Fast paths"), and only the remaining blocks test every sample. Output is 2x2
// quads (the unit the fragment shader runs on, so derivatives have neighbours) with a per-pixel
// sample mask. Results are exact (integer edge functions), so block-level accept/reject never changes
// coverage, only speed. With one sample per pixel a small part (a small triangle in a tile) reads
// its blocks from masks instead: its edges' signs at 64 pixel centres at once give the same blocks,
// statistics and quads (RasterWalk).
#pragma once
#include <cstdint>
#include <vector>

#include "softgl/core/simd.h"
#include "softgl/pipeline/setup.h"

namespace softgl {

// Sample positions inside a pixel, in 1/256 pixel from the pixel's lower-left corner (window
// coordinates, y up). The 2/4/8/16 patterns are the Vulkan/D3D standard sample locations (all on
// the 1/16 grid, so exact in 8 sub-pixel bits), taken with the same numbers in GL window
// coordinates (which is how ANGLE's Vulkan back end maps framebuffer objects: GL row 0 is memory
// row 0). 1 sample: the pixel centre.
struct SamplePattern {
    int count;
    int32_t x[16], y[16];
};
// samples: 1, 2, 4, 8 or 16; anything else throws std::invalid_argument.
const SamplePattern& sample_pattern(int samples);

// A 2x2 block of pixels with its lower-left pixel at (x, y), both even. Pixel i (i = dx + 2*dy)
// has its sample mask in bits [16*i, 16*i + 16): bit 16*i + s is sample s of the pattern.
struct Quad {
    // Default construction leaves the fields unset: the rasterizer grows its output by an upper
    // bound and then writes the quads in place.
    Quad() {}
    Quad(int32_t x, int32_t y, uint64_t coverage) : x(x), y(y), coverage(coverage) {}
    int32_t x, y;
    uint64_t coverage;
};
inline constexpr int kQuadPixelBits = 16;
inline uint32_t quad_pixel_mask(const Quad& q, int i) {
    return uint32_t(q.coverage >> (kQuadPixelBits * i)) & 0xFFFFu;
}

struct TileRect {
    int32_t x0, y0, x1, y1;   // pixels [x0, x1) x [y0, y1); x0, y0 even
};

struct RasterStats {
    uint64_t blocks_rejected = 0, blocks_accepted = 0, blocks_partial = 0, quads = 0;
    void add(const RasterStats& o) {
        blocks_rejected += o.blocks_rejected; blocks_accepted += o.blocks_accepted;
        blocks_partial += o.blocks_partial; quads += o.quads;
    }
};

inline constexpr int kBlockSize = 8;

// How rasterize_at walks a primitive. Any: with one sample per pixel and every edge's |a| + |b|
// below 2^19, a part within the 8x8 pixels from an even pixel (most pairs of a small triangle and
// a tile) is one small window (every edge's sign at its 64 pixel centres at once, int32 lanes), a
// part of at most 16 blocks walks its blocks as such windows ("masked blocks"); the rest takes the
// block walk. Blocks: always the block walk (the reference the others are tested against).
enum class RasterWalk : uint8_t { Any, Blocks };

// Appends to `out` the quads of `prim` inside `tile` (intersected with the primitive's bounding
// box), in a fixed order (blocks bottom-up then left-right, quads likewise). Quads with no covered
// sample are not emitted. `level` picks the kernels (AVX2 / AVX-512 evaluate a block's rows of
// edge values in int64 lanes, a small window's rows in int32 lanes; below AVX2 the scalar
// reference); every level and walk gives the same quads and stats.
void rasterize_at(SimdLevel level, const PrimitiveSetup& prim, const TileRect& tile, const SamplePattern& pattern,
                  std::vector<Quad>& out, RasterStats& stats, RasterWalk walk = RasterWalk::Any);
inline void rasterize(const PrimitiveSetup& prim, const TileRect& tile, const SamplePattern& pattern,
                      std::vector<Quad>& out, RasterStats& stats) {
    rasterize_at(best_simd_level(), prim, tile, pattern, out, stats);
}

}  // namespace softgl
