// What a draw must be able to undo: when it stops part-way (its work budget ran out, or Ctrl-C:
// core/work_budget.h), every colour, depth and stencil value it wrote goes back to what it was
// before the call (docs/reliability.md, "Work budget and Ctrl-C").
//
// The mechanism is a first-touch copy per tile: the tile pass calls save() as it starts a tile
// (the worker that owns the tile, so no two threads save one tile), and the first call for a tile
// in the draw copies the tile's pixels of every attachment. A draw that completes only pays that
// copy for the tiles it touches (once per draw, not per batch); a stopped draw copies them back.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "softgl/pipeline/bin.h"
#include "softgl/pipeline/raster.h"
#include "softgl/surface/render_target.h"

namespace softgl {

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
