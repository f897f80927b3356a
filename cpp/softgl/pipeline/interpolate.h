// Varying interpolation: the fragment shader's smooth inputs at the pixel centres of a run of
// quads, perspective-correct (ES 3.0 §3.6.1 eq. 3.9; lines §3.5.1 eq. 3.7).
//
// Every lane evaluates exactly PrimitiveSetup::eval / weights_at in double precision and sums the
// weighted vertex values in a fixed order, then rounds to float:
//   q   = 1 / (inv_w.c + inv_w.a * fx + inv_w.b * fy)
//   w_k = (weight[k].c + weight[k].a * fx + weight[k].b * fy) * q
//   out = float(((0 + w_0 * v_0) + w_1 * v_1) + w_2 * v_2)          (lines: two terms)
// The SSE2, AVX2 and AVX-512 levels run these IEEE operations on 2 / 4 / 8 lanes at once, in the
// same order and without FMA (DESIGN §3), so every level gives the same bits.
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

struct VaryingInterpolation {
    const PrimitiveSetup* prim = nullptr;
    int vertices = 3;                 // 3: triangles (weight[0..2]), 2: lines (weight[0..1])
    size_t count = 0;                 // varying words to fill
    const int* words = nullptr;       // their word numbers
    const double* values = nullptr;   // vertex k's value of words[i] at values[k * count + i]
};

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
