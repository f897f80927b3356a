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
// (d_k = 0; an infinity too), with or without perspective. Against the exact value the error is a
// few float ulps of the vertex values' magnitude (measured in tests/pipeline/test_interpolate.py).
// Double precision, used before, cost 40% of a large-triangle frame for no visible gain in 8-bit
// colour.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "softgl/core/simd.h"
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
// prepare_interpolation's two parts: d_k from v_k and v_0 (0 where they are equal, infinities
// included: inf - inf would be NaN), and the planes with `values` already v_0, d_1, d_2 (the tile
// pass gathers the vertices' words straight into that form).
inline float vertex_difference(float vk, float v0) { return vk == v0 ? 0.0f : vk - v0; }
void set_interpolation_planes(const PrimitiveSetup& p, int vertices, int32_t base_x, int32_t base_y, const int* words,
                              size_t count, const float* values, VaryingInterpolation& v);

// Lane 4*i + j is pixel j (dx = j & 1, dy = j >> 1) of quads[i]; word words[k] of lane l goes to
// out[words[k] * stride + l] as float bits. `level` picks the instruction set (tests); the
// pipeline calls the best one.
void interpolate_varyings_at(SimdLevel level, const VaryingInterpolation& v, const Quad* quads, size_t n,
                             uint32_t* out, size_t stride);
inline void interpolate_varyings(const VaryingInterpolation& v, const Quad* quads, size_t n, uint32_t* out,
                                 size_t stride) {
    interpolate_varyings_at(best_simd_level(), v, quads, n, out, stride);
}
// The same for single pixels (the tile pass's gathered batches without helper lanes): lane l is
// pixel (xy[2l], xy[2l + 1]), with the bits interpolate_varyings_at gives that pixel in a quad.
// Thin primitives fill a quad's four lanes with one or two pixels, so their pixels cost less
// one by one than as quads.
void interpolate_pixels_at(SimdLevel level, const VaryingInterpolation& v, const int32_t* xy, size_t n, uint32_t* out,
                           size_t stride);

// Whether l_1 and l_2 (lines: l_1) are finite at every lane of quads[0..n) whose masks[lane] is
// non-zero, as interpolate_varyings computes them (every level gives the scalar reference's bits).
// Then a word with d_1 = d_2 = 0 comes out as v_0 + (+-0) + (+-0): exactly v_0 when v_0 is not
// -0 (-0 + +0 = +0) and not NaN (which arithmetic may quiet) -- a flat primitive (tile_pass.cpp).
bool weights_finite(const VaryingInterpolation& v, const Quad* quads, const uint16_t* masks, size_t n);
// The same for every pixel with 0 <= x - base_x <= width and 0 <= y - base_y <= height, by a bound
// worked out once (a primitive's tile): false when the bound cannot show it (then ask
// weights_finite lane by lane).
bool weights_finite_in(const VaryingInterpolation& v, int32_t width, int32_t height);

// When all vertices have the same w (every 2D draw), Q is a constant plane (a = b = 0) and
// (c + 0*dx) + 0*dy == c for any finite non-zero c and finite offsets (adding a zero of either
// sign to a non-zero number leaves it unchanged), so every lane's q is 1 / c: computed once. When
// that q is 1 (w = 1), l * 1 == l bit for bit (+-0, infinities, denormals -- no FTZ/DAZ is set --
// and the quiet NaNs arithmetic produces), so the weights skip the multiply.
struct ConstantQ {
    bool constant, unit;
    float q;
    explicit ConstantQ(const FloatPlane& pl)
        : constant(pl.a == 0 && pl.b == 0 && std::isfinite(pl.c) && pl.c != 0), unit(constant && 1.0f / pl.c == 1.0f),
          q(1.0f / pl.c) {}
};

// Whether l_1 and l_2 are finite at every pixel: q constant and |(c + a*dx) + b*dy| * |q| far below
// FLT_MAX for any offsets an int32 gives (|dx|, |dy| <= 2^31), with room for the float roundings
// (each a factor of at most 1 + 2^-23). NaN or infinite planes fail the test.
inline bool weights_always_finite(const VaryingInterpolation& v, const ConstantQ& cq) {
    if (!cq.constant) return false;
    for (int k = 0; k + 1 < v.vertices; ++k) {
        const FloatPlane& pl = v.weight[k];
        const double bound = (std::fabs(double(pl.c)) + (std::fabs(double(pl.a)) + std::fabs(double(pl.b))) * 0x1p31) *
                             std::fabs(double(cq.q)) * 4.0;
        if (!(bound < 0x1p127)) return false;
    }
    return true;
}

}  // namespace softgl

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SOFTGL_HAVE_AVX512_INTERPOLATOR 1

namespace softgl {

#define SOFTGL_AVX512_TARGET __attribute__((target("avx512f,avx512bw,avx512dq,avx512vl")))
// GCC 12's AVX-512 intrinsics start from _mm512_undefined_*(), which -W(maybe-)uninitialized
// reports once they are inlined (GCC bug 105593, fixed in GCC 13).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// The AVX-512 interpolation of 16 lanes (four quads, lane 4*i + j pixel j of quad i) in registers:
// interpolate_avx512 stores its values, fragment_ops.cpp's fused copy kernel packs them into
// pixels without the trip through memory. Call only on a CPU with AVX-512 F+BW+DQ+VL.
template <int V>   // 3: triangles, 2: lines
struct Avx512Interpolator {
    __m512 pa[V], pb[V], pc[V];   // Q, L_1 (, L_2)
    ConstantQ cq;
    __m512 q_constant;
    __m512i base_x, base_y;
    // Four quads' 16 int32 words to lanes: pick a lane's quad x (y), add its pixel's dx (dy).
    __m512i pick_x, pick_y, pixel_x, pixel_y;
    SOFTGL_AVX512_TARGET explicit Avx512Interpolator(const VaryingInterpolation& v)
        : cq(v.inv_w), q_constant(_mm512_set1_ps(cq.q)), base_x(_mm512_set1_epi32(v.base_x)),
          base_y(_mm512_set1_epi32(v.base_y)),
          pick_x(_mm512_setr_epi32(0, 0, 0, 0, 4, 4, 4, 4, 8, 8, 8, 8, 12, 12, 12, 12)),
          pick_y(_mm512_add_epi32(pick_x, _mm512_set1_epi32(1))),
          pixel_x(_mm512_setr_epi32(0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1)),
          pixel_y(_mm512_setr_epi32(0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1)) {
        for (int k = 0; k < V; ++k) {
            const FloatPlane& pl = k == 0 ? v.inv_w : v.weight[k - 1];
            pa[k] = _mm512_set1_ps(pl.a), pb[k] = _mm512_set1_ps(pl.b), pc[k] = _mm512_set1_ps(pl.c);
        }
    }
    // The part of each plane's value that depends on the column alone, c + a * dx, for lanes in
    // columns x (dx = x - base_x); Q's only when it is not constant.
    struct Columns {
        __m512 p[V];
    };
    SOFTGL_AVX512_TARGET Columns columns_at(__m512i x) const {
        const __m512 dx = _mm512_cvtepi32_ps(_mm512_sub_epi32(x, base_x));
        Columns col;
        for (int k = 0; k < V; ++k)
            col.p[k] = k == 0 && cq.constant ? pc[0] : _mm512_add_ps(pc[k], _mm512_mul_ps(pa[k], dx));
        return col;
    }
    // The weights l_1, l_2 (lines: 0) of the lanes in columns `col` and rows y (dy = y - base_y).
    SOFTGL_AVX512_TARGET void weights_at(const Columns& col, __m512i y, __m512& l1, __m512& l2) const {
        const __m512 dy = _mm512_cvtepi32_ps(_mm512_sub_epi32(y, base_y));
        auto eval = [&](int k) SOFTGL_AVX512_TARGET { return _mm512_add_ps(col.p[k], _mm512_mul_ps(pb[k], dy)); };
        const __m512 q = cq.constant ? q_constant : _mm512_div_ps(_mm512_set1_ps(1.0f), eval(0));
        l1 = cq.unit ? eval(1) : _mm512_mul_ps(eval(1), q);
        l2 = V == 3 ? (cq.unit ? eval(2) : _mm512_mul_ps(eval(2), q)) : _mm512_setzero_ps();
    }
    SOFTGL_AVX512_TARGET void weights_at(__m512i x, __m512i y, __m512& l1, __m512& l2) const {
        weights_at(columns_at(x), y, l1, l2);
    }
    // The same for the 16 lanes of four quads given as 16 int32 words (x at 0, 4, 8, 12; y one after).
    SOFTGL_AVX512_TARGET void weights(__m512i xy, __m512& l1, __m512& l2) const {
        weights_at(_mm512_add_epi32(_mm512_permutexvar_epi32(pick_x, xy), pixel_x),
                   _mm512_add_epi32(_mm512_permutexvar_epi32(pick_y, xy), pixel_y), l1, l2);
    }
    // out = (v_0 + l_1 * d_1) + l_2 * d_2 (lines: v_0 + l_1 * d_1).
    SOFTGL_AVX512_TARGET static __m512 value(float v0, float d1, float d2, __m512 l1, __m512 l2) {
        __m512 s = _mm512_add_ps(_mm512_set1_ps(v0), _mm512_mul_ps(l1, _mm512_set1_ps(d1)));
        if constexpr (V == 3) s = _mm512_add_ps(s, _mm512_mul_ps(l2, _mm512_set1_ps(d2)));
        return s;
    }
};
#pragma GCC diagnostic pop
#undef SOFTGL_AVX512_TARGET

}  // namespace softgl
#endif

namespace softgl {

}  // namespace softgl
