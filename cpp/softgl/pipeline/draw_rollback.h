// What a draw must be able to undo: when it stops part-way (its work budget ran out, or Ctrl-C:
// core/work_budget.h), every colour, depth and stencil value it wrote goes back to what it was
// before the call (docs/reliability.md, "Work budget and Ctrl-C").
//
// The mechanism is a first-touch copy per tile: the tile pass calls save() as it starts a tile
// (the worker that owns the tile, so no two threads save one tile), and the first call for a tile
// in the draw copies the tile's pixels of every attachment. A stopped draw copies them back.
//
// Only draws that can be stopped after writing pixels keep copies (rollback_needed below); the
// others defer a stop (Ctrl-C) to their end, which comes soon, and cannot run out of budget.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "softgl/core/work_budget.h"
#include "softgl/pipeline/bin.h"
#include "softgl/pipeline/raster.h"
#include "softgl/surface/render_target.h"

namespace softgl {

// A draw's fragment work is estimated, before its first tile pass, from its first batch: the sum
// over its primitives of (bounding box width + 2) x (height + 2) pixels (Bins::quad_pixels_bound)
// times (the fragment shader's instruction bound + kFragmentWorkUnits), plus kTilePrimitiveWorkUnits
// per (primitive, tile) pair: an upper bound of what the tile pass charges the budget, and a
// measure of its time. Past kRollbackWorkThreshold a Ctrl-C mid-draw matters, so the draw keeps
// copies. 2^28 units is calibrated by benchmarks/work_units.py (docs/reliability.md): 0.02-0.10 s
// of one thread's work for the single-batch draws this rule decides (fragment loops 0.1 ns a
// unit, blended full-screen layers 0.36), so a draw without copies defers a Ctrl-C by at most
// about the poll's 0.1 s target, while copying a whole 512 x 512 target (2 MiB) costs
// milliseconds, a few percent of such a draw at most.
inline constexpr uint64_t kRollbackWorkThreshold = uint64_t(1) << 28;

// Whether a draw keeps copies of the pixels it writes: when it runs in more than one batch (a
// later batch can stop after an earlier one wrote), when its fragment shader has a loop with no
// counted bound (glsl::instructions_bound), or when its estimated fragment work passes
// kRollbackWorkThreshold or what is left of its budget.
bool rollback_needed(bool several_batches, uint64_t fragment_work_estimate, uint64_t budget_left);

// The estimate above, saturating.
uint64_t fragment_work_estimate(uint64_t pairs, uint64_t pixels, uint64_t instructions_bound);

// Heap bytes of the copies kept between draws on the calling thread (charged with the draw's
// other scratch: pipeline/draw.cpp).
uint64_t rollback_scratch_bytes();

class DrawRollback {
public:
    // Starts a draw into `target` over `grid`'s tiles (nothing is copied yet).
    DrawRollback(RenderTarget& target, const TileGrid& grid);
    // Before the draw first writes tile `tile` (rect `r`): keeps a copy of its pixels.
    void save(size_t tile, const TileRect& r) {
        if (!saved_[tile]) save_tile(tile, r);
    }
    // Puts every saved tile back (the draw stopped).
    void restore();
    // The most the copies of a draw into `target` can take: every pixel of every attachment.
    static uint64_t bytes_bound(RenderTarget& target);
    // Bytes copied so far (the cost of the mechanism, for docs/reliability.md).
    size_t bytes_saved() const;

private:
    // One attachment's storage: pixel (x, y) at base + y * pitch + x * pixel_bytes (all samples).
    struct Plane {
        uint8_t* base;
        size_t pixel_bytes, pitch;
    };
    void save_tile(size_t tile, const TileRect& r);
    template <class T>
    void add_image_plane(std::vector<T>& storage, const Image& img, size_t offset, size_t per_texel);

    std::vector<Plane> planes_;
    std::vector<uint8_t>& saved_;                   // per tile: copied in this draw
    std::vector<std::vector<uint8_t>>& copies_;     // per tile: its pixels, plane after plane
    std::vector<TileRect>& rects_;                  // per tile: the rectangle copied
};

}  // namespace softgl
