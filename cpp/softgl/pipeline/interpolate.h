// Varying interpolation: the fragment shader's smooth inputs at the pixel centres of a run of
// quads, perspective-correct (ES 3.0 §3.6.1 eq. 3.9; lines §3.5.1 eq. 3.7).
//
// Single precision, as GPUs, SwiftShader and llvmpipe interpolate, in one fixed operation order
// without FMA, so that every CPU and every SIMD level gives the same bits:
//  - per primitive and tile (prepare_interpolation): the planes Q of 1/w and L_k of l_k/w, the
//    perspective weight of vertex k (PrimitiveSetup::inv_w, weight[1], weight[2]), are moved in
//    double to the centre of a base pixel (the tile's corner), then rounded to float (c, a, b).
//    The vertex values become v_0, d_1 = v_1 - v_0 and d_2 = v_2 - v_0 (float; d_k = 0 when
//    v_k == v_0, infinities included).
//  - per pixel, in float, with dx = x - base_x and dy = y - base_y (small integers, exact):
//      q   = 1 / ((Q.c + Q.a * dx) + Q.b * dy)
//      l_k = ((L_k.c + L_k.a * dx) + L_k.b * dy) * q                    k = 1, 2
//      out = (v_0 + l_1 * d_1) + l_2 * d_2                              (lines: v_0 + l_1 * d_1)
// v_0 plus weighted differences keeps a varying that is equal at every vertex exactly that value
// (d_k = 0; an infinity too), with or without perspective. Against the exact value the error is a few float ulps
// of the vertex values' magnitude (measured in tests/pipeline/test_interpolate.py). Double
// precision, used before, cost 40% of a large-triangle frame for no visible gain in 8-bit colour.
#pragma once
#include <cstddef>
#include <cstdint>

#include "softgl/pipeline/fragment_ops.h"
#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/setup.h"

namespace softgl {

// The offset of pixel x's centre from a plane origin, in pixels (PrimitiveSetup::eval's terms).
inline double pixel_centre_offset(int32_t x, int64_t origin) {
    return double(int64_t(x) * kSubPixel + kSubPixel / 2 - origin) * (1.0 / kSubPixel);
}

// value(dx, dy) = (c + a * dx) + b * dy in float, (dx, dy) pixels from the base pixel.
struct FloatPlane {
    float a = 0, b = 0, c = 0;
};

struct VaryingInterpolation {
    int vertices = 3;                 // 3: triangles, 2: lines
    size_t count = 0;                 // varying words to fill
    const int* words = nullptr;       // their word numbers
    // v_0 of words[i] at values[i], d_k at values[k * count + i] (prepare_interpolation's output).
    const float* values = nullptr;
    int32_t base_x = 0, base_y = 0;   // the pixel whose centre is the planes' origin
    FloatPlane inv_w, weight[2];      // Q, L_1, L_2 (lines: L_1 only)
};

// Fills `v` for primitive p with planes based at pixel (base_x, base_y). `values` holds each
// vertex's float values of the words (vertex k's at values[k * count + i]) and is turned in place
// into v_0, d_1, d_2; it must outlive the interpolation.
void prepare_interpolation(const PrimitiveSetup& p, int vertices, int32_t base_x, int32_t base_y, const int* words,
                           size_t count, float* values, VaryingInterpolation& v);

// Lane 4*i + j is pixel j (dx = j & 1, dy = j >> 1) of quads[i]; word words[k] of lane l goes to
// out[words[k] * stride + l] as float bits. `level` picks the instruction set (tests); the
// pipeline calls the best one.
void interpolate_varyings_at(SimdLevel level, const VaryingInterpolation& v, const Quad* quads, size_t n,
                             uint32_t* out, size_t stride);
inline void interpolate_varyings(const VaryingInterpolation& v, const Quad* quads, size_t n, uint32_t* out,
                                 size_t stride) {
    interpolate_varyings_at(best_simd_level(), v, quads, n, out, stride);
}

}  // namespace softgl
