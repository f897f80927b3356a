#include "softgl/pipeline/raster.h"

#include <algorithm>
#include <stdexcept>

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

// Appends a quad field by field: a Quad built aside and copied whole makes the CPU load 16 bytes
// just stored as 4 + 4 + 8 (a store-forwarding stall on every quad).
inline void emit(std::vector<Quad>& out, int32_t x, int32_t y, uint64_t coverage) {
    Quad& q = out.emplace_back();
    q.x = x, q.y = y, q.coverage = coverage;
}

template <int N>
void raster_edges(const PrimitiveSetup& p, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                  const SamplePattern& sp, std::vector<Quad>& out, RasterStats& stats) {
    const int S = sp.count;
    const uint64_t full_pixel = S == 16 ? 0xFFFFu : ((uint64_t(1) << S) - 1);
    int64_t so[N][16];     // edge value offset of each sample from its pixel's corner
    for (int i = 0; i < N; ++i)
        for (int s = 0; s < S; ++s) so[i][s] = p.a[i] * sp.x[s] + p.b[i] * sp.y[s];
    int64_t dx[N], dy[N];  // edge steps of one pixel in x and in y
    for (int i = 0; i < N; ++i) dx[i] = p.a[i] * kSubPixel, dy[i] = p.b[i] * kSubPixel;
    // The extent of the samples within a pixel: block tests cover exactly the samples' hull.
    int32_t sx0 = sp.x[0], sx1 = sp.x[0], sy0 = sp.y[0], sy1 = sp.y[0];
    for (int s = 1; s < S; ++s) {
        sx0 = std::min(sx0, sp.x[s]); sx1 = std::max(sx1, sp.x[s]);
        sy0 = std::min(sy0, sp.y[s]); sy1 = std::max(sy1, sp.y[s]);
    }

    for (int32_t by = y0 & ~(kBlockSize - 1); by < y1; by += kBlockSize) {
        const int32_t cy0 = std::max(by, y0), cy1 = std::min(by + kBlockSize, y1);
        for (int32_t bx = x0 & ~(kBlockSize - 1); bx < x1; bx += kBlockSize) {
            const int32_t cx0 = std::max(bx, x0), cx1 = std::min(bx + kBlockSize, x1);
            // The rectangle spanned by the block's samples, in fixed point; edges are linear, so
            // their extremes over it are at corners chosen by the coefficients' signs.
            const int64_t X0 = int64_t(cx0) * kSubPixel + sx0, X1 = int64_t(cx1 - 1) * kSubPixel + sx1;
            const int64_t Y0 = int64_t(cy0) * kSubPixel + sy0, Y1 = int64_t(cy1 - 1) * kSubPixel + sy1;
            bool reject = false, accept = true;
            for (int i = 0; i < N; ++i) {
                const int64_t a = p.a[i], b = p.b[i], c = p.c[i];
                const int64_t emax = a * (a > 0 ? X1 : X0) + b * (b > 0 ? Y1 : Y0) + c;
                const int64_t emin = a * (a > 0 ? X0 : X1) + b * (b > 0 ? Y0 : Y1) + c;
                if (emax < 0) { reject = true; break; }
                if (emin < 0) accept = false;
            }
            if (reject) { ++stats.blocks_rejected; continue; }
            if (accept) ++stats.blocks_accepted;
            else ++stats.blocks_partial;

            if (accept && ((cx0 | cx1 | cy0 | cy1) & 1) == 0) {
                // Whole block inside every edge and its clipped rectangle made of whole quads:
                // every quad is fully covered, no per-pixel bounds to test.
                const uint64_t full_quad = full_pixel | full_pixel << kQuadPixelBits |
                                           full_pixel << (2 * kQuadPixelBits) | full_pixel << (3 * kQuadPixelBits);
                for (int32_t qy = cy0; qy < cy1; qy += 2)
                    for (int32_t qx = cx0; qx < cx1; qx += 2) emit(out, qx, qy, full_quad);
                stats.quads += (uint64_t(cx1 - cx0) / 2) * (uint64_t(cy1 - cy0) / 2);
                continue;
            }
            if (accept) {
                // Whole block inside every edge: full coverage, only the clip to [cx0, cx1) x
                // [cy0, cy1) decides which pixels of each quad are present.
                for (int32_t qy = cy0 & ~1; qy < cy1; qy += 2) {
                    const bool row0 = qy >= cy0, row1 = qy + 1 < cy1;
                    for (int32_t qx = cx0 & ~1; qx < cx1; qx += 2) {
                        const bool col0 = qx >= cx0, col1 = qx + 1 < cx1;
                        uint64_t cov = 0;
                        if (row0 && col0) cov |= full_pixel;
                        if (row0 && col1) cov |= full_pixel << kQuadPixelBits;
                        if (row1 && col0) cov |= full_pixel << (2 * kQuadPixelBits);
                        if (row1 && col1) cov |= full_pixel << (3 * kQuadPixelBits);
                        if (cov) {
                            emit(out, qx, qy, cov);
                            ++stats.quads;
                        }
                    }
                }
                continue;
            }
            // Partial block: edge values stepped across the block (exact integers, so the same
            // values as evaluating every pixel); one sample folds its offset into the start.
            const int32_t qx0 = cx0 & ~1;
            for (int32_t qy = cy0 & ~1; qy < cy1; qy += 2) {
                int64_t er[N];   // at pixel (qx, qy) of the current quad
                {
                    const int64_t X = int64_t(qx0) * kSubPixel, Y = int64_t(qy) * kSubPixel;
                    for (int i = 0; i < N; ++i) er[i] = p.a[i] * X + p.b[i] * Y + p.c[i] + (S == 1 ? so[i][0] : 0);
                }
                const bool row0 = qy >= cy0, row1 = qy + 1 < cy1;
                for (int32_t qx = qx0; qx < cx1; qx += 2) {
                    const bool col0 = qx >= cx0, col1 = qx + 1 < cx1;
                    const bool present[4] = {row0 && col0, row0 && col1, row1 && col0, row1 && col1};
                    uint64_t cov = 0;
                    if (S == 1) {
                        // Branch-free: a pixel is inside when no edge value is negative, i.e. the
                        // OR of the values has no sign bit.
                        for (int j = 0; j < 4; ++j) {
                            int64_t edge_or = 0;
                            for (int i = 0; i < N; ++i)
                                edge_or |= er[i] + ((j & 1) ? dx[i] : 0) + ((j >> 1) ? dy[i] : 0);
                            cov |= uint64_t(edge_or >= 0 && present[j]) << (kQuadPixelBits * j);
                        }
                    } else for (int j = 0; j < 4; ++j) {
                        if (!present[j]) continue;
                        int64_t e[N];
                        for (int i = 0; i < N; ++i) e[i] = er[i] + ((j & 1) ? dx[i] : 0) + ((j >> 1) ? dy[i] : 0);
                        uint64_t m = 0;
                        for (int s = 0; s < S; ++s) {
                            bool in = true;
                            for (int i = 0; i < N; ++i) in &= e[i] + so[i][s] >= 0;
                            m |= uint64_t(in) << s;
                        }
                        cov |= m << (kQuadPixelBits * j);
                    }
                    for (int i = 0; i < N; ++i) er[i] += 2 * dx[i];
                    if (cov) {
                        emit(out, qx, qy, cov);
                        ++stats.quads;
                    }
                }
            }
        }
    }
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

void rasterize(const PrimitiveSetup& prim, const TileRect& tile, const SamplePattern& pattern,
               std::vector<Quad>& out, RasterStats& stats) {
    const int32_t x0 = std::max(prim.x0, tile.x0), y0 = std::max(prim.y0, tile.y0);
    const int32_t x1 = std::min(prim.x1, tile.x1), y1 = std::min(prim.y1, tile.y1);
    if (x0 >= x1 || y0 >= y1) return;
    if (prim.edge_count == 3) raster_edges<3>(prim, x0, y0, x1, y1, pattern, out, stats);
    else raster_edges<4>(prim, x0, y0, x1, y1, pattern, out, stats);
}

}  // namespace softgl
