#include "softgl/pipeline/interpolate.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SOFTGL_HAVE_AVX2_INTERPOLATION 1
#endif

namespace softgl {

namespace {

uint32_t float_bits(double v) {
    const float f = float(v);
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

// The reference: one lane at a time, the expressions of the header comment.
void interpolate_scalar(const VaryingInterpolation& v, const Quad* quads, size_t n, uint32_t* out, size_t stride) {
    const PrimitiveSetup& p = *v.prim;
    auto eval = [](const Plane& pl, double fx, double fy) { return pl.c + pl.a * fx + pl.b * fy; };
    for (size_t i = 0; i < n; ++i) {
        for (int j = 0; j < 4; ++j) {
            const size_t lane = 4 * i + size_t(j);
            const double fx = pixel_centre_offset(quads[i].x + (j & 1), p.origin_x);
            const double fy = pixel_centre_offset(quads[i].y + (j >> 1), p.origin_y);
            const double q = 1.0 / eval(p.inv_w, fx, fy);
            double w[3];
            for (int k = 0; k < v.vertices; ++k) w[k] = eval(p.weight[k], fx, fy) * q;
            for (size_t k = 0; k < v.count; ++k) {
                double s = (0.0 + w[0] * v.values[k]) + w[1] * v.values[v.count + k];
                if (v.vertices == 3) s = s + w[2] * v.values[2 * v.count + k];
                out[size_t(v.words[k]) * stride + lane] = float_bits(s);
            }
        }
    }
}

// When all vertices have the same w (every 2D draw), inv_w is a constant plane (a = b = 0) and
// c + 0*fx + 0*fy == c for any finite non-zero c and finite offsets (adding a zero of either
// sign to a non-zero number leaves it unchanged), so every lane's q is 1 / c: computed once.
bool constant_inv_w(const Plane& pl) {
    return pl.a == 0 && pl.b == 0 && std::isfinite(pl.c) && pl.c != 0;
}

#if defined(__SSE2__)
// Two lanes per register: a quad's lower row (lanes 0, 1: fy0) then its upper row (lanes 2, 3: fy1).
template <int V>
void interpolate_sse2(const VaryingInterpolation& v, const Quad* quads, size_t n, uint32_t* out, size_t stride) {
    const PrimitiveSetup& p = *v.prim;
    // Locals: stores to `out` could otherwise alias the words and force reloads.
    const double* const values = v.values;
    const int* const words = v.words;
    const size_t count = v.count;
    const bool constant_q = constant_inv_w(p.inv_w);
    const __m128d one = _mm_set1_pd(1.0), zero = _mm_setzero_pd(), q_constant = _mm_set1_pd(1.0 / p.inv_w.c);
    auto eval = [](const Plane& pl, __m128d fx, __m128d fy) {
        return _mm_add_pd(_mm_add_pd(_mm_set1_pd(pl.c), _mm_mul_pd(_mm_set1_pd(pl.a), fx)),
                          _mm_mul_pd(_mm_set1_pd(pl.b), fy));
    };
    for (size_t i = 0; i < n; ++i) {
        const __m128d fx = _mm_setr_pd(pixel_centre_offset(quads[i].x, p.origin_x),
                                       pixel_centre_offset(quads[i].x + 1, p.origin_x));
        for (int row = 0; row < 2; ++row) {
            const __m128d fy = _mm_set1_pd(pixel_centre_offset(quads[i].y + row, p.origin_y));
            const __m128d q = constant_q ? q_constant : _mm_div_pd(one, eval(p.inv_w, fx, fy));
            __m128d w[V];
            for (int k = 0; k < V; ++k) w[k] = _mm_mul_pd(eval(p.weight[k], fx, fy), q);
            const size_t lane = 4 * i + 2 * size_t(row);
            for (size_t k = 0; k < count; ++k) {
                __m128d s = _mm_add_pd(zero, _mm_mul_pd(w[0], _mm_set1_pd(values[k])));
                s = _mm_add_pd(s, _mm_mul_pd(w[1], _mm_set1_pd(values[count + k])));
                if constexpr (V == 3) s = _mm_add_pd(s, _mm_mul_pd(w[2], _mm_set1_pd(values[2 * count + k])));
                _mm_storel_pd(reinterpret_cast<double*>(out + size_t(words[k]) * stride + lane),
                              _mm_castps_pd(_mm_cvtpd_ps(s)));
            }
        }
    }
}
#endif

#if defined(SOFTGL_HAVE_AVX2_INTERPOLATION)
// One quad per register (lanes 0..3). Compiled for AVX2 (no FMA) here only; called only when the
// CPU has it.
template <int V>
__attribute__((target("avx2"))) void interpolate_avx2(const VaryingInterpolation& v, const Quad* quads, size_t n,
                                                      uint32_t* out, size_t stride) {
    const PrimitiveSetup& p = *v.prim;
    const double* const values = v.values;
    const int* const words = v.words;
    const size_t count = v.count;
    const bool constant_q = constant_inv_w(p.inv_w);
    const __m256d one = _mm256_set1_pd(1.0), zero = _mm256_setzero_pd(), q_constant = _mm256_set1_pd(1.0 / p.inv_w.c);
    __m256d pa[V + 1], pb[V + 1], pc[V + 1];   // weight[0..V-1], then inv_w
    for (int k = 0; k <= V; ++k) {
        const Plane& pl = k < V ? p.weight[k] : p.inv_w;
        pa[k] = _mm256_set1_pd(pl.a), pb[k] = _mm256_set1_pd(pl.b), pc[k] = _mm256_set1_pd(pl.c);
    }
    // b*fy depends only on a quad's row and c + a*fx only on its column, and quads come in rows
    // of a few columns: each partial term is computed once (the last row, a small table of
    // columns) and reused, so every lane still evaluates ((c + a*fx) + b*fy) * q, those operations.
    __m256d row_term[V + 1];
    int32_t row_y = 0;
    bool have_row = false;
    struct Column {
        int32_t x;
        __m256d term[V + 1];
    };
    constexpr int kColumns = 8;   // slot (x / 2) % 8
    Column columns[kColumns];
    for (int j = 0; j < kColumns; ++j) columns[j].x = 2 * j + 2;   // a tag that never maps to slot j
    // Runs of up to 32 quads: the weights of a run first (4 lanes per quad), then each word over
    // the run with its vertex values in registers and its output contiguous.
    constexpr size_t kRun = 32;
    alignas(32) double weights[V][4 * kRun];
    for (size_t i0 = 0; i0 < n; i0 += kRun) {
        const size_t m = std::min(kRun, n - i0);
        for (size_t i = 0; i < m; ++i) {
            const Quad& quad = quads[i0 + i];
            if (!have_row || quad.y != row_y) {
                const double fy0 = pixel_centre_offset(quad.y, p.origin_y), fy1 = pixel_centre_offset(quad.y + 1, p.origin_y);
                const __m256d fy = _mm256_setr_pd(fy0, fy0, fy1, fy1);
                for (int k = 0; k <= V; ++k) row_term[k] = _mm256_mul_pd(pb[k], fy);
                row_y = quad.y, have_row = true;
            }
            Column& column = columns[(quad.x >> 1) & (kColumns - 1)];
            if (column.x != quad.x) {
                const double fx0 = pixel_centre_offset(quad.x, p.origin_x), fx1 = pixel_centre_offset(quad.x + 1, p.origin_x);
                const __m256d fx = _mm256_setr_pd(fx0, fx1, fx0, fx1);
                for (int k = 0; k <= V; ++k) column.term[k] = _mm256_add_pd(pc[k], _mm256_mul_pd(pa[k], fx));
                column.x = quad.x;
            }
            const __m256d q = constant_q ? q_constant : _mm256_div_pd(one, _mm256_add_pd(column.term[V], row_term[V]));
            for (int k = 0; k < V; ++k)
                _mm256_store_pd(&weights[k][4 * i], _mm256_mul_pd(_mm256_add_pd(column.term[k], row_term[k]), q));
        }
        for (size_t k = 0; k < count; ++k) {
            const __m256d v0 = _mm256_set1_pd(values[k]), v1 = _mm256_set1_pd(values[count + k]);
            const __m256d v2 = _mm256_set1_pd(V == 3 ? values[2 * count + k] : 0.0);
            float* const dst = reinterpret_cast<float*>(out + size_t(words[k]) * stride + 4 * i0);
            for (size_t i = 0; i < m; ++i) {
                __m256d s = _mm256_add_pd(zero, _mm256_mul_pd(_mm256_load_pd(&weights[0][4 * i]), v0));
                s = _mm256_add_pd(s, _mm256_mul_pd(_mm256_load_pd(&weights[1][4 * i]), v1));
                if constexpr (V == 3) s = _mm256_add_pd(s, _mm256_mul_pd(_mm256_load_pd(&weights[2][4 * i]), v2));
                _mm_storeu_ps(dst + 4 * i, _mm256_cvtpd_ps(s));
            }
        }
    }
}

// Two quads per register (lanes 0..3 quads[i], 4..7 quads[i + 1]), so a register's output is 8
// contiguous floats; otherwise interpolate_avx2's plan, except that each pair's pixel offsets are
// computed in vector registers from the two quads' coordinates (pixel_centre_offset's integer
// terms, then its conversion and scaling) and the planes evaluated in full: cheaper here than
// interpolate_avx2's row and column caches and their branches. An odd run's last quad is paired
// with itself, its second half never stored.
template <int V>
__attribute__((target("avx512f,avx512bw,avx512dq,avx512vl"))) void interpolate_avx512(
    const VaryingInterpolation& v, const Quad* quads, size_t n, uint32_t* out, size_t stride) {
    static_assert(sizeof(Quad) == 16 && offsetof(Quad, x) == 0 && offsetof(Quad, y) == 4, "two quads in 8 int32s");
    const PrimitiveSetup& p = *v.prim;
    const double* const values = v.values;
    const int* const words = v.words;
    const size_t count = v.count;
    const bool constant_q = constant_inv_w(p.inv_w);
    // w = 1 at every vertex (2D draws) makes q = 1 / 1 = 1 exactly, and e * 1.0 == e bit for bit
    // for every double e (+-0, +-inf, denormals: no FTZ/DAZ is set; NaN: e is an arithmetic result,
    // a quiet NaN, which x * 1 returns unchanged), so the weights skip that multiply.
    const bool unit_q = constant_q && 1.0 / p.inv_w.c == 1.0;
    const __m512d one = _mm512_set1_pd(1.0), zero = _mm512_setzero_pd(), q_constant = _mm512_set1_pd(1.0 / p.inv_w.c);
    __m512d pa[V + 1], pb[V + 1], pc[V + 1];   // weight[0..V-1], then inv_w
    for (int k = 0; k <= V; ++k) {
        const Plane& pl = k < V ? p.weight[k] : p.inv_w;
        pa[k] = _mm512_set1_pd(pl.a), pb[k] = _mm512_set1_pd(pl.b), pc[k] = _mm512_set1_pd(pl.c);
    }
    // Lane l's offset is ((coordinate << 8) + centre[l]) * (1 / kSubPixel), exactly
    // pixel_centre_offset's int64 terms (coordinate * kSubPixel + kSubPixel / 2 - origin, centre[l]
    // adding the pixel's dx or dy in its quad), conversion and product.
    static_assert(kSubPixel == 256, "the shift by 8");
    constexpr int64_t h = kSubPixel / 2, h1 = kSubPixel + kSubPixel / 2;
    const __m512i centre_x = _mm512_sub_epi64(_mm512_setr_epi64(h, h1, h, h1, h, h1, h, h1), _mm512_set1_epi64(p.origin_x));
    const __m512i centre_y = _mm512_sub_epi64(_mm512_setr_epi64(h, h, h1, h1, h, h, h1, h1), _mm512_set1_epi64(p.origin_y));
    // Two quads loaded as 8 int32 words: x at 0 and 4, y at 1 and 5.
    const __m256i pick_x = _mm256_setr_epi32(0, 0, 0, 0, 4, 4, 4, 4), pick_y = _mm256_setr_epi32(1, 1, 1, 1, 5, 5, 5, 5);
    const __m512d inv_sub = _mm512_set1_pd(1.0 / kSubPixel);
    auto offsets = [&](__m256i pair, __m256i pick, __m512i centre) __attribute__((target("avx512f,avx512dq"))) {
        const __m512i coordinate = _mm512_cvtepi32_epi64(_mm256_permutevar8x32_epi32(pair, pick));
        return _mm512_mul_pd(_mm512_cvtepi64_pd(_mm512_add_epi64(_mm512_slli_epi64(coordinate, 8), centre)), inv_sub);
    };
    constexpr size_t kRun = 32;   // even: a lone last quad's 8 lanes still fit
    alignas(64) double weights[V][4 * kRun];
    for (size_t i0 = 0; i0 < n; i0 += kRun) {
        const size_t m = std::min(kRun, n - i0);
        for (size_t i = 0; i < m; i += 2) {
            const Quad* const q0 = quads + i0 + i;
            const __m256i pair = i + 1 < m ? _mm256_loadu_si256(reinterpret_cast<const __m256i*>(q0))
                                           : _mm256_broadcastsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(q0)));
            const __m512d fx = offsets(pair, pick_x, centre_x), fy = offsets(pair, pick_y, centre_y);
            auto eval = [&](int k) __attribute__((target("avx512f"))) {
                return _mm512_add_pd(_mm512_add_pd(pc[k], _mm512_mul_pd(pa[k], fx)), _mm512_mul_pd(pb[k], fy));
            };
            const __m512d q = constant_q ? q_constant : _mm512_div_pd(one, eval(V));
            for (int k = 0; k < V; ++k) _mm512_store_pd(&weights[k][4 * i], unit_q ? eval(k) : _mm512_mul_pd(eval(k), q));
        }
        for (size_t k = 0; k < count; ++k) {
            const __m512d v0 = _mm512_set1_pd(values[k]), v1 = _mm512_set1_pd(values[count + k]);
            const __m512d v2 = _mm512_set1_pd(V == 3 ? values[2 * count + k] : 0.0);
            float* const dst = reinterpret_cast<float*>(out + size_t(words[k]) * stride + 4 * i0);
            for (size_t i = 0; i < m; i += 2) {
                __m512d s = _mm512_add_pd(zero, _mm512_mul_pd(_mm512_load_pd(&weights[0][4 * i]), v0));
                s = _mm512_add_pd(s, _mm512_mul_pd(_mm512_load_pd(&weights[1][4 * i]), v1));
                if constexpr (V == 3) s = _mm512_add_pd(s, _mm512_mul_pd(_mm512_load_pd(&weights[2][4 * i]), v2));
                const __mmask8 lanes = i + 1 < m ? 0xFF : 0x0F;
                _mm256_mask_storeu_ps(dst + 4 * i, lanes, _mm512_maskz_cvtpd_ps(lanes, s));
            }
        }
    }
}
#endif

}  // namespace

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
            return v.vertices == 3 ? interpolate_avx2<3>(v, quads, n, out, stride)
                                   : interpolate_avx2<2>(v, quads, n, out, stride);
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

}  // namespace softgl
