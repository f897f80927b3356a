// The early depth test (ES 3.0 §4.1.6, run before shading when the shader neither discards nor
// writes depth) of a run of quads, for the common case: 24-bit depth words, no stencil. Each
// covered sample compares depth_word(Depth24, prim.depth_at(sample)) with the stored word, and on
// a pass with depth writes enabled stores it. The pixels of one primitive are distinct, so they
// are independent. One sample per pixel: the AVX2 and AVX-512 levels test a row of up to four
// side-by-side quads at once (two pixel rows of 8), a lone quad's four pixels at once. Four samples per
// pixel (MSAA 4x): the AVX2 level tests a pixel's four samples at once, the AVX-512 level a
// quad's pixel row (two pixels, 8 sample words); other sample counts run the scalar level. All
// give the same words and decisions as the scalar level (docs/architecture.md, "Numeric rules").
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "softgl/core/simd.h"
#include "softgl/core/state.h"
#include "softgl/core/tuning.h"
#include "softgl/pipeline/bin.h"
#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/setup.h"

namespace softgl {

struct EarlyDepth {
    const PrimitiveSetup* prim = nullptr;
    const SamplePattern* pattern = nullptr;   // the samples per pixel and their positions
    GLenum func = gl::LESS;
    bool write = true;
    uint32_t* depth = nullptr;                // word of sample s of pixel (x, y): depth[(y * pitch + x) * samples + s]
    size_t pitch = 0;
    // Optional: colour pixels with the depth's layout (one sample, 4 bytes a pixel, `pitch`), which
    // the draw reads after shading the survivors (blending) or writes: the AVX2 and AVX-512
    // levels ask for a quad row's colour lines while they test their depth, and for the depth
    // lines of the block row below (the rasterizer's next), since a tile's 256-byte rows are too
    // short a run for the hardware prefetchers. Hints only: no byte depends on them.
    const uint32_t* prefetch_color = nullptr;
};

// Tests the covered samples (quad_pixel_mask) of quads[0, n); survived[4*i + j] is the mask of
// the samples of pixel j of quads[i] that are covered and pass. Returns the number that failed.
size_t early_depth_test_at(SimdLevel level, const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived);
inline size_t early_depth_test(const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    return early_depth_test_at(best_simd_level(), t, quads, n, survived);
}

// The same test of every pixel of [x0, x1) x [y0, y1), one sample per pixel, with x0, y0 even and
// x1 - x0 a multiple of 8, y1 - y0 of 2 (whole 8x8 blocks the primitive covers): the words and
// decisions early_depth_test gives the quads the rasterizer emits there, without the quads.
// Returns the number that failed; `quads_passed` gains the number of those quads with a pixel
// that passed.
size_t early_depth_rect_at(SimdLevel level, const EarlyDepth& t, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                           uint64_t& quads_passed);

// Depth bounds per 8x8 block of a tile, to skip the raster and early depth test of a primitive
// that fails the test at every pixel of the tile (one sample per pixel, LESS/LEQUAL/GREATER/
// GEQUAL, 24-bit depth, no stencil). A block's smallest and largest stored words are read when
// first needed and again after a primitive that may write depth covered the block, so they are
// always exact: the decision depends on the stored words only (same at any thread count, batch
// size or SIMD level). The primitive's plane is linear, so its extreme over the pixel centres of
// its bounding box within the tile is at a corner; a margin of rounding error keeps the test
// conservative (depth_word is monotonic). One per worker, begun per tile pass.
class DepthBounds {
public:
    // Starts tile `rect` of a draw whose early depth test is t (prim unset), in `mode` (the draw
    // plan's: Off skips nothing; SabotagedForTests takes the primitive's depth at the wrong
    // corner, so that a test comparing with Off must fail), reading blocks at `level`.
    void begin_tile(const EarlyDepth& t, const TileRect& rect, DepthBoundsMode mode, SimdLevel level);
    // Whether every fragment of `p` in the tile fails the test; if not, and the test writes
    // depth, the blocks under p's bounding box are read again when next needed.
    bool hides(const PrimitiveSetup& p) {
        if (!enabled_) return false;
        // The primitive's pixels lie in its bounding box within the tile. A small one costs less
        // to rasterize and test than its blocks' bounds.
        const int32_t x0 = std::max(p.x0, rect_.x0), x1 = std::min(p.x1, rect_.x1);
        const int32_t y0 = std::max(p.y0, rect_.y0), y1 = std::min(p.y1, rect_.y1);
        if (x0 >= x1 || y0 >= y1 || int64_t(x1 - x0) * int64_t(y1 - y0) < kMinPixels) return false;
        return hides_box(p, x0, y0, x1, y1);
    }

private:
    static constexpr int kBlocksPerRow = kTileSize / kBlockSize;
    static_assert(kBlocksPerRow * kBlocksPerRow == 64, "one bit of `known_` per block");
    static constexpr int64_t kMinPixels = 256;   // bounding box area in the tile
    bool hides_box(const PrimitiveSetup& p, int32_t x0, int32_t y0, int32_t x1, int32_t y1);
    void read_block(int block);
    bool enabled_ = false, write_ = false, vector_ = false, sabotaged_ = false;
    GLenum func_ = gl::LESS;
    TileRect rect_{};
    int64_t sample_x_ = 0, sample_y_ = 0;     // the pixel's sample position in 1/256 pixel
    const uint32_t* depth_ = nullptr;         // EarlyDepth::depth and pitch
    size_t pitch_ = 0;
    uint64_t known_ = 0;                      // bit b: min_[b], max_[b] are current
    uint32_t min_[kBlocksPerRow * kBlocksPerRow] = {}, max_[kBlocksPerRow * kBlocksPerRow] = {};
};

}  // namespace softgl
