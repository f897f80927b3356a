#include "softgl/pipeline/interpolate.h"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SOFTGL_HAVE_AVX2_INTERPOLATION 1
#endif

namespace softgl {

void set_interpolation_planes(const PrimitiveSetup& p, int vertices, int32_t base_x, int32_t base_y, const int* words,
                              size_t count, const float* values, VaryingInterpolation& v) {
    const double ox = pixel_centre_offset(base_x, p.origin_x), oy = pixel_centre_offset(base_y, p.origin_y);
    // The plane's value at the base pixel's centre, in PrimitiveSetup::eval's order.
    auto rebase = [&](const Plane& pl) { return FloatPlane{float(pl.a), float(pl.b), float((pl.c + pl.a * ox) + pl.b * oy)}; };
    v.vertices = vertices;
    v.count = count;
    v.words = words;
    v.values = values;
    v.base_x = base_x, v.base_y = base_y;
    v.inv_w = rebase(p.inv_w);
    v.weight[0] = rebase(p.weight[1]);
    v.weight[1] = vertices == 3 ? rebase(p.weight[2]) : FloatPlane{};
}

void prepare_interpolation(const PrimitiveSetup& p, int vertices, int32_t base_x, int32_t base_y, const int* words,
                           size_t count, float* values, VaryingInterpolation& v) {
    // A value equal at every vertex is then kept exactly (vertex_difference).
    for (int k = 1; k < vertices; ++k)
        for (size_t i = 0; i < count; ++i) {
            float& d = values[size_t(k) * count + i];
            d = vertex_difference(d, values[i]);
        }
    set_interpolation_planes(p, vertices, base_x, base_y, words, count, values, v);
}

namespace {

// A lane's pixel offset from the base: int32 arithmetic that wraps (as the SIMD levels' does),
// then converted; exact for every offset within 2^24 pixels.
inline float lane_offset(int32_t coordinate, int32_t pixel, int32_t base) {
    return float(int32_t(uint32_t(coordinate) + uint32_t(pixel) - uint32_t(base)));
}

// The reference: one lane at a time, the expressions of the header comment.
inline void interpolate_lane(const VaryingInterpolation& v, float dx, float dy, uint32_t* out, size_t stride,
                             size_t lane) {
    auto eval = [](const FloatPlane& pl, float dx, float dy) { return (pl.c + pl.a * dx) + pl.b * dy; };
    const size_t count = v.count;
    const float q = 1.0f / eval(v.inv_w, dx, dy);
    const float l1 = eval(v.weight[0], dx, dy) * q;
    const float l2 = v.vertices == 3 ? eval(v.weight[1], dx, dy) * q : 0.0f;
    for (size_t k = 0; k < count; ++k) {
        float s = v.values[k] + l1 * v.values[count + k];
        if (v.vertices == 3) s = s + l2 * v.values[2 * count + k];
        std::memcpy(&out[size_t(v.words[k]) * stride + lane], &s, 4);
    }
}

void interpolate_scalar(const VaryingInterpolation& v, const Quad* quads, size_t n, uint32_t* out, size_t stride) {
    for (size_t i = 0; i < n; ++i)
        for (int j = 0; j < 4; ++j)
            interpolate_lane(v, lane_offset(quads[i].x, j & 1, v.base_x), lane_offset(quads[i].y, j >> 1, v.base_y), out,
                             stride, 4 * i + size_t(j));
}

void interpolate_pixels_scalar(const VaryingInterpolation& v, const int32_t* xy, size_t n, uint32_t* out,
                               size_t stride) {
    for (size_t l = 0; l < n; ++l)
        interpolate_lane(v, lane_offset(xy[2 * l], 0, v.base_x), lane_offset(xy[2 * l + 1], 0, v.base_y), out, stride, l);
}

#if defined(__SSE2__)
// One quad per register.
template <int V>
void interpolate_sse2(const VaryingInterpolation& v, const Quad* quads, size_t n, uint32_t* out, size_t stride) {
    const float* const values = v.values;
    const int* const words = v.words;
    const size_t count = v.count;
    const ConstantQ cq(v.inv_w);
    const __m128 one = _mm_set1_ps(1.0f), q_constant = _mm_set1_ps(cq.q);
    const __m128i px = _mm_setr_epi32(0, 1, 0, 1), py = _mm_setr_epi32(0, 0, 1, 1);
    const __m128i base_x = _mm_set1_epi32(v.base_x), base_y = _mm_set1_epi32(v.base_y);
    auto eval = [](const FloatPlane& pl, __m128 dx, __m128 dy) {
        return _mm_add_ps(_mm_add_ps(_mm_set1_ps(pl.c), _mm_mul_ps(_mm_set1_ps(pl.a), dx)), _mm_mul_ps(_mm_set1_ps(pl.b), dy));
    };
    for (size_t i = 0; i < n; ++i) {
        const __m128 dx = _mm_cvtepi32_ps(_mm_sub_epi32(_mm_add_epi32(_mm_set1_epi32(quads[i].x), px), base_x));
        const __m128 dy = _mm_cvtepi32_ps(_mm_sub_epi32(_mm_add_epi32(_mm_set1_epi32(quads[i].y), py), base_y));
        const __m128 q = cq.constant ? q_constant : _mm_div_ps(one, eval(v.inv_w, dx, dy));
        const __m128 l1 = _mm_mul_ps(eval(v.weight[0], dx, dy), q);
        const __m128 l2 = V == 3 ? _mm_mul_ps(eval(v.weight[1], dx, dy), q) : _mm_setzero_ps();
        for (size_t k = 0; k < count; ++k) {
            __m128 s = _mm_add_ps(_mm_set1_ps(values[k]), _mm_mul_ps(l1, _mm_set1_ps(values[count + k])));
            if constexpr (V == 3) s = _mm_add_ps(s, _mm_mul_ps(l2, _mm_set1_ps(values[2 * count + k])));
            _mm_storeu_ps(reinterpret_cast<float*>(out + size_t(words[k]) * stride + 4 * i), s);
        }
    }
}
#endif

#if defined(SOFTGL_HAVE_AVX2_INTERPOLATION)
// Two quads per register (lanes 0..3 quads[i], 4..7 quads[i + 1]), their coordinates loaded as 8
// int32 words (x at 0 and 4, y at 1 and 5); an odd count's last quad is paired with itself and
// only its half stored. Compiled for AVX2 (no FMA) here only; called only when the CPU has it.
// C > 0: exactly C words (at most 8), their vertex values broadcast and their rows located once before the
// loop (the stores through `out` may alias v.values, so the general loop reads them again for
// every pair): the same operations on the same values.
template <int V, int C>
__attribute__((target("avx2"))) void interpolate_avx2(const VaryingInterpolation& v, const Quad* quads, size_t n,
                                                      uint32_t* out, size_t stride) {
    static_assert(sizeof(Quad) == 16 && offsetof(Quad, x) == 0 && offsetof(Quad, y) == 4, "two quads in 8 int32s");
    const float* const values = v.values;
    const int* const words = v.words;
    const size_t count = v.count;
    constexpr int kHeld = C > 0 ? C : 1;
    __m256 held[3][kHeld];   // v_0, d_1 (, d_2) of each word
    float* rows[kHeld];      // each word's lanes
    if constexpr (C > 0)
        for (int k = 0; k < C; ++k) {
            for (int r = 0; r < V; ++r) held[r][k] = _mm256_broadcast_ss(values + size_t(r) * count + size_t(k));
            rows[k] = reinterpret_cast<float*>(out + size_t(words[k]) * stride);
        }
    const ConstantQ cq(v.inv_w);
    const __m256 one = _mm256_set1_ps(1.0f), q_constant = _mm256_set1_ps(cq.q);
    const __m256i pick_x = _mm256_setr_epi32(0, 0, 0, 0, 4, 4, 4, 4), pick_y = _mm256_setr_epi32(1, 1, 1, 1, 5, 5, 5, 5);
    const __m256i px = _mm256_setr_epi32(0, 1, 0, 1, 0, 1, 0, 1), py = _mm256_setr_epi32(0, 0, 1, 1, 0, 0, 1, 1);
    const __m256i base_x = _mm256_set1_epi32(v.base_x), base_y = _mm256_set1_epi32(v.base_y);
    __m256 pa[V], pb[V], pc[V];   // Q, L_1 (, L_2)
    for (int k = 0; k < V; ++k) {
        const FloatPlane& pl = k == 0 ? v.inv_w : v.weight[k - 1];
        pa[k] = _mm256_set1_ps(pl.a), pb[k] = _mm256_set1_ps(pl.b), pc[k] = _mm256_set1_ps(pl.c);
    }
    // Quads i and i + 1 (Pair) or quad i alone (an odd count's last); Q: 0 q per lane, 1 q
    // constant, 2 q == 1 (not multiplied by). Each loop below is one of these, without branches.
    auto step = [&](size_t i, auto pair_tag, auto q_tag) __attribute__((target("avx2"))) {
        constexpr bool pair = decltype(pair_tag)::value;
        constexpr int Q = decltype(q_tag)::value;
        const __m256i xy = pair ? _mm256_loadu_si256(reinterpret_cast<const __m256i*>(quads + i))
                                : _mm256_broadcastsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(quads + i)));
        const __m256 dx = _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_add_epi32(_mm256_permutevar8x32_epi32(xy, pick_x), px), base_x));
        const __m256 dy = _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_add_epi32(_mm256_permutevar8x32_epi32(xy, pick_y), py), base_y));
        auto eval = [&](int k) __attribute__((target("avx2"))) {
            return _mm256_add_ps(_mm256_add_ps(pc[k], _mm256_mul_ps(pa[k], dx)), _mm256_mul_ps(pb[k], dy));
        };
        const __m256 q = Q == 0 ? _mm256_div_ps(one, eval(0)) : q_constant;
        const __m256 l1 = Q == 2 ? eval(1) : _mm256_mul_ps(eval(1), q);
        const __m256 l2 = V == 3 ? (Q == 2 ? eval(2) : _mm256_mul_ps(eval(2), q)) : _mm256_setzero_ps();
        if constexpr (C > 0) {
            for (int k = 0; k < C; ++k) {
                __m256 s = _mm256_add_ps(held[0][k], _mm256_mul_ps(l1, held[1][k]));
                if constexpr (V == 3) s = _mm256_add_ps(s, _mm256_mul_ps(l2, held[2][k]));
                if (pair) _mm256_storeu_ps(rows[k] + 4 * i, s);
                else _mm_storeu_ps(rows[k] + 4 * i, _mm256_castps256_ps128(s));
            }
        } else {
            for (size_t k = 0; k < count; ++k) {
                __m256 s = _mm256_add_ps(_mm256_broadcast_ss(values + k), _mm256_mul_ps(l1, _mm256_broadcast_ss(values + count + k)));
                if constexpr (V == 3) s = _mm256_add_ps(s, _mm256_mul_ps(l2, _mm256_broadcast_ss(values + 2 * count + k)));
                float* const dst = reinterpret_cast<float*>(out + size_t(words[k]) * stride + 4 * i);
                if (pair) _mm256_storeu_ps(dst, s);
                else _mm_storeu_ps(dst, _mm256_castps256_ps128(s));
            }
        }
    };
    auto loop = [&](auto q_tag) __attribute__((target("avx2"))) {
        size_t i = 0;
        for (; i + 1 < n; i += 2) step(i, std::true_type{}, q_tag);
        if (i < n) step(i, std::false_type{}, q_tag);
    };
    if (cq.unit) loop(std::integral_constant<int, 2>{});
    else if (cq.constant) loop(std::integral_constant<int, 1>{});
    else loop(std::integral_constant<int, 0>{});
}

// interpolate_avx2 with the word count fixed where it is small (texture coordinates and a colour:
// up to 8 words; held values past the registers are read from the stack, still fewer instructions).
template <int V>
__attribute__((target("avx2"))) void interpolate_avx2_counted(const VaryingInterpolation& v, const Quad* quads,
                                                              size_t n, uint32_t* out, size_t stride) {
    switch (v.count) {
        case 1: return interpolate_avx2<V, 1>(v, quads, n, out, stride);
        case 2: return interpolate_avx2<V, 2>(v, quads, n, out, stride);
        case 3: return interpolate_avx2<V, 3>(v, quads, n, out, stride);
        case 4: return interpolate_avx2<V, 4>(v, quads, n, out, stride);
        case 5: return interpolate_avx2<V, 5>(v, quads, n, out, stride);
        case 6: return interpolate_avx2<V, 6>(v, quads, n, out, stride);
        case 7: return interpolate_avx2<V, 7>(v, quads, n, out, stride);
        case 8: return interpolate_avx2<V, 8>(v, quads, n, out, stride);
        default: return interpolate_avx2<V, 0>(v, quads, n, out, stride);
    }
}

// Eight pixels per register, their (x, y) pairs loaded as two rows of 8 int32 words and split
// into x and y; a last group of fewer pixels is loaded and stored under a mask. The lanes'
// arithmetic is interpolate_avx2's.
template <int V>
__attribute__((target("avx2"))) void interpolate_pixels_avx2(const VaryingInterpolation& v, const int32_t* xy,
                                                             size_t n, uint32_t* out, size_t stride) {
    const float* const values = v.values;
    const int* const words = v.words;
    const size_t count = v.count;
    const ConstantQ cq(v.inv_w);
    const __m256 one = _mm256_set1_ps(1.0f), q_constant = _mm256_set1_ps(cq.q);
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256i split = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);   // x0..x3 y0..y3 of a row
    const __m256i base_x = _mm256_set1_epi32(v.base_x), base_y = _mm256_set1_epi32(v.base_y);
    __m256 pa[V], pb[V], pc[V];   // Q, L_1 (, L_2)
    for (int k = 0; k < V; ++k) {
        const FloatPlane& pl = k == 0 ? v.inv_w : v.weight[k - 1];
        pa[k] = _mm256_set1_ps(pl.a), pb[k] = _mm256_set1_ps(pl.b), pc[k] = _mm256_set1_ps(pl.c);
    }
    for (size_t i = 0; i < n; i += 8) {
        const bool full = i + 8 <= n;
        const int m = full ? 8 : int(n - i);
        const int* const at = reinterpret_cast<const int*>(xy + 2 * i);
        __m256i lo, hi;   // pixels i .. i + 3 and i + 4 .. i + 7
        if (full) {
            lo = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(at));
            hi = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(at + 8));
        } else {
            lo = _mm256_maskload_epi32(at, _mm256_cmpgt_epi32(_mm256_set1_epi32(2 * m), lane));
            hi = _mm256_maskload_epi32(at + 8, _mm256_cmpgt_epi32(_mm256_set1_epi32(2 * m - 8), lane));
        }
        lo = _mm256_permutevar8x32_epi32(lo, split), hi = _mm256_permutevar8x32_epi32(hi, split);
        const __m256 dx = _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_permute2x128_si256(lo, hi, 0x20), base_x));
        const __m256 dy = _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_permute2x128_si256(lo, hi, 0x31), base_y));
        auto eval = [&](int k) __attribute__((target("avx2"))) {
            return _mm256_add_ps(_mm256_add_ps(pc[k], _mm256_mul_ps(pa[k], dx)), _mm256_mul_ps(pb[k], dy));
        };
        const __m256 q = cq.constant ? q_constant : _mm256_div_ps(one, eval(0));
        const __m256 l1 = cq.unit ? eval(1) : _mm256_mul_ps(eval(1), q);
        const __m256 l2 = V == 3 ? (cq.unit ? eval(2) : _mm256_mul_ps(eval(2), q)) : _mm256_setzero_ps();
        const __m256i keep = _mm256_cmpgt_epi32(_mm256_set1_epi32(m), lane);
        for (size_t k = 0; k < count; ++k) {
            __m256 s = _mm256_add_ps(_mm256_broadcast_ss(values + k), _mm256_mul_ps(l1, _mm256_broadcast_ss(values + count + k)));
            if constexpr (V == 3) s = _mm256_add_ps(s, _mm256_mul_ps(l2, _mm256_broadcast_ss(values + 2 * count + k)));
            float* const dst = reinterpret_cast<float*>(out + size_t(words[k]) * stride + i);
            if (full) _mm256_storeu_ps(dst, s);
            else _mm256_maskstore_ps(dst, keep, s);
        }
    }
}

// Four quads per register, from 16 int32 words (x at 0, 4, 8, 12; y one after); a last group of
// fewer quads is loaded and stored under a mask (masked stores are slow: only there). Words go
// in batches of 16 whose destinations are computed once.
template <int V>
__attribute__((target("avx512f,avx512bw,avx512dq,avx512vl"))) void interpolate_avx512(
    const VaryingInterpolation& v, const Quad* quads, size_t n, uint32_t* out, size_t stride) {
    const float* const values = v.values;
    const size_t count = v.count;
    const Avx512Interpolator<V> interpolator(v);
    constexpr size_t kBatch = 16;
    float* dst[kBatch];
    for (size_t k0 = 0; k0 < count; k0 += kBatch) {
        const size_t batch = count - k0 < kBatch ? count - k0 : kBatch;
        for (size_t k = 0; k < batch; ++k) dst[k] = reinterpret_cast<float*>(out + size_t(v.words[k0 + k]) * stride);
        const float* const v0 = values + k0;
        const float* const d1 = values + count + k0;
        const float* const d2 = V == 3 ? values + 2 * count + k0 : d1;   // lines: unused
        auto group = [&](size_t i, __mmask16 lanes, bool full) __attribute__((target("avx512f,avx512bw,avx512dq,avx512vl"))) {
            const __m512i xy = full ? _mm512_loadu_si512(quads + i) : _mm512_maskz_loadu_epi32(lanes, quads + i);
            __m512 l1, l2;
            interpolator.weights(xy, l1, l2);
            for (size_t k = 0; k < batch; ++k) {
                const __m512 s = Avx512Interpolator<V>::value(v0[k], d1[k], d2[k], l1, l2);
                if (full) _mm512_storeu_ps(dst[k] + 4 * i, s);
                else _mm512_mask_storeu_ps(dst[k] + 4 * i, lanes, s);
            }
        };
        size_t i = 0;
        for (; i + 4 <= n; i += 4) group(i, 0xFFFF, true);
        if (i < n) group(i, __mmask16((1u << (4 * (n - i))) - 1), false);
    }
}
#endif

}  // namespace

bool weights_finite(const VaryingInterpolation& v, const Quad* quads, const uint16_t* masks, size_t n) {
    const ConstantQ cq(v.inv_w);
    if (weights_always_finite(v, cq)) return true;
    // interpolate_scalar's weights, lane by lane (a constant Q's q is 1 / c there too: ConstantQ).
    auto eval = [](const FloatPlane& pl, float dx, float dy) { return (pl.c + pl.a * dx) + pl.b * dy; };
    for (size_t i = 0; i < n; ++i)
        for (int j = 0; j < 4; ++j) {
            if (!masks[4 * i + size_t(j)]) continue;
            const float dx = lane_offset(quads[i].x, j & 1, v.base_x), dy = lane_offset(quads[i].y, j >> 1, v.base_y);
            const float q = 1.0f / eval(v.inv_w, dx, dy);
            if (!std::isfinite(eval(v.weight[0], dx, dy) * q)) return false;
            if (v.vertices == 3 && !std::isfinite(eval(v.weight[1], dx, dy) * q)) return false;
        }
    return true;
}

// Each plane's float value e = (c + a*dx) + b*dy differs from the exact c + a*dx + b*dy by at most
// 3 float roundings of terms no larger than M = |c| + |a|*width + |b|*height (2^-24 relative
// each), plus 2^-149 per operation where results are subnormal; the exact value's extremes over
// the rectangle are at its corners (computed in double: error 2^-53 M per operation). So with
// slack = 2^-21 M + 2^-120: Q's float value is at least min Q - slack, q = 1 / that at most (1 +
// 2^-24) / (min Q - slack), and |l_k| <= (max |L_k| + slack_k) * q * (1 + 2^-24). When Q's lower
// bound is above 2^-100 and each l_k's bound below 2^120, every weight is finite.
bool weights_finite_in(const VaryingInterpolation& v, int32_t width, int32_t height) {
    struct Range {
        double lo, hi, slack;
    };
    const double w = double(width), h = double(height);
    auto range = [&](const FloatPlane& pl) {
        const double a = pl.a, b = pl.b, c = pl.c;
        const double corners[4] = {c, c + a * w, c + b * h, (c + a * w) + b * h};
        Range r{corners[0], corners[0], (std::fabs(c) + std::fabs(a) * w + std::fabs(b) * h) * 0x1p-21 + 0x1p-120};
        for (double e : corners) r.lo = std::min(r.lo, e), r.hi = std::max(r.hi, e);
        return r;
    };
    const Range q = range(v.inv_w);
    const double q_low = q.lo - q.slack;
    if (!(q_low > 0x1p-100) || !std::isfinite(q.hi + q.slack)) return false;
    const double q_max = (1.0 / q_low) * (1.0 + 0x1p-23);
    for (int k = 0; k + 1 < v.vertices; ++k) {
        const Range l = range(v.weight[k]);
        const double l_max = (std::max(std::fabs(l.lo), std::fabs(l.hi)) + l.slack) * q_max * (1.0 + 0x1p-23);
        if (!(l_max < 0x1p120)) return false;
    }
    return true;
}

void interpolate_varyings_at(SimdLevel level, const VaryingInterpolation& v, const Quad* quads, size_t n,
                             uint32_t* out, size_t stride) {
    switch (level) {
        case SimdLevel::Scalar: break;
        case SimdLevel::AVX512:
#if defined(SOFTGL_HAVE_AVX2_INTERPOLATION)
            return v.vertices == 3 ? interpolate_avx512<3>(v, quads, n, out, stride)
                                   : interpolate_avx512<2>(v, quads, n, out, stride);
#endif
            [[fallthrough]];
        case SimdLevel::AVX2:
#if defined(SOFTGL_HAVE_AVX2_INTERPOLATION)
            return v.vertices == 3 ? interpolate_avx2_counted<3>(v, quads, n, out, stride)
                                   : interpolate_avx2_counted<2>(v, quads, n, out, stride);
#endif
            [[fallthrough]];
        case SimdLevel::SSE2:
#if defined(__SSE2__)
            return v.vertices == 3 ? interpolate_sse2<3>(v, quads, n, out, stride)
                                   : interpolate_sse2<2>(v, quads, n, out, stride);
#endif
            break;
    }
    interpolate_scalar(v, quads, n, out, stride);
}

void interpolate_pixels_at(SimdLevel level, const VaryingInterpolation& v, const int32_t* xy, size_t n, uint32_t* out,
                           size_t stride) {
#if defined(SOFTGL_HAVE_AVX2_INTERPOLATION)
    // AVX-512 takes the AVX2 kernel: a batch's single pixels are few per primitive.
    if (level >= SimdLevel::AVX2)
        return v.vertices == 3 ? interpolate_pixels_avx2<3>(v, xy, n, out, stride)
                               : interpolate_pixels_avx2<2>(v, xy, n, out, stride);
#endif
    (void)level;
    interpolate_pixels_scalar(v, xy, n, out, stride);
}

}  // namespace softgl
