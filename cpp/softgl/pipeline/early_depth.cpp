#include "softgl/pipeline/early_depth.h"

#include "softgl/pipeline/depth_stencil.h"
#include "softgl/surface/texture.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SOFTGL_HAVE_AVX2_EARLY_DEPTH 1
#endif

namespace softgl {

namespace {

// The reference: pixel by pixel, through the definitions (depth_at, depth_word, compare).
size_t early_depth_scalar(const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    const PrimitiveSetup& p = *t.prim;
    size_t killed = 0;
    for (size_t i = 0; i < n; ++i) {
        for (int j = 0; j < 4; ++j) {
            uint16_t& out = survived[4 * i + size_t(j)];
            out = 0;
            if (!(quad_pixel_mask(quads[i], j) & 1u)) continue;
            const int32_t x = quads[i].x + (j & 1), y = quads[i].y + (j >> 1);
            const uint32_t z = depth_word(Encoding::Depth24, p.depth_at(int64_t(x) * kSubPixel + t.sample_x,
                                                                        int64_t(y) * kSubPixel + t.sample_y));
            uint32_t* stored = &t.depth[size_t(y) * t.pitch + size_t(x)];
            if (compare(t.func, z, *stored)) {
                if (t.write) *stored = z;
                out = 1;
            } else {
                ++killed;
            }
        }
    }
    return killed;
}

#if defined(SOFTGL_HAVE_AVX2_EARLY_DEPTH)
// A quad per step: the four depths as depth_at computes them (plane at the sample, + offset),
// then depth_word's clamp (NaN -> 0; depth_at's own clamp changes nothing after it) and
// floor(d * (2^24 - 1) + 0.5) as truncation (the same for these non-negative values). The
// comparison is compare()'s, as the set of orderings (less, equal, greater) the function accepts.
// Pixels outside the coverage are neither read nor written (they may lie outside the buffer).
__attribute__((target("avx2"))) size_t early_depth_avx2(const EarlyDepth& t, const Quad* quads, size_t n,
                                                       uint16_t* survived) {
    const PrimitiveSetup& p = *t.prim;
    const __m256d a = _mm256_set1_pd(p.depth.a), b = _mm256_set1_pd(p.depth.b), c = _mm256_set1_pd(p.depth.c);
    const __m256d offset = _mm256_set1_pd(p.depth_offset), zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
    const __m256d scale = _mm256_set1_pd(16777215.0), half = _mm256_set1_pd(0.5);
    const __m128i less = _mm_set1_epi32(compare(t.func, 0, 1) ? -1 : 0);
    const __m128i equal = _mm_set1_epi32(compare(t.func, 1, 1) ? -1 : 0);
    const __m128i greater = _mm_set1_epi32(compare(t.func, 1, 0) ? -1 : 0);
    const __m128i sign = _mm_set1_epi32(int32_t(0x80000000u));
    size_t killed = 0;
    for (size_t i = 0; i < n; ++i) {
        const Quad& quad = quads[i];
        const int64_t X = int64_t(quad.x) * kSubPixel + t.sample_x - p.origin_x;
        const int64_t Y = int64_t(quad.y) * kSubPixel + t.sample_y - p.origin_y;
        const double fx0 = double(X) * (1.0 / kSubPixel), fx1 = double(X + kSubPixel) * (1.0 / kSubPixel);
        const double fy0 = double(Y) * (1.0 / kSubPixel), fy1 = double(Y + kSubPixel) * (1.0 / kSubPixel);
        const __m256d fx = _mm256_setr_pd(fx0, fx1, fx0, fx1), fy = _mm256_setr_pd(fy0, fy0, fy1, fy1);
        const __m256d z = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(c, _mm256_mul_pd(a, fx)), _mm256_mul_pd(b, fy)), offset);
        const __m256d d = _mm256_and_pd(_mm256_blendv_pd(one, z, _mm256_cmp_pd(z, one, _CMP_LT_OQ)),
                                        _mm256_cmp_pd(z, zero, _CMP_GT_OQ));
        const __m128i word = _mm256_cvttpd_epi32(_mm256_add_pd(_mm256_mul_pd(d, scale), half));
        // Covered pixels (sample 0 of each 16-bit pixel mask) as lane masks.
        const uint64_t cov = quad.coverage;
        const __m128i covered = _mm_setr_epi32(cov & 1 ? -1 : 0, (cov >> 16) & 1 ? -1 : 0, (cov >> 32) & 1 ? -1 : 0,
                                               (cov >> 48) & 1 ? -1 : 0);
        const int tested = _mm_movemask_ps(_mm_castsi128_ps(covered));
        uint32_t* row0 = &t.depth[size_t(quad.y) * t.pitch + size_t(quad.x)];
        const bool upper = (cov >> 32) & 0x10001u;
        uint32_t* row1 = upper ? row0 + t.pitch : row0;   // a pointer into the buffer either way
        // A fully covered quad (most quads of large primitives) is four pixels of this tile:
        // plain 8-byte row loads and stores, which are much cheaper than masked ones. Otherwise
        // masked accesses, because uncovered pixels may lie outside the buffer or the tile.
        const bool full = tested == 0xF;
        __m128i stored;
        if (full) {
            stored = _mm_unpacklo_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(row0)),
                                        _mm_loadl_epi64(reinterpret_cast<const __m128i*>(row1)));
        } else {
            const __m128i m0 = _mm_unpacklo_epi64(covered, _mm_setzero_si128());   // lanes 0, 1 -> row 0
            const __m128i m1 = _mm_unpackhi_epi64(covered, _mm_setzero_si128());   // lanes 2, 3 -> row 1
            stored = _mm_unpacklo_epi64(_mm_maskload_epi32(reinterpret_cast<const int*>(row0), m0),
                                        _mm_maskload_epi32(reinterpret_cast<const int*>(row1), m1));
        }
        const __m128i zs = _mm_xor_si128(word, sign), ss = _mm_xor_si128(stored, sign);   // unsigned order
        const __m128i lt = _mm_cmplt_epi32(zs, ss), eq = _mm_cmpeq_epi32(zs, ss), gt = _mm_cmpgt_epi32(zs, ss);
        const __m128i pass = _mm_and_si128(covered, _mm_or_si128(_mm_or_si128(_mm_and_si128(lt, less), _mm_and_si128(eq, equal)),
                                                                 _mm_and_si128(gt, greater)));
        const int passed = _mm_movemask_ps(_mm_castsi128_ps(pass));
        if (t.write && passed) {
            if (full) {   // failed pixels get their stored word back
                const __m128i out = _mm_blendv_epi8(stored, word, pass);
                _mm_storel_epi64(reinterpret_cast<__m128i*>(row0), out);
                _mm_storel_epi64(reinterpret_cast<__m128i*>(row1), _mm_unpackhi_epi64(out, out));
            } else {
                _mm_maskstore_epi32(reinterpret_cast<int*>(row0), _mm_unpacklo_epi64(pass, _mm_setzero_si128()), word);
                _mm_maskstore_epi32(reinterpret_cast<int*>(row1), _mm_unpackhi_epi64(pass, _mm_setzero_si128()),
                                    _mm_unpackhi_epi64(word, word));
            }
        }
        for (int j = 0; j < 4; ++j) survived[4 * i + size_t(j)] = uint16_t((passed >> j) & 1);
        killed += size_t(__builtin_popcount(unsigned(tested & ~passed)));
    }
    return killed;
}

// Two quads per step (lanes 0..3 quads[i], 4..7 quads[i + 1]; a quad without a partner twice, its
// copy neither stored nor counted), otherwise early_depth_avx2's arithmetic. AVX-512 masked loads
// and stores suppress faults and are cheap, so every quad row goes through a coverage mask, and the
// unsigned comparison gives bit masks directly.
__attribute__((target("avx512f,avx512bw,avx512dq,avx512vl"))) size_t early_depth_avx512(
    const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    const PrimitiveSetup& p = *t.prim;
    const __m512d a = _mm512_set1_pd(p.depth.a), b = _mm512_set1_pd(p.depth.b), c = _mm512_set1_pd(p.depth.c);
    const __m512d offset = _mm512_set1_pd(p.depth_offset), zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
    const __m512d scale = _mm512_set1_pd(16777215.0), half = _mm512_set1_pd(0.5), unit = _mm512_set1_pd(1.0 / kSubPixel);
    const unsigned less = compare(t.func, 0, 1) ? 0xFF : 0, equal = compare(t.func, 1, 1) ? 0xFF : 0;
    const unsigned greater = compare(t.func, 1, 0) ? 0xFF : 0;
    auto covered = [](uint64_t cov) {   // sample 0 of each 16-bit pixel mask -> bits 0..3
        return unsigned((cov & 1) | ((cov >> 15) & 2) | ((cov >> 30) & 4) | ((cov >> 45) & 8));
    };
    size_t killed = 0;
    bool pair = false;
    for (size_t i = 0; i < n; i += pair ? 2 : 1) {
        // Both quads are read before either is written: a quad repeated right after itself (never
        // within one primitive, whose quads are distinct and 2-aligned) is tested alone.
        pair = i + 1 < n && (quads[i + 1].x != quads[i].x || quads[i + 1].y != quads[i].y);
        const Quad& q0 = quads[i];
        const Quad& q1 = quads[pair ? i + 1 : i];
        const int64_t X0 = int64_t(q0.x) * kSubPixel + t.sample_x - p.origin_x, X1 = int64_t(q1.x) * kSubPixel + t.sample_x - p.origin_x;
        const int64_t Y0 = int64_t(q0.y) * kSubPixel + t.sample_y - p.origin_y, Y1 = int64_t(q1.y) * kSubPixel + t.sample_y - p.origin_y;
        const int64_t S = kSubPixel;
        const __m512d fx = _mm512_mul_pd(_mm512_cvtepi64_pd(_mm512_setr_epi64(X0, X0 + S, X0, X0 + S, X1, X1 + S, X1, X1 + S)), unit);
        const __m512d fy = _mm512_mul_pd(_mm512_cvtepi64_pd(_mm512_setr_epi64(Y0, Y0, Y0 + S, Y0 + S, Y1, Y1, Y1 + S, Y1 + S)), unit);
        const __m512d z = _mm512_add_pd(_mm512_add_pd(_mm512_add_pd(c, _mm512_mul_pd(a, fx)), _mm512_mul_pd(b, fy)), offset);
        // depth_word's clamp: z < 1 ? z : 1, then NaN and z <= 0 -> 0.
        const __m512d d = _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(z, zero, _CMP_GT_OQ),
                                              _mm512_mask_mov_pd(one, _mm512_cmp_pd_mask(z, one, _CMP_LT_OQ), z));
        const __m256i word = _mm512_maskz_cvttpd_epi32(0xFF, _mm512_add_pd(_mm512_mul_pd(d, scale), half));
        const unsigned cov = covered(q0.coverage) | (pair ? covered(q1.coverage) << 4 : 0);
        // Rows of quad h: pixels (lanes 4h, 4h+1) and (4h+2, 4h+3); uncovered pixels are not touched.
        uint32_t* rows[4];
        for (int h = 0; h < 2; ++h) {
            const Quad& q = h ? q1 : q0;
            rows[2 * h] = &t.depth[size_t(q.y) * t.pitch + size_t(q.x)];
            rows[2 * h + 1] = (cov >> (4 * h + 2)) & 3 ? rows[2 * h] + t.pitch : rows[2 * h];   // in the buffer either way
        }
        auto row_mask = [](unsigned m, int r) { return __mmask8((m >> (2 * r)) & 3); };
        const __m128i r0 = _mm_maskz_loadu_epi32(row_mask(cov, 0), rows[0]), r1 = _mm_maskz_loadu_epi32(row_mask(cov, 1), rows[1]);
        const __m128i r2 = _mm_maskz_loadu_epi32(row_mask(cov, 2), rows[2]), r3 = _mm_maskz_loadu_epi32(row_mask(cov, 3), rows[3]);
        const __m256i stored = _mm256_setr_m128i(_mm_unpacklo_epi64(r0, r1), _mm_unpacklo_epi64(r2, r3));
        const unsigned lt = _mm256_cmplt_epu32_mask(word, stored), eq = _mm256_cmpeq_epu32_mask(word, stored);
        const unsigned passed = cov & ((lt & less) | (eq & equal) | (~(lt | eq) & greater));
        if (t.write && passed) {
            const __m128i w0 = _mm256_castsi256_si128(word), w1 = _mm256_extracti128_si256(word, 1);
            _mm_mask_storeu_epi32(rows[0], row_mask(passed, 0), w0);
            _mm_mask_storeu_epi32(rows[1], row_mask(passed, 1), _mm_unpackhi_epi64(w0, w0));
            _mm_mask_storeu_epi32(rows[2], row_mask(passed, 2), w1);
            _mm_mask_storeu_epi32(rows[3], row_mask(passed, 3), _mm_unpackhi_epi64(w1, w1));
        }
        const __m128i out = _mm_maskz_mov_epi16(__mmask8(passed), _mm_set1_epi16(1));
        if (pair) _mm_storeu_si128(reinterpret_cast<__m128i*>(survived + 4 * i), out);
        else _mm_storel_epi64(reinterpret_cast<__m128i*>(survived + 4 * i), out);
        killed += size_t(__builtin_popcount(cov & ~passed));
    }
    return killed;
}
#endif

}  // namespace

size_t early_depth_test_at(SimdLevel level, const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
#if defined(SOFTGL_HAVE_AVX2_EARLY_DEPTH)
    if (level == SimdLevel::AVX512) return early_depth_avx512(t, quads, n, survived);
    if (level == SimdLevel::AVX2) return early_depth_avx2(t, quads, n, survived);
#endif
    (void)level;
    return early_depth_scalar(t, quads, n, survived);
}

}  // namespace softgl
