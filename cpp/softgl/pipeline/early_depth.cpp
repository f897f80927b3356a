#include "softgl/pipeline/early_depth.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "softgl/pipeline/depth_stencil.h"
#include "softgl/surface/texture.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SOFTGL_HAVE_AVX2_EARLY_DEPTH 1
#endif

namespace softgl {

namespace {

// The reference: sample by sample, through the definitions (depth_at, depth_word, compare).
size_t early_depth_scalar(const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    const PrimitiveSetup& p = *t.prim;
    const SamplePattern& pattern = *t.pattern;
    const size_t S = size_t(pattern.count);
    size_t killed = 0;
    for (size_t i = 0; i < n; ++i) {
        for (int j = 0; j < 4; ++j) {
            const uint32_t covered = quad_pixel_mask(quads[i], j);
            uint32_t passed = 0;
            const int32_t x = quads[i].x + (j & 1), y = quads[i].y + (j >> 1);
            for (size_t s = 0; s < S; ++s) {
                if (!(covered & (1u << s))) continue;
                const uint32_t z = depth_word(Encoding::Depth24, p.depth_at(int64_t(x) * kSubPixel + pattern.x[s],
                                                                            int64_t(y) * kSubPixel + pattern.y[s]));
                uint32_t* stored = &t.depth[(size_t(y) * t.pitch + size_t(x)) * S + s];
                if (compare(t.func, z, *stored)) {
                    if (t.write) *stored = z;
                    passed |= 1u << s;
                } else {
                    ++killed;
                }
            }
            survived[4 * i + size_t(j)] = uint16_t(passed);
        }
    }
    return killed;
}

#if defined(SOFTGL_HAVE_AVX2_EARLY_DEPTH)
// Bits 0-3 of b moved to bits 0, 16, 32, 48: the partial products land in disjoint bit ranges
// [15j, 15j + 4), so nothing carries.
inline uint64_t spread_pixel_bits(uint64_t b) { return (b * 0x0000200040008001ull) & 0x0001000100010001ull; }

// Four depths at a time as depth_at computes them (plane at the sample, + offset), then
// depth_word's clamp (NaN -> 0; depth_at's own clamp changes nothing after it) and
// floor(d * (2^24 - 1) + 0.5) as truncation (the same for these non-negative values); the
// comparison is compare()'s, as the set of orderings (less, equal, greater) the function accepts.
struct DepthWordsAvx2 {
    __m256d a, b, c, offset, zero, one, scale, half;
    __m128i less, equal, greater, sign;

    __attribute__((target("avx2"))) explicit DepthWordsAvx2(const EarlyDepth& t)
        : a(_mm256_set1_pd(t.prim->depth.a)), b(_mm256_set1_pd(t.prim->depth.b)), c(_mm256_set1_pd(t.prim->depth.c)),
          offset(_mm256_set1_pd(t.prim->depth_offset)), zero(_mm256_setzero_pd()), one(_mm256_set1_pd(1.0)),
          scale(_mm256_set1_pd(16777215.0)), half(_mm256_set1_pd(0.5)),
          less(_mm_set1_epi32(compare(t.func, 0, 1) ? -1 : 0)), equal(_mm_set1_epi32(compare(t.func, 1, 1) ? -1 : 0)),
          greater(_mm_set1_epi32(compare(t.func, 1, 0) ? -1 : 0)), sign(_mm_set1_epi32(int32_t(0x80000000u))) {}
    // The words at plane offsets (fx, fy).
    __attribute__((target("avx2"))) __m128i words(__m256d fx, __m256d fy) const { return words_by(fx, _mm256_mul_pd(b, fy)); }
    // The same with the product b * fy given (the quads of a row share it).
    __attribute__((target("avx2"))) __m128i words_by(__m256d fx, __m256d b_fy) const {
        const __m256d z = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(c, _mm256_mul_pd(a, fx)), b_fy), offset);
        const __m256d d = _mm256_and_pd(_mm256_blendv_pd(one, z, _mm256_cmp_pd(z, one, _CMP_LT_OQ)),
                                        _mm256_cmp_pd(z, zero, _CMP_GT_OQ));
        return _mm256_cvttpd_epi32(_mm256_add_pd(_mm256_mul_pd(d, scale), half));
    }
    // The covered lanes whose word passes against the stored one (unsigned order).
    __attribute__((target("avx2"))) __m128i pass(__m128i word, __m128i stored, __m128i covered) const {
        const __m128i zs = _mm_xor_si128(word, sign), ss = _mm_xor_si128(stored, sign);
        const __m128i lt = _mm_cmplt_epi32(zs, ss), eq = _mm_cmpeq_epi32(zs, ss), gt = _mm_cmpgt_epi32(zs, ss);
        return _mm_and_si128(covered, _mm_or_si128(_mm_or_si128(_mm_and_si128(lt, less), _mm_and_si128(eq, equal)),
                                                   _mm_and_si128(gt, greater)));
    }
};

// Whether quads[0, 4) are side by side (x stepping by 2, the same y) with all four pixels covered
// (sample 0 of each), as the rasterizer emits the quad-rows of a covered 8x8 block: two vector
// compares of the four quads (x, y, coverage & sample 0 bits) with that.
static_assert(sizeof(Quad) == 16 && offsetof(Quad, x) == 0 && offsetof(Quad, y) == 4 && offsetof(Quad, coverage) == 8);
__attribute__((target("avx2"))) inline bool full_run_avx2(const Quad* quads) {
    constexpr int32_t kPixel0 = 0x00010001;   // sample 0 of two pixels (a 32-bit half of the coverage)
    const __m256i keep = _mm256_setr_epi32(-1, -1, kPixel0, kPixel0, -1, -1, kPixel0, kPixel0);
    int64_t first_xy;
    std::memcpy(&first_xy, quads, 8);
    const __m256i first = _mm256_and_si256(_mm256_set1_epi64x(first_xy), _mm256_setr_epi32(-1, -1, 0, 0, -1, -1, 0, 0));
    const __m256i lo = _mm256_add_epi32(first, _mm256_setr_epi32(0, 0, kPixel0, kPixel0, 2, 0, kPixel0, kPixel0));
    const __m256i hi = _mm256_add_epi32(first, _mm256_setr_epi32(4, 0, kPixel0, kPixel0, 6, 0, kPixel0, kPixel0));
    const __m256i q01 = _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(quads)), keep);
    const __m256i q23 = _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(quads + 2)), keep);
    return _mm256_movemask_epi8(_mm256_and_si256(_mm256_cmpeq_epi32(q01, lo), _mm256_cmpeq_epi32(q23, hi))) == -1;
}

// The 8 words of a pixel row of a full run: depth.words_by's operations on two halves of 4 pixels
// (fx of pixel k is fx0 + k exactly: int64 positions below 2^53 scaled by a power of two).
__attribute__((target("avx2"))) inline __m256i row_words_avx2(const DepthWordsAvx2& depth, __m256d fx_lo, __m256d fx_hi,
                                                              __m256d b_fy) {
    return _mm256_set_m128i(depth.words_by(fx_hi, b_fy), depth.words_by(fx_lo, b_fy));
}

// The passing pixels of a row of 8 (all covered) against the stored words, written when `write`.
__attribute__((target("avx2"))) inline __m256i test_row_avx2(const DepthWordsAvx2& depth, bool write, __m256i word,
                                                             uint32_t* row) {
    const __m256i stored = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row));
    const __m256i sign = _mm256_set1_epi32(int32_t(0x80000000u));
    const __m256i zs = _mm256_xor_si256(word, sign), ss = _mm256_xor_si256(stored, sign);
    const __m256i lt = _mm256_cmpgt_epi32(ss, zs), eq = _mm256_cmpeq_epi32(zs, ss), gt = _mm256_cmpgt_epi32(zs, ss);
    const __m256i pass = _mm256_or_si256(
        _mm256_or_si256(_mm256_and_si256(lt, _mm256_broadcastsi128_si256(depth.less)),
                        _mm256_and_si256(eq, _mm256_broadcastsi128_si256(depth.equal))),
        _mm256_and_si256(gt, _mm256_broadcastsi128_si256(depth.greater)));
    if (write) _mm256_storeu_si256(reinterpret_cast<__m256i*>(row), _mm256_blendv_epi8(stored, word, pass));
    return pass;
}

// The same for the `covered` lanes of a row of 8 only: the others are neither read nor written.
__attribute__((target("avx2"))) inline __m256i test_row_masked_avx2(const DepthWordsAvx2& depth, bool write, __m256i word,
                                                                    uint32_t* row, __m256i covered) {
    const __m256i stored = _mm256_maskload_epi32(reinterpret_cast<const int*>(row), covered);
    const __m256i sign = _mm256_set1_epi32(int32_t(0x80000000u));
    const __m256i zs = _mm256_xor_si256(word, sign), ss = _mm256_xor_si256(stored, sign);
    const __m256i lt = _mm256_cmpgt_epi32(ss, zs), eq = _mm256_cmpeq_epi32(zs, ss), gt = _mm256_cmpgt_epi32(zs, ss);
    const __m256i pass = _mm256_and_si256(
        covered, _mm256_or_si256(_mm256_or_si256(_mm256_and_si256(lt, _mm256_broadcastsi128_si256(depth.less)),
                                                 _mm256_and_si256(eq, _mm256_broadcastsi128_si256(depth.equal))),
                                 _mm256_and_si256(gt, _mm256_broadcastsi128_si256(depth.greater))));
    if (write) _mm256_maskstore_epi32(reinterpret_cast<int*>(row), pass, word);
    return pass;
}

// A quad per step (DepthWordsAvx2), or two to four side by side as two rows of 8 pixels: plain
// accesses when there are four with every pixel covered (full_run_avx2: the quad-rows of covered
// blocks), masked ones otherwise (the rows of small primitives: a quad at a time cost ~90
// instructions, a run of them ~70). Pixels outside the coverage are neither read nor written (they
// may lie outside the buffer). Each pixel's word and test are the
// quad step's, and the pixels of a row are distinct, so testing them together is in order.
__attribute__((target("avx2"))) size_t early_depth_avx2(const EarlyDepth& t, const Quad* quads, size_t n,
                                                       uint16_t* survived) {
    const PrimitiveSetup& p = *t.prim;
    const DepthWordsAvx2 depth(t);
    // In locals: the stores below may alias anything as far as the compiler knows.
    const int64_t x_origin = t.pattern->x[0] - p.origin_x, y_origin = t.pattern->y[0] - p.origin_y;
    uint32_t* const buffer = t.depth;
    const size_t pitch = t.pitch;
    const uint32_t* const colour = t.prefetch_color;
    const bool write = t.write;
    // b * fy of the current row of quads (the rasterizer emits a block's quads row by row): the
    // product words() forms, once per row.
    int64_t row_y = int64_t(INT32_MIN) - 1;   // none yet
    __m256d b_fy = _mm256_setzero_pd();
    size_t killed = 0;
    int32_t run_x = quads[0].x + 1;   // the quad column fx_lo, fx_hi belong to (none yet)
    __m256d fx_lo = _mm256_setzero_pd(), fx_hi = _mm256_setzero_pd();
    for (size_t i = 0; i < n; ++i) {
        const Quad& quad = quads[i];
        // The quads side by side from this one (x stepping by 2, the same y), up to four: the
        // rasterizer emits a block's quads row by row, so a small primitive's rows are such runs.
        size_t k = 1;
        while (k < 4 && i + k < n && quads[i + k].y == quad.y && quads[i + k].x == quad.x + 2 * int32_t(k)) ++k;
        if (k > 1) {
            if (quad.x != run_x) {
                const int64_t X = int64_t(quad.x) * kSubPixel + x_origin;
                const __m256d fx0 = _mm256_set1_pd(double(X) * (1.0 / kSubPixel));
                fx_lo = _mm256_add_pd(fx0, _mm256_setr_pd(0, 1, 2, 3)), fx_hi = _mm256_add_pd(fx0, _mm256_setr_pd(4, 5, 6, 7));
                run_x = quad.x;
            }
            const int64_t Y = int64_t(quad.y) * kSubPixel + y_origin;
            const __m256d b_fy0 = _mm256_mul_pd(depth.b, _mm256_set1_pd(double(Y) * (1.0 / kSubPixel)));
            const __m256d b_fy1 = _mm256_mul_pd(depth.b, _mm256_set1_pd(double(Y + kSubPixel) * (1.0 / kSubPixel)));
            uint32_t* row0 = &buffer[size_t(quad.y) * pitch + size_t(quad.x)];
            if (k == 4 && full_run_avx2(quads + i)) {
                const __m256i pass0 = test_row_avx2(depth, write, row_words_avx2(depth, fx_lo, fx_hi, b_fy0), row0);
                const __m256i pass1 = test_row_avx2(depth, write, row_words_avx2(depth, fx_lo, fx_hi, b_fy1), row0 + pitch);
                // survived's order, pixel j of quad q at 4q + j: rows a (pass0), b (pass1) as
                // a0 a1 b0 b1 a2 a3 b2 b3 | a4 a5 b4 b5 a6 a7 b6 b7, then 0 / 1.
                const __m256i lo = _mm256_unpacklo_epi64(pass0, pass1), hi = _mm256_unpackhi_epi64(pass0, pass1);
                const __m256i masks = _mm256_and_si256(_mm256_packs_epi32(lo, hi), _mm256_set1_epi16(1));
                _mm256_storeu_si256(reinterpret_cast<__m256i*>(survived + 4 * i), masks);
                killed += size_t(16 - __builtin_popcount(unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(pass0))) |
                                                         unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(pass1))) << 8));
                i += 3;
                continue;
            }
            // A run with uncovered pixels: the two pixel rows of its k quads as lanes 0 .. 2k - 1
            // of two rows of 8, through masked accesses (uncovered pixels may lie outside the
            // buffer or the tile), the rest of each row masked off.
            alignas(32) uint64_t coverage[4] = {0, 0, 0, 0};
            for (size_t q = 0; q < k; ++q) coverage[q] = quads[i + q].coverage;
            // As 32-bit elements, quad q's pixels 0|1 (row 0) at 2q and 2|3 (row 1) at 2q + 1:
            // gathered per row, widened to a 32-bit lane per pixel, sample 0's bit spread over it.
            const __m256i by_row = _mm256_permutevar8x32_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(coverage)),
                                                               _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
            const __m256i covered0 = _mm256_srai_epi32(_mm256_slli_epi32(_mm256_cvtepu16_epi32(_mm256_castsi256_si128(by_row)), 31), 31);
            const __m256i covered1 =
                _mm256_srai_epi32(_mm256_slli_epi32(_mm256_cvtepu16_epi32(_mm256_extracti128_si256(by_row, 1)), 31), 31);
            const unsigned tested0 = unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(covered0)));
            const unsigned tested1 = unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(covered1)));
            uint32_t* row1 = tested1 ? row0 + pitch : row0;   // a pointer into the buffer either way
            {
                // Hints as for one quad below (EarlyDepth::prefetch_color); the run's 8 pixels
                // may lie in two lines.
                const uintptr_t below = reinterpret_cast<uintptr_t>(row0) + 8 * 4 * pitch;
                __builtin_prefetch(reinterpret_cast<const void*>(below), 1);
                __builtin_prefetch(reinterpret_cast<const void*>(below + 28), 1);
                if (colour) {
                    const uintptr_t c0 = reinterpret_cast<uintptr_t>(colour + size_t(quad.y) * pitch + size_t(quad.x));
                    __builtin_prefetch(reinterpret_cast<const void*>(c0), 1);
                    __builtin_prefetch(reinterpret_cast<const void*>(c0 + 28), 1);
                }
            }
            // Row 0 is tested first, then row 1: distinct pixels, so the order does not matter.
            const __m256i pass0 = test_row_masked_avx2(depth, write, row_words_avx2(depth, fx_lo, fx_hi, b_fy0), row0, covered0);
            const __m256i pass1 = test_row_masked_avx2(depth, write, row_words_avx2(depth, fx_lo, fx_hi, b_fy1), row1, covered1);
            // survived's order as for a full run above. Entries past the run's 4k are the next
            // quads', which are stored again when those are tested; at the end of the array, only
            // the run's are stored (masked stores are slow on some CPUs: not otherwise).
            const __m256i lo = _mm256_unpacklo_epi64(pass0, pass1), hi = _mm256_unpackhi_epi64(pass0, pass1);
            const __m256i masks = _mm256_and_si256(_mm256_packs_epi32(lo, hi), _mm256_set1_epi16(1));
            if (i + 4 <= n) {
                _mm256_storeu_si256(reinterpret_cast<__m256i*>(survived + 4 * i), masks);
            } else {
                const __m256i entries = _mm256_cmpgt_epi32(_mm256_set1_epi32(int32_t(2 * k)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
                _mm256_maskstore_epi32(reinterpret_cast<int*>(survived + 4 * i), entries, masks);
            }
            const unsigned passed = unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(pass0))) |
                                    unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(pass1))) << 8;
            killed += size_t(__builtin_popcount((tested0 | tested1 << 8) & ~passed));
            i += k - 1;
            continue;
        }
        if (quad.y != row_y) {
            const int64_t Y = int64_t(quad.y) * kSubPixel + y_origin;
            const double fy0 = double(Y) * (1.0 / kSubPixel), fy1 = double(Y + kSubPixel) * (1.0 / kSubPixel);
            b_fy = _mm256_mul_pd(depth.b, _mm256_setr_pd(fy0, fy0, fy1, fy1));
            row_y = quad.y;
        }
        const int64_t X = int64_t(quad.x) * kSubPixel + x_origin;
        const double fx0 = double(X) * (1.0 / kSubPixel), fx1 = double(X + kSubPixel) * (1.0 / kSubPixel);
        const __m128i word = depth.words_by(_mm256_setr_pd(fx0, fx1, fx0, fx1), b_fy);
        // Covered pixels (sample 0 of each 16-bit pixel mask) as lane masks: the four masks
        // widened to 32-bit lanes, their bit 0 moved to the sign and spread over the lane.
        const uint64_t cov = quad.coverage;
        const __m128i covered =
            _mm_srai_epi32(_mm_slli_epi32(_mm_cvtepu16_epi32(_mm_cvtsi64_si128(int64_t(cov))), 31), 31);
        const int tested = _mm_movemask_ps(_mm_castsi128_ps(covered));
        const size_t at = size_t(quad.y) * pitch + size_t(quad.x);
        uint32_t* row0 = &buffer[at];
        {
            // Hints (EarlyDepth::prefetch_color): the depth of the quad eight rows down, the
            // colour of this one. Never fault, change no byte.
            const uintptr_t below = reinterpret_cast<uintptr_t>(row0) + 8 * 4 * pitch;
            __builtin_prefetch(reinterpret_cast<const void*>(below), 1);
            __builtin_prefetch(reinterpret_cast<const void*>(below + 4 * pitch), 1);
            if (colour) {
                const uintptr_t c0 = reinterpret_cast<uintptr_t>(colour + at);
                __builtin_prefetch(reinterpret_cast<const void*>(c0), 1);
                __builtin_prefetch(reinterpret_cast<const void*>(c0 + 4 * pitch), 1);
            }
        }
        const bool upper = (cov >> 32) & 0x10001u;
        uint32_t* row1 = upper ? row0 + pitch : row0;   // a pointer into the buffer either way
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
        const __m128i pass = depth.pass(word, stored, covered);
        const int passed = _mm_movemask_ps(_mm_castsi128_ps(pass));
        if (write && passed) {
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
        // Pixel j's mask (0 or 1) in bits 16j: the four survived words in one store.
        const uint64_t masks = spread_pixel_bits(uint64_t(passed));
        std::memcpy(survived + 4 * i, &masks, 8);
        killed += size_t(__builtin_popcount(unsigned(tested & ~passed)));
    }
    return killed;
}

// Four samples per pixel: a pixel's four samples per step, lanes as above (the positions'
// int64 offsets converted one by one, as depth_at does, since AVX2 has no int64 conversion).
__attribute__((target("avx2"))) size_t early_depth_4x_avx2(const EarlyDepth& t, const Quad* quads, size_t n,
                                                          uint16_t* survived) {
    const PrimitiveSetup& p = *t.prim;
    const SamplePattern& pattern = *t.pattern;
    const DepthWordsAvx2 depth(t);
    const __m128i bits = _mm_setr_epi32(1, 2, 4, 8);
    size_t killed = 0;
    for (size_t i = 0; i < n; ++i) {
        const Quad& quad = quads[i];
        for (int j = 0; j < 4; ++j) {
            const uint32_t mask = quad_pixel_mask(quad, j) & 0xFu;
            survived[4 * i + size_t(j)] = 0;
            if (!mask) continue;
            const int32_t x = quad.x + (j & 1), y = quad.y + (j >> 1);
            const int64_t X = int64_t(x) * kSubPixel - p.origin_x, Y = int64_t(y) * kSubPixel - p.origin_y;
            double fx[4], fy[4];
            for (int s = 0; s < 4; ++s)
                fx[s] = double(X + pattern.x[s]) * (1.0 / kSubPixel), fy[s] = double(Y + pattern.y[s]) * (1.0 / kSubPixel);
            const __m128i word = depth.words(_mm256_loadu_pd(fx), _mm256_loadu_pd(fy));
            const __m128i covered = _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(int32_t(mask)), bits), bits);
            int* const samples = reinterpret_cast<int*>(&t.depth[(size_t(y) * t.pitch + size_t(x)) * 4]);
            const __m128i stored = _mm_maskload_epi32(samples, covered);
            const __m128i pass = depth.pass(word, stored, covered);
            if (t.write) _mm_maskstore_epi32(samples, pass, word);
            const int passed = _mm_movemask_ps(_mm_castsi128_ps(pass));
            survived[4 * i + size_t(j)] = uint16_t(passed);
            killed += size_t(__builtin_popcount(mask & ~unsigned(passed)));
        }
    }
    return killed;
}

// The AVX-512 level takes a row of up to four quads at once: consecutive quads with the same y
// and x stepping by 2, as the rasterizer emits the quad-rows of a block (a covered 8x8 block is
// four rows of four full quads, which one vector compare recognizes). That is two pixel rows of
// up to 8 pixels, 8 double lanes each: fx and c + a*fx once per column of quads (the quad-rows
// of a block share it), then each row's depths in the scalar definition's order
// ((c + a*fx) + b*fy) + offset. Two exact shortcuts: adding a zero offset changes nothing but the
// sign of a zero depth (word 0 either way), and a flat plane (a = b = 0, so a*fx and b*fy are
// zeros, fx and fy being finite) gives every pixel the word of c + offset. The rows compare
// as unsigned words (kPredicate is compare()'s function as a vpcmpud predicate) and store the
// passing words; masked loads and stores touch covered pixels only. The pixels of a row are
// distinct, so testing them together is in order. pext/pdep (BMI2, which every AVX-512 CPU has)
// gather the coverage and scatter the results in survived's order.
#define SOFTGL_AVX512_EARLY_DEPTH __attribute__((target("avx512f,avx512bw,avx512dq,avx512vl,bmi,bmi2")))
// A pixel row's words: ((cax + byf) + offset), depth_word's clamp as min(max(z, 0), 1) (vmaxpd
// returns its second operand for NaN: 0), then converted. (Zero-masking with all lanes: GCC 12
// warns about the undefined sources of the unmasked forms.)
SOFTGL_AVX512_EARLY_DEPTH inline __m256i row_words(__m512d cax, __m512d byf, bool add_offset, __m512d offset) {
    constexpr __mmask8 kAll = 0xFF;
    __m512d z = _mm512_add_pd(cax, byf);
    if (add_offset) z = _mm512_add_pd(z, offset);
    const __m512d d = _mm512_maskz_min_pd(kAll, _mm512_maskz_max_pd(kAll, z, _mm512_setzero_pd()), _mm512_set1_pd(1.0));
    return _mm512_maskz_cvttpd_epi32(kAll, _mm512_add_pd(_mm512_mul_pd(d, _mm512_set1_pd(16777215.0)), _mm512_set1_pd(0.5)));
}

// Tests the `covered` pixels of a row against their words; returns the passing ones.
template <int kPredicate>
SOFTGL_AVX512_EARLY_DEPTH inline uint32_t test_row(bool write, __m256i word, uint32_t* row, __mmask8 covered) {
    const __m256i stored = _mm256_maskz_loadu_epi32(covered, row);
    const __mmask8 pass = _mm256_mask_cmp_epu32_mask(covered, word, stored, kPredicate);
    if (write) _mm256_mask_storeu_epi32(row, pass, word);
    return pass;
}

// Whether quads[0, 4) are the common case, all four pixels covered and side by side (x stepping
// by 2, the same y): one compare of the four quads (x, y, coverage & sample 0 bits) with that.
static_assert(sizeof(Quad) == 16 && offsetof(Quad, x) == 0 && offsetof(Quad, y) == 4 && offsetof(Quad, coverage) == 8);
SOFTGL_AVX512_EARLY_DEPTH inline bool full_run(const Quad* quads) {
    constexpr int32_t kPixel0 = 0x00010001;   // sample 0 of two pixels (a 32-bit half of the coverage)
    const __m512i keep = _mm512_setr_epi32(-1, -1, kPixel0, kPixel0, -1, -1, kPixel0, kPixel0,
                                           -1, -1, kPixel0, kPixel0, -1, -1, kPixel0, kPixel0);
    const __m512i steps = _mm512_setr_epi32(0, 0, kPixel0, kPixel0, 2, 0, kPixel0, kPixel0,
                                            4, 0, kPixel0, kPixel0, 6, 0, kPixel0, kPixel0);
    int64_t first_xy;
    std::memcpy(&first_xy, quads, 8);
    const __m512i first = _mm512_maskz_mov_epi32(0x3333, _mm512_set1_epi64(first_xy));
    return _mm512_cmpeq_epi32_mask(_mm512_and_si512(_mm512_loadu_si512(quads), keep), _mm512_add_epi32(first, steps)) == 0xFFFF;
}

// kFlat: the plane is flat. Everything the loop reads from t and the primitive is copied first
// (the stores could alias them as far as the compiler knows).
template <int kPredicate, bool kFlat>
SOFTGL_AVX512_EARLY_DEPTH size_t early_depth_avx512(const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    const PrimitiveSetup& p = *t.prim;
    const __m512d a = _mm512_set1_pd(p.depth.a), c = _mm512_set1_pd(p.depth.c), offset = _mm512_set1_pd(p.depth_offset);
    const double b = p.depth.b;
    const bool add_offset = p.depth_offset != 0.0, write = t.write;
    const int64_t x_origin = t.pattern->x[0] - p.origin_x, y_origin = t.pattern->y[0] - p.origin_y;
    uint32_t* const depth = t.depth;
    const size_t pitch = t.pitch;
    const uint32_t* const colour = t.prefetch_color;
    const __m256i flat_word = row_words(c, _mm512_setzero_pd(), add_offset, offset);
    const __m512i pixel_steps = _mm512_setr_epi64(0, kSubPixel, 2 * kSubPixel, 3 * kSubPixel, 4 * kSubPixel,
                                                  5 * kSubPixel, 6 * kSubPixel, 7 * kSubPixel);
    const __m256i ones = _mm256_set1_epi16(1);
    size_t killed = 0;
    int32_t cax_x = quads[0].x + 1;   // the quad column cax belongs to (none yet)
    __m512d cax = _mm512_setzero_pd();
    for (size_t i = 0; i < n;) {
        const Quad& first = quads[i];
        // k quads side by side; their covered pixels in survived's order (bit 4*q + j: pixel j
        // of quad q), then per pixel row.
        size_t k = 4;
        uint32_t covered = 0xFFFF;
        __mmask8 covered0 = 0xFF, covered1 = 0xFF;
        if (i + 4 > n || !full_run(quads + i)) {
            k = 1;
            while (k < 4 && i + k < n && quads[i + k].y == first.y && quads[i + k].x == first.x + 2 * int32_t(k)) ++k;
            covered = 0;
            for (size_t q = 0; q < k; ++q)
                covered |= uint32_t(_pext_u64(quads[i + q].coverage, 0x0001000100010001ull)) << (4 * q);
            covered0 = __mmask8(_pext_u32(covered, 0x3333u)), covered1 = __mmask8(_pext_u32(covered, 0xCCCCu));
        }
        const size_t at = size_t(first.y) * pitch + size_t(first.x);
        uint32_t* row0 = &depth[at];
        uint32_t* row1 = covered1 ? row0 + pitch : row0;   // a pointer into the buffer either way
        {
            // Hints (EarlyDepth::prefetch_color): never fault, change no byte. The first and last
            // pixel of a row of 8 may lie in two lines.
            const uintptr_t below = reinterpret_cast<uintptr_t>(row0) + 8 * 4 * pitch;
            __builtin_prefetch(reinterpret_cast<const void*>(below), 1);
            __builtin_prefetch(reinterpret_cast<const void*>(below + 28), 1);
            __builtin_prefetch(reinterpret_cast<const void*>(below + 4 * pitch), 1);
            __builtin_prefetch(reinterpret_cast<const void*>(below + 4 * pitch + 28), 1);
            if (colour) {
                const uintptr_t c0 = reinterpret_cast<uintptr_t>(colour + at);
                __builtin_prefetch(reinterpret_cast<const void*>(c0), 1);
                __builtin_prefetch(reinterpret_cast<const void*>(c0 + 28), 1);
                __builtin_prefetch(reinterpret_cast<const void*>(c0 + 4 * pitch), 1);
                __builtin_prefetch(reinterpret_cast<const void*>(c0 + 4 * pitch + 28), 1);
            }
        }
        __m256i word0 = flat_word, word1 = flat_word;
        if constexpr (!kFlat) {
            if (first.x != cax_x) {
                const int64_t X = int64_t(first.x) * kSubPixel + x_origin;
                const __m512d fx = _mm512_mul_pd(_mm512_cvtepi64_pd(_mm512_add_epi64(_mm512_set1_epi64(X), pixel_steps)),
                                                 _mm512_set1_pd(1.0 / kSubPixel));
                cax = _mm512_add_pd(c, _mm512_mul_pd(a, fx));
                cax_x = first.x;
            }
            const int64_t Y = int64_t(first.y) * kSubPixel + y_origin;
            word0 = row_words(cax, _mm512_set1_pd(b * (double(Y) * (1.0 / kSubPixel))), add_offset, offset);
            word1 = row_words(cax, _mm512_set1_pd(b * (double(Y + kSubPixel) * (1.0 / kSubPixel))), add_offset, offset);
        }
        const uint32_t passed = uint32_t(_pdep_u32(test_row<kPredicate>(write, word0, row0, covered0), 0x3333u) |
                                         _pdep_u32(test_row<kPredicate>(write, word1, row1, covered1), 0xCCCCu));
        _mm256_mask_storeu_epi16(survived + 4 * i, __mmask16((1u << (4 * k)) - 1), _mm256_maskz_mov_epi16(__mmask16(passed), ones));
        killed += size_t(__builtin_popcount(covered & ~passed));
        i += k;
    }
    return killed;
}

template <bool kFlat>
SOFTGL_AVX512_EARLY_DEPTH size_t early_depth_avx512(const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    constexpr int kNever = 3, kAlways = 7;   // vpcmpud's FALSE and TRUE predicates (unnamed in GCC's headers)
    switch (t.func) {
        case gl::NEVER: return early_depth_avx512<kNever, kFlat>(t, quads, n, survived);
        case gl::LESS: return early_depth_avx512<_MM_CMPINT_LT, kFlat>(t, quads, n, survived);
        case gl::EQUAL: return early_depth_avx512<_MM_CMPINT_EQ, kFlat>(t, quads, n, survived);
        case gl::LEQUAL: return early_depth_avx512<_MM_CMPINT_LE, kFlat>(t, quads, n, survived);
        case gl::GREATER: return early_depth_avx512<_MM_CMPINT_NLE, kFlat>(t, quads, n, survived);
        case gl::NOTEQUAL: return early_depth_avx512<_MM_CMPINT_NE, kFlat>(t, quads, n, survived);
        case gl::GEQUAL: return early_depth_avx512<_MM_CMPINT_NLT, kFlat>(t, quads, n, survived);
        default: return early_depth_avx512<kAlways, kFlat>(t, quads, n, survived);   // ALWAYS, as compare()
    }
}

SOFTGL_AVX512_EARLY_DEPTH size_t early_depth_avx512(const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    if (n == 0) return 0;
    const Plane& plane = t.prim->depth;
    return plane.a == 0.0 && plane.b == 0.0 ? early_depth_avx512<true>(t, quads, n, survived)
                                            : early_depth_avx512<false>(t, quads, n, survived);
}

// Four samples per pixel: a quad's pixel row is two pixels' 8 consecutive sample words, 8 double
// lanes (lane l: sample l % 4 of pixel l / 4). Each lane's position is the scalar definition's
// int64 X - origin (exact), converted and scaled as depth_at does, then row_words and test_row
// as above. pext/pdep move the rows' sample bits between the quad's coverage and survived.
template <int kPredicate>
SOFTGL_AVX512_EARLY_DEPTH size_t early_depth_4x_avx512(const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    const PrimitiveSetup& p = *t.prim;
    const SamplePattern& pattern = *t.pattern;
    const __m512d a = _mm512_set1_pd(p.depth.a), b = _mm512_set1_pd(p.depth.b), c = _mm512_set1_pd(p.depth.c);
    const __m512d offset = _mm512_set1_pd(p.depth_offset), inv_sub = _mm512_set1_pd(1.0 / kSubPixel);
    const bool add_offset = p.depth_offset != 0.0, write = t.write;
    const __m512i lane_x = _mm512_setr_epi64(pattern.x[0], pattern.x[1], pattern.x[2], pattern.x[3], kSubPixel + pattern.x[0],
                                             kSubPixel + pattern.x[1], kSubPixel + pattern.x[2], kSubPixel + pattern.x[3]);
    const __m512i lane_y = _mm512_setr_epi64(pattern.y[0], pattern.y[1], pattern.y[2], pattern.y[3], pattern.y[0],
                                             pattern.y[1], pattern.y[2], pattern.y[3]);
    uint32_t* const depth = t.depth;
    const size_t pitch = t.pitch;
    constexpr uint64_t kSamples = 0x000F000F000F000Full;   // samples 0-3 of each pixel of a quad
    size_t killed = 0;
    for (size_t i = 0; i < n; ++i) {
        const Quad& quad = quads[i];
        const uint32_t covered = uint32_t(_pext_u64(quad.coverage, kSamples));   // row 0: bits 0-7, row 1: 8-15
        const __mmask8 covered0 = __mmask8(covered), covered1 = __mmask8(covered >> 8);
        const int64_t X = int64_t(quad.x) * kSubPixel - p.origin_x, Y = int64_t(quad.y) * kSubPixel - p.origin_y;
        const __m512d fx = _mm512_mul_pd(_mm512_cvtepi64_pd(_mm512_add_epi64(_mm512_set1_epi64(X), lane_x)), inv_sub);
        const __m512d fy0 = _mm512_mul_pd(_mm512_cvtepi64_pd(_mm512_add_epi64(_mm512_set1_epi64(Y), lane_y)), inv_sub);
        const __m512d fy1 = _mm512_mul_pd(_mm512_cvtepi64_pd(_mm512_add_epi64(_mm512_set1_epi64(Y + kSubPixel), lane_y)), inv_sub);
        const __m512d cax = _mm512_add_pd(c, _mm512_mul_pd(a, fx));
        uint32_t* row0 = &depth[(size_t(quad.y) * pitch + size_t(quad.x)) * 4];
        uint32_t* row1 = covered1 ? row0 + 4 * pitch : row0;   // a pointer into the buffer either way
        uint32_t passed = 0;
        if (covered0) passed = test_row<kPredicate>(write, row_words(cax, _mm512_mul_pd(b, fy0), add_offset, offset), row0, covered0);
        if (covered1)
            passed |= test_row<kPredicate>(write, row_words(cax, _mm512_mul_pd(b, fy1), add_offset, offset), row1, covered1) << 8;
        const uint64_t masks = _pdep_u64(passed, kSamples);
        std::memcpy(survived + 4 * i, &masks, 8);
        killed += size_t(__builtin_popcount(covered & ~passed));
    }
    return killed;
}

SOFTGL_AVX512_EARLY_DEPTH size_t early_depth_4x_avx512(const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    constexpr int kNever = 3, kAlways = 7;
    switch (t.func) {
        case gl::NEVER: return early_depth_4x_avx512<kNever>(t, quads, n, survived);
        case gl::LESS: return early_depth_4x_avx512<_MM_CMPINT_LT>(t, quads, n, survived);
        case gl::EQUAL: return early_depth_4x_avx512<_MM_CMPINT_EQ>(t, quads, n, survived);
        case gl::LEQUAL: return early_depth_4x_avx512<_MM_CMPINT_LE>(t, quads, n, survived);
        case gl::GREATER: return early_depth_4x_avx512<_MM_CMPINT_NLE>(t, quads, n, survived);
        case gl::NOTEQUAL: return early_depth_4x_avx512<_MM_CMPINT_NE>(t, quads, n, survived);
        case gl::GEQUAL: return early_depth_4x_avx512<_MM_CMPINT_NLT>(t, quads, n, survived);
        default: return early_depth_4x_avx512<kAlways>(t, quads, n, survived);
    }
}
#endif

}  // namespace

size_t early_depth_test_at(SimdLevel level, const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
#if defined(SOFTGL_HAVE_AVX2_EARLY_DEPTH)
    if (t.pattern->count == 1) {
        if (level == SimdLevel::AVX512) return early_depth_avx512(t, quads, n, survived);
        if (level == SimdLevel::AVX2) return early_depth_avx2(t, quads, n, survived);
    } else if (t.pattern->count == 4) {
        if (level == SimdLevel::AVX512) return early_depth_4x_avx512(t, quads, n, survived);
        if (level == SimdLevel::AVX2) return early_depth_4x_avx2(t, quads, n, survived);
    }
#endif
    (void)level;
    return early_depth_scalar(t, quads, n, survived);
}

namespace {

// The reference: a quad at a time through early_depth_scalar (the quads a covered rectangle
// rasterizes to: every pixel's one sample covered).
size_t early_depth_rect_scalar(const EarlyDepth& t, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                               uint64_t& quads_passed) {
    size_t killed = 0;
    uint16_t survived[4];
    for (int32_t y = y0; y < y1; y += 2)
        for (int32_t x = x0; x < x1; x += 2) {
            const Quad q{x, y, 0x0001000100010001ull};
            killed += early_depth_scalar(t, &q, 1, survived);
            quads_passed += (survived[0] | survived[1] | survived[2] | survived[3]) != 0;
        }
    return killed;
}

#if defined(SOFTGL_HAVE_AVX2_EARLY_DEPTH)
// early_depth_avx2's full runs (four quads side by side, all covered), one per 8 pixels of a
// pair of rows: the same words (DepthWordsAvx2 from the same fx, b * fy) and tests.
__attribute__((target("avx2"))) size_t early_depth_rect_avx2(const EarlyDepth& t, int32_t x0, int32_t y0, int32_t x1,
                                                            int32_t y1, uint64_t& quads_passed) {
    const PrimitiveSetup& p = *t.prim;
    const DepthWordsAvx2 depth(t);
    const int64_t x_origin = t.pattern->x[0] - p.origin_x, y_origin = t.pattern->y[0] - p.origin_y;
    uint32_t* const buffer = t.depth;
    const size_t pitch = t.pitch;
    const bool write = t.write;
    size_t killed = 0;
    uint64_t passed_quads = 0;
    for (int32_t y = y0; y < y1; y += 2) {
        const int64_t Y = int64_t(y) * kSubPixel + y_origin;
        const __m256d b_fy0 = _mm256_mul_pd(depth.b, _mm256_set1_pd(double(Y) * (1.0 / kSubPixel)));
        const __m256d b_fy1 = _mm256_mul_pd(depth.b, _mm256_set1_pd(double(Y + kSubPixel) * (1.0 / kSubPixel)));
        for (int32_t x = x0; x < x1; x += 8) {
            const int64_t X = int64_t(x) * kSubPixel + x_origin;
            const __m256d fx0 = _mm256_set1_pd(double(X) * (1.0 / kSubPixel));
            const __m256d fx_lo = _mm256_add_pd(fx0, _mm256_setr_pd(0, 1, 2, 3));
            const __m256d fx_hi = _mm256_add_pd(fx0, _mm256_setr_pd(4, 5, 6, 7));
            uint32_t* const row0 = &buffer[size_t(y) * pitch + size_t(x)];
            const __m256i pass0 = test_row_avx2(depth, write, row_words_avx2(depth, fx_lo, fx_hi, b_fy0), row0);
            const __m256i pass1 = test_row_avx2(depth, write, row_words_avx2(depth, fx_lo, fx_hi, b_fy1), row0 + pitch);
            const unsigned m0 = unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(pass0)));
            const unsigned m1 = unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(pass1)));
            killed += size_t(16 - __builtin_popcount(m0 | m1 << 8));
            const unsigned any = m0 | m1;   // quad q: pixels 2q, 2q + 1 of either row
            passed_quads += uint64_t(__builtin_popcount((any | any >> 1) & 0x55u));
        }
    }
    quads_passed += passed_quads;
    return killed;
}
#endif

}  // namespace

size_t early_depth_rect_at(SimdLevel level, const EarlyDepth& t, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                           uint64_t& quads_passed) {
#if defined(SOFTGL_HAVE_AVX2_EARLY_DEPTH)
    // AVX-512 too: its quad kernels give the AVX2 level's words and decisions (early_depth.h).
    if (t.pattern->count == 1 && (level == SimdLevel::AVX512 || level == SimdLevel::AVX2))
        return early_depth_rect_avx2(t, x0, y0, x1, y1, quads_passed);
#endif
    (void)level;
    return early_depth_rect_scalar(t, x0, y0, x1, y1, quads_passed);
}

}  // namespace softgl

namespace softgl {

namespace {

// depth_word(Encoding::Depth24, z) for a finite z: the clamp, then the rounding.
inline uint32_t depth24_word(double z) {
    const double d = z > 0.0 ? z : 0.0;
    return uint32_t((d < 1.0 ? d : 1.0) * 16777215.0 + 0.5);
}

#if defined(SOFTGL_HAVE_AVX2_EARLY_DEPTH)
// The smallest and largest word of 8 rows of 8 words.
__attribute__((target("avx2"))) void block_bounds_avx2(const uint32_t* row, size_t pitch, uint32_t& lo, uint32_t& hi) {
    __m256i mn = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row)), mx = mn;
    for (int r = 1; r < kBlockSize; ++r) {
        const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + size_t(r) * pitch));
        mn = _mm256_min_epu32(mn, v), mx = _mm256_max_epu32(mx, v);
    }
    __m128i l = _mm_min_epu32(_mm256_castsi256_si128(mn), _mm256_extracti128_si256(mn, 1));
    __m128i h = _mm_max_epu32(_mm256_castsi256_si128(mx), _mm256_extracti128_si256(mx, 1));
    l = _mm_min_epu32(l, _mm_shuffle_epi32(l, 0x4E)), h = _mm_max_epu32(h, _mm_shuffle_epi32(h, 0x4E));
    l = _mm_min_epu32(l, _mm_shuffle_epi32(l, 0xB1)), h = _mm_max_epu32(h, _mm_shuffle_epi32(h, 0xB1));
    lo = uint32_t(_mm_cvtsi128_si32(l)), hi = uint32_t(_mm_cvtsi128_si32(h));
}
#endif

}  // namespace

void DepthBounds::begin_tile(const EarlyDepth& t, const TileRect& rect, DepthBoundsMode mode, SimdLevel level) {
    enabled_ = mode != DepthBoundsMode::Off && t.pattern->count == 1 &&
               (t.func == gl::LESS || t.func == gl::LEQUAL || t.func == gl::GREATER || t.func == gl::GEQUAL);
    sabotaged_ = mode == DepthBoundsMode::SabotagedForTests;
    func_ = t.func;
    write_ = t.write;
    vector_ = level >= SimdLevel::AVX2;
    rect_ = rect;
    sample_x_ = t.pattern->x[0], sample_y_ = t.pattern->y[0];
    depth_ = t.depth;
    pitch_ = t.pitch;
    known_ = 0;
}

void DepthBounds::read_block(int block) {
    const int32_t x0 = rect_.x0 + block % kBlocksPerRow * kBlockSize, y0 = rect_.y0 + block / kBlocksPerRow * kBlockSize;
    const int32_t x1 = std::min(x0 + kBlockSize, rect_.x1), y1 = std::min(y0 + kBlockSize, rect_.y1);
    const uint32_t* const first = &depth_[size_t(y0) * pitch_ + size_t(x0)];
    uint32_t lo = UINT32_MAX, hi = 0;
#if defined(SOFTGL_HAVE_AVX2_EARLY_DEPTH)
    if (vector_ && x1 - x0 == kBlockSize && y1 - y0 == kBlockSize) {
        block_bounds_avx2(first, pitch_, lo, hi);
    } else
#endif
    {
        for (int32_t y = 0; y < y1 - y0; ++y)
            for (int32_t x = 0; x < x1 - x0; ++x) {
                const uint32_t v = first[size_t(y) * pitch_ + size_t(x)];
                lo = std::min(lo, v), hi = std::max(hi, v);
            }
    }
    min_[block] = lo, max_[block] = hi;
    known_ |= uint64_t(1) << block;
}

bool DepthBounds::hides_box(const PrimitiveSetup& p, int32_t x0, int32_t y0, int32_t x1, int32_t y1) {
    const int bx0 = (x0 - rect_.x0) / kBlockSize, bx1 = (x1 - 1 - rect_.x0) / kBlockSize;
    const int by0 = (y0 - rect_.y0) / kBlockSize, by1 = (y1 - 1 - rect_.y0) / kBlockSize;
    const uint64_t row = ((uint64_t(1) << (bx1 - bx0 + 1)) - 1) << bx0;
    uint64_t blocks = 0;
    for (int by = by0; by <= by1; ++by) blocks |= row << (by * kBlocksPerRow);

    // The plane as depth_at evaluates it at the pixel centre of (x, y): ((c + a*fx) + b*fy) +
    // offset. Each evaluation is within a few units in the last place of the sum of its terms'
    // magnitudes, at most `size` over the box (|fx|, |fy| largest at a corner): a corner's value
    // less (plus) 2^-40 * size is below (above) every pixel's value in the box.
    const double a = p.depth.a, b = p.depth.b, c = p.depth.c, offset = p.depth_offset;
    const auto fx = [&](int32_t x) { return double(int64_t(x) * kSubPixel + sample_x_ - p.origin_x) * (1.0 / kSubPixel); };
    const auto fy = [&](int32_t y) { return double(int64_t(y) * kSubPixel + sample_y_ - p.origin_y) * (1.0 / kSubPixel); };
    const double size = std::fabs(c) + std::fabs(offset) + std::fabs(a) * std::max(std::fabs(fx(x0)), std::fabs(fx(x1 - 1))) +
                        std::fabs(b) * std::max(std::fabs(fy(y0)), std::fabs(fy(y1 - 1)));
    bool hidden = false;
    if (std::isfinite(size)) {
        const double margin = size * 0x1p-40;
        // Fails everywhere: LESS/LEQUAL when the nearest value is not below (not at most) every
        // stored word, GREATER/GEQUAL when the farthest is not above (not at least) every one.
        const bool nearest = func_ == gl::LESS || func_ == gl::LEQUAL;
        const bool low_x = (a >= 0) == (nearest != sabotaged_), low_y = (b >= 0) == (nearest != sabotaged_);
        const double corner = ((c + a * fx(low_x ? x0 : x1 - 1)) + b * fy(low_y ? y0 : y1 - 1)) + offset;
        const uint32_t word = depth24_word(nearest ? corner - margin : corner + margin);
        // Hidden when every block's stored words are on the failing side of `word`. One block that
        // is not decides "not hidden": the blocks already known are looked at first, and no further
        // block is read after the first that decides (a primitive in front of what is drawn, the
        // common case, read every block of its box before, only to be drawn). The decision is the
        // same as over all blocks.
        const auto fails_at = [&](int block) {
            return func_ == gl::LESS ? word >= max_[block] : func_ == gl::LEQUAL ? word > max_[block]
                 : func_ == gl::GREATER ? word <= min_[block] : word < min_[block];
        };
        hidden = true;
        for (uint64_t rest = blocks & known_; hidden && rest; rest &= rest - 1) hidden = fails_at(__builtin_ctzll(rest));
        for (uint64_t rest = blocks & ~known_; hidden && rest; rest &= rest - 1) {
            const int block = __builtin_ctzll(rest);
            read_block(block);
            hidden = fails_at(block);
        }
    }
    if (!hidden && write_) known_ &= ~blocks;   // its test may change these blocks' words
    return hidden;
}

}  // namespace softgl
