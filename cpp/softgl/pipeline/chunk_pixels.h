// A chunk's destination pixels on the single-sampled RGBA8 drawing buffer, moved between the
// buffer and the chunk's lanes (lane 4 * i + j: pixel j of quad i, masks[lane] its coverage of 0 or
// 1), for the colour kernels of the tile pass (pipeline/tile_pass, the write step). A quad inside
// the buffer moves as two 8-byte rows (lanes 0, 1 and 2, 3 are pixels x, x + 1 of rows y and
// y + 1); four side by side (a row of an 8x8 block, as the rasterizer emits them) as two 32-byte
// rows. A partial quad keeps its uncovered pixels' old values (a select, not a branch per pixel:
// the pixels are in this worker's tile). A quad reaching past the buffer's edge moves pixel by
// pixel, covered ones only.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "softgl/pipeline/raster.h"

namespace softgl {

static_assert(kQuadPixelBits == 16, "a quad's coverage is its four uint16_t pixel masks, pixel 0 first");
static_assert(offsetof(Quad, y) == 4, "a quad's x and y side by side (ChunkPixels::row_of_four)");

struct ChunkPixels {
    uint8_t* color;               // pixel (0, 0)
    size_t pitch;                 // pixels from one row to the next
    int32_t last_x, last_y;       // a quad at x < last_x, y < last_y is inside
    uint8_t* at(const Quad& q) const { return color + 4 * (size_t(q.y) * pitch + size_t(q.x)); }
    bool inside(const Quad& q) const { return q.x < last_x && q.y < last_y; }
    // Whether q[0..3] lie side by side, all inside. x and y as one word: x + 2k does not carry into
    // y, as quads lie in the buffer (x >= 0).
    bool row_of_four(const Quad* q) const {
        uint64_t xy[4];
        for (int k = 0; k < 4; ++k) std::memcpy(&xy[k], &q[k].x, 8);
        return xy[1] == xy[0] + 2 && xy[2] == xy[0] + 4 && xy[3] == xy[0] + 6 && q[0].x + 6 < last_x && q[0].y < last_y;
    }
};
inline constexpr uint64_t kWholeQuad = 0x0001000100010001u;   // four masks of 1 (S == 1)

// The chunk's runs of four whole quads side by side (bit i: quads i .. i + 3), found as
// store_chunk_pixels walks the chunk: the fused copy kernel and the blend table write those
// straight into the buffer (PixelRows), and the two functions below skip them when given them as
// `skip`. n <= 64.
inline uint64_t whole_rows_of_four(const ChunkPixels buffer, const Quad* q, const uint16_t* masks, size_t n) {
    uint64_t rows = 0;
    for (size_t i = 0; i + 4 <= n;) {
        // Four 8-byte loads (one 32-byte copy went through the stack: a store-forwarding stall).
        uint64_t m0, m1, m2, m3;
        std::memcpy(&m0, masks + 4 * i, 8), std::memcpy(&m1, masks + 4 * i + 4, 8);
        std::memcpy(&m2, masks + 4 * i + 8, 8), std::memcpy(&m3, masks + 4 * i + 12, 8);
        if ((m0 & m1 & m2 & m3) == kWholeQuad && buffer.row_of_four(q + i)) {
            rows |= uint64_t(1) << i;
            i += 4;
        } else {
            ++i;
        }
    }
    return rows;
}

// The covered pixels of quads q[0, n) into lanes.
void load_chunk_pixels(const ChunkPixels buffer, const Quad* q, const uint16_t* masks, size_t n, uint32_t* lanes,
                       uint64_t skip = 0);
// The covered lanes into the buffer; returns the number of pixels written.
uint64_t store_chunk_pixels(const ChunkPixels buffer, const Quad* q, const uint16_t* masks, size_t n,
                            const uint32_t* lanes, uint64_t skip = 0);

// The same for lanes that are single covered pixels: lane l is pixel (xy[2l], xy[2l + 1]).
inline void load_lane_pixels(const ChunkPixels buffer, const int32_t* xy, size_t n, uint32_t* lanes) {
    for (size_t l = 0; l < n; ++l)
        std::memcpy(&lanes[l], buffer.color + 4 * (size_t(xy[2 * l + 1]) * buffer.pitch + size_t(xy[2 * l])), 4);
}
inline void store_lane_pixels(const ChunkPixels buffer, const int32_t* xy, size_t n, const uint32_t* lanes) {
    for (size_t l = 0; l < n; ++l)
        std::memcpy(buffer.color + 4 * (size_t(xy[2 * l + 1]) * buffer.pitch + size_t(xy[2 * l])), &lanes[l], 4);
}

}  // namespace softgl
