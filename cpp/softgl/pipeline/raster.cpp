#include "softgl/pipeline/raster.h"

#include <algorithm>
#include <stdexcept>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SOFTGL_HAVE_SIMD_RASTER 1
#endif

namespace softgl {

namespace {

SamplePattern make_pattern(int count, const double (*pos)[2]) {
    SamplePattern p{};
    p.count = count;
    for (int i = 0; i < count; ++i) {
        p.x[i] = int32_t(pos[i][0] * kSubPixel);
        p.y[i] = int32_t(pos[i][1] * kSubPixel);
    }
    return p;
}

// Vulkan 1.x "Standard sample locations" table (= D3D11 standard patterns).
const double kPos1[1][2] = {{0.5, 0.5}};
const double kPos2[2][2] = {{0.75, 0.75}, {0.25, 0.25}};
const double kPos4[4][2] = {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}};
const double kPos8[8][2] = {{0.5625, 0.3125}, {0.4375, 0.6875}, {0.8125, 0.5625},
                            {0.3125, 0.1875}, {0.1875, 0.8125}, {0.0625, 0.4375},
                            {0.6875, 0.9375}, {0.9375, 0.0625}};
const double kPos16[16][2] = {{0.5625, 0.5625}, {0.4375, 0.3125}, {0.3125, 0.625},
                              {0.75, 0.4375},   {0.1875, 0.375},  {0.625, 0.8125},
                              {0.8125, 0.6875}, {0.6875, 0.1875}, {0.375, 0.875},
                              {0.5, 0.0625},    {0.25, 0.125},    {0.125, 0.75},
                              {0.0, 0.5},       {0.9375, 0.25},   {0.875, 0.9375},
                              {0.0625, 0.0}};

// Writes a quad field by field: a Quad built aside and copied whole makes the CPU load 16 bytes
// just stored as 4 + 4 + 8 (a store-forwarding stall on every quad).
inline void put(Quad* q, int32_t x, int32_t y, uint64_t coverage) { q->x = x, q->y = y, q->coverage = coverage; }

// Whole blocks: the 16 quads of an 8x8 block at (bx, by), all with the same coverage, in the
// output order (rows bottom-up, then left-right). Returns the end of the written quads.
using PutBlockFn = Quad* (*)(Quad* q, int32_t bx, int32_t by, uint64_t coverage);

Quad* put_block(Quad* q, int32_t bx, int32_t by, uint64_t coverage) {
    for (int r = 0; r < kBlockSize; r += 2)
        for (int k = 0; k < kBlockSize; k += 2) put(q++, bx + k, by + r, coverage);
    return q;
}

#if defined(SOFTGL_HAVE_SIMD_RASTER)
// A row of 4 quads is one 64-byte store: 32-bit lanes x, y, low and high coverage word per quad.
__attribute__((target("avx512f"))) Quad* put_block_avx512(Quad* q, int32_t bx, int32_t by, uint64_t coverage) {
    const int32_t lo = int32_t(uint32_t(coverage)), hi = int32_t(uint32_t(coverage >> 32));
    __m512i row = _mm512_set_epi32(hi, lo, by, bx + 6, hi, lo, by, bx + 4, hi, lo, by, bx + 2, hi, lo, by, bx);
    const __m512i up = _mm512_set_epi32(0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 2, 0);   // y += 2
    for (int r = 0; r < kBlockSize; r += 2, q += 4) {
        _mm512_storeu_si512(q, row);
        row = _mm512_add_epi32(row, up);
    }
    return q;
}
#endif

// ---- SIMD partial blocks ----
// One sample position over the rows [r0, r1) of an 8x8 block: bit 8*r + k of the result is set
// when pixel (k, r) has every edge value >= 0. e[i] is edge i at column 0 of row r0 (sample offset
// included), col[i][k] = k * dx[i], dy[i] one row's step. Integer sums do not depend on their
// order, so each lane holds exactly the value the scalar path computes for its pixel.
template <int N>
struct BlockSteps {
    int64_t col[N][8];
    int64_t dy[N];
};
template <int N>
using InsideRowsFn = uint64_t (*)(const BlockSteps<N>& st, const int64_t* e, int r0, int r1);

#if defined(SOFTGL_HAVE_SIMD_RASTER)
template <int N>
__attribute__((target("avx2"))) uint64_t inside_rows_avx2(const BlockSteps<N>& st, const int64_t* e, int r0,
                                                          int r1) {
    __m256i lo[N], hi[N], step[N];
    for (int i = 0; i < N; ++i) {
        const __m256i base = _mm256_set1_epi64x(e[i]);
        lo[i] = _mm256_add_epi64(base, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&st.col[i][0])));
        hi[i] = _mm256_add_epi64(base, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&st.col[i][4])));
        step[i] = _mm256_set1_epi64x(st.dy[i]);
    }
    uint64_t inside = 0;
    for (int r = r0; r < r1; ++r) {
        // A pixel is inside when the OR of its edge values has no sign bit.
        __m256i ol = lo[0], oh = hi[0];
        for (int i = 1; i < N; ++i) ol = _mm256_or_si256(ol, lo[i]), oh = _mm256_or_si256(oh, hi[i]);
        const unsigned neg = unsigned(_mm256_movemask_pd(_mm256_castsi256_pd(ol))) |
                             unsigned(_mm256_movemask_pd(_mm256_castsi256_pd(oh))) << 4;
        inside |= uint64_t(~neg & 0xFFu) << (8 * r);
        for (int i = 0; i < N; ++i) lo[i] = _mm256_add_epi64(lo[i], step[i]), hi[i] = _mm256_add_epi64(hi[i], step[i]);
    }
    return inside;
}

template <int N>
__attribute__((target("avx512f,avx512bw,avx512dq,avx512vl"))) uint64_t inside_rows_avx512(const BlockSteps<N>& st,
                                                                                          const int64_t* e, int r0,
                                                                                          int r1) {
    __m512i v[N], step[N];
    for (int i = 0; i < N; ++i) {
        v[i] = _mm512_add_epi64(_mm512_set1_epi64(e[i]), _mm512_loadu_si512(&st.col[i][0]));
        step[i] = _mm512_set1_epi64(st.dy[i]);
    }
    uint64_t inside = 0;
    for (int r = r0; r < r1; ++r) {
        __m512i o = v[0];
        for (int i = 1; i < N; ++i) o = _mm512_or_si512(o, v[i]);
        inside |= uint64_t(uint8_t(~_mm512_movepi64_mask(o))) << (8 * r);
        for (int i = 0; i < N; ++i) v[i] = _mm512_add_epi64(v[i], step[i]);
    }
    return inside;
}
#endif

// The 4 pixel bits b (bit j = pixel j of a quad) moved to bits 16*j: the four partial products
// land in disjoint bit ranges [15j, 15j + 4), so nothing carries.
inline uint64_t spread_quad_bits(uint64_t b) { return (b * 0x0000200040008001ull) & 0x0001000100010001ull; }

// What raster_edges knows of a primitive before it walks the blocks (all exact integers). In a
// local: the quads' uint64 stores could alias the edges if they were read from memory.
template <int N>
struct EdgeWalk {
    int S;                              // samples per pixel
    uint64_t full_pixel, full_quad;     // the coverage of a whole pixel, of a whole quad
    int64_t A[N], B[N], C[N];           // edge i at (X, Y) in fixed point: A[i] * X + B[i] * Y + C[i]
    int64_t dx[N], dy[N];               // edge steps of one pixel in x and in y
    int64_t so[N][16];                  // edge value offset of each sample from its pixel's corner
    int32_t sx0, sx1, sy0, sy1;         // the extent of the samples within a pixel
    bool whole_blocks;                  // whole blocks test their corner (to_max, to_min)
    int64_t to_max[N], to_min[N];
};

// An 8x8 block at (bx, by), clipped to [cx0, cx1) x [cy0, cy1).
struct Block {
    int32_t bx, by, cx0, cy0, cx1, cy1;
};

template <int N>
__attribute__((always_inline)) inline void set_up_walk(EdgeWalk<N>& w, const PrimitiveSetup& p, const SamplePattern& sp,
                                                       int32_t x0, int32_t y0, int32_t x1, int32_t y1) {
    const int S = w.S = sp.count;
    w.full_pixel = S == 16 ? 0xFFFFu : ((uint64_t(1) << S) - 1);
    w.full_quad = w.full_pixel | w.full_pixel << kQuadPixelBits | w.full_pixel << (2 * kQuadPixelBits) |
                  w.full_pixel << (3 * kQuadPixelBits);
    for (int i = 0; i < N; ++i) w.A[i] = p.a[i], w.B[i] = p.b[i], w.C[i] = p.c[i];
    for (int i = 0; i < N; ++i)
        for (int s = 0; s < S; ++s) w.so[i][s] = p.a[i] * sp.x[s] + p.b[i] * sp.y[s];
    for (int i = 0; i < N; ++i) w.dx[i] = p.a[i] * kSubPixel, w.dy[i] = p.b[i] * kSubPixel;
    // The extent of the samples within a pixel: block tests cover exactly the samples' hull.
    w.sx0 = sp.x[0], w.sx1 = sp.x[0], w.sy0 = sp.y[0], w.sy1 = sp.y[0];
    for (int s = 1; s < S; ++s) {
        w.sx0 = std::min(w.sx0, sp.x[s]); w.sx1 = std::max(w.sx1, sp.x[s]);
        w.sy0 = std::min(w.sy0, sp.y[s]); w.sy1 = std::max(w.sy1, sp.y[s]);
    }
    // Edges are linear, so their extremes over a rectangle of samples are at its corners: the
    // larger and the smaller of a*X0, a*X1 plus those of b*Y0, b*Y1 (min/max: no branch on signs).
    // A whole (unclipped) block's sample rectangle is its corner (bx, by) plus constant offsets, so
    // an edge's extremes over it are the edge at the corner plus constants (the same integers).
    // Set up only for triangles whose rectangle holds a whole block: small triangles do not pay for
    // it, and lines and points (4 edges) are mostly thin, so the extra branch costs them more than
    // it saves (measured).
    w.whole_blocks = N == 3 && ((x0 + kBlockSize - 1) & ~(kBlockSize - 1)) + kBlockSize <= x1 &&
                     ((y0 + kBlockSize - 1) & ~(kBlockSize - 1)) + kBlockSize <= y1;
    constexpr int32_t kLast = (kBlockSize - 1) * kSubPixel;   // last pixel of a block, fixed point
    for (int i = 0; i < N; ++i) w.to_max[i] = w.to_min[i] = 0;
    if (w.whole_blocks)
        for (int i = 0; i < N; ++i) {
            const int64_t ax0 = w.A[i] * w.sx0, ax1 = w.A[i] * (kLast + w.sx1);
            const int64_t by0 = w.B[i] * w.sy0, by1 = w.B[i] * (kLast + w.sy1);
            w.to_max[i] = std::max(ax0, ax1) + std::max(by0, by1);
            w.to_min[i] = std::min(ax0, ax1) + std::min(by0, by1);
        }
}

// The OR of the edges' maxima over the block's samples (negative: the block is outside some
// edge) and of their minima (not negative: inside every edge); branch-free. row: the edges at
// (0, by) when the block's row is whole.
template <int N>
__attribute__((always_inline)) inline void block_extremes(const EdgeWalk<N>& w, const Block& blk, bool whole_rows,
                                                          const int64_t (&row)[N], int64_t& max_or, int64_t& min_or) {
    max_or = 0, min_or = 0;
    if (whole_rows && blk.cx0 == blk.bx && blk.cx1 == blk.bx + kBlockSize) {
        for (int i = 0; i < N; ++i) {
            const int64_t corner = row[i] + w.A[i] * (int64_t(blk.bx) * kSubPixel);
            max_or |= corner + w.to_max[i];
            min_or |= corner + w.to_min[i];
        }
        return;
    }
    // The rectangle spanned by the clipped block's samples.
    const int64_t X0 = int64_t(blk.cx0) * kSubPixel + w.sx0, X1 = int64_t(blk.cx1 - 1) * kSubPixel + w.sx1;
    const int64_t Y0 = int64_t(blk.cy0) * kSubPixel + w.sy0, Y1 = int64_t(blk.cy1 - 1) * kSubPixel + w.sy1;
    for (int i = 0; i < N; ++i) {
        const int64_t ax0 = w.A[i] * X0, ax1 = w.A[i] * X1, by0 = w.B[i] * Y0, by1 = w.B[i] * Y1;
        max_or |= std::max(ax0, ax1) + std::max(by0, by1) + w.C[i];
        min_or |= std::min(ax0, ax1) + std::min(by0, by1) + w.C[i];
    }
}

// Whole block inside every edge and its clipped rectangle made of whole quads: every quad is
// fully covered, no per-pixel bounds to test.
template <int N>
__attribute__((always_inline)) inline Quad* put_covered_quads(Quad* q, const EdgeWalk<N>& w, const Block& blk,
                                                              PutBlockFn put_block) {
    if (blk.cx1 - blk.cx0 == kBlockSize && blk.cy1 - blk.cy0 == kBlockSize) return put_block(q, blk.bx, blk.by, w.full_quad);
    for (int32_t qy = blk.cy0; qy < blk.cy1; qy += 2)
        for (int32_t qx = blk.cx0; qx < blk.cx1; qx += 2) put(q++, qx, qy, w.full_quad);
    return q;
}

// SIMD levels: pixel masks of the block (bit 8*r + k: pixel (bx + k, by + r)), one per sample,
// limited to the clipped rectangle; then each quad's bits are gathered from them.
template <int N>
__attribute__((always_inline)) inline Quad* put_quads_from_masks(Quad* q, const EdgeWalk<N>& w, const Block& blk,
                                                                 bool accept, const BlockSteps<N>& steps,
                                                                 InsideRowsFn<N> inside_rows) {
    const int S = w.S;
    const int r0 = blk.cy0 - blk.by, r1 = blk.cy1 - blk.by, k0 = blk.cx0 - blk.bx, k1 = blk.cx1 - blk.bx;
    const uint64_t row_bits = ((uint64_t(1) << k1) - (uint64_t(1) << k0)) * 0x0101010101010101ull;
    const uint64_t present = row_bits & ((r1 == 8 ? ~uint64_t(0) : (uint64_t(1) << (8 * r1)) - 1) &
                                         ~((uint64_t(1) << (8 * r0)) - 1));
    uint64_t mask[16];   // partial blocks: the pixels covering sample s
    uint64_t any = present;
    if (!accept) {
        const int64_t X = int64_t(blk.bx) * kSubPixel, Y = int64_t(blk.cy0) * kSubPixel;
        int64_t e0[N], e[N];
        for (int i = 0; i < N; ++i) e0[i] = w.A[i] * X + w.B[i] * Y + w.C[i];
        any = 0;
        for (int s = 0; s < S; ++s) {
            for (int i = 0; i < N; ++i) e[i] = e0[i] + w.so[i][s];
            mask[s] = inside_rows(steps, e, r0, r1) & present;
            any |= mask[s];
        }
    }
    // The non-empty quads: bit 16*p + 2*k for the quad of rows 2p, 2p + 1 and columns
    // 2k, 2k + 1. Ascending bits are the scalar path's order (rows, then columns).
    const uint64_t pairs = (any | any >> 8) & 0x00FF00FF00FF00FFull;
    for (uint64_t quads = (pairs | pairs >> 1) & 0x0055005500550055ull; quads; quads &= quads - 1) {
        const int sh = __builtin_ctzll(quads);
        uint64_t cov;
        if (S == 1 || accept) {   // one sample, or full pixels where present
            cov = spread_quad_bits((any >> sh & 3) | (any >> (sh + 8) & 3) << 2) * w.full_pixel;
        } else {
            cov = 0;
            for (int s = 0; s < S; ++s)
                cov |= spread_quad_bits((mask[s] >> sh & 3) | (mask[s] >> (sh + 8) & 3) << 2) << s;
        }
        put(q++, blk.bx + (sh & 7), blk.by + (sh >> 3), cov);
    }
    return q;
}

// Scalar level, whole block inside every edge: full coverage, only the clip to [cx0, cx1) x
// [cy0, cy1) decides which pixels of each quad are present.
template <int N>
__attribute__((always_inline)) inline Quad* put_clipped_quads(Quad* q, const EdgeWalk<N>& w, const Block& blk) {
    for (int32_t qy = blk.cy0 & ~1; qy < blk.cy1; qy += 2) {
        const bool row0 = qy >= blk.cy0, row1 = qy + 1 < blk.cy1;
        for (int32_t qx = blk.cx0 & ~1; qx < blk.cx1; qx += 2) {
            const bool col0 = qx >= blk.cx0, col1 = qx + 1 < blk.cx1;
            uint64_t cov = 0;
            if (row0 && col0) cov |= w.full_pixel;
            if (row0 && col1) cov |= w.full_pixel << kQuadPixelBits;
            if (row1 && col0) cov |= w.full_pixel << (2 * kQuadPixelBits);
            if (row1 && col1) cov |= w.full_pixel << (3 * kQuadPixelBits);
            put(q, qx, qy, cov);   // kept when not empty
            q += cov != 0;
        }
    }
    return q;
}

// Scalar level, partial block: edge values stepped across the block (exact integers, so the
// same values as evaluating every pixel); one sample folds its offset into the start.
template <int N>
__attribute__((always_inline)) inline Quad* put_tested_quads(Quad* q, const EdgeWalk<N>& w, const Block& blk) {
    const int S = w.S;
    const int32_t qx0 = blk.cx0 & ~1;
    for (int32_t qy = blk.cy0 & ~1; qy < blk.cy1; qy += 2) {
        int64_t er[N];   // at pixel (qx, qy) of the current quad
        {
            const int64_t X = int64_t(qx0) * kSubPixel, Y = int64_t(qy) * kSubPixel;
            for (int i = 0; i < N; ++i) er[i] = w.A[i] * X + w.B[i] * Y + w.C[i] + (S == 1 ? w.so[i][0] : 0);
        }
        const bool row0 = qy >= blk.cy0, row1 = qy + 1 < blk.cy1;
        for (int32_t qx = qx0; qx < blk.cx1; qx += 2) {
            const bool col0 = qx >= blk.cx0, col1 = qx + 1 < blk.cx1;
            const bool present[4] = {row0 && col0, row0 && col1, row1 && col0, row1 && col1};
            uint64_t cov = 0;
            if (S == 1) {
                // Branch-free: a pixel is inside when no edge value is negative, i.e. the
                // OR of the values has no sign bit.
                for (int j = 0; j < 4; ++j) {
                    int64_t edge_or = 0;
                    for (int i = 0; i < N; ++i)
                        edge_or |= er[i] + ((j & 1) ? w.dx[i] : 0) + ((j >> 1) ? w.dy[i] : 0);
                    cov |= uint64_t(edge_or >= 0 && present[j]) << (kQuadPixelBits * j);
                }
            } else for (int j = 0; j < 4; ++j) {
                if (!present[j]) continue;
                int64_t e[N];
                for (int i = 0; i < N; ++i) e[i] = er[i] + ((j & 1) ? w.dx[i] : 0) + ((j >> 1) ? w.dy[i] : 0);
                uint64_t m = 0;
                for (int s = 0; s < S; ++s) {
                    bool in = true;
                    for (int i = 0; i < N; ++i) in &= e[i] + w.so[i][s] >= 0;
                    m |= uint64_t(in) << s;
                }
                cov |= m << (kQuadPixelBits * j);
            }
            for (int i = 0; i < N; ++i) er[i] += 2 * w.dx[i];
            put(q, qx, qy, cov);   // kept when not empty
            q += cov != 0;
        }
    }
    return q;
}

template <int N>
void raster_edges(const PrimitiveSetup& p, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                  const SamplePattern& sp, InsideRowsFn<N> inside_rows, PutBlockFn put_block, std::vector<Quad>& out,
                  RasterStats& stats) {
    EdgeWalk<N> w;
    set_up_walk(w, p, sp, x0, y0, x1, y1);
    BlockSteps<N> steps;
    if (inside_rows)
        for (int i = 0; i < N; ++i) {
            for (int k = 0; k < 8; ++k) steps.col[i][k] = k * w.dx[i];
            steps.dy[i] = w.dy[i];
        }
    // The output grows once by an upper bound, every quad of the clipped rectangle, and quads are
    // written in place (no capacity check per quad); it shrinks to the quads written at the end.
    const size_t first = out.size();
    out.resize(first + size_t((x1 - (x0 & ~1) + 1) / 2) * size_t((y1 - (y0 & ~1) + 1) / 2));
    Quad* const begin = out.data() + first;
    Quad* q = begin;
    uint64_t rejected = 0, accepted = 0, partial = 0;   // counters in locals, as the edges
    for (int32_t by = y0 & ~(kBlockSize - 1); by < y1; by += kBlockSize) {
        const int32_t cy0 = std::max(by, y0), cy1 = std::min(by + kBlockSize, y1);
        const bool whole_rows = w.whole_blocks && cy0 == by && cy1 == by + kBlockSize;
        int64_t row[N] = {};   // the edges at (0, by)
        if (whole_rows)
            for (int i = 0; i < N; ++i) row[i] = w.B[i] * (int64_t(by) * kSubPixel) + w.C[i];
        for (int32_t bx = x0 & ~(kBlockSize - 1); bx < x1; bx += kBlockSize) {
            const Block blk{bx, by, std::max(bx, x0), cy0, std::min(bx + kBlockSize, x1), cy1};
            int64_t max_or, min_or;
            block_extremes(w, blk, whole_rows, row, max_or, min_or);
            const bool accept = min_or >= 0;
            if (max_or < 0) { ++rejected; continue; }
            accepted += accept;
            partial += !accept;
            if (accept && ((blk.cx0 | blk.cx1 | blk.cy0 | blk.cy1) & 1) == 0) q = put_covered_quads(q, w, blk, put_block);
            else if (inside_rows) q = put_quads_from_masks(q, w, blk, accept, steps, inside_rows);
            else if (accept) q = put_clipped_quads(q, w, blk);
            else q = put_tested_quads(q, w, blk);
        }
    }
    stats.blocks_rejected += rejected, stats.blocks_accepted += accepted, stats.blocks_partial += partial;
    stats.quads += uint64_t(q - begin);
    out.resize(first + size_t(q - begin));
}

// ---- Small windows (one sample per pixel) ----
// Most (primitive, tile) pairs of a mesh of small triangles are a few pixels. When the part to
// rasterize fits in the 8x8 pixels from (wx, wy) = (x0 & ~1, y0 & ~1) (even, so quads start on
// them), each edge's sign at the 64 pixel centres is found in one pass, and the blocks, their
// statistics and the quads follow from those masks with no block walk: the same quads, order and
// statistics as raster_edges. With one sample per pixel its block tests are tests of pixels: an
// edge's extremes over a clipped block's sample rectangle are at the centres of its corner pixels,
// so a block is rejected when some edge is negative at every one of its pixels and accepted when
// every pixel is inside.
//
// Edge values in int32: at pixel (wx + k, wy + r) an edge is E0 + k * 256a + r * 256b, E0 its exact
// int64 value at the centre of (wx, wy). When |a| + |b| < 2^19 the steps add less than 2^30 in
// magnitude over the window (and its next row), so E0 clamped to [-2^30, 2^30] keeps every pixel's
// sign and no sum reaches 2^31.
constexpr int32_t kWindow = 8;
constexpr int64_t kWindowEdgeStepMax = int64_t(1) << 19;   // |a| + |b| below this
constexpr int64_t kWindowClamp = int64_t(1) << 30;

template <int N>
struct WindowEdges {
    int32_t e0[N], dx[N], dy[N];   // each edge at the centre of (wx, wy) (clamped), its steps per pixel
    int rows;                      // rows [0, rows) of the window are needed (1..8)
};
// Bit 8*r + k set when every edge is >= 0 at the centre of pixel (wx + k, wy + r), for the rows
// [0, rows) (other bits unspecified): the edges' values ORed, the sign of the OR.
template <int N>
using WindowMasksFn = uint64_t (*)(const WindowEdges<N>& w);

template <int N>
uint64_t window_masks_scalar(const WindowEdges<N>& w) {
    uint64_t m = 0;
    for (int r = 0; r < w.rows; ++r)
        for (int k = 0; k < kWindow; ++k) {
            bool in = true;
            for (int i = 0; i < N; ++i) in &= w.e0[i] + k * w.dx[i] + r * w.dy[i] >= 0;
            m |= uint64_t(in) << (kWindow * r + k);
        }
    return m;
}

#if defined(SOFTGL_HAVE_SIMD_RASTER)
// A pixel row of 8 int32 lanes per step; the sign bits of the edges' OR are the outside pixels.
template <int N>
__attribute__((target("avx2"))) uint64_t window_masks_avx2(const WindowEdges<N>& w) {
    const __m256i k = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    __m256i v[N], step[N];
    for (int i = 0; i < N; ++i) {
        v[i] = _mm256_add_epi32(_mm256_set1_epi32(w.e0[i]), _mm256_mullo_epi32(k, _mm256_set1_epi32(w.dx[i])));
        step[i] = _mm256_set1_epi32(w.dy[i]);
    }
    uint64_t outside = 0;
    for (int r = 0; r < w.rows; ++r) {
        __m256i o = v[0];
        for (int i = 1; i < N; ++i) o = _mm256_or_si256(o, v[i]);
        outside |= uint64_t(uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(o)))) << (kWindow * r);
        for (int i = 0; i < N; ++i) v[i] = _mm256_add_epi32(v[i], step[i]);
    }
    return ~outside;
}

// Two pixel rows of 16 int32 lanes per step, the edges' OR compared into a mask.
template <int N>
__attribute__((target("avx512f"))) uint64_t window_masks_avx512(const WindowEdges<N>& w) {
    const __m512i k = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7);
    const __m512i r = _mm512_setr_epi32(0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1);
    const __m512i zero = _mm512_setzero_si512();
    __m512i v[N], step[N];
    for (int i = 0; i < N; ++i) {
        v[i] = _mm512_add_epi32(_mm512_set1_epi32(w.e0[i]), _mm512_add_epi32(_mm512_mullo_epi32(k, _mm512_set1_epi32(w.dx[i])),
                                                                             _mm512_mullo_epi32(r, _mm512_set1_epi32(w.dy[i]))));
        step[i] = _mm512_set1_epi32(2 * w.dy[i]);
    }
    uint64_t m = 0;
    for (int j = 0; 2 * j < w.rows; ++j) {
        __m512i o = v[0];
        for (int i = 1; i < N; ++i) o = _mm512_or_si512(o, v[i]);
        m |= uint64_t(_mm512_cmpge_epi32_mask(o, zero)) << (2 * kWindow * j);
        for (int i = 0; i < N; ++i) v[i] = _mm512_add_epi32(v[i], step[i]);
    }
    return m;
}
#endif

// Whether every edge's steps fit the int32 windows (|a| + |b| < 2^19). The edge count as a
// template argument: an unrolled test (this runs once per primitive and tile).
template <int N>
inline bool small_steps(const PrimitiveSetup& p) {
    bool small = true;
    for (int i = 0; i < N; ++i)
        small &= (p.a[i] < 0 ? -p.a[i] : p.a[i]) + (p.b[i] < 0 ? -p.b[i] : p.b[i]) < kWindowEdgeStepMax;
    return small;
}
inline bool small_steps(const PrimitiveSetup& p) {
    return p.edge_count == 3 ? small_steps<3>(p) : p.edge_count == 2 ? small_steps<2>(p) : small_steps<4>(p);
}

// The edges of the window whose pixel (0, 0) is (ox, oy), for its rows [0, rows).
template <int N>
__attribute__((always_inline)) inline WindowEdges<N> window_edges(const PrimitiveSetup& p, int32_t ox, int32_t oy,
                                                                  int rows) {
    WindowEdges<N> w;
    const int64_t X = int64_t(ox) * kSubPixel + kSubPixel / 2, Y = int64_t(oy) * kSubPixel + kSubPixel / 2;
    for (int i = 0; i < N; ++i) {
        const int64_t e = p.a[i] * X + p.b[i] * Y + p.c[i];
        w.e0[i] = int32_t(std::min(std::max(e, -kWindowClamp), kWindowClamp));
        w.dx[i] = int32_t(p.a[i] * kSubPixel);
        w.dy[i] = int32_t(p.b[i] * kSubPixel);
    }
    w.rows = rows;
    return w;
}

// Pixels [k0, k1) x [r0, r1) of a window (bit 8*r + k).
inline uint64_t window_rect(int k0, int r0, int k1, int r1) {
    const uint64_t cols = ((uint64_t(1) << k1) - (uint64_t(1) << k0)) * 0x0101010101010101ull;
    return cols & (r1 == kWindow ? ~uint64_t(0) : (uint64_t(1) << (kWindow * r1)) - 1) &
           ~((uint64_t(1) << (kWindow * r0)) - 1);
}

// The quads with a covered pixel: bit 16*p + 2*k for rows 2p, 2p + 1 and columns 2k, 2k + 1.
inline uint64_t window_quads(uint64_t covered) {
    const uint64_t pairs = (covered | covered >> kWindow) & 0x00FF00FF00FF00FFull;
    return (pairs | pairs >> 1) & 0x0055005500550055ull;
}

struct BlockCounts {
    uint64_t rejected = 0, accepted = 0, partial = 0;
};

// Whether some edge is negative at every pixel centre of `block` (not empty): at its largest there,
// a corner of the block's rectangle of pixels (int32: within the window's bounds).
template <int N>
inline bool block_outside(const WindowEdges<N>& w, uint64_t block) {
    uint64_t cols = block | block >> 32;
    cols |= cols >> 16;
    cols = (cols | cols >> 8) & 0xFF;
    const int32_t k0 = __builtin_ctzll(cols), k1 = 31 - __builtin_clz(uint32_t(cols));
    const int32_t r0 = __builtin_ctzll(block) >> 3, r1 = (63 - __builtin_clzll(block)) >> 3;
    bool outside = false;
    for (int i = 0; i < N; ++i)
        outside |= w.e0[i] + std::max(k0 * w.dx[i], k1 * w.dx[i]) + std::max(r0 * w.dy[i], r1 * w.dy[i]) < 0;
    return outside;
}

// One block of a window w whose pixel (0, 0) is (ox, oy): `block` is the block's pixels in the
// clipped rectangle (not empty), covered its pixels inside every edge, quads window_quads(covered).
// Counts the block as raster_edges does (rejected only when no pixel is covered and some edge is
// negative at all of them) and writes its quads in its order (rows bottom-up, then left-right).
template <int N>
__attribute__((always_inline)) inline Quad* window_block(Quad* q, const WindowEdges<N>& w, uint64_t covered,
                                                         uint64_t quads, uint64_t block, int32_t ox, int32_t oy,
                                                         BlockCounts& counts) {
    if ((covered & block) == 0 && block_outside(w, block)) {
        ++counts.rejected;
        return q;
    }
    const bool whole = (covered & block) == block;
    counts.accepted += whole;
    counts.partial += !whole;
    // Quads never straddle blocks (both start on even pixels): the block's quads are its bits.
    // A quad's pixels are bits sh, sh + 1, sh + 8 and sh + 9 of covered: one shift, each bit
    // moved to its pixel's 16 (spread_quad_bits' layout).
    for (uint64_t rest = quads & window_quads(block); rest; rest &= rest - 1) {
        const int sh = __builtin_ctzll(rest);
        const uint64_t x = covered >> sh;
        put(q++, ox + (sh & (kWindow - 1)), oy + (sh >> 3),
            (x & 1) | (x & 2) << 15 | (x & (uint64_t(1) << kWindow)) << 24 | (x & (uint64_t(2) << kWindow)) << 39);
    }
    return q;
}

template <int N>
void raster_window(const PrimitiveSetup& p, int32_t x0, int32_t y0, int32_t x1, int32_t y1, WindowMasksFn<N> masks,
                   std::vector<Quad>& out, RasterStats& stats) {
    const int32_t wx = x0 & ~1, wy = y0 & ~1;
    const WindowEdges<N> w = window_edges<N>(p, wx, wy, y1 - wy);
    const uint64_t present = window_rect(x0 - wx, y0 - wy, x1 - wx, y1 - wy);
    const uint64_t covered = present & masks(w);
    const uint64_t quads = window_quads(covered);
    // Grown by the window's most quads, 16, and shrunk to those written: no popcount (a libgcc
    // call below the POPCNT instruction set).
    const size_t first = out.size();
    out.resize(first + size_t(kWindow / 2) * size_t(kWindow / 2));
    Quad* q = out.data() + first;
    // The window's columns [0, kx) lie in the block at wx & ~7, the others in the next block;
    // rows [0, ry) likewise. Blocks in raster_edges' order: bottom-up, then left-right.
    const int kx = kBlockSize - (wx & (kBlockSize - 1)), ry = kBlockSize - (wy & (kBlockSize - 1));
    const uint64_t left = window_rect(0, 0, kx, kWindow), low = window_rect(0, 0, kWindow, ry);
    const uint64_t parts[4] = {low & left, low & ~left, ~low & left, ~low & ~left};
    BlockCounts counts;
    for (const uint64_t part : parts)
        if (const uint64_t block = present & part) q = window_block<N>(q, w, covered, quads, block, wx, wy, counts);
    stats.blocks_rejected += counts.rejected, stats.blocks_accepted += counts.accepted;
    stats.blocks_partial += counts.partial;
    stats.quads += uint64_t(q - (out.data() + first));
    out.resize(size_t(q - out.data()));
}

// A part of at most kMaskedBlocksMax blocks that is not one window: block by block in
// raster_edges' order, each block a window (masks at its 64 pixel centres, no corner tests).
// Larger parts keep raster_edges, whose corner tests settle most of their blocks without masks.
constexpr int kMaskedBlocksMax = 16;

template <int N>
void raster_masked_blocks(const PrimitiveSetup& p, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                          WindowMasksFn<N> masks, PutBlockFn put_block, std::vector<Quad>& out, RasterStats& stats) {
    const size_t first = out.size();
    out.resize(first + size_t((x1 - (x0 & ~1) + 1) / 2) * size_t((y1 - (y0 & ~1) + 1) / 2));
    Quad* const begin = out.data() + first;
    Quad* q = begin;
    BlockCounts counts;
    // Each block's window_edges, stepped from the row's first block: the same exact int64 edge
    // values (a block to the right adds a * 8 pixels), clamped alike.
    const int32_t bx0 = x0 & ~(kBlockSize - 1);
    WindowEdges<N> w = window_edges<N>(p, bx0, y0 & ~(kBlockSize - 1), kWindow);
    int64_t step[N];
    for (int i = 0; i < N; ++i) step[i] = p.a[i] * (int64_t(kBlockSize) * kSubPixel);
    for (int32_t by = y0 & ~(kBlockSize - 1); by < y1; by += kBlockSize) {
        const int r0 = std::max(by, y0) - by, r1 = std::min(by + kBlockSize, y1) - by;
        w.rows = r1;
        int64_t e[N];
        const int64_t X = int64_t(bx0) * kSubPixel + kSubPixel / 2, Y = int64_t(by) * kSubPixel + kSubPixel / 2;
        for (int i = 0; i < N; ++i) e[i] = p.a[i] * X + p.b[i] * Y + p.c[i];
        for (int32_t bx = bx0; bx < x1; bx += kBlockSize) {
            for (int i = 0; i < N; ++i) {
                w.e0[i] = int32_t(std::min(std::max(e[i], -kWindowClamp), kWindowClamp));
                e[i] += step[i];
            }
            const uint64_t block = window_rect(std::max(bx, x0) - bx, r0, std::min(bx + kBlockSize, x1) - bx, r1);
            const uint64_t covered = block & masks(w);
            if (covered == ~uint64_t(0)) {   // whole and unclipped: 16 full quads
                ++counts.accepted;
                q = put_block(q, bx, by, 0x0001000100010001ull);
                continue;
            }
            q = window_block<N>(q, w, covered, window_quads(covered), block, bx, by, counts);
        }
    }
    stats.blocks_rejected += counts.rejected, stats.blocks_accepted += counts.accepted;
    stats.blocks_partial += counts.partial;
    stats.quads += uint64_t(q - begin);
    out.resize(first + size_t(q - begin));
}

}  // namespace

const SamplePattern& sample_pattern(int samples) {
    static const SamplePattern p1 = make_pattern(1, kPos1), p2 = make_pattern(2, kPos2),
                               p4 = make_pattern(4, kPos4), p8 = make_pattern(8, kPos8),
                               p16 = make_pattern(16, kPos16);
    switch (samples) {
        case 1: return p1;
        case 2: return p2;
        case 4: return p4;
        case 8: return p8;
        case 16: return p16;
        default: throw std::invalid_argument("sample count must be 1, 2, 4, 8 or 16");
    }
}

void rasterize_at(SimdLevel level, const PrimitiveSetup& prim, const TileRect& tile, const SamplePattern& pattern,
                  std::vector<Quad>& out, RasterStats& stats, RasterWalk walk) {
    const int32_t x0 = std::max(prim.x0, tile.x0), y0 = std::max(prim.y0, tile.y0);
    const int32_t x1 = std::min(prim.x1, tile.x1), y1 = std::min(prim.y1, tile.y1);
    if (x0 >= x1 || y0 >= y1) return;
    PutBlockFn block = put_block;
#if defined(SOFTGL_HAVE_SIMD_RASTER)
    if (level == SimdLevel::AVX512) block = put_block_avx512;
#endif
    if (walk == RasterWalk::Any && pattern.count == 1 && small_steps(prim)) {
        WindowMasksFn<3> masks3 = window_masks_scalar<3>;
        WindowMasksFn<2> masks2 = window_masks_scalar<2>;
        WindowMasksFn<4> masks4 = window_masks_scalar<4>;
#if defined(SOFTGL_HAVE_SIMD_RASTER)
        if (level == SimdLevel::AVX512)
            masks3 = window_masks_avx512<3>, masks2 = window_masks_avx512<2>, masks4 = window_masks_avx512<4>;
        else if (level == SimdLevel::AVX2)
            masks3 = window_masks_avx2<3>, masks2 = window_masks_avx2<2>, masks4 = window_masks_avx2<4>;
#endif
        if (x1 - (x0 & ~1) <= kWindow && y1 - (y0 & ~1) <= kWindow) {
            if (prim.edge_count == 3) raster_window<3>(prim, x0, y0, x1, y1, masks3, out, stats);
            else if (prim.edge_count == 2) raster_window<2>(prim, x0, y0, x1, y1, masks2, out, stats);
            else raster_window<4>(prim, x0, y0, x1, y1, masks4, out, stats);
            return;
        }
        const int64_t blocks = int64_t(((x1 - 1) >> 3) - (x0 >> 3) + 1) * int64_t(((y1 - 1) >> 3) - (y0 >> 3) + 1);
        if (blocks <= kMaskedBlocksMax) {
            if (prim.edge_count == 3) raster_masked_blocks<3>(prim, x0, y0, x1, y1, masks3, block, out, stats);
            else if (prim.edge_count == 2) raster_masked_blocks<2>(prim, x0, y0, x1, y1, masks2, block, out, stats);
            else raster_masked_blocks<4>(prim, x0, y0, x1, y1, masks4, block, out, stats);
            return;
        }
    }
    InsideRowsFn<3> rows3 = nullptr;
    InsideRowsFn<4> rows4 = nullptr;
    InsideRowsFn<2> rows2 = nullptr;
#if defined(SOFTGL_HAVE_SIMD_RASTER)
    if (level == SimdLevel::AVX512)
        rows3 = inside_rows_avx512<3>, rows4 = inside_rows_avx512<4>, rows2 = inside_rows_avx512<2>;
    else if (level == SimdLevel::AVX2)
        rows3 = inside_rows_avx2<3>, rows4 = inside_rows_avx2<4>, rows2 = inside_rows_avx2<2>;
#else
    (void)level;
#endif
    if (prim.edge_count == 3) raster_edges<3>(prim, x0, y0, x1, y1, pattern, rows3, block, out, stats);
    else if (prim.edge_count == 2) raster_edges<2>(prim, x0, y0, x1, y1, pattern, rows2, block, out, stats);
    else raster_edges<4>(prim, x0, y0, x1, y1, pattern, rows4, block, out, stats);
}

}  // namespace softgl
