#include "softgl/pipeline/fragment_ops.h"

#include <algorithm>
#include <array>
#include <cstdint>

#include "softgl/pipeline/chunk_pixels.h"
#include "softgl/pipeline/interpolate.h"

namespace softgl {

const float* unorm8_to_float_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[size_t(i)] = float(i) / 255.0f;
        return t;
    }();
    return table.data();
}

ColorKernel color_kernel(const BlendOp& op) {
    if (op.is_plain_write()) return ColorKernel::Plain;
    if (op.eq_rgb != gl::FUNC_ADD || op.eq_alpha != gl::FUNC_ADD) return ColorKernel::Generic;
    if (op.src_rgb == gl::SRC_ALPHA && op.src_alpha == gl::SRC_ALPHA && op.dst_rgb == gl::ONE_MINUS_SRC_ALPHA &&
        op.dst_alpha == gl::ONE_MINUS_SRC_ALPHA)
        return ColorKernel::AlphaOver;
    if (op.src_rgb == gl::ONE && op.src_alpha == gl::ONE && op.dst_rgb == gl::ONE && op.dst_alpha == gl::ONE)
        return ColorKernel::Additive;
    return ColorKernel::Generic;
}

namespace {
template <ColorKernel K>
void write_n(const BlendOp& op, const float* src, uint8_t* dst, size_t n) {
    const bool all = op.write[0] && op.write[1] && op.write[2] && op.write[3];
    const float* table = unorm8_to_float_table();
    for (size_t i = 0; i < n; ++i) write_color<K>(op, all, table, src + 4 * i, dst + 4 * i);
}
}  // namespace

void write_colors(const BlendOp& op, const float* src, uint8_t* dst, size_t n) {
    switch (color_kernel(op)) {
        case ColorKernel::Plain: return write_n<ColorKernel::Plain>(op, src, dst, n);
        case ColorKernel::AlphaOver: return write_n<ColorKernel::AlphaOver>(op, src, dst, n);
        case ColorKernel::Additive: return write_n<ColorKernel::Additive>(op, src, dst, n);
        case ColorKernel::Generic: return write_n<ColorKernel::Generic>(op, src, dst, n);
    }
}

}  // namespace softgl

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SOFTGL_HAVE_AVX2_KERNELS 1
#endif

namespace softgl {

namespace {

template <ColorKernel K>
void lanes_scalar(const BlendOp& op, const float* src, size_t stride, uint32_t* dst, size_t first, size_t n) {
    const bool all = op.write[0] && op.write[1] && op.write[2] && op.write[3];
    const float* table = unorm8_to_float_table();
    for (size_t l = first; l < n; ++l) {
        const float s[4] = {src[l], src[stride + l], src[2 * stride + l], src[3 * stride + l]};
        uint8_t px[4];
        std::memcpy(px, &dst[l], 4);
        write_color<K>(op, all, table, s, px);
        std::memcpy(&dst[l], px, 4);
    }
}

#if defined(__SSE2__)
inline __m128 clamp01_ps(__m128 v) {
    // maxps(a, b) is a > b ? a : b and minps(a, b) is a < b ? a : b (the second operand when
    // either is NaN): v > 0 ? (v < 1 ? v : 1) : 0 with NaN and -0 -> +0, exactly clamp01.
    return _mm_min_ps(_mm_max_ps(v, _mm_setzero_ps()), _mm_set1_ps(1.0f));
}
// unorm8_from_float on four lanes: clamp (same decisions as its branches), then
// trunc(double(v) * 255 + 0.5) in double precision.
inline __m128i unorm8_ps(__m128 v) {
    v = clamp01_ps(v);
    const __m128d k = _mm_set1_pd(255.0), h = _mm_set1_pd(0.5);
    const __m128d lo = _mm_add_pd(_mm_mul_pd(_mm_cvtps_pd(v), k), h);
    const __m128d hi = _mm_add_pd(_mm_mul_pd(_mm_cvtps_pd(_mm_movehl_ps(v, v)), k), h);
    return _mm_unpacklo_epi64(_mm_cvttpd_epi32(lo), _mm_cvttpd_epi32(hi));
}
#endif

template <ColorKernel K>
void lanes(const BlendOp& op, const float* src, size_t stride, uint32_t* dst, size_t n, size_t l = 0) {
#if defined(__SSE2__)
    uint32_t keep = 0;   // destination bits kept by the colour mask
    for (int c = 0; c < 4; ++c)
        if (!op.write[size_t(c)]) keep |= 0xFFu << (8 * c);
    const __m128i keep_v = _mm_set1_epi32(int(keep));
    const __m128i byte = _mm_set1_epi32(0xFF);
    const __m128 k255 = _mm_set1_ps(255.0f);
    for (; l + 4 <= n; l += 4) {
        const __m128i d32 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(dst + l));
        __m128 s[4];
        for (int c = 0; c < 4; ++c) s[c] = clamp01_ps(_mm_loadu_ps(src + size_t(c) * stride + l));
        __m128i packed = _mm_setzero_si128();
        for (int c = 0; c < 4; ++c) {
            __m128 out;
            if constexpr (K == ColorKernel::Plain) {
                out = s[c];
            } else {
                __m128 d;
                if (c == 3 && !op.has_alpha) d = _mm_set1_ps(1.0f);
                else d = _mm_div_ps(_mm_cvtepi32_ps(_mm_and_si128(_mm_srli_epi32(d32, 8 * c), byte)), k255);
                if constexpr (K == ColorKernel::AlphaOver) {
                    const __m128 sf = s[3], df = _mm_sub_ps(_mm_set1_ps(1.0f), s[3]);
                    out = _mm_add_ps(_mm_mul_ps(s[c], sf), _mm_mul_ps(d, df));
                } else {   // Additive
                    const __m128 one = _mm_set1_ps(1.0f);
                    out = _mm_add_ps(_mm_mul_ps(s[c], one), _mm_mul_ps(d, one));
                }
            }
            packed = _mm_or_si128(packed, _mm_slli_epi32(unorm8_ps(out), 8 * c));
        }
        if (keep) packed = _mm_or_si128(_mm_andnot_si128(keep_v, packed), _mm_and_si128(keep_v, d32));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + l), packed);
    }
#endif
    lanes_scalar<K>(op, src, stride, dst, l, n);
}

#if defined(SOFTGL_HAVE_AVX2_KERNELS)
// The lane kernel eight lanes at a time, compiled for AVX2 only here and called only when the CPU
// has it. The blend arithmetic is the SSE2 kernel's (the table's float(d) / 255.0f as a division,
// float multiply and add, no contraction); float -> unorm8 is an exact integer form, so the bytes are the scalar
// path's (tests/pipeline/test_fragment_ops.py checks every float in [0, 1]). The division stays:
// exact division-free forms of d / 255.0f (float(double(d) * (1.0 / 255)); t = float(d * 257),
// (t + t * (2^-16 + 2^-32)) * 2^-16) and a gather from the table all measured slower.
__attribute__((target("avx2"))) inline __m256 clamp01_ps8(__m256 v) {
    return _mm256_min_ps(_mm256_max_ps(v, _mm256_setzero_ps()), _mm256_set1_ps(1.0f));   // as clamp01_ps
}
// float_to_unorm8(v) for v already in [0, 1], in integers with no rounding anywhere: v = m * 2^(e-150)
// (m the significand with its implicit bit, e the biased exponent), so v*255 = (m*255) * 2^-s with
// s = 150 - e, and floor(v*255 + 0.5) = floor((floor(v*510) + 1) / 2) with
// floor(v*510) = m*255 >> (s-1). m*255 = (m << 8) - m < 2^32. vpsrlvd gives 0 for counts of 32 or
// more: the right answer for v < 2^-9, where v*255 < 0.5 (0 and subnormals included).
// Returns floor(v*510) + 1 (at most 511): the byte is its bits 1..8, which unorm8_at_byte_ps8 moves
// into place with one shift.
__attribute__((target("avx2"))) inline __m256i floor_v510_plus_1_ps8(__m256 v) {
    const __m256i bits = _mm256_castps_si256(v);
    const __m256i m = _mm256_or_si256(_mm256_and_si256(bits, _mm256_set1_epi32(0x7FFFFF)), _mm256_set1_epi32(0x800000));
    const __m256i m255 = _mm256_sub_epi32(_mm256_slli_epi32(m, 8), m);
    const __m256i shift = _mm256_sub_epi32(_mm256_set1_epi32(149), _mm256_srli_epi32(bits, 23));   // s - 1
    return _mm256_add_epi32(_mm256_srlv_epi32(m255, shift), _mm256_set1_epi32(1));
}
// float_to_unorm8(v) of clamped v as byte c of each lane: (x >> 1) << 8c, the second shift folded
// into the first and a mask (shifts have fewer ports than logic).
__attribute__((target("avx2"))) inline __m256i unorm8_at_byte_ps8(__m256 v, int c) {
    const __m256i x = floor_v510_plus_1_ps8(v);
    if (c == 0) return _mm256_srli_epi32(x, 1);
    return _mm256_and_si256(_mm256_slli_epi32(x, 8 * c - 1), _mm256_set1_epi32(int(0xFFu << (8 * c))));
}

// Eight lanes of the lane kernel: src + l the first lane's red (channels `stride` apart), d32 the
// destination pixels; the pixels it writes (the colour mask's channels kept from d32).
template <ColorKernel K>
__attribute__((target("avx2"), always_inline)) inline __m256i blend8_avx2(const BlendOp& op, uint32_t keep,
                                                                         const float* src, size_t stride, __m256i d32) {
    const __m256i byte = _mm256_set1_epi32(0xFF);
    const __m256 k255 = _mm256_set1_ps(255.0f);
    {
        __m256 s[4];
        for (int c = 0; c < 4; ++c) s[c] = clamp01_ps8(_mm256_loadu_ps(src + size_t(c) * stride));
        __m256i packed = _mm256_setzero_si256();
        for (int c = 0; c < 4; ++c) {
            __m256 out;
            if constexpr (K == ColorKernel::Plain) {
                out = s[c];   // clamped already
            } else {
                __m256 d;
                if (c == 3 && !op.has_alpha) d = _mm256_set1_ps(1.0f);
                else d = _mm256_div_ps(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(d32, 8 * c), byte)), k255);
                if constexpr (K == ColorKernel::AlphaOver) {
                    const __m256 sf = s[3], df = _mm256_sub_ps(_mm256_set1_ps(1.0f), s[3]);
                    out = _mm256_add_ps(_mm256_mul_ps(s[c], sf), _mm256_mul_ps(d, df));
                } else {   // Additive
                    const __m256 one = _mm256_set1_ps(1.0f);
                    out = _mm256_add_ps(_mm256_mul_ps(s[c], one), _mm256_mul_ps(d, one));
                }
                out = clamp01_ps8(out);
            }
            packed = _mm256_or_si256(packed, unorm8_at_byte_ps8(out, c));
        }
        if (keep) {
            const __m256i keep_v = _mm256_set1_epi32(int(keep));
            packed = _mm256_or_si256(_mm256_andnot_si256(keep_v, packed), _mm256_and_si256(keep_v, d32));
        }
        return packed;
    }
}

template <ColorKernel K>
__attribute__((target("avx2"))) void lanes_avx2(const BlendOp& op, const float* src, size_t stride, uint32_t* dst,
                                               size_t n) {
    uint32_t keep = 0;
    for (int c = 0; c < 4; ++c)
        if (!op.write[size_t(c)]) keep |= 0xFFu << (8 * c);
    size_t l = 0;
    for (; l + 8 <= n; l += 8) {
        const __m256i d32 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(dst + l));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst + l), blend8_avx2<K>(op, keep, src + l, stride, d32));
    }
    lanes<K>(op, src, stride, dst, n, l);   // the rest: four, then one at a time
}

// blend8_avx2 with float -> unorm8 by the FMA of unorm8_pixels_ps16 (its proof: exact for v in
// [0, 1 + 2^-22]), for CPUs with FMA: the integer form's ten operations per channel become two.
// AlphaOver's result lies in that range unclamped (blend_ps16's argument); the other kernels
// clamp as blend8_avx2 does.
inline bool has_fma() { return __builtin_cpu_supports("fma"); }
template <ColorKernel K>
__attribute__((target("avx2,fma"), always_inline)) inline __m256i blend8_fma(const BlendOp& op, uint32_t keep,
                                                                            const float* src, size_t stride, __m256i d32) {
    const __m256i byte = _mm256_set1_epi32(0xFF);
    const __m256 k255 = _mm256_set1_ps(255.0f);
    __m256 s[4];
    for (int c = 0; c < 4; ++c) s[c] = clamp01_ps8(_mm256_loadu_ps(src + size_t(c) * stride));
    __m256i packed = _mm256_setzero_si256();
    for (int c = 0; c < 4; ++c) {
        __m256 out;
        if constexpr (K == ColorKernel::Plain) {
            out = s[c];
        } else {
            __m256 d;
            if (c == 3 && !op.has_alpha) d = _mm256_set1_ps(1.0f);
            else d = _mm256_div_ps(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(d32, 8 * c), byte)), k255);
            if constexpr (K == ColorKernel::AlphaOver) {
                const __m256 df = _mm256_sub_ps(_mm256_set1_ps(1.0f), s[3]);
                out = _mm256_add_ps(_mm256_mul_ps(s[c], s[3]), _mm256_mul_ps(d, df));
            } else {   // Additive
                const __m256 one = _mm256_set1_ps(1.0f);
                out = clamp01_ps8(_mm256_add_ps(_mm256_mul_ps(s[c], one), _mm256_mul_ps(d, one)));
            }
        }
        // 2^23 + the byte; shifting by 8c (c >= 1) drops the exponent bits 0x4B.
        const __m256i n = _mm256_castps_si256(_mm256_fmadd_ps(out, k255, _mm256_set1_ps(0x1p23f)));
        packed = _mm256_or_si256(packed, c == 0 ? _mm256_and_si256(n, byte) : _mm256_slli_epi32(n, 8 * c));
    }
    if (keep) {
        const __m256i keep_v = _mm256_set1_epi32(int(keep));
        packed = _mm256_or_si256(_mm256_andnot_si256(keep_v, packed), _mm256_and_si256(keep_v, d32));
    }
    return packed;
}
#endif

// AVX-512 VBMI (byte permutes): the table lookups' instructions, on top of the AVX512 level.
inline bool has_vbmi() { return cpu_has_avx512_vbmi(); }

#define SOFTGL_AVX512 "avx512f,avx512bw,avx512dq,avx512vl"
// GCC 12's AVX-512 intrinsics start from _mm512_undefined_*(), which -W(maybe-)uninitialized
// reports once they are inlined here (GCC bug 105593, fixed in GCC 13).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// The lane kernel sixteen lanes at a time: the AVX2 kernel's operations, lane for lane, in 512-bit
// registers (the same clamps, the same division for d / 255; float -> unorm8 by an FMA, exact too).
__attribute__((target(SOFTGL_AVX512))) inline __m512 clamp01_ps16(__m512 v) {
    return _mm512_min_ps(_mm512_max_ps(v, _mm512_setzero_ps()), _mm512_set1_ps(1.0f));   // as clamp01_ps
}
// float_to_unorm8 of four channels' values v (each in [0, 1 + 2^-22]: clamped, or a blend of
// clamped values) packed into pixels, byte c = channel c. float_to_unorm8(v) is floor(v*255 + 0.5)
// (double(v) * 255 + 0.5 is exact in double). One FMA gives it: v*255 + 2^23 is rounded once, to
// nearest even, into [2^23, 2^24) where floats are the integers, so the result is 2^23 + n with n
// the integer nearest v*255, bits 0x4B000000 + n. That n is floor(v*255 + 0.5) but at a tie,
// v*255 = k + 0.5, i.e. v = (2k + 1)/510, a float only when 255 divides 2k + 1 (2k + 1 <= 511): v =
// 1/2, k = 127, which the tie rounds to even 128, floor's value too. v < 1 + 2^-22 keeps n <= 255.
// An FMA here is an exact integer conversion, not a contraction of the reference's arithmetic
// (tests/pipeline/test_fragment_ops.py checks every float in [0, 1] against float_to_unorm8).
// Shifting by 8c (c >= 1) drops the exponent bits 0x4B, and channel 0 keeps its low byte.
__attribute__((target(SOFTGL_AVX512))) inline __m512i unorm8_pixels_ps16(const __m512 (&v)[4]) {
    __m512i n[4];
    for (int c = 0; c < 4; ++c)
        n[c] = _mm512_castps_si512(_mm512_fmadd_ps(v[c], _mm512_set1_ps(255.0f), _mm512_set1_ps(0x1p23f)));
    // (n0 & 0xFF) | n1 << 8 (0xEA: a & b | c), then | n2 << 16 | n3 << 24 (0xFE: a | b | c).
    const __m512i rg = _mm512_ternarylogic_epi32(n[0], _mm512_set1_epi32(0xFF), _mm512_slli_epi32(n[1], 8), 0xEA);
    return _mm512_ternarylogic_epi32(rg, _mm512_slli_epi32(n[2], 16), _mm512_slli_epi32(n[3], 24), 0xFE);
}
// Destination byte c of each lane as float(byte) / 255.0f * 2^32, exactly and without a division:
// byte / 255 is 0.bbbb... in base 256, so u = byte * 0x01010101 (the byte in all four bytes, one
// vpshufb) is byte / 255 * 2^32 truncated, and the rest is byte / 255 < 1. u has 24 + b significant
// bits (b the byte's bit length); the b a float drops are the byte itself, at least half their
// place, and the rest is > 0, so the correctly rounded value always rounds u up: a conversion
// rounding toward +inf gives it (0 -> 0 and 255 -> 2^32 too). tests/pipeline/test_fragment_ops.py
// blends every destination byte against every alpha k / 255 (round to nearest there fails it).
__attribute__((target(SOFTGL_AVX512))) inline __m512 unorm8_to_float_times_2p32_ps16(__m512i d32, int c) {
    const __m512i spread = _mm512_add_epi8(_mm512_set1_epi8(char(c)), _mm512_set4_epi32(0x0C0C0C0C, 0x08080808, 0x04040404, 0));
    return _mm512_cvt_roundepu32_ps(_mm512_shuffle_epi8(d32, spread), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
}
// write_color<K> of 16 lanes with every channel written: s clamped, d32 the destination pixels.
// d * df is the reference's product: (d * 2^32) * (df * 2^-32) is the same real number (power-of-two
// scalings of a value that is 0 or at least 2^-24 are exact), at least 2^-32 when not 0, so it
// rounds to the same float.
template <ColorKernel K>
__attribute__((target(SOFTGL_AVX512))) inline __m512i blend_ps16(const BlendOp& op, const __m512 s[4], __m512i d32) {
    const __m512 two_m32 = _mm512_set1_ps(0x1p-32f);
    const __m512 df = _mm512_sub_ps(_mm512_set1_ps(1.0f), s[3]);   // AlphaOver: 1 - s[3]
    const __m512 df_2m32 = _mm512_mul_ps(df, two_m32);
    __m512 out[4];
    for (int c = 0; c < 4; ++c) {
        const bool d_is_one = c == 3 && !op.has_alpha;
        if constexpr (K == ColorKernel::Plain) {
            out[c] = s[c];
        } else if constexpr (K == ColorKernel::AlphaOver) {
            // s * sf + d * df with sf = s[3], df = 1 - s[3]. s, d and df lie in [0, 1], so out is
            // in [0, 1 + 2^-22] (each product at most its factor, a + (1 - a) within an ulp of 1):
            // no clamp, as unorm8_pixels_ps16 allows up to 1 + 2^-22.
            const __m512 d_df = d_is_one ? df : _mm512_mul_ps(unorm8_to_float_times_2p32_ps16(d32, c), df_2m32);
            out[c] = _mm512_add_ps(_mm512_mul_ps(s[c], s[3]), d_df);
        } else {   // Additive: s * 1 + d * 1, where the multiplications by 1 are exact
            const __m512 d = d_is_one ? _mm512_set1_ps(1.0f) : _mm512_mul_ps(unorm8_to_float_times_2p32_ps16(d32, c), two_m32);
            out[c] = clamp01_ps16(_mm512_add_ps(s[c], d));
        }
    }
    return unorm8_pixels_ps16(out);
}

// One colour for every lane (bit for bit), as a shader that reads only uniforms gives: lane l's
// result is then a function of its destination byte per channel (K blends per channel), a
// BlendTable, built with every channel written, so that a later call with another colour mask
// finds every channel's entries (apply_table takes the channels to write from the call's op).
struct UniformColorTable {
    uint32_t colour[4] = {};
    int kernel = -1;
    bool has_alpha = false;
    BlendTable table;
    bool matches(int k, bool alpha, const uint32_t c[4]) const {
        return kernel == k && has_alpha == alpha && std::memcmp(colour, c, 16) == 0;
    }
    void key(int k, bool alpha, const uint32_t c[4]) {
        std::memcpy(colour, c, 16);
        kernel = k, has_alpha = alpha;
    }
};
// The bits in which lanes l .. l + 15 (those in `lanes`) differ from want[c], over the channels.
__attribute__((target(SOFTGL_AVX512))) inline __m512i colour_difference(const float* src, size_t stride, size_t l,
                                                                       __mmask16 lanes, const __m512i want[4]) {
    __m512i d = _mm512_setzero_si512();
    for (int c = 0; c < 4; ++c)
        d = _mm512_or_si512(d, _mm512_maskz_xor_epi32(lanes, _mm512_maskz_loadu_epi32(lanes, src + size_t(c) * stride + l), want[c]));
    return d;
}
// Whether every lane's colour has lane 0's bits (colour[c] = channel c). The first 16 lanes
// decide quickly when colours vary; the rest are tested once at the end (an exit per block costs
// more in branch misses than the loads it saves).
__attribute__((target(SOFTGL_AVX512))) inline bool uniform_colour(const float* src, size_t stride, size_t n,
                                                                  uint32_t colour[4]) {
    __m512i want[4];
    for (int c = 0; c < 4; ++c) {
        std::memcpy(&colour[c], src + size_t(c) * stride, 4);
        want[c] = _mm512_set1_epi32(int(colour[c]));
    }
    const auto lanes_below = [](size_t k) { return __mmask16(k >= 16 ? 0xFFFF : (1u << k) - 1); };
    __m512i differ = colour_difference(src, stride, 0, lanes_below(n), want);
    if (_mm512_test_epi32_mask(differ, differ)) return false;
    for (size_t l = 16; l < n; l += 16) differ = _mm512_or_si512(differ, colour_difference(src, stride, l, lanes_below(n - l), want));
    return _mm512_test_epi32_mask(differ, differ) == 0;
}

// The tables of the last few colours, per thread. A lit box's faces come in turns (a batch per
// face and tile), so one entry was rebuilt at almost every call. Building a table costs about as
// much as blending a few hundred lanes, more than a batch of at most 128, so a colour gets a table
// at its second call since it was last seen missing (`candidate`); a first call blends its lanes.
// Either way the bytes are the lane kernel's (the table holds its results), so the choice changes
// only the time.
struct UniformColorTables {
    static constexpr size_t kEntries = 4;
    UniformColorTable entry[kEntries];
    size_t next = 0;                 // the entry replaced next (round robin)
    UniformColorTable candidate;     // key only: the last colour that missed
};

template <ColorKernel K>
const UniformColorTable* uniform_colour_table(const BlendOp& op, const uint32_t colour[4]) {
    thread_local UniformColorTables tables;
    for (const UniformColorTable& t : tables.entry)
        if (t.matches(int(K), op.has_alpha, colour)) return &t;
    if (!tables.candidate.matches(int(K), op.has_alpha, colour)) {
        tables.candidate.key(int(K), op.has_alpha, colour);
        return nullptr;
    }
    UniformColorTable& t = tables.entry[tables.next];
    tables.next = (tables.next + 1) % UniformColorTables::kEntries;
    float src[4];
    std::memcpy(src, colour, 16);
    BlendOp every_channel = op;
    every_channel.write = {true, true, true, true};
    build_blend_table(K, every_channel, src, t.table);
    t.key(int(K), op.has_alpha, colour);
    return &t;
}

// A table applied to 64 destination bytes (16 pixels): per channel c in `channels` (bit c) two
// 128-entry byte lookups (vpermi2b, AVX-512 VBMI), bit 7 of the destination byte choosing between
// them; the other channels keep their bytes. q[c][k] holds the table's bytes 64k .. 64k + 63.
// Every lookup indexes the destination itself (merging each into the last one's result instead
// made a chain of eight lookups per 16 pixels: 1.3x slower).
__attribute__((target(SOFTGL_AVX512 ",avx512vbmi"))) inline __m512i look_up(const __m512i (&q)[4][4], unsigned channels,
                                                                            __m512i d) {
    const __mmask64 upper = _mm512_movepi8_mask(d);   // destination bytes >= 128
    __m512i r = d;
    for (int c = 0; c < 4; ++c) {
        if (!(channels >> c & 1)) continue;
        const __mmask64 channel = 0x1111111111111111ull << c;
        r = _mm512_mask_mov_epi8(r, channel & ~upper, _mm512_permutex2var_epi8(q[c][0], d, q[c][1]));
        r = _mm512_mask_mov_epi8(r, channel & upper, _mm512_permutex2var_epi8(q[c][2], d, q[c][3]));
    }
    return r;
}
__attribute__((target(SOFTGL_AVX512))) inline void load_table(const uint8_t (&bytes)[4][256], __m512i (&q)[4][4]) {
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k) q[c][k] = _mm512_load_si512(&bytes[c][64 * k]);
}
__attribute__((target(SOFTGL_AVX512 ",avx512vbmi"))) void apply_table(const UniformColorTable& t, const BlendOp& op,
                                                                     uint32_t* dst, size_t n) {
    __m512i q[4][4];
    load_table(t.table.bytes, q);
    unsigned channels = 0;
    for (int c = 0; c < 4; ++c) channels |= unsigned(op.write[size_t(c)]) << c;
    size_t l = 0;
    for (; l + 16 <= n; l += 16) _mm512_storeu_si512(dst + l, look_up(q, channels, _mm512_loadu_si512(dst + l)));
    if (l < n) {
        const __mmask16 tail = __mmask16((1u << (n - l)) - 1);
        _mm512_mask_storeu_epi32(dst + l, tail, look_up(q, channels, _mm512_maskz_loadu_epi32(tail, dst + l)));
    }
}

// The rasterizer walks a tile's 8x8 blocks row by row (raster.h): a row of four's pixels eight
// rows up are drawn a block row later, about when they arrive when fetched now. A tile's block
// row is only 256 bytes wide, too short for the hardware prefetchers, and without this the
// lookups waited on the destination's loads (most of the time of full-screen blended layers).
inline void prefetch_block_below(const uint8_t* row0, size_t pitch) {
    __builtin_prefetch(row0 + 4 * 8 * pitch, 1);
    __builtin_prefetch(row0 + 4 * 9 * pitch, 1);
}

// apply_blend_table_at's AVX-512 VBMI level: the lanes of four quads at a time (those not in a
// row of four), then each row of four as one register (two rows of eight pixels).
__attribute__((target(SOFTGL_AVX512 ",avx512vbmi"))) void apply_blend_table_avx512(const BlendTable& t, const Quad* quads,
                                                                                  size_t n, uint32_t* dst,
                                                                                  const PixelRows& rows) {
    __m512i q[4][4];
    load_table(t.bytes, q);
    const uint64_t in_row = rows.rows | rows.rows << 1 | rows.rows << 2 | rows.rows << 3;
    for (size_t i = 0; i < n; i += 4) {
        __mmask16 lanes = 0;
        for (size_t k = 0; k < 4 && i + k < n; ++k)
            if (!(in_row >> (i + k) & 1)) lanes = __mmask16(lanes | 0xFu << (4 * k));
        if (lanes) _mm512_mask_storeu_epi32(dst + 4 * i, lanes, look_up(q, t.channels, _mm512_maskz_loadu_epi32(lanes, dst + 4 * i)));
    }
    for (uint64_t r = rows.rows; r; r &= r - 1) {
        const Quad& quad = quads[__builtin_ctzll(r)];
        uint8_t* const row0 = rows.color + 4 * (size_t(quad.y) * rows.pitch + size_t(quad.x));
        uint8_t* const row1 = row0 + 4 * rows.pitch;
        prefetch_block_below(row0, rows.pitch);
        const __m512i d = _mm512_inserti64x4(_mm512_castsi256_si512(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(row0))),
                                             _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row1)), 1);
        const __m512i px = look_up(q, t.channels, d);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(row0), _mm512_castsi512_si256(px));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(row1), _mm512_extracti64x4_epi64(px, 1));
    }
}

// apply_blend_table_to_rect_at's AVX-512 VBMI level: each row as 16 pixels at a time, the last
// ones masked. A tile's rows are 256 bytes apart by a whole buffer row, too short a run for the
// hardware prefetchers: the row kAheadRows below is fetched while this one is looked up.
constexpr int32_t kAheadRows = 4;
__attribute__((target(SOFTGL_AVX512 ",avx512vbmi"))) void apply_blend_table_to_rect_avx512(const BlendTable& t,
                                                                                          const PixelRect& r) {
    __m512i q[4][4];
    load_table(t.bytes, q);
    const size_t width = size_t(r.x1 - r.x0);
    for (int32_t y = r.y0; y < r.y1; ++y) {
        uint32_t* const row = reinterpret_cast<uint32_t*>(r.color) + size_t(y) * r.pitch + size_t(r.x0);
        if (y + kAheadRows < r.y1)
            for (size_t b = 0; b < 4 * width; b += 64) __builtin_prefetch(reinterpret_cast<const uint8_t*>(row + kAheadRows * r.pitch) + b, 1);
        size_t x = 0;
        for (; x + 16 <= width; x += 16) _mm512_storeu_si512(row + x, look_up(q, t.channels, _mm512_loadu_si512(row + x)));
        if (x < width) {
            const __mmask16 tail = __mmask16((1u << (width - x)) - 1);
            _mm512_mask_storeu_epi32(row + x, tail, look_up(q, t.channels, _mm512_maskz_loadu_epi32(tail, row + x)));
        }
    }
}

// Lanes l .. l + 15 of the lane kernel (only those in `tail` unless Full: masked loads and
// stores only where needed).
template <ColorKernel K, bool Full>
__attribute__((target(SOFTGL_AVX512), always_inline)) inline void lanes16(const BlendOp& op, const float* src, size_t stride,
                                                           uint32_t* dst, size_t l, __mmask16 tail, __m512i keep) {
    const __m512i d32 = Full ? _mm512_loadu_si512(dst + l) : _mm512_maskz_loadu_epi32(tail, dst + l);
    __m512 s[4];
    for (int c = 0; c < 4; ++c) {
        const float* p = src + size_t(c) * stride + l;
        s[c] = clamp01_ps16(Full ? _mm512_loadu_ps(p) : _mm512_maskz_loadu_ps(tail, p));
    }
    // keep ? d32 : blended, bit by bit.
    const __m512i px = _mm512_ternarylogic_epi32(keep, blend_ps16<K>(op, s, d32), d32, 0xAC);
    if (Full) _mm512_storeu_si512(dst + l, px);
    else _mm512_mask_storeu_epi32(dst + l, tail, px);
}

template <ColorKernel K>
__attribute__((target(SOFTGL_AVX512))) void lanes_avx512(const BlendOp& op, const float* src, size_t stride,
                                                         uint32_t* dst, size_t n) {
    uint32_t keep = 0;
    for (int c = 0; c < 4; ++c)
        if (!op.write[size_t(c)]) keep |= 0xFFu << (8 * c);
    uint32_t colour[4];
    if (n > 0 && uniform_colour(src, stride, n, colour)) {
        if constexpr (K == ColorKernel::Plain) {
            // Every lane gets the same pixel.
            __m512 s[4];
            for (int c = 0; c < 4; ++c) s[c] = clamp01_ps16(_mm512_castsi512_ps(_mm512_set1_epi32(int(colour[c]))));
            const __m512i packed = blend_ps16<K>(op, s, _mm512_setzero_si512());
            const __mmask64 write = ~_mm512_movepi8_mask(_mm512_set1_epi32(int(keep)));   // keep has whole bytes of 0xFF
            size_t l = 0;
            for (; l + 16 <= n; l += 16)
                _mm512_storeu_si512(dst + l, _mm512_mask_mov_epi8(_mm512_loadu_si512(dst + l), write, packed));
            if (l < n) {
                const __mmask16 tail = __mmask16((1u << (n - l)) - 1);
                _mm512_mask_storeu_epi32(dst + l, tail, _mm512_mask_mov_epi8(_mm512_maskz_loadu_epi32(tail, dst + l), write, packed));
            }
            return;
        } else if (has_vbmi()) {
            if (const UniformColorTable* t = uniform_colour_table<K>(op, colour)) return apply_table(*t, op, dst, n);
        }
    }
    const __m512i keep_v = _mm512_set1_epi32(int(keep));
    size_t l = 0;
    for (; l + 16 <= n; l += 16) lanes16<K, true>(op, src, stride, dst, l, 0xFFFF, keep_v);
    if (l < n) lanes16<K, false>(op, src, stride, dst, l, __mmask16((1u << (n - l)) - 1), keep_v);
}

// The fused copy kernel (write_interpolated_color_lanes): the interpolation of 16 lanes
// (interpolate.h, Avx512Interpolator: interpolate_avx512's operations) goes straight into
// lanes16's colour arithmetic, in registers: the varying's four channel arrays are neither
// written nor read back (they were a third of a large copy-shader triangle's time). A whole row
// of four quads is computed in row order (lanes 0..7 row y, 8..15 row y + 1: the same pixels,
// so the same values) and goes straight into the buffer's rows, without the lanes' scatter.
template <ColorKernel K, int V, bool AlphaFixed>
__attribute__((target(SOFTGL_AVX512))) void interpolated_lanes_avx512(const BlendOp& op, const VaryingInterpolation& v,
                                                                     size_t first, const Quad* quads, size_t n,
                                                                     uint32_t* dst, const PixelRows& rows) {
    const Avx512Interpolator<V> interpolator(v);
    float v0[4], d1[4], d2[4];
    for (size_t c = 0; c < 4; ++c) {
        v0[c] = v.values[first + c];
        d1[c] = v.values[v.count + first + c];
        d2[c] = V == 3 ? v.values[2 * v.count + first + c] : 0.0f;
    }
    uint32_t keep = 0;
    for (int c = 0; c < 4; ++c)
        if (!op.write[size_t(c)]) keep |= 0xFFu << (8 * c);
    const __m512i keep_v = _mm512_set1_epi32(int(keep));
    const bool read_dst = K != ColorKernel::Plain || keep;
    const __m512 alpha = clamp01_ps16(_mm512_set1_ps(v0[3]));   // every lane's alpha when AlphaFixed (below)
    auto pixels = [&](__m512 l1, __m512 l2, __m512i d32) __attribute__((target(SOFTGL_AVX512))) {
        __m512 s[4];
        for (int c = 0; c < 4; ++c)
            s[c] = AlphaFixed && c == 3 ? alpha : clamp01_ps16(Avx512Interpolator<V>::value(v0[c], d1[c], d2[c], l1, l2));
        return _mm512_ternarylogic_epi32(keep_v, blend_ps16<K>(op, s, d32), d32, 0xAC);   // as lanes16
    };
    auto group = [&](size_t i, __mmask16 lanes, bool full) __attribute__((target(SOFTGL_AVX512))) {
        const __m512i xy = full ? _mm512_loadu_si512(quads + i) : _mm512_maskz_loadu_epi32(lanes, quads + i);
        __m512 l1, l2;
        interpolator.weights(xy, l1, l2);
        uint32_t* const d = dst + 4 * i;
        const __m512i d32 = !read_dst ? _mm512_setzero_si512() : full ? _mm512_loadu_si512(d) : _mm512_maskz_loadu_epi32(lanes, d);
        const __m512i px = pixels(l1, l2, d32);
        if (full) _mm512_storeu_si512(d, px);
        else _mm512_mask_storeu_epi32(d, lanes, px);
    };
    auto tail = [&](size_t i) { return i + 4 <= n ? __mmask16(0xFFFF) : __mmask16((1u << (4 * (n - i))) - 1); };
    if (!rows.rows) {
        for (size_t i = 0; i < n; i += 4) group(i, tail(i), i + 4 <= n);
        return;
    }
    const __m512i row_x = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7);
    const __m512i row_y = _mm512_setr_epi32(0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1);
    const uint64_t in_row = rows.rows | rows.rows << 1 | rows.rows << 2 | rows.rows << 3;
    // Rows of four come in runs down the same columns (the raster's 8x8 blocks): their columns'
    // part of the planes is computed once per run.
    typename Avx512Interpolator<V>::Columns columns{};
    int64_t columns_x = INT64_MIN;   // none yet
    size_t done = 0;   // the lanes of quads before `done` are written
    for (size_t i = 0; i < n;) {
        if (rows.rows >> i & 1) {
            if (quads[i].x != columns_x) {
                columns = interpolator.columns_at(_mm512_add_epi32(_mm512_set1_epi32(quads[i].x), row_x));
                columns_x = quads[i].x;
            }
            __m512 l1, l2;
            interpolator.weights_at(columns, _mm512_add_epi32(_mm512_set1_epi32(quads[i].y), row_y), l1, l2);
            uint8_t* const row0 = rows.color + 4 * (size_t(quads[i].y) * rows.pitch + size_t(quads[i].x));
            uint8_t* const row1 = row0 + 4 * rows.pitch;
            const __m512i d32 = !read_dst ? _mm512_setzero_si512()
                : _mm512_inserti64x4(_mm512_castsi256_si512(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(row0))),
                                     _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row1)), 1);
            const __m512i px = pixels(l1, l2, d32);
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(row0), _mm512_castsi512_si256(px));
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(row1), _mm512_extracti64x4_epi64(px, 1));
            i += 4;
            continue;
        }
        if (i >= done) {   // quads i .. i + 3 but those of rows of four
            __mmask16 lanes = tail(i);
            for (size_t k = 0; k < 4; ++k)
                if (i + k < n && (in_row >> (i + k) & 1)) lanes = __mmask16(lanes & ~(0xFu << (4 * k)));
            group(i, lanes, lanes == 0xFFFF);
            done = i + 4;
        }
        ++i;
    }
}
template <ColorKernel K>
void lanes_at(SimdLevel level, const BlendOp& op, const float* src, size_t stride, uint32_t* dst, size_t n);

// write_color_quads_at's fallback, and its reference: the quads' covered pixels into lanes, the
// lane kernel, the covered lanes back (tile_pass's write step without blend_in_place).
template <ColorKernel K>
uint64_t quads_in_turn(SimdLevel level, const BlendOp& op, const float* src, size_t stride, const ChunkPixels& buffer,
                       const Quad* quads, const uint16_t* masks, size_t n, uint32_t* lanes) {
    load_chunk_pixels(buffer, quads, masks, n, lanes);
    lanes_at<K>(level, op, src, stride, lanes, 4 * n);
    return store_chunk_pixels(buffer, quads, masks, n, lanes);
}

// Whether quads a and b have different positions (so no pixel in common: quads sit at even x, y).
inline bool apart(const Quad& a, const Quad& b) { return a.x != b.x || a.y != b.y; }

// blend_in_place, AVX2 with FMA: two quads (eight lanes) at a time, read from and written to the buffer's
// rows (lanes 4i, 4i + 1 are row y's two pixels, 4i + 2, 4i + 3 row y + 1's), uncovered lanes
// written back as read. A pair that is not inside the buffer or shares its position (a gathered
// batch may hold one primitive's uncovered pixel of a quad and another's covered one) goes
// through quads_in_turn, as does a last single quad.
template <ColorKernel K>
__attribute__((target("avx2,fma"))) uint64_t quads_avx2(const BlendOp& op, const float* src, size_t stride,
                                                    const ChunkPixels& buffer, const Quad* quads, const uint16_t* masks,
                                                    size_t n, uint64_t& in_place) {
    uint32_t keep = 0;
    for (int c = 0; c < 4; ++c)
        if (!op.write[size_t(c)]) keep |= 0xFFu << (8 * c);
    const size_t row_bytes = 4 * buffer.pitch;
    uint64_t written = 0;
    alignas(32) uint32_t lanes[8];
    size_t i = 0;
    for (; i + 2 <= n; i += 2) {
        const Quad& a = quads[i];
        const Quad& b = quads[i + 1];
        if (!buffer.inside(a) || !buffer.inside(b) || !apart(a, b)) {
            written += quads_in_turn<K>(SimdLevel::AVX2, op, src + 4 * i, stride, buffer, quads + i, masks + 4 * i, 2, lanes);
            continue;
        }
        uint8_t* const pa = buffer.at(a);
        uint8_t* const pb = buffer.at(b);
        const __m128i ra = _mm_castpd_si128(_mm_loadh_pd(_mm_castsi128_pd(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(pa))),
                                                         reinterpret_cast<const double*>(pa + row_bytes)));
        const __m128i rb = _mm_castpd_si128(_mm_loadh_pd(_mm_castsi128_pd(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(pb))),
                                                         reinterpret_cast<const double*>(pb + row_bytes)));
        const __m256i d32 = _mm256_inserti128_si256(_mm256_castsi128_si256(ra), rb, 1);
        const __m256i uncovered = _mm256_cmpeq_epi32(
            _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(masks + 4 * i))), _mm256_setzero_si256());
        const __m256i px = _mm256_blendv_epi8(blend8_fma<K>(op, keep, src + 4 * i, stride, d32), d32, uncovered);
        written += uint64_t(8 - __builtin_popcount(unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(uncovered)))));
        in_place += 2;
        const __m128i wa = _mm256_castsi256_si128(px), wb = _mm256_extracti128_si256(px, 1);
        _mm_storel_epi64(reinterpret_cast<__m128i*>(pa), wa);
        _mm_storeh_pd(reinterpret_cast<double*>(pa + row_bytes), _mm_castsi128_pd(wa));
        _mm_storel_epi64(reinterpret_cast<__m128i*>(pb), wb);
        _mm_storeh_pd(reinterpret_cast<double*>(pb + row_bytes), _mm_castsi128_pd(wb));
    }
    if (i < n) written += quads_in_turn<K>(SimdLevel::AVX2, op, src + 4 * i, stride, buffer, quads + i, masks + 4 * i, n - i, lanes);
    return written;
}

// blend_in_place, AVX-512: four quads (sixteen lanes) at a time, as quads_avx2 does two. A chunk
// of one colour in every lane goes through quads_in_turn, whose lane kernel blends it by table.
template <ColorKernel K>
__attribute__((target(SOFTGL_AVX512))) uint64_t quads_avx512(const BlendOp& op, const float* src, size_t stride,
                                                             const ChunkPixels& buffer, const Quad* quads,
                                                             const uint16_t* masks, size_t n, uint32_t* scratch,
                                                             uint64_t& in_place) {
    uint32_t colour[4];
    if (K != ColorKernel::Plain && has_vbmi() && n > 0 && uniform_colour(src, stride, 4 * n, colour))
        return quads_in_turn<K>(SimdLevel::AVX512, op, src, stride, buffer, quads, masks, n, scratch);
    uint32_t keep = 0;
    for (int c = 0; c < 4; ++c)
        if (!op.write[size_t(c)]) keep |= 0xFFu << (8 * c);
    const __m512i keep_v = _mm512_set1_epi32(int(keep));
    const size_t row_bytes = 4 * buffer.pitch;
    uint64_t written = 0;
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const Quad* const q = quads + i;
        const bool whole = buffer.row_of_four(q) ||
            (buffer.inside(q[0]) && buffer.inside(q[1]) && buffer.inside(q[2]) && buffer.inside(q[3]) && apart(q[0], q[1]) &&
             apart(q[0], q[2]) && apart(q[0], q[3]) && apart(q[1], q[2]) && apart(q[1], q[3]) && apart(q[2], q[3]));
        if (!whole) {
            written += quads_in_turn<K>(SimdLevel::AVX512, op, src + 4 * i, stride, buffer, q, masks + 4 * i, 4, scratch);
            continue;
        }
        uint8_t* p[4];
        __m128i r[4];
        for (int k = 0; k < 4; ++k) {
            p[k] = buffer.at(q[k]);
            r[k] = _mm_castpd_si128(_mm_loadh_pd(_mm_castsi128_pd(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p[k]))),
                                                 reinterpret_cast<const double*>(p[k] + row_bytes)));
        }
        const __m512i d32 = _mm512_inserti64x4(
            _mm512_castsi256_si512(_mm256_inserti128_si256(_mm256_castsi128_si256(r[0]), r[1], 1)),
            _mm256_inserti128_si256(_mm256_castsi128_si256(r[2]), r[3], 1), 1);
        const __mmask16 covered = _mm256_test_epi16_mask(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(masks + 4 * i)),
                                                         _mm256_set1_epi16(-1));
        __m512 s[4];
        for (int c = 0; c < 4; ++c) s[c] = clamp01_ps16(_mm512_loadu_ps(src + size_t(c) * stride + 4 * i));
        // keep ? d32 : blended (as lanes16), and d32 in the uncovered lanes.
        const __m512i px = _mm512_mask_mov_epi32(d32, covered, _mm512_ternarylogic_epi32(keep_v, blend_ps16<K>(op, s, d32), d32, 0xAC));
        written += uint64_t(__builtin_popcount(unsigned(covered)));
        in_place += 4;
        for (int k = 0; k < 4; ++k) {
            const __m128i w = _mm512_extracti32x4_epi32(px, k);
            _mm_storel_epi64(reinterpret_cast<__m128i*>(p[k]), w);
            _mm_storeh_pd(reinterpret_cast<double*>(p[k] + row_bytes), _mm_castsi128_pd(w));
        }
    }
    if (i < n) written += quads_in_turn<K>(SimdLevel::AVX512, op, src + 4 * i, stride, buffer, quads + i, masks + 4 * i, n - i, scratch);
    return written;
}

#pragma GCC diagnostic pop
#undef SOFTGL_AVX512

template <ColorKernel K>
void lanes_at(SimdLevel level, const BlendOp& op, const float* src, size_t stride, uint32_t* dst, size_t n) {
    switch (level) {
        case SimdLevel::Scalar: return lanes_scalar<K>(op, src, stride, dst, 0, n);
        case SimdLevel::SSE2: return lanes<K>(op, src, stride, dst, n);
        case SimdLevel::AVX2:
#if defined(SOFTGL_HAVE_AVX2_KERNELS)
            return lanes_avx2<K>(op, src, stride, dst, n);
#else
            return lanes<K>(op, src, stride, dst, n);
#endif
        case SimdLevel::AVX512:
#if defined(SOFTGL_HAVE_AVX2_KERNELS)
            return lanes_avx512<K>(op, src, stride, dst, n);
#else
            return lanes<K>(op, src, stride, dst, n);
#endif
    }
}

// A row of four quads' pixels in the buffer <-> their lanes (quad order), for the levels that
// go through lanes.
template <bool ToLanes>
void move_row_of_four(const PixelRows& rows, const Quad& q, uint32_t* lanes) {
    uint8_t* const row0 = rows.color + 4 * (size_t(q.y) * rows.pitch + size_t(q.x));
    for (size_t k = 0; k < 4; ++k)
        for (size_t y = 0; y < 2; ++y) {
            uint8_t* const px = row0 + 4 * (y * rows.pitch + 2 * k);
            if (ToLanes) std::memcpy(lanes + 4 * k + 2 * y, px, 8);
            else std::memcpy(px, lanes + 4 * k + 2 * y, 8);
        }
}

#if defined(SOFTGL_HAVE_AVX2_KERNELS) && defined(SOFTGL_HAVE_AVX512_INTERPOLATOR)
// Alpha equal at every vertex (d_1 = d_2 = 0: opaque or evenly translucent geometry) is
// (v_0 + l_1 * 0) + l_2 * 0 at each lane: with finite weights the products are zeros, which leave
// v_0 as it is or turn a zero v_0 into a zero (clamped to the same +0), so alpha is clamp01(v_0)
// in every lane, and the kernel skips its interpolation.
template <ColorKernel K, int V>
void interpolated_lanes_avx512(const BlendOp& op, const VaryingInterpolation& v, size_t first, const Quad* quads,
                               size_t n, uint32_t* dst, const PixelRows& rows) {
    const bool alpha_fixed = weights_always_finite(v, ConstantQ(v.inv_w)) && v.values[v.count + first + 3] == 0 &&
                             (V == 2 || v.values[2 * v.count + first + 3] == 0);
    if (alpha_fixed) interpolated_lanes_avx512<K, V, true>(op, v, first, quads, n, dst, rows);
    else interpolated_lanes_avx512<K, V, false>(op, v, first, quads, n, dst, rows);
}
#endif

template <ColorKernel K>
void interpolated_lanes_at(SimdLevel level, const BlendOp& op, const VaryingInterpolation& v, size_t first,
                           const Quad* quads, size_t n, uint32_t* dst, const PixelRows& rows) {
#if defined(SOFTGL_HAVE_AVX2_KERNELS) && defined(SOFTGL_HAVE_AVX512_INTERPOLATOR)
    if (level == SimdLevel::AVX512)
        return v.vertices == 3 ? interpolated_lanes_avx512<K, 3>(op, v, first, quads, n, dst, rows)
                               : interpolated_lanes_avx512<K, 2>(op, v, first, quads, n, dst, rows);
#endif
    // The two stages in turn, a chunk of quads at a time, on the varying's four words alone; rows
    // of four go through lanes of their own (one chunk then: n <= 64).
    float values[3 * 4];
    const int words[4] = {0, 1, 2, 3};
    for (int k = 0; k < v.vertices; ++k)
        for (size_t c = 0; c < 4; ++c) values[4 * k + c] = v.values[size_t(k) * v.count + first + c];
    VaryingInterpolation four = v;
    four.count = 4, four.words = words, four.values = values;
    constexpr size_t kQuads = 64;
    uint32_t lanes[4 * 4 * kQuads], pixels[4 * kQuads];
    for (size_t i = 0; i < n; i += kQuads) {
        const size_t m = n - i < kQuads ? n - i : kQuads;
        std::memcpy(pixels, dst + 4 * i, 16 * m);
        for (size_t k = 0; k < m; ++k)
            if (rows.rows >> (i + k) & 1) move_row_of_four<true>(rows, quads[i + k], pixels + 4 * k);
        interpolate_varyings_at(level, four, quads + i, m, lanes, 4 * m);
        lanes_at<K>(level, op, reinterpret_cast<const float*>(lanes), 4 * m, pixels, 4 * m);
        for (size_t k = 0; k < m; ++k)
            if (rows.rows >> (i + k) & 1) move_row_of_four<false>(rows, quads[i + k], pixels + 4 * k);
        // Quads of a row keep their lanes in dst.
        for (size_t k = 0; k < m; ++k) {
            bool in_row = false;
            for (size_t r = 0; r < 4 && r <= i + k; ++r) in_row |= (rows.rows >> (i + k - r) & 1) != 0;
            if (!in_row) std::memcpy(dst + 4 * (i + k), pixels + 4 * k, 16);
        }
    }
}

// apply_blend_table_at's other levels: a byte lookup per channel.
inline uint32_t look_up_pixel(const BlendTable& t, uint32_t px) {
    return uint32_t(t.bytes[0][px & 0xFF]) | uint32_t(t.bytes[1][px >> 8 & 0xFF]) << 8 |
           uint32_t(t.bytes[2][px >> 16 & 0xFF]) << 16 | uint32_t(t.bytes[3][px >> 24]) << 24;
}
void apply_blend_table_scalar(const BlendTable& t, const Quad* quads, size_t n, uint32_t* dst, const PixelRows& rows) {
    const uint64_t in_row = rows.rows | rows.rows << 1 | rows.rows << 2 | rows.rows << 3;
    for (size_t i = 0; i < n; ++i)
        if (!(in_row >> i & 1))
            for (size_t j = 0; j < 4; ++j) dst[4 * i + j] = look_up_pixel(t, dst[4 * i + j]);
    for (uint64_t r = rows.rows; r; r &= r - 1) {
        const Quad& quad = quads[__builtin_ctzll(r)];
        uint8_t* const row0 = rows.color + 4 * (size_t(quad.y) * rows.pitch + size_t(quad.x));
        prefetch_block_below(row0, rows.pitch);
        for (size_t y = 0; y < 2; ++y)
            for (size_t x = 0; x < 8; ++x) {
                uint8_t* const p = row0 + 4 * (y * rows.pitch + x);
                uint32_t px;
                std::memcpy(&px, p, 4);
                px = look_up_pixel(t, px);
                std::memcpy(p, &px, 4);
            }
    }
}
void apply_blend_table_to_rect_scalar(const BlendTable& t, const PixelRect& r) {
    for (int32_t y = r.y0; y < r.y1; ++y) {
        uint32_t* const row = reinterpret_cast<uint32_t*>(r.color) + size_t(y) * r.pitch;
        for (int32_t x = r.x0; x < r.x1; ++x) row[x] = look_up_pixel(t, row[x]);
    }
}

}  // namespace

void write_color_lanes_at(SimdLevel level, ColorKernel kernel, const BlendOp& op, const float* src, size_t stride,
                          uint32_t* dst, size_t n) {
    switch (kernel) {
        case ColorKernel::Plain: return lanes_at<ColorKernel::Plain>(level, op, src, stride, dst, n);
        case ColorKernel::AlphaOver: return lanes_at<ColorKernel::AlphaOver>(level, op, src, stride, dst, n);
        case ColorKernel::Additive: return lanes_at<ColorKernel::Additive>(level, op, src, stride, dst, n);
        case ColorKernel::Generic: return lanes_scalar<ColorKernel::Generic>(op, src, stride, dst, 0, n);
    }
}

void write_color_lanes(ColorKernel kernel, const BlendOp& op, const float* src, size_t stride, uint32_t* dst,
                       size_t n) {
    write_color_lanes_at(best_simd_level(), kernel, op, src, stride, dst, n);
}

namespace {
template <ColorKernel K>
uint64_t quads_at(SimdLevel level, bool in_place, const BlendOp& op, const float* src, size_t stride,
                  const ChunkPixels& buffer, const Quad* quads, const uint16_t* masks, size_t n, uint32_t* scratch,
                  uint64_t& quads_in_place) {
#if defined(SOFTGL_HAVE_AVX2_KERNELS)
    if (in_place && level == SimdLevel::AVX2 && has_fma()) return quads_avx2<K>(op, src, stride, buffer, quads, masks, n, quads_in_place);
    if (in_place && level == SimdLevel::AVX512)
        return quads_avx512<K>(op, src, stride, buffer, quads, masks, n, scratch, quads_in_place);
#else
    (void)in_place, (void)quads_in_place;
#endif
    return quads_in_turn<K>(level, op, src, stride, buffer, quads, masks, n, scratch);
}
}  // namespace

uint64_t write_color_quads_at(SimdLevel level, bool in_place, ColorKernel kernel, const BlendOp& op, const float* src,
                              size_t stride, const ChunkPixels& buffer, const Quad* quads, const uint16_t* masks,
                              size_t n, uint32_t* scratch, uint64_t& quads_in_place) {
    switch (kernel) {
        case ColorKernel::Plain: return quads_at<ColorKernel::Plain>(level, in_place, op, src, stride, buffer, quads, masks, n, scratch, quads_in_place);
        case ColorKernel::AlphaOver: return quads_at<ColorKernel::AlphaOver>(level, in_place, op, src, stride, buffer, quads, masks, n, scratch, quads_in_place);
        case ColorKernel::Additive: return quads_at<ColorKernel::Additive>(level, in_place, op, src, stride, buffer, quads, masks, n, scratch, quads_in_place);
        case ColorKernel::Generic: break;   // not offered (header)
    }
    return 0;
}

void write_interpolated_color_lanes_at(SimdLevel level, ColorKernel kernel, const BlendOp& op,
                                       const VaryingInterpolation& v, size_t first, const Quad* quads, size_t n,
                                       uint32_t* dst, const PixelRows& rows) {
    switch (kernel) {
        case ColorKernel::Plain: return interpolated_lanes_at<ColorKernel::Plain>(level, op, v, first, quads, n, dst, rows);
        case ColorKernel::AlphaOver: return interpolated_lanes_at<ColorKernel::AlphaOver>(level, op, v, first, quads, n, dst, rows);
        case ColorKernel::Additive: return interpolated_lanes_at<ColorKernel::Additive>(level, op, v, first, quads, n, dst, rows);
        case ColorKernel::Generic: break;   // not offered (header)
    }
}

void write_interpolated_color_lanes(ColorKernel kernel, const BlendOp& op, const VaryingInterpolation& v, size_t first,
                                    const Quad* quads, size_t n, uint32_t* dst, const PixelRows& rows) {
    write_interpolated_color_lanes_at(best_simd_level(), kernel, op, v, first, quads, n, dst, rows);
}

bool blend_is_per_channel(const BlendOp& op) {
    if (!op.has_alpha) return true;   // d[3] reads as 1
    for (GLenum f : {op.src_rgb, op.dst_rgb})
        if (f == gl::DST_ALPHA || f == gl::ONE_MINUS_DST_ALPHA || f == gl::SRC_ALPHA_SATURATE) return false;
    return true;
}

void build_blend_table(ColorKernel kernel, const BlendOp& op, const float colour[4], BlendTable& table) {
    float src[4 * 256];
    uint32_t px[256];
    for (size_t c = 0; c < 4; ++c) std::fill_n(src + 256 * c, 256, colour[c]);
    for (uint32_t d = 0; d < 256; ++d) px[d] = d * 0x01010101u;
    // The lane kernels give the scalar level's bytes at every level (tests/pipeline/
    // test_fragment_ops.py); AVX2 at most, since the AVX-512 level would look this uniform colour
    // up in the tables being built.
    write_color_lanes_at(std::min(best_simd_level(), SimdLevel::AVX2), kernel, op, src, 256, px, 256);
    for (size_t c = 0; c < 4; ++c)
        for (size_t d = 0; d < 256; ++d) table.bytes[c][d] = uint8_t(px[d] >> (8 * c));
    table.channels = 0;
    for (int c = 0; c < 4; ++c) table.channels |= unsigned(op.write[size_t(c)]) << c;
}

void apply_blend_table_at(SimdLevel level, const BlendTable& table, const Quad* quads, size_t n, uint32_t* dst,
                          const PixelRows& rows) {
    if (level == SimdLevel::AVX512 && has_vbmi()) return apply_blend_table_avx512(table, quads, n, dst, rows);
    apply_blend_table_scalar(table, quads, n, dst, rows);
}

void apply_blend_table(const BlendTable& table, const Quad* quads, size_t n, uint32_t* dst, const PixelRows& rows) {
    apply_blend_table_at(best_simd_level(), table, quads, n, dst, rows);
}

void apply_blend_table_to_rect_at(SimdLevel level, const BlendTable& table, const PixelRect& rect) {
    if (level == SimdLevel::AVX512 && has_vbmi()) return apply_blend_table_to_rect_avx512(table, rect);
    apply_blend_table_to_rect_scalar(table, rect);
}

void apply_blend_table_to_rect(const BlendTable& table, const PixelRect& rect) {
    apply_blend_table_to_rect_at(best_simd_level(), table, rect);
}

}  // namespace softgl
