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
#endif

}  // namespace

size_t early_depth_test_at(SimdLevel level, const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
#if defined(SOFTGL_HAVE_AVX2_EARLY_DEPTH)
    if (level == SimdLevel::AVX2 || level == SimdLevel::AVX512) return early_depth_avx2(t, quads, n, survived);
#endif
    (void)level;
    return early_depth_scalar(t, quads, n, survived);
}

}  // namespace softgl
