#include "softgl/pipeline/setup.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <utility>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SOFTGL_HAVE_SIMD_PROJECTION 1
#endif

namespace softgl {

namespace {

constexpr uint32_t kGlFront = 0x404, kGlBack = 0x405, kGlFrontAndBack = 0x408, kGlCcw = 0x901;

// floor(a / kSubPixel): the pixel of a fixed-point coordinate. An arithmetic shift (defined for
// negative a in C++20, and by GCC and Clang before), no division.
int64_t floor_pixel(int64_t a) { return a >> kSubPixelBits; }

// floor(x) for |x| < 2^62, exactly, without a libm call: truncate, then step down for negative
// non-integers.
int64_t floor_int(double x) {
    const int64_t t = int64_t(x);
    return t - int64_t(double(t) > x);   // no branch: the sign of x's fraction is random
}

// Snap a window coordinate to 1/256 pixel, round to nearest. The clamp catches the last ulp that
// guard-band clipping may leave outside the band (and keeps the conversion defined).
int64_t snap(double window) {
    window = std::min(std::max(window, -kGuardBand), kGuardBand);
    return floor_int(window * double(kSubPixel) + 0.5);
}

// Edge from (xj, yj) to (xk, yk) of a counter-clockwise polygon (window y up): E >= 0 inside.
// The tie rule (setup.h) is folded into c: an excluded edge needs E >= 1, i.e. E > 0.
void make_edge(PrimitiveSetup& s, int i, int64_t xj, int64_t yj, int64_t xk, int64_t yk) {
    const int64_t a = yj - yk, b = xk - xj;
    // a > 0: the edge runs downwards (interior to its right): a "left" edge.
    // a == 0, b > 0: horizontal, running right, interior above: a "bottom" edge.
    // Without branches: which edges are included is random for small triangles.
    const int excluded = !((a > 0) | ((a == 0) & (b > 0)));
    s.a[i] = a;
    s.b[i] = b;
    s.c[i] = -(a * xj + b * yj) - excluded;
    s.area_offset[i] = double(excluded);   // the area shape is the untied edge
}

// Two doubles per register (GCC/Clang vector extension): the same IEEE operations lane by lane.
typedef double Double2 __attribute__((vector_size(16)));

// Two planes (one per lane) through (0, 0, v0), (dx1, dy1, v1), (dx2, dy2, v2) (pixel offsets from
// vertex 0); inv_det = 1 / (dx1*dy2 - dx2*dy1).
void plane3(Double2 v0, Double2 v1, Double2 v2, double dx1, double dy1, double dx2, double dy2,
            double inv_det, Plane& p0, Plane& p1) {
    const Double2 a = ((v1 - v0) * dy2 - (v2 - v0) * dy1) * inv_det;
    const Double2 b = ((v2 - v0) * dx1 - (v1 - v0) * dx2) * inv_det;
    p0.a = a[0]; p0.b = b[0]; p0.c = v0[0];
    p1.a = a[1]; p1.b = b[1]; p1.c = v0[1];
}

// Whether the sample at the centre of some pixel of the bounding box is inside the triangle's
// edges (the rasterizer's exact test, tie rule included): a few pixels at most. The edge values
// step from pixel to pixel by 256 a and 256 b, the same exact integers as evaluating each.
bool covers_a_centre(const PrimitiveSetup& s) {
    const int64_t X = int64_t(s.x0) * kSubPixel + kSubPixel / 2, Y = int64_t(s.y0) * kSubPixel + kSubPixel / 2;
    int64_t row0 = s.a[0] * X + s.b[0] * Y + s.c[0];
    int64_t row1 = s.a[1] * X + s.b[1] * Y + s.c[1];
    int64_t row2 = s.a[2] * X + s.b[2] * Y + s.c[2];
    for (int32_t y = s.y0; y < s.y1; ++y) {
        int64_t e0 = row0, e1 = row1, e2 = row2;
        for (int32_t x = s.x0; x < s.x1; ++x) {
            if ((e0 | e1 | e2) >= 0) return true;   // every edge >= 0
            e0 += s.a[0] * kSubPixel, e1 += s.a[1] * kSubPixel, e2 += s.a[2] * kSubPixel;
        }
        row0 += s.b[0] * kSubPixel, row1 += s.b[1] * kSubPixel, row2 += s.b[2] * kSubPixel;
    }
    return false;
}

// What Setup::emit_triangle reads of a vertex: its snapped position, window z, and the values its
// planes interpolate, in three pairs: (z, 1/w), (weight_0/w, weight_1/w), (weight_2/w, 0).
template <class V>
std::array<Double2, 3> plane_values(const V& v) {   // Setup::WindowVertex: weights of its own
    const Double2 inv_w = {v.inv_w, v.inv_w};
    const Double2 w01 = Double2{v.weight[0], v.weight[1]} * inv_w;
    const Double2 w2 = Double2{v.weight[2], 0} * inv_w;
    return {Double2{v.z, v.inv_w}, w01, w2};
}

// A projected vertex of an unclipped triangle, corner k: its weights are 1 for vertex k and 0 for
// the others, so weight_j/w is 1/w or 0 -- the products 1 * (1/w) and 0 * (1/w) (1/w > 0 and
// finite) that plane_values computes for a WindowVertex with those weights.
struct UnitCorner {
    int64_t X, Y;
    double z, inv_w;
    int k;
    UnitCorner(const WindowPosition& p, int corner) : X(p.X), Y(p.Y), z(p.z), inv_w(p.inv_w), k(corner) {}
};

inline std::array<Double2, 3> plane_values(const UnitCorner& v) {
    return {Double2{v.z, v.inv_w}, Double2{v.k == 0 ? v.inv_w : 0.0, v.k == 1 ? v.inv_w : 0.0},
            Double2{v.k == 2 ? v.inv_w : 0.0, 0.0}};
}

Plane constant_plane(double v) {
    Plane p;
    p.c = v;
    return p;
}

}  // namespace

RasterState RasterState::for_target(int32_t width, int32_t height) {
    RasterState s;
    s.width = width;
    s.height = height;
    s.clip_x1 = width;
    s.clip_y1 = height;
    s.viewport.width = width;
    s.viewport.height = height;
    return s;
}

void RasterState::set_scissor(int32_t x, int32_t y, int32_t w, int32_t h) {
    clip_x0 = std::max(0, x);
    clip_y0 = std::max(0, y);
    clip_x1 = int32_t(std::min<int64_t>(width, int64_t(x) + w));
    clip_y1 = int32_t(std::min<int64_t>(height, int64_t(y) + h));
}

void SetupStats::add(const SetupStats& o) {
    primitives += o.primitives; invalid += o.invalid; outside += o.outside; clipped += o.clipped;
    culled += o.culled; zero_area += o.zero_area; emitted += o.emitted;
}

Setup::Setup(const RasterState& state)
    : state_(state), clipper_(state.viewport),
      transform_{state.viewport.scale_x(), state.viewport.offset_x(), state.viewport.scale_y(),
                 state.viewport.offset_y(), state.viewport.scale_z(), state.viewport.offset_z()} {
    // ES 3.0 §3.6.1: which faces cullFace drops (none when culling is off).
    const bool front = state.cull_face && (state.cull_face_mode == kGlFront || state.cull_face_mode == kGlFrontAndBack);
    const bool back = state.cull_face && (state.cull_face_mode == kGlBack || state.cull_face_mode == kGlFrontAndBack);
    cull_bits_ = uint8_t(front << 1 | back);
    ccw_is_front_ = state.front_face == kGlCcw;
}

inline Setup::WindowVertex Setup::project(const Vec4d& p, const double weight[3]) const {
    // ES 3.0 §2.12: perspective division, then the viewport transform.
    // Two divisions per instruction (GCC/Clang vector extension, IEEE division in each lane: the
    // same results as four scalar divisions, which dominate this function).
    typedef double Double2 __attribute__((vector_size(16)));
    const ViewportTransform& vp = transform_;
    const Double2 w2 = {p.w, p.w};
    const Double2 xy = Double2{p.x, p.y} / w2;
    const Double2 z_inv = Double2{p.z, 1.0} / w2;
    const Double2 window = Double2{vp.scale_x, vp.scale_y} * xy + Double2{vp.offset_x, vp.offset_y};
    WindowVertex w;
    w.X = snap(window[0]);
    w.Y = snap(window[1]);
    w.z = vp.scale_z * z_inv[0] + vp.offset_z;
    w.inv_w = z_inv[1];
    for (int k = 0; k < 3; ++k) w.weight[k] = weight[k];
    return w;
}

double Setup::resolvable_difference(double max_abs_z) const {
    // ES 3.0 §3.6.5: r is the smallest resolvable difference of window z. Fixed-point N-bit
    // depth: 1 / (2^N - 1), one step of the unorm encoding. Floating-point depth: 2^(e - 23),
    // e the exponent of the largest z of the primitive.
    if (state_.depth_bits > 0) return 1.0 / (std::ldexp(1.0, state_.depth_bits) - 1.0);
    if (!(max_abs_z > 0)) return std::ldexp(1.0, -126 - 23);
    int e = 0;
    std::frexp(max_abs_z, &e);         // max_abs_z = m * 2^e, m in [0.5, 1): IEEE exponent e - 1
    return std::ldexp(1.0, e - 1 - 23);
}

inline bool Setup::finish_bbox(PrimitiveSetup& s, int64_t xmin, int64_t ymin, int64_t xmax,
                        int64_t ymax) {
    // Pixel px has samples at px*256 + [0, 255]; it can be covered only if that range meets
    // [xmin, xmax].
    const int64_t x0 = std::max<int64_t>(floor_pixel(xmin), state_.clip_x0);
    const int64_t y0 = std::max<int64_t>(floor_pixel(ymin), state_.clip_y0);
    const int64_t x1 = std::min<int64_t>(floor_pixel(xmax) + 1, state_.clip_x1);
    const int64_t y1 = std::min<int64_t>(floor_pixel(ymax) + 1, state_.clip_y1);
    if (x0 >= x1 || y0 >= y1) return false;
    s.x0 = int32_t(x0); s.y0 = int32_t(y0); s.x1 = int32_t(x1); s.y1 = int32_t(y1);
    return true;
}

namespace {

// One vertex of project_vertices: the per-vertex part of Clipper::accepts, then Setup::project's
// operations (the same IEEE operations in every instantiation, so vectorised copies give the same
// bits). A vertex outside projects (0, 0, 0, 1) instead, so no NaN is converted to an integer.
__attribute__((always_inline)) inline void project_vertex(const float* p, const Clipper& clipper,
                                                          const ViewportTransform& vp, WindowPosition& out) {
    const Vec4d v{p[0], p[1], p[2], p[3]};
    const bool inside = finite_vertex(v) & (v.w >= kMinClippedW) & ((clipper.outcode(v) & ~kClipW) == 0);
    const double x = inside ? v.x : 0.0, y = inside ? v.y : 0.0, z = inside ? v.z : 0.0;
    const double w = inside ? v.w : 1.0;
    out.X = snap(vp.scale_x * (x / w) + vp.offset_x);
    out.Y = snap(vp.scale_y * (y / w) + vp.offset_y);
    out.z = vp.scale_z * (z / w) + vp.offset_z;
    out.inv_w = inside ? 1.0 / w : 0.0;
}

void project_scalar(const float* positions, size_t count, const Clipper& clipper,
                    const ViewportTransform& vp, WindowPosition* out) {
    for (size_t i = 0; i < count; ++i) project_vertex(positions + 4 * i, clipper, vp, out[i]);
}

#if defined(SOFTGL_HAVE_SIMD_PROJECTION)
// project_vertex for 8 vertices at a time: the same IEEE operations lane by lane, the clamp as
// max/min with the operand order that keeps std::max/std::min's result for NaN, and the exact
// floor as truncation (vcvttpd2qq) stepped down where the truncation exceeds the value.
// GCC 12's AVX-512 headers initialise their "undefined" operands from themselves.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#define SOFTGL_AVX512_PROJECTION __attribute__((target("avx512f,avx512dq")))

// snap() of 8 window coordinates.
SOFTGL_AVX512_PROJECTION inline __m512i snap8(__m512d window) {
    window = _mm512_min_pd(_mm512_set1_pd(kGuardBand), _mm512_max_pd(_mm512_set1_pd(-kGuardBand), window));
    const __m512d x = _mm512_add_pd(_mm512_mul_pd(window, _mm512_set1_pd(double(kSubPixel))), _mm512_set1_pd(0.5));
    const __m512i t = _mm512_cvttpd_epi64(x);
    const __mmask8 above = _mm512_cmp_pd_mask(_mm512_cvtepi64_pd(t), x, _CMP_GT_OQ);
    return _mm512_mask_sub_epi64(t, above, t, _mm512_set1_epi64(1));
}

SOFTGL_AVX512_PROJECTION inline __mmask8 ge(__m512d a, __m512d b) { return _mm512_cmp_pd_mask(a, b, _CMP_GE_OQ); }

SOFTGL_AVX512_PROJECTION void project_avx512(const float* positions, size_t count, const Clipper& clipper,
                                             const ViewportTransform& vp, WindowPosition* out) {
    const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
    // x, y, z, w of 8 vertices (two registers of 4 vertices each), one component per register.
    const __m512i pick[4] = {
        _mm512_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28, 0, 0, 0, 0, 0, 0, 0, 0),
        _mm512_setr_epi32(1, 5, 9, 13, 17, 21, 25, 29, 0, 0, 0, 0, 0, 0, 0, 0),
        _mm512_setr_epi32(2, 6, 10, 14, 18, 22, 26, 30, 0, 0, 0, 0, 0, 0, 0, 0),
        _mm512_setr_epi32(3, 7, 11, 15, 19, 23, 27, 31, 0, 0, 0, 0, 0, 0, 0, 0)};
    const __m512d p3x = _mm512_set1_pd(clipper.plane(3, 0)), p3w = _mm512_set1_pd(clipper.plane(3, 3));
    const __m512d p4x = _mm512_set1_pd(clipper.plane(4, 0)), p4w = _mm512_set1_pd(clipper.plane(4, 3));
    const __m512d p5y = _mm512_set1_pd(clipper.plane(5, 1)), p5w = _mm512_set1_pd(clipper.plane(5, 3));
    const __m512d p6y = _mm512_set1_pd(clipper.plane(6, 1)), p6w = _mm512_set1_pd(clipper.plane(6, 3));
    const __m512d min_w = _mm512_set1_pd(kMinClippedW);
    const __m512d scale_x = _mm512_set1_pd(vp.scale_x), offset_x = _mm512_set1_pd(vp.offset_x);
    const __m512d scale_y = _mm512_set1_pd(vp.scale_y), offset_y = _mm512_set1_pd(vp.offset_y);
    const __m512d scale_z = _mm512_set1_pd(vp.scale_z), offset_z = _mm512_set1_pd(vp.offset_z);
    // Records (X, Y, z, inv_w) of 2 vertices per register: interleave X with Y and z with inv_w,
    // then take 2 + 2 of those pairs.
    const __m512i pair_lo = _mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11);
    const __m512i pair_hi = _mm512_setr_epi64(4, 12, 5, 13, 6, 14, 7, 15);
    const __m512i record_lo = _mm512_setr_epi64(0, 1, 8, 9, 2, 3, 10, 11);
    const __m512i record_hi = _mm512_setr_epi64(4, 5, 12, 13, 6, 7, 14, 15);
    size_t i = 0;
    for (; i + 8 <= count; i += 8) {
        const __m512 lo = _mm512_loadu_ps(positions + 4 * i), hi = _mm512_loadu_ps(positions + 4 * i + 16);
        __m512d c[4];
        for (int k = 0; k < 4; ++k)
            c[k] = _mm512_cvtps_pd(_mm512_castps512_ps256(_mm512_permutex2var_ps(lo, pick[k], hi)));
        __m512d x = c[0], y = c[1], z = c[2], w = c[3];
        __mmask8 inside = 0xff;
        for (int k = 0; k < 4; ++k) inside &= _mm512_cmp_pd_mask(_mm512_sub_pd(c[k], c[k]), zero, _CMP_EQ_OQ);
        inside &= ge(w, min_w) & ge(_mm512_add_pd(z, w), zero) & ge(_mm512_sub_pd(w, z), zero);
        inside &= ge(_mm512_add_pd(_mm512_mul_pd(p3x, x), _mm512_mul_pd(p3w, w)), zero);
        inside &= ge(_mm512_add_pd(_mm512_mul_pd(p4x, x), _mm512_mul_pd(p4w, w)), zero);
        inside &= ge(_mm512_add_pd(_mm512_mul_pd(p5y, y), _mm512_mul_pd(p5w, w)), zero);
        inside &= ge(_mm512_add_pd(_mm512_mul_pd(p6y, y), _mm512_mul_pd(p6w, w)), zero);
        x = _mm512_maskz_mov_pd(inside, x);
        y = _mm512_maskz_mov_pd(inside, y);
        z = _mm512_maskz_mov_pd(inside, z);
        w = _mm512_mask_blend_pd(inside, one, w);
        const __m512i X = snap8(_mm512_add_pd(_mm512_mul_pd(scale_x, _mm512_div_pd(x, w)), offset_x));
        const __m512i Y = snap8(_mm512_add_pd(_mm512_mul_pd(scale_y, _mm512_div_pd(y, w)), offset_y));
        const __m512i Z = _mm512_castpd_si512(_mm512_add_pd(_mm512_mul_pd(scale_z, _mm512_div_pd(z, w)), offset_z));
        const __m512i inv_w = _mm512_castpd_si512(_mm512_maskz_div_pd(inside, one, w));
        const __m512i xy_lo = _mm512_permutex2var_epi64(X, pair_lo, Y), xy_hi = _mm512_permutex2var_epi64(X, pair_hi, Y);
        const __m512i zw_lo = _mm512_permutex2var_epi64(Z, pair_lo, inv_w), zw_hi = _mm512_permutex2var_epi64(Z, pair_hi, inv_w);
        int64_t* const dst = &out[i].X;
        _mm512_storeu_si512(dst, _mm512_permutex2var_epi64(xy_lo, record_lo, zw_lo));
        _mm512_storeu_si512(dst + 8, _mm512_permutex2var_epi64(xy_lo, record_hi, zw_lo));
        _mm512_storeu_si512(dst + 16, _mm512_permutex2var_epi64(xy_hi, record_lo, zw_hi));
        _mm512_storeu_si512(dst + 24, _mm512_permutex2var_epi64(xy_hi, record_hi, zw_hi));
    }
    for (; i < count; ++i) project_vertex(positions + 4 * i, clipper, vp, out[i]);
}
#pragma GCC diagnostic pop

// project_vertex for 4 vertices at a time with AVX2: the same IEEE operations lane by lane as
// project_avx512. AVX2 has no double-to-int64 conversion, but a clamped window coordinate times
// 256 is below 2^28 + 1 in magnitude, so truncation to int32 (vcvttpd2dq) is exact and is widened
// afterwards. The coordinate is never NaN: x/w of float32 inputs is below 2^277, finite in double.
#define SOFTGL_AVX2_PROJECTION __attribute__((target("avx2")))

// snap() of 4 window coordinates.
SOFTGL_AVX2_PROJECTION inline __m256i snap4(__m256d window) {
    window = _mm256_min_pd(_mm256_set1_pd(kGuardBand), _mm256_max_pd(_mm256_set1_pd(-kGuardBand), window));
    const __m256d x = _mm256_add_pd(_mm256_mul_pd(window, _mm256_set1_pd(double(kSubPixel))), _mm256_set1_pd(0.5));
    const __m128i t = _mm256_cvttpd_epi32(x);
    const __m256d above = _mm256_cmp_pd(_mm256_cvtepi32_pd(t), x, _CMP_GT_OQ);   // all ones: step down
    return _mm256_add_epi64(_mm256_cvtepi32_epi64(t), _mm256_castpd_si256(above));
}

SOFTGL_AVX2_PROJECTION inline __m256d ge4(__m256d a, __m256d b) { return _mm256_cmp_pd(a, b, _CMP_GE_OQ); }

SOFTGL_AVX2_PROJECTION void project_avx2(const float* positions, size_t count, const Clipper& clipper,
                                         const ViewportTransform& vp, WindowPosition* out) {
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
    const __m256d p3x = _mm256_set1_pd(clipper.plane(3, 0)), p3w = _mm256_set1_pd(clipper.plane(3, 3));
    const __m256d p4x = _mm256_set1_pd(clipper.plane(4, 0)), p4w = _mm256_set1_pd(clipper.plane(4, 3));
    const __m256d p5y = _mm256_set1_pd(clipper.plane(5, 1)), p5w = _mm256_set1_pd(clipper.plane(5, 3));
    const __m256d p6y = _mm256_set1_pd(clipper.plane(6, 1)), p6w = _mm256_set1_pd(clipper.plane(6, 3));
    const __m256d min_w = _mm256_set1_pd(kMinClippedW);
    const __m256d scale_x = _mm256_set1_pd(vp.scale_x), offset_x = _mm256_set1_pd(vp.offset_x);
    const __m256d scale_y = _mm256_set1_pd(vp.scale_y), offset_y = _mm256_set1_pd(vp.offset_y);
    const __m256d scale_z = _mm256_set1_pd(vp.scale_z), offset_z = _mm256_set1_pd(vp.offset_z);
    size_t i = 0;
    for (; i + 4 <= count; i += 4) {
        // x, y, z, w of 4 vertices, one component per register.
        __m128 r0 = _mm_loadu_ps(positions + 4 * i), r1 = _mm_loadu_ps(positions + 4 * i + 4);
        __m128 r2 = _mm_loadu_ps(positions + 4 * i + 8), r3 = _mm_loadu_ps(positions + 4 * i + 12);
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        __m256d x = _mm256_cvtps_pd(r0), y = _mm256_cvtps_pd(r1), z = _mm256_cvtps_pd(r2), w = _mm256_cvtps_pd(r3);
        __m256d inside;
        const __m256d finite_x = _mm256_cmp_pd(_mm256_sub_pd(x, x), zero, _CMP_EQ_OQ);
        const __m256d finite_y = _mm256_cmp_pd(_mm256_sub_pd(y, y), zero, _CMP_EQ_OQ);
        const __m256d finite_z = _mm256_cmp_pd(_mm256_sub_pd(z, z), zero, _CMP_EQ_OQ);
        const __m256d finite_w = _mm256_cmp_pd(_mm256_sub_pd(w, w), zero, _CMP_EQ_OQ);
        inside = _mm256_and_pd(_mm256_and_pd(finite_x, finite_y), _mm256_and_pd(finite_z, finite_w));
        inside = _mm256_and_pd(inside, _mm256_and_pd(ge4(w, min_w), ge4(_mm256_add_pd(z, w), zero)));
        inside = _mm256_and_pd(inside, ge4(_mm256_sub_pd(w, z), zero));
        inside = _mm256_and_pd(inside, ge4(_mm256_add_pd(_mm256_mul_pd(p3x, x), _mm256_mul_pd(p3w, w)), zero));
        inside = _mm256_and_pd(inside, ge4(_mm256_add_pd(_mm256_mul_pd(p4x, x), _mm256_mul_pd(p4w, w)), zero));
        inside = _mm256_and_pd(inside, ge4(_mm256_add_pd(_mm256_mul_pd(p5y, y), _mm256_mul_pd(p5w, w)), zero));
        inside = _mm256_and_pd(inside, ge4(_mm256_add_pd(_mm256_mul_pd(p6y, y), _mm256_mul_pd(p6w, w)), zero));
        x = _mm256_and_pd(inside, x);
        y = _mm256_and_pd(inside, y);
        z = _mm256_and_pd(inside, z);
        w = _mm256_blendv_pd(one, w, inside);
        const __m256i X = snap4(_mm256_add_pd(_mm256_mul_pd(scale_x, _mm256_div_pd(x, w)), offset_x));
        const __m256i Y = snap4(_mm256_add_pd(_mm256_mul_pd(scale_y, _mm256_div_pd(y, w)), offset_y));
        const __m256i Z = _mm256_castpd_si256(_mm256_add_pd(_mm256_mul_pd(scale_z, _mm256_div_pd(z, w)), offset_z));
        const __m256i inv_w = _mm256_castpd_si256(_mm256_and_pd(inside, _mm256_div_pd(one, w)));
        // Records (X, Y, z, inv_w): a 4 x 4 transpose of 64-bit elements.
        const __m256i xy02 = _mm256_unpacklo_epi64(X, Y), xy13 = _mm256_unpackhi_epi64(X, Y);
        const __m256i zw02 = _mm256_unpacklo_epi64(Z, inv_w), zw13 = _mm256_unpackhi_epi64(Z, inv_w);
        __m256i* const dst = reinterpret_cast<__m256i*>(&out[i]);
        _mm256_storeu_si256(dst + 0, _mm256_permute2x128_si256(xy02, zw02, 0x20));
        _mm256_storeu_si256(dst + 1, _mm256_permute2x128_si256(xy13, zw13, 0x20));
        _mm256_storeu_si256(dst + 2, _mm256_permute2x128_si256(xy02, zw02, 0x31));
        _mm256_storeu_si256(dst + 3, _mm256_permute2x128_si256(xy13, zw13, 0x31));
    }
    for (; i < count; ++i) project_vertex(positions + 4 * i, clipper, vp, out[i]);
}
#endif


// ---- Facing and culling of a block of triangles (Setup::triangles) ----
// What becomes of each triangle, from its projected vertices alone (Setup::unclipped_triangle's
// tests): the integers decide, so every level gives the same classes.
enum TriangleClass : uint8_t { kEmit, kZeroArea, kCulled, kClipped };

// cull_bits: Setup::cull_bits_ (bit 1 culls front faces, bit 0 back faces).
struct FacingRule {
    uint8_t cull_bits;
    bool ccw_is_front;
};

// One triangle: kClipped when a vertex failed the per-vertex acceptance (inv_w 0: clip it, or drop
// it, on the reference path); else its doubled signed area (exact: snapped coordinates lie within
// the guard band, |X| <= 2^28, so the products stay below 2^59) and what it decides.
inline uint8_t classify_triangle(const WindowPosition& p0, const WindowPosition& p1, const WindowPosition& p2,
                                 FacingRule rule, int64_t& area2) {
    area2 = (p1.X - p0.X) * (p2.Y - p0.Y) - (p2.X - p0.X) * (p1.Y - p0.Y);
    if (!((p0.inv_w > 0) & (p1.inv_w > 0) & (p2.inv_w > 0))) return kClipped;
    if (area2 == 0) return kZeroArea;
    const bool front = rule.ccw_is_front == (area2 > 0);
    return (rule.cull_bits >> int(front)) & 1 ? kCulled : kEmit;
}

void classify_scalar(const WindowPosition* window, const uint32_t* vertices, size_t count, FacingRule rule,
                     uint8_t* cls, int64_t* area2) {
    for (size_t n = 0; n < count; ++n) {
        const uint32_t* const v = vertices + 3 * n;
        cls[n] = classify_triangle(window[v[0]], window[v[1]], window[v[2]], rule, area2[n]);
    }
}

#if defined(SOFTGL_HAVE_SIMD_PROJECTION)
// classify_scalar for 4 triangles at a time: the vertices' fields gathered, the area's products by
// vpmuldq (signed 32 x 32 -> 64 bits: exact, the coordinate differences are below 2^29 because
// snap() clamps every coordinate to the guard band), the same integer tests.
// GCC 12's gather intrinsics initialise their "undefined" operands from themselves.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
SOFTGL_AVX2_PROJECTION void classify_avx2(const WindowPosition* window, const uint32_t* vertices, size_t count,
                                          FacingRule rule, uint8_t* cls, int64_t* area2) {
    static_assert(sizeof(WindowPosition) == 32, "4 words a vertex: X, Y, z, inv_w");
    const long long* const base = reinterpret_cast<const long long*>(window);
    const double* const inv_w_base = reinterpret_cast<const double*>(window) + 3;
    const __m128i stride = _mm_setr_epi32(0, 3, 6, 9);
    const __m256i zero = _mm256_setzero_si256();
    const __m256d zero_d = _mm256_setzero_pd();
    // Culled: front & cull front, or back & cull back (all-ones lanes where set).
    const __m256i cull_front = _mm256_set1_epi64x((rule.cull_bits & 2) ? -1 : 0);
    const __m256i cull_back = _mm256_set1_epi64x((rule.cull_bits & 1) ? -1 : 0);
    const __m256i flip = _mm256_set1_epi64x(rule.ccw_is_front ? 0 : -1);   // positive area is front when CCW
    size_t n = 0;
    for (; n + 4 <= count; n += 4) {
        const int* const v = reinterpret_cast<const int*>(vertices + 3 * n);
        __m256i X[3], Y[3];
        __m256d inside = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
        for (int k = 0; k < 3; ++k) {
            const __m128i word = _mm_slli_epi32(_mm_i32gather_epi32(v + k, stride, 4), 2);   // vertex * 4 words
            X[k] = _mm256_i32gather_epi64(base, word, 8);
            Y[k] = _mm256_i32gather_epi64(base + 1, word, 8);
            inside = _mm256_and_pd(inside, _mm256_cmp_pd(_mm256_i32gather_pd(inv_w_base, word, 8), zero_d, _CMP_GT_OQ));
        }
        const __m256i dx1 = _mm256_sub_epi64(X[1], X[0]), dy1 = _mm256_sub_epi64(Y[1], Y[0]);
        const __m256i dx2 = _mm256_sub_epi64(X[2], X[0]), dy2 = _mm256_sub_epi64(Y[2], Y[0]);
        const __m256i area = _mm256_sub_epi64(_mm256_mul_epi32(dx1, dy2), _mm256_mul_epi32(dx2, dy1));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(area2 + n), area);
        const __m256i is_zero = _mm256_cmpeq_epi64(area, zero);
        const __m256i front = _mm256_xor_si256(_mm256_cmpgt_epi64(area, zero), flip);
        const __m256i culled = _mm256_or_si256(_mm256_and_si256(front, cull_front), _mm256_andnot_si256(front, cull_back));
        const int in = _mm256_movemask_pd(inside);
        const int zm = _mm256_movemask_pd(_mm256_castsi256_pd(is_zero));
        const int cm = _mm256_movemask_pd(_mm256_castsi256_pd(culled));
        for (int j = 0; j < 4; ++j) {
            const int bit = 1 << j;
            cls[n + size_t(j)] = !(in & bit) ? kClipped : (zm & bit) ? kZeroArea : (cm & bit) ? kCulled : kEmit;
        }
    }
    classify_scalar(window, vertices + 3 * n, count - n, rule, cls + n, area2 + n);
}
#pragma GCC diagnostic pop
#endif

// ---- Records of unclipped triangles, 4 at a time (Setup::triangles) ----
// Setup::emit_triangle's fields for triangles that classify as kEmit, from the same integer and
// IEEE double operations lane by lane (no fused multiply-add: the file is built with
// -ffp-contract=off and the kernel enables no FMA), so every field has the reference's bits.
struct RecordBlockRule {
    bool ccw_is_front;
    bool tight;                               // sample_bounds with one sample (emit_triangle)
    int32_t clip_x0, clip_y0, clip_x1, clip_y1;
};

#if defined(SOFTGL_HAVE_SIMD_PROJECTION)
// A 4 x 4 transpose of 64-bit elements: out[j] = (r0[j], r1[j], r2[j], r3[j]).
SOFTGL_AVX2_PROJECTION inline void transpose4(__m256d r0, __m256d r1, __m256d r2, __m256d r3, __m256d out[4]) {
    const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
    const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
    out[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
    out[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
    out[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
    out[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}

// The low 32 bits of 4 int64 lanes (values that fit in int32).
SOFTGL_AVX2_PROJECTION inline __m128i low32(__m256i v) {
    return _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
}

SOFTGL_AVX2_PROJECTION inline __m256i min64(__m256i a, __m256i b) {
    return _mm256_castpd_si256(_mm256_blendv_pd(_mm256_castsi256_pd(a), _mm256_castsi256_pd(b),
                                                _mm256_castsi256_pd(_mm256_cmpgt_epi64(a, b))));
}
SOFTGL_AVX2_PROJECTION inline __m256i max64(__m256i a, __m256i b) {
    return _mm256_castpd_si256(_mm256_blendv_pd(_mm256_castsi256_pd(a), _mm256_castsi256_pd(b),
                                                _mm256_castsi256_pd(_mm256_cmpgt_epi64(b, a))));
}

// Two planes through (0, 0, v0), (dx1, dy1, v1), (dx2, dy2, v2), 4 triangles per register: plane3's
// operations in plane3's order.
SOFTGL_AVX2_PROJECTION inline void plane4(__m256d v0, __m256d v1, __m256d v2, __m256d dx1, __m256d dy1, __m256d dx2,
                                          __m256d dy2, __m256d inv_det, __m256d& a, __m256d& b) {
    const __m256d d1 = _mm256_sub_pd(v1, v0), d2 = _mm256_sub_pd(v2, v0);
    a = _mm256_mul_pd(_mm256_sub_pd(_mm256_mul_pd(d1, dy2), _mm256_mul_pd(d2, dy1)), inv_det);
    b = _mm256_mul_pd(_mm256_sub_pd(_mm256_mul_pd(d2, dx1), _mm256_mul_pd(d1, dx2)), inv_det);
}

// Records for triangles list[0 .. m) of the block (vertices[3t .. 3t + 2], doubled signed area
// area2[t], not 0, all vertices accepted), written in order to dst[0 ..) for the triangles
// emit_triangle keeps (bounding box not empty; with rule.tight, a box of at most 4 pixels covers
// a pixel centre): every field emit_triangle writes with polygon offset off. Returns how many were
// written; `sink` takes the stores of dropped triangles.
SOFTGL_AVX2_PROJECTION size_t build_records_avx2(const WindowPosition* window, const uint32_t* vertices,
                                                 const uint8_t* list, size_t m, const int64_t* area2,
                                                 uint32_t first_primitive, const RecordBlockRule& rule,
                                                 PrimitiveSetup* dst, PrimitiveSetup* sink) {
    static_assert(offsetof(PrimitiveSetup, a) == 0 && offsetof(PrimitiveSetup, b) == 32 &&
                  offsetof(PrimitiveSetup, c) == 64 && offsetof(PrimitiveSetup, x0) == 96 &&
                  offsetof(PrimitiveSetup, origin_x) == 112 && offsetof(PrimitiveSetup, depth) == 128 &&
                  offsetof(PrimitiveSetup, depth_offset) == 152 && offsetof(PrimitiveSetup, weight) == 160 &&
                  offsetof(PrimitiveSetup, inv_w) == 232 && offsetof(PrimitiveSetup, area_offset) == 288,
                  "the stores below write the record's fields in this layout");
    const __m256i zero = _mm256_setzero_si256();
    const __m256d zero_d = _mm256_setzero_pd();
    const __m256d inv = _mm256_set1_pd(1.0 / kSubPixel), det_num = _mm256_set1_pd(double(kSubPixel * kSubPixel));
    const __m256i low = _mm256_set1_epi64x(rule.tight ? kSubPixel / 2 - 1 : 0);
    const __m256i high = _mm256_set1_epi64x(rule.tight ? kSubPixel / 2 : 0);
    const __m128i clip_x0 = _mm_set1_epi32(rule.clip_x0), clip_y0 = _mm_set1_epi32(rule.clip_y0);
    const __m128i clip_x1 = _mm_set1_epi32(rule.clip_x1), clip_y1 = _mm_set1_epi32(rule.clip_y1);
    const __m128i one32 = _mm_set1_epi32(1), four32 = _mm_set1_epi32(4);
    const __m256d one_d = _mm256_set1_pd(1.0);
    size_t written = 0;
    for (size_t g = 0; g < m; g += 4) {
        const int lanes = int(std::min<size_t>(4, m - g));
        size_t t[4];
        for (int j = 0; j < 4; ++j) t[j] = list[std::min(g + size_t(j), m - 1)];
        // Corner k of the 4 triangles: X, Y, z, inv_w, one register each.
        __m256d X[3], Y[3], Z[3], W[3];
        for (int k = 0; k < 3; ++k) {
            __m256d r[4];
            for (int j = 0; j < 4; ++j)
                r[j] = _mm256_loadu_pd(reinterpret_cast<const double*>(&window[vertices[3 * t[j] + size_t(k)]]));
            __m256d f[4];
            transpose4(r[0], r[1], r[2], r[3], f);
            X[k] = f[0], Y[k] = f[1], Z[k] = f[2], W[k] = f[3];
        }
        const __m256i area = _mm256_setr_epi64x(area2[t[0]], area2[t[1]], area2[t[2]], area2[t[3]]);
        // Counter-clockwise order: corners 1 and 2 swap where the area is negative.
        const __m256d swap = _mm256_castsi256_pd(_mm256_cmpgt_epi64(zero, area));
        const __m256i x0 = _mm256_castpd_si256(X[0]), y0 = _mm256_castpd_si256(Y[0]);
        const __m256i x1 = _mm256_castpd_si256(_mm256_blendv_pd(X[1], X[2], swap));
        const __m256i y1 = _mm256_castpd_si256(_mm256_blendv_pd(Y[1], Y[2], swap));
        const __m256i x2 = _mm256_castpd_si256(_mm256_blendv_pd(X[2], X[1], swap));
        const __m256i y2 = _mm256_castpd_si256(_mm256_blendv_pd(Y[2], Y[1], swap));

        // Bounding box (finish_bbox): the pixel coordinates fit in int32 (guard band).
        const __m256i xmin = _mm256_add_epi64(min64(x0, min64(x1, x2)), low);
        const __m256i ymin = _mm256_add_epi64(min64(y0, min64(y1, y2)), low);
        const __m256i xmax = _mm256_sub_epi64(max64(x0, max64(x1, x2)), high);
        const __m256i ymax = _mm256_sub_epi64(max64(y0, max64(y1, y2)), high);
        const __m128i bx0 = _mm_max_epi32(_mm_srai_epi32(low32(xmin), kSubPixelBits), clip_x0);
        const __m128i by0 = _mm_max_epi32(_mm_srai_epi32(low32(ymin), kSubPixelBits), clip_y0);
        const __m128i bx1 = _mm_min_epi32(_mm_add_epi32(_mm_srai_epi32(low32(xmax), kSubPixelBits), one32), clip_x1);
        const __m128i by1 = _mm_min_epi32(_mm_add_epi32(_mm_srai_epi32(low32(ymax), kSubPixelBits), one32), clip_y1);
        const __m128i box_ok = _mm_and_si128(_mm_cmplt_epi32(bx0, bx1), _mm_cmplt_epi32(by0, by1));
        const int valid = _mm_movemask_ps(_mm_castsi128_ps(box_ok)) & ((1 << lanes) - 1);
        // Boxes of at most 4 pixels (tight only): the pixel-centre test below.
        const __m128i pixels = _mm_mullo_epi32(_mm_sub_epi32(bx1, bx0), _mm_sub_epi32(by1, by0));
        const int tiny = rule.tight ? valid & ~_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(pixels, four32))) : 0;
        __m128 box[4] = {_mm_castsi128_ps(bx0), _mm_castsi128_ps(by0), _mm_castsi128_ps(bx1), _mm_castsi128_ps(by1)};
        _MM_TRANSPOSE4_PS(box[0], box[1], box[2], box[3]);

        // Edges (make_edge): edge i opposite vertex i; a, b and the coordinates fit in int32, so
        // vpmuldq's products are the exact int64 products.
        const __m256i ex[3][2] = {{x1, x2}, {x2, x0}, {x0, x1}}, ey[3][2] = {{y1, y2}, {y2, y0}, {y0, y1}};
        __m256d ea[3], eb[3], ec[3], eo[3];
        for (int i = 0; i < 3; ++i) {
            const __m256i a = _mm256_sub_epi64(ey[i][0], ey[i][1]), b = _mm256_sub_epi64(ex[i][1], ex[i][0]);
            const __m256i included = _mm256_or_si256(_mm256_cmpgt_epi64(a, zero),
                                                     _mm256_and_si256(_mm256_cmpeq_epi64(a, zero), _mm256_cmpgt_epi64(b, zero)));
            const __m256i sum = _mm256_add_epi64(_mm256_mul_epi32(a, ex[i][0]), _mm256_mul_epi32(b, ey[i][0]));
            // -(a xj + b yj) - excluded: adding all ones subtracts 1.
            const __m256i c = _mm256_add_epi64(_mm256_sub_epi64(zero, sum), _mm256_andnot_si256(included, _mm256_set1_epi64x(-1)));
            ea[i] = _mm256_castsi256_pd(a), eb[i] = _mm256_castsi256_pd(b), ec[i] = _mm256_castsi256_pd(c);
            eo[i] = _mm256_andnot_pd(_mm256_castsi256_pd(included), one_d);
        }
        __m256d rows[4];
        PrimitiveSetup* d[4];
        // Which lanes are kept decides where each lane's stores go: edges and box first, so the
        // centre test reads them from the record.
        int keep = valid;
        for (int j = 0; j < 4; ++j) d[j] = sink;
        if (tiny) {
            transpose4(ea[0], ea[1], ea[2], zero_d, rows);
            for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(sink + j) + 0, rows[j]);
            transpose4(eb[0], eb[1], eb[2], zero_d, rows);
            for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(sink + j) + 4, rows[j]);
            transpose4(ec[0], ec[1], ec[2], zero_d, rows);
            for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(sink + j) + 8, rows[j]);
            for (int j = 0; j < 4; ++j) _mm_storeu_ps(reinterpret_cast<float*>(reinterpret_cast<double*>(sink + j) + 12), box[j]);
            for (int j = 0; j < 4; ++j)
                if (((tiny >> j) & 1) && !covers_a_centre(sink[j])) keep &= ~(1 << j);
        }
        for (int j = 0; j < 4; ++j) {
            d[j] = (keep >> j) & 1 ? dst + written : sink + 4;
            written += (keep >> j) & 1;
        }
        if (!keep) continue;
        transpose4(ea[0], ea[1], ea[2], zero_d, rows);
        for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(d[j]) + 0, rows[j]);
        transpose4(eb[0], eb[1], eb[2], zero_d, rows);
        for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(d[j]) + 4, rows[j]);
        transpose4(ec[0], ec[1], ec[2], zero_d, rows);
        for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(d[j]) + 8, rows[j]);
        for (int j = 0; j < 4; ++j) _mm_storeu_ps(reinterpret_cast<float*>(reinterpret_cast<double*>(d[j]) + 12), box[j]);
        transpose4(eo[0], eo[1], eo[2], zero_d, rows);
        for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(d[j]) + 36, rows[j]);

        // Planes: pixel offsets from vertex 0 (exact in double: below 2^30 in fixed point).
        const __m256d dx1 = _mm256_mul_pd(_mm256_cvtepi32_pd(low32(_mm256_sub_epi64(x1, x0))), inv);
        const __m256d dy1 = _mm256_mul_pd(_mm256_cvtepi32_pd(low32(_mm256_sub_epi64(y1, y0))), inv);
        const __m256d dx2 = _mm256_mul_pd(_mm256_cvtepi32_pd(low32(_mm256_sub_epi64(x2, x0))), inv);
        const __m256d dy2 = _mm256_mul_pd(_mm256_cvtepi32_pd(low32(_mm256_sub_epi64(y2, y0))), inv);
        // |area2| up to 2^59: converted as emit_triangle converts it (scalar, rounding to nearest).
        double area_d[4];
        for (int j = 0; j < 4; ++j) area_d[j] = double(area2[t[j]] < 0 ? -area2[t[j]] : area2[t[j]]);
        const __m256d inv_det = _mm256_div_pd(det_num, _mm256_loadu_pd(area_d));
        const __m256d z1 = _mm256_blendv_pd(Z[1], Z[2], swap), z2 = _mm256_blendv_pd(Z[2], Z[1], swap);
        const __m256d w1 = _mm256_blendv_pd(W[1], W[2], swap), w2 = _mm256_blendv_pd(W[2], W[1], swap);
        // Unit corners (UnitCorner): weight_m / w is 1/w at corner m, 0 elsewhere. Vertex 1 of the
        // counter-clockwise order is corner 2 where swapped, corner 1 otherwise; vertex 2 the other.
        const __m256d w0 = W[0];
        const __m256d w1_at1 = _mm256_andnot_pd(swap, w1), w1_at2 = _mm256_and_pd(swap, w1);
        const __m256d w2_at1 = _mm256_and_pd(swap, w2), w2_at2 = _mm256_andnot_pd(swap, w2);
        __m256d pa, pb, qa, qb;
        plane4(Z[0], z1, z2, dx1, dy1, dx2, dy2, inv_det, pa, pb);            // depth
        transpose4(pa, pb, Z[0], zero_d, rows);                               // depth, depth_offset
        for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(d[j]) + 16, rows[j]);
        plane4(w0, zero_d, zero_d, dx1, dy1, dx2, dy2, inv_det, pa, pb);      // weight[0]
        plane4(zero_d, w1_at1, w2_at1, dx1, dy1, dx2, dy2, inv_det, qa, qb);  // weight[1]
        transpose4(pa, pb, w0, qa, rows);                                     // weight[0], weight[1].a
        for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(d[j]) + 20, rows[j]);
        plane4(zero_d, w1_at2, w2_at2, dx1, dy1, dx2, dy2, inv_det, pa, pb);  // weight[2]
        transpose4(qb, zero_d, pa, pb, rows);                                 // weight[1].b, .c, weight[2].a, .b
        for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(d[j]) + 24, rows[j]);
        plane4(w0, w1, w2, dx1, dy1, dx2, dy2, inv_det, pa, pb);              // inv_w
        transpose4(zero_d, pa, pb, w0, rows);                                 // weight[2].c, inv_w
        for (int j = 0; j < 4; ++j) _mm256_storeu_pd(reinterpret_cast<double*>(d[j]) + 28, rows[j]);
        alignas(32) int64_t ox[4], oy[4];
        _mm256_store_si256(reinterpret_cast<__m256i*>(ox), x0);
        _mm256_store_si256(reinterpret_cast<__m256i*>(oy), y0);
        for (int j = 0; j < 4; ++j) {
            PrimitiveSetup& s = *d[j];
            s.origin_x = ox[j], s.origin_y = oy[j];
            const uint32_t* const v = vertices + 3 * t[j];
            s.vertex[0] = v[0], s.vertex[1] = v[1], s.vertex[2] = v[2];
            s.primitive = first_primitive + uint32_t(t[j]);
            s.kind = PrimitiveKind::Triangle;
            s.edge_count = 3;
            s.front_facing = rule.ccw_is_front == (area2[t[j]] > 0);
            s.area_shape = AreaShape::Polygon;
            s.point_x = s.point_y = s.point_size = 0;
        }
    }
    return written;
}
#endif

}  // namespace

void Setup::project_vertices(const float* positions, size_t count, WindowPosition* out, SimdLevel level) const {
#if defined(SOFTGL_HAVE_SIMD_PROJECTION)
    if (level == SimdLevel::AVX512) return project_avx512(positions, count, clipper_, transform_, out);
    if (level == SimdLevel::AVX2) return project_avx2(positions, count, clipper_, transform_, out);
#endif
    (void)level;
    project_scalar(positions, count, clipper_, transform_, out);
}

void Setup::triangle(const float* p0, const float* p1, const float* p2, uint32_t i0, uint32_t i1,
                     uint32_t i2, uint32_t primitive, std::vector<PrimitiveSetup>& out) {
    const float* const p[3] = {p0, p1, p2};
    WindowPosition window[3];
    for (int i = 0; i < 3; ++i) project_vertex(p[i], clipper_, transform_, window[i]);
    const WindowPosition* const w[3] = {&window[0], &window[1], &window[2]};
    const uint32_t vertex[3] = {i0, i1, i2};
    triangle(p, w, vertex, primitive, out);
}

void Setup::triangle(const float* positions, const WindowPosition* window, const uint32_t vertex[3],
                     uint32_t primitive, std::vector<PrimitiveSetup>& out) {
    const float* const p[3] = {positions + 4 * size_t(vertex[0]), positions + 4 * size_t(vertex[1]),
                               positions + 4 * size_t(vertex[2])};
    const WindowPosition* const w[3] = {&window[vertex[0]], &window[vertex[1]], &window[vertex[2]]};
    triangle(p, w, vertex, primitive, out);
}

inline void Setup::triangle(const float* const p[3], const WindowPosition* const wp[3], const uint32_t vertex[3],
                            uint32_t primitive, std::vector<PrimitiveSetup>& out) {
    ++stats.primitives;
    if ((wp[0]->inv_w > 0) & (wp[1]->inv_w > 0) & (wp[2]->inv_w > 0)) {
        // The common case (Clipper::accepts): what clip_triangle would return, unchanged.
        WindowVertex w[3];
        for (int i = 0; i < 3; ++i) {
            w[i].X = wp[i]->X; w[i].Y = wp[i]->Y; w[i].z = wp[i]->z; w[i].inv_w = wp[i]->inv_w;
            for (int k = 0; k < 3; ++k) w[i].weight[k] = k == i ? 1.0 : 0.0;
        }
        unclipped_triangle(w, vertex, primitive, out);
        return;
    }
    const Vec4d v[3] = {{p[0][0], p[0][1], p[0][2], p[0][3]},
                        {p[1][0], p[1][1], p[1][2], p[1][3]},
                        {p[2][0], p[2][1], p[2][2], p[2][3]}};
    ClipVertex poly[kMaxClipVertices];
    const int n = clipper_.clip_triangle(v, poly);
    if (n == 0) {
        if (!finite_vertex(v[0]) || !finite_vertex(v[1]) || !finite_vertex(v[2])) ++stats.invalid;
        else ++stats.outside;
        return;
    }
    WindowVertex w[kMaxClipVertices];
    for (int i = 0; i < n; ++i) w[i] = project(poly[i].position, poly[i].weight);
    if (n == 3 && poly[0].weight[0] == 1 && poly[1].weight[1] == 1 && poly[2].weight[2] == 1) {
        unclipped_triangle(w, vertex, primitive, out);
        return;
    }

    // Clipped polygon: the facing is that of the whole polygon (shoelace, 128-bit: up to 10 terms of
    // 2^59), and it is triangulated as a fan. A fan triangle that snapping made degenerate or
    // inverted is dropped: it covers no sample the neighbours do not.
    ++stats.clipped;
    __int128 poly_area2 = 0;
    for (int i = 0; i < n; ++i) {
        const int j = i + 1 == n ? 0 : i + 1;
        poly_area2 += __int128(w[i].X) * w[j].Y - __int128(w[j].X) * w[i].Y;
    }
    if (poly_area2 == 0) { ++stats.zero_area; return; }
    const bool ccw = poly_area2 > 0;
    const bool front = (state_.front_face == kGlCcw) == ccw;
    if (culled(front)) { ++stats.culled; return; }
    for (int i = 1; i + 1 < n; ++i) {
        const int64_t area2 = (w[i].X - w[0].X) * (w[i + 1].Y - w[0].Y) -
                              (w[i + 1].X - w[0].X) * (w[i].Y - w[0].Y);
        if (area2 == 0 || (area2 > 0) != ccw) continue;
        emit_triangle(w[0], w[i], w[i + 1], area2, front, vertex, primitive, out);
    }
}

inline bool Setup::culled(bool front) const { return (cull_bits_ >> int(front)) & 1; }

inline void Setup::unclipped_triangle(const WindowVertex w[3], const uint32_t vertex[3],
                               uint32_t primitive, std::vector<PrimitiveSetup>& out) {
    // ES 3.0 §3.6.1: the facing comes from the signed area in window coordinates.
    const int64_t area2 = (w[1].X - w[0].X) * (w[2].Y - w[0].Y) -
                          (w[2].X - w[0].X) * (w[1].Y - w[0].Y);
    if (area2 == 0) { ++stats.zero_area; return; }
    const bool front = ccw_is_front_ == (area2 > 0);
    if (culled(front)) { ++stats.culled; return; }
    emit_triangle(w[0], w[1], w[2], area2, front, vertex, primitive, out);
}

void Setup::triangles(const float* positions, const WindowPosition* window, const uint32_t* vertices,
                      size_t count, uint32_t first_primitive, std::vector<PrimitiveSetup>& out, SimdLevel level) {
    // A block at a time: classes and areas first (vectorised), then each triangle in order.
    constexpr size_t kBlock = 256;
    uint8_t cls[kBlock];
    int64_t area2[kBlock];
    const FacingRule rule{cull_bits_, ccw_is_front_};
    for (size_t first = 0; first < count; first += kBlock) {
        const size_t block = std::min(kBlock, count - first);
        const uint32_t* const block_vertices = vertices + 3 * first;
#if defined(SOFTGL_HAVE_SIMD_PROJECTION)
        if (level >= SimdLevel::AVX2) classify_avx2(window, block_vertices, block, rule, cls, area2);
        else
#endif
            classify_scalar(window, block_vertices, block, rule, cls, area2);
#if defined(SOFTGL_HAVE_SIMD_PROJECTION)
        // AVX2 and AVX-512 (which has AVX2): the records of emitted triangles 4 at a time.
        if (level >= SimdLevel::AVX2) {
            emit_block_avx2(positions, window, block_vertices, block, first_primitive + uint32_t(first), cls, area2, out);
            continue;
        }
#endif
        for (size_t n = 0; n < block; ++n) {
            const uint32_t* const vertex = block_vertices + 3 * n;
            const uint32_t primitive = first_primitive + uint32_t(first + n);
            switch (cls[n]) {
                case kEmit: {
                    ++stats.primitives;
                    const WindowPosition& p0 = window[vertex[0]];
                    const WindowPosition& p1 = window[vertex[1]];
                    const WindowPosition& p2 = window[vertex[2]];
                    emit_triangle(UnitCorner(p0, 0), UnitCorner(p1, 1), UnitCorner(p2, 2), area2[n],
                                  ccw_is_front_ == (area2[n] > 0), vertex, primitive, out);
                    break;
                }
                case kZeroArea: ++stats.primitives, ++stats.zero_area; break;
                case kCulled: ++stats.primitives, ++stats.culled; break;
                default: triangle(positions, window, vertex, primitive, out); break;   // clipped or dropped: the reference
            }
        }
    }
    (void)level;
}

#if defined(SOFTGL_HAVE_SIMD_PROJECTION)
void Setup::emit_block_avx2(const float* positions, const WindowPosition* window, const uint32_t* vertices,
                            size_t count, uint32_t first_primitive, const uint8_t* cls, const int64_t* area2,
                            std::vector<PrimitiveSetup>& out) {
    // Groups of 64 triangles. A group with no triangle to clip: the emitted ones' records are built
    // 4 at a time straight into `out` (build_records_avx2), in order, with the counters and the
    // polygon offset of emit_triangle. A group with one: triangle by triangle, as below AVX2.
    constexpr size_t kGroup = 64;
    PrimitiveSetup sink[8];   // stores of dropped triangles (and the centre test's edges)
    uint8_t list[kGroup];
    const bool tight = state_.sample_bounds && state_.samples == 1;
    const RecordBlockRule rule{ccw_is_front_, tight, state_.clip_x0, state_.clip_y0, state_.clip_x1, state_.clip_y1};
    for (size_t g0 = 0; g0 < count; g0 += kGroup) {
        const size_t group = std::min(kGroup, count - g0);
        size_t m = 0, zero_area = 0, culled = 0, clipped = 0;
        for (size_t n = g0; n < g0 + group; ++n) {
            list[m] = uint8_t(n);
            m += cls[n] == kEmit, zero_area += cls[n] == kZeroArea, culled += cls[n] == kCulled;
            clipped += cls[n] == kClipped;
        }
        if (clipped) {
            for (size_t n = g0; n < g0 + group; ++n) {
                const uint32_t* const vertex = vertices + 3 * n;
                const uint32_t primitive = first_primitive + uint32_t(n);
                switch (cls[n]) {
                    case kEmit: {
                        ++stats.primitives;
                        emit_triangle(UnitCorner(window[vertex[0]], 0), UnitCorner(window[vertex[1]], 1),
                                      UnitCorner(window[vertex[2]], 2), area2[n], ccw_is_front_ == (area2[n] > 0),
                                      vertex, primitive, out);
                        break;
                    }
                    case kZeroArea: ++stats.primitives, ++stats.zero_area; break;
                    case kCulled: ++stats.primitives, ++stats.culled; break;
                    default: triangle(positions, window, vertex, primitive, out); break;
                }
            }
            continue;
        }
        stats.primitives += group, stats.zero_area += zero_area, stats.culled += culled;
        if (m == 0) continue;
        const size_t first = out.size();
        out.resize(first + m);   // PrimitiveSetup's constructor writes nothing
        const size_t kept = build_records_avx2(window, vertices, list, m, area2, first_primitive, rule,
                                               out.data() + first, sink);
        out.resize(first + kept);
        stats.outside += m - kept, stats.emitted += kept;
        if (state_.polygon_offset_fill)   // as emit_triangle
            for (size_t r = first; r < first + kept; ++r) {
                PrimitiveSetup& s = out[r];
                const double slope = std::max(std::fabs(s.depth.a), std::fabs(s.depth.b));
                const double zmax = std::max({std::fabs(window[s.vertex[0]].z), std::fabs(window[s.vertex[1]].z),
                                              std::fabs(window[s.vertex[2]].z)});
                s.depth_offset = slope * state_.polygon_offset_factor +
                                 resolvable_difference(zmax) * state_.polygon_offset_units;
            }
    }
}
#endif

template <class V>
inline void Setup::emit_triangle(const V& w0, const V& w1, const V& w2, int64_t area2, bool front,
                                 const uint32_t vertex[3], uint32_t primitive, std::vector<PrimitiveSetup>& out) {
    // Counter-clockwise vertex order (interior has E >= 0).
    const V& v0 = w0;
    const V& v1 = area2 < 0 ? w2 : w1;
    const V& v2 = area2 < 0 ? w1 : w2;
    if (area2 < 0) area2 = -area2;
    // Nested min/max: conditional moves (min({...}) is a loop of unpredictable branches).
    int64_t xmin = std::min(v0.X, std::min(v1.X, v2.X)), xmax = std::max(v0.X, std::max(v1.X, v2.X));
    int64_t ymin = std::min(v0.Y, std::min(v1.Y, v2.Y)), ymax = std::max(v0.Y, std::max(v1.Y, v2.Y));
    const bool tight = state_.sample_bounds && state_.samples == 1;
    if (tight) {
        // Pixel p's centre p * 256 + 128 lies in [min, max] for floor_pixel(min + 127) <= p <=
        // floor_pixel(max - 128): finish_bbox's floor_pixel(min) and floor_pixel(max) + 1 of these
        // are exactly that range (a centre on the extent's border stays in: it may be covered).
        const int64_t low = kSubPixel / 2 - 1, high = kSubPixel / 2;
        xmin += low, ymin += low, xmax -= high, ymax -= high;
    }
    PrimitiveSetup& s = out.emplace_back();   // built in place (no copy of the large record)
    if (!finish_bbox(s, xmin, ymin, xmax, ymax)) { ++stats.outside; out.pop_back(); return; }
    make_edge(s, 0, v1.X, v1.Y, v2.X, v2.Y);     // edge i is opposite vertex i
    make_edge(s, 1, v2.X, v2.Y, v0.X, v0.Y);
    make_edge(s, 2, v0.X, v0.Y, v1.X, v1.Y);
    s.a[3] = s.b[3] = s.c[3] = 0;
    s.area_offset[3] = 0;
    s.area_shape = AreaShape::Polygon;
    if (tight && (s.x1 - s.x0) * (s.y1 - s.y0) <= 4 && !covers_a_centre(s)) { ++stats.outside; out.pop_back(); return; }

    s.origin_x = v0.X;
    s.origin_y = v0.Y;
    const double inv = 1.0 / kSubPixel;
    const double dx1 = double(v1.X - v0.X) * inv, dy1 = double(v1.Y - v0.Y) * inv;
    const double dx2 = double(v2.X - v0.X) * inv, dy2 = double(v2.Y - v0.Y) * inv;
    const double inv_det = double(kSubPixel * kSubPixel) / double(area2);
    const std::array<Double2, 3> q0 = plane_values(v0), q1 = plane_values(v1), q2 = plane_values(v2);
    Plane unused;
    plane3(q0[0], q1[0], q2[0], dx1, dy1, dx2, dy2, inv_det, s.depth, s.inv_w);
    plane3(q0[1], q1[1], q2[1], dx1, dy1, dx2, dy2, inv_det, s.weight[0], s.weight[1]);
    plane3(q0[2], q1[2], q2[2], dx1, dy1, dx2, dy2, inv_det, s.weight[2], unused);
    s.depth_offset = 0;
    if (state_.polygon_offset_fill) {
        // ES 3.0 §3.6.5: o = m * factor + r * units, m = max(|dz/dx|, |dz/dy|) (the allowed
        // approximation of the gradient length), added to every fragment's depth, then clamped.
        const double m = std::max(std::fabs(s.depth.a), std::fabs(s.depth.b));
        const double zmax = std::max({std::fabs(v0.z), std::fabs(v1.z), std::fabs(v2.z)});
        s.depth_offset = m * state_.polygon_offset_factor +
                         resolvable_difference(zmax) * state_.polygon_offset_units;
    }
    for (int k = 0; k < 3; ++k) s.vertex[k] = vertex[k];
    s.primitive = primitive;
    s.kind = PrimitiveKind::Triangle;
    s.edge_count = 3;
    s.front_facing = front;
    s.point_x = s.point_y = s.point_size = 0;
    ++stats.emitted;
}

void Setup::point(const float* p, float size, uint32_t index, uint32_t primitive,
                  std::vector<PrimitiveSetup>& out) {
    ++stats.primitives;
    const Vec4d v{p[0], p[1], p[2], p[3]};
    if (!finite_vertex(v)) { ++stats.invalid; return; }
    // ES 3.0 §2.17: a point is clipped by its centre, but only against w, near and far here: in x
    // and y a wide point whose centre is off-screen still draws its visible part (WebGL
    // conformance clipping-wide-points). Centres beyond the guard band are dropped (they are
    // 2^20 pixels away from any pixel). w = 0 leaves only the origin, which is no point (clip.h).
    if ((clipper_.outcode(v) & (kClipW | kClipNear | kClipFar)) || !(v.w > 0)) {
        ++stats.outside;
        return;
    }
    const ViewportTransform& vp = transform_;
    const double xw = vp.scale_x * (v.x / v.w) + vp.offset_x;
    const double yw = vp.scale_y * (v.y / v.w) + vp.offset_y;
    if (!(std::fabs(xw) <= kGuardBand && std::fabs(yw) <= kGuardBand)) { ++stats.outside; return; }
    // ES 3.0 §3.4: the size is clamped to the implementation's range. NaN becomes the minimum.
    double sz = size;
    if (!(sz >= state_.point_size_min)) sz = state_.point_size_min;
    if (sz > state_.point_size_max) sz = state_.point_size_max;

    // The square of side sz centred on the snapped centre; its edges follow the same tie rule as
    // triangles, so x in [left, right) and y in [bottom, top).
    PrimitiveSetup s;
    const int64_t X = snap(xw), Y = snap(yw);
    const int64_t h = int64_t(std::floor(sz * (kSubPixel / 2) + 0.5));
    const int64_t l = X - h, r = X + h, b = Y - h, t = Y + h;
    make_edge(s, 0, l, b, r, b);
    make_edge(s, 1, r, b, r, t);
    make_edge(s, 2, r, t, l, t);
    make_edge(s, 3, l, t, l, b);
    if (h == 0 || !finish_bbox(s, l, b, r, t)) { ++stats.outside; return; }
    s.origin_x = X;
    s.origin_y = Y;
    s.depth = constant_plane(vp.scale_z * (v.z / v.w) + vp.offset_z);
    s.depth_offset = 0;                         // polygon offset applies to polygons only
    s.inv_w = constant_plane(1.0 / v.w);
    s.weight[0] = constant_plane(1.0 / v.w);    // weights (1, 0, 0)
    s.weight[1] = s.weight[2] = constant_plane(0);
    s.vertex[0] = s.vertex[1] = s.vertex[2] = index;
    s.primitive = primitive;
    s.kind = PrimitiveKind::Point;
    s.edge_count = 4;
    s.front_facing = true;                      // ES 3.0 §3.6.1: points and lines are front-facing
    s.point_x = float(double(X) / kSubPixel);
    s.point_y = float(double(Y) / kSubPixel);
    s.point_size = float(double(2 * h) / kSubPixel);
    s.area_shape = state_.point_smooth && !state_.point_smooth_square ? AreaShape::Disk
                                                                       : AreaShape::Polygon;
    out.push_back(s);
    ++stats.emitted;
}

namespace {

// ---- The diamond-exit rule for width-1 lines, ES 3.0 §3.5.1 ----
// §3.5.1 perturbs both end points by (-eps, -eps^2), eps > 0 infinitesimal, so that no end point
// lies on a diamond's boundary. Every quantity tested below is an integer plus terms in eps and
// eps^2; its sign is the integer's unless that is 0, when the eps terms (worked out by hand at each
// test) decide: the limit eps -> 0, exactly. All in int64: snapped coordinates stay below 2^28 +
// 2^15 in magnitude (guard band, viewport.h; wide-line shift), so the products stay below 2^59.
constexpr int64_t kDiamondRadius = kSubPixel / 2;   // R_f = {|x - x_f| + |y - y_f| < 1/2}

// Does the segment from (ax, ay) to (bx, by) (fixed point, perturbed per §3.5.1) produce the
// fragment whose centre is (fx, fy)? It does when the segment meets the open diamond R_f and the
// end point is not inside R_f.
bool diamond_exit(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t fx, int64_t fy) {
    // |x - eps - fx| + |y - eps^2 - fy| < R. On the boundary the eps term decides: it is -eps
    // (inside) when x > fx, +eps when x <= fx (|u - eps| = |u| - eps for u > 0, |u| + eps else).
    auto inside = [&](int64_t x, int64_t y) {
        const int64_t d = std::abs(x - fx) + std::abs(y - fy) - kDiamondRadius;
        return d < 0 || (d == 0 && x > fx);
    };
    if (inside(bx, by)) return false;
    if (inside(ax, ay)) return true;
    // The L1 distance to the centre is convex and piecewise linear along the segment: besides the
    // end points its minimum can only be where the segment crosses x = fx or y = fy.
    const int64_t dx = bx - ax, dy = by - ay;
    // The crossing of x = fx, at t = (fx - ax + eps) / dx, lies on the segment when t is in
    // [0, 1]; a numerator of 0 or dx is moved inside (dx > 0) or outside (dx < 0) by the +eps.
    const int64_t tx = fx - ax;
    if (dx > 0 ? (0 <= tx && tx < dx) : (dx <= tx && tx < 0)) {
        // There |dx| * |y(t) - fy| = |c + dy*eps - dx*eps^2| < R |dx|; on equality (c != 0) the
        // sign of sign(c) * (dy*eps - dx*eps^2) decides.
        const int64_t c = (ay - fy) * dx + dy * tx;
        const int64_t m = std::abs(c) - kDiamondRadius * std::abs(dx);
        if (m < 0 || (m == 0 && (dy != 0 ? (c > 0) == (dy < 0) : (c > 0) == (dx > 0)))) return true;
    }
    // The crossing of y = fy, at t = (fy - ay + eps^2) / dy: the same with the axes swapped, where
    // |dy| * |x(t) - fx| = |c - dy*eps + dx*eps^2| (dy != 0 here decides a tie).
    const int64_t ty = fy - ay;
    if (dy > 0 ? (0 <= ty && ty < dy) : (dy <= ty && ty < 0)) {
        const int64_t c = (ax - fx) * dy + dx * ty;
        const int64_t m = std::abs(c) - kDiamondRadius * std::abs(dy);
        if (m < 0 || (m == 0 && (c > 0) == (dy > 0))) return true;
    }
    return false;
}

// Does the segment produce a fragment in major-axis column (x-major) or row (y-major) `m`?
//
// A column whose diamonds end before the segment starts or begin after it ends has none (the
// perturbation moves the ends by less than the one-unit margin). Otherwise only the diamonds whose
// centre is within R of the line at the column centre, minor coordinate y* (in the minor direction;
// at most two) can be met: a segment point P in the closed diamond of centre (C, f) has
// |y* - f| <= |y* - P_minor| + |P_minor - f| <= |P_major - C| + |P_minor - f| <= R, the line's slope
// being at most 1. With f = n*256 + 128 that is n <= y* / 256 <= n + 1, found in exact integers.
bool diamond_exit_in(int64_t ax, int64_t ay, int64_t bx, int64_t by, bool x_major, int64_t m) {
    const int64_t centre = m * kSubPixel + kSubPixel / 2;
    const int64_t ma = x_major ? ax : ay, mb = x_major ? bx : by;
    if (std::max(ma, mb) < centre - kDiamondRadius || std::min(ma, mb) > centre + kDiamondRadius) return false;
    const int64_t na = x_major ? ay : ax, dmajor = mb - ma, dminor = x_major ? by - ay : bx - ax;
    // y* = num / den, den = the major difference (not 0: |major| >= |minor| and not both 0).
    int64_t num = na * dmajor + dminor * (centre - ma), den = dmajor;
    if (den < 0) num = -num, den = -den;
    den *= kSubPixel;
    int64_t n = num / den, rem = num % den;   // n = floor(y* / 256)
    if (rem < 0) --n, rem += den;
    for (int64_t k = n; k >= n - (rem == 0); --k) {   // and n - 1 when y* / 256 is an integer
        const int64_t other = k * kSubPixel + kSubPixel / 2;
        if (x_major ? diamond_exit(ax, ay, bx, by, centre, other)
                    : diamond_exit(ax, ay, bx, by, other, centre))
            return true;
    }
    return false;
}

// The first and last major-axis pixel index with a fragment, column by column. Every column
// strictly between them has one (the segment crosses its centre line inside the diamond), so only
// the ends need the exact test; for long lines each scan stops after at most three columns. False:
// no fragment at all.
bool diamond_exit_scan(int64_t ax, int64_t ay, int64_t bx, int64_t by, bool x_major, int64_t& first, int64_t& last) {
    // Only columns whose diamonds reach the segment's major range [mn, mx] can have a fragment
    // (diamond_exit_in's first test): m * 256 <= mx and (m + 1) * 256 >= mn, i.e. from
    // ceil(mn / 256) - 1 to floor(mx / 256). The scans start there, not one column further out.
    const int64_t mn = std::min(x_major ? ax : ay, x_major ? bx : by), mx = std::max(x_major ? ax : ay, x_major ? bx : by);
    const int64_t lo = floor_pixel(mn + kSubPixel - 1) - 1;
    const int64_t hi = floor_pixel(mx);
    first = lo;
    while (first <= hi && !diamond_exit_in(ax, ay, bx, by, x_major, first)) ++first;
    if (first > hi) return false;
    last = hi;
    while (last > first && !diamond_exit_in(ax, ay, bx, by, x_major, last)) --last;
    return true;
}

// The same range from the two end points only, for a segment steeper along its major axis than
// along its minor one (|slope| < 1; the scan decides the slope +-1). Along such a segment the L1
// distance to a diamond's centre strictly grows with the distance to the centre's major line
// (|major - C| grows at rate 1, |minor - f| at a rate below 1), so, with the perturbed ends never
// on a centre line (the perturbation moves them by less than the integer gap):
//  - a column whose centre line C the segment crosses (by major coordinate C in [a, b) going up,
//    [b, a) going down: diamond_exit's crossing condition) has a fragment unless the end point is
//    inside the diamond it crosses; the end point can only be in that of the last such column
//    (the one nearest the end; there it is the diamond of the end's minor pixel, found without a
//    division: an end inside makes the crossing strictly inside the same diamond);
//  - a column the segment does not cross has its nearest point at an end: beyond the start, a
//    fragment when the start is inside the diamond of its minor pixel and the end is not; beyond
//    the end, none (the segment would have to enter the diamond through the end).
// The minor pixel of an end at minor coordinate n is floor((n - 1) / 256): on a pixel border the
// diamond to its left, which diamond_exit's tie (x > cx) may hold; for y either one is outside.
inline bool diamond_exit_ends(int64_t ax, int64_t ay, int64_t bx, int64_t by, bool x_major, int64_t& first,
                              int64_t& last) {
    // Major (m) and minor (n) coordinates; diamond_exit's tie (x > cx) is on the major axis when
    // the segment is x-major.
    const int64_t am = x_major ? ax : ay, an = x_major ? ay : ax, bm = x_major ? bx : by, bn = x_major ? by : bx;
    auto inside = [x_major](int64_t m, int64_t n, int64_t cm, int64_t cn) {
        const int64_t d = std::abs(m - cm) + std::abs(n - cn) - kDiamondRadius;
        return d < 0 || (d == 0 && (x_major ? m > cm : n > cn));
    };
    auto centre = [](int64_t pixel) { return pixel * kSubPixel + kSubPixel / 2; };
    const bool up = bm > am;
    const int64_t step = up ? 1 : -1;
    // The crossed columns (centres in [am, bm) going up, [bm, am) going down), from the one nearest
    // the start to the one nearest the end; the column beyond the start.
    const int64_t cross_a = floor_pixel(am + (up ? kSubPixel / 2 - 1 : -kSubPixel / 2 - 1));
    const int64_t cross_b = floor_pixel(bm + (up ? -kSubPixel / 2 - 1 : kSubPixel / 2 - 1));
    const int64_t before = cross_a - step;
    const int64_t fa = centre(floor_pixel(an - 1)), fb = centre(floor_pixel(bn - 1));
    const int64_t c_before = centre(before);
    const bool start = inside(am, an, c_before, fa) && !inside(bm, bn, c_before, fa);
    // The crossed columns with a fragment: cross_a .. end (none when end is before cross_a).
    const bool crosses = up ? cross_a <= cross_b : cross_b <= cross_a;
    const int64_t end = crosses && inside(bm, bn, centre(cross_b), fb) ? cross_b - step : cross_b;
    const bool crossed = up ? cross_a <= end : end <= cross_a;
    if (!start && !crossed) return false;
    const int64_t from = start ? before : cross_a, to = crossed ? end : before;
    first = std::min(from, to);
    last = std::max(from, to);
    return true;
}

// diamond_exit_span for Setup::line, which knows the major axis.
inline bool diamond_exit_columns(int64_t ax, int64_t ay, int64_t bx, int64_t by, bool x_major, int64_t& first,
                                 int64_t& last) {
    if (std::abs(bx - ax) == std::abs(by - ay)) return diamond_exit_scan(ax, ay, bx, by, x_major, first, last);
    return diamond_exit_ends(ax, ay, bx, by, x_major, first, last);
}

}  // namespace

bool diamond_exit_span(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t& first, int64_t& last,
                       DiamondExitMethod method) {
    const bool x_major = std::abs(bx - ax) >= std::abs(by - ay);
    if (method == DiamondExitMethod::Scan) return diamond_exit_scan(ax, ay, bx, by, x_major, first, last);
    return diamond_exit_columns(ax, ay, bx, by, x_major, first, last);
}

void Setup::line(const float* p0, const float* p1, uint32_t i0, uint32_t i1, uint32_t primitive,
                 std::vector<PrimitiveSetup>& out) {
    WindowPosition w[2];
    project_vertex(p0, clipper_, transform_, w[0]);
    project_vertex(p1, clipper_, transform_, w[1]);
    line(p0, p1, w[0], w[1], i0, i1, primitive, out);
}

void Setup::line(const float* positions, const WindowPosition* window, const uint32_t vertex[2], uint32_t primitive,
                 std::vector<PrimitiveSetup>& out) {
    line(positions + 4 * size_t(vertex[0]), positions + 4 * size_t(vertex[1]), window[vertex[0]], window[vertex[1]],
         vertex[0], vertex[1], primitive, out);
}

inline void Setup::line(const float* p0, const float* p1, const WindowPosition& w0, const WindowPosition& w1,
                        uint32_t i0, uint32_t i1, uint32_t primitive, std::vector<PrimitiveSetup>& out) {
    ++stats.primitives;
    WindowVertex a, e;
    if ((w0.inv_w > 0) & (w1.inv_w > 0)) {
        // The common case (Clipper::accepts for both ends): what clip_line and project would give,
        // the ends unchanged with weights (1, 0, 0) and (0, 1, 0).
        a = WindowVertex{w0.X, w0.Y, w0.z, w0.inv_w, {1, 0, 0}};
        e = WindowVertex{w1.X, w1.Y, w1.z, w1.inv_w, {0, 1, 0}};
    } else {
        const Vec4d v[2] = {{p0[0], p0[1], p0[2], p0[3]}, {p1[0], p1[1], p1[2], p1[3]}};
        ClipVertex c[2];
        if (!clipper_.clip_line(v, c)) {
            if (!finite_vertex(v[0]) || !finite_vertex(v[1])) ++stats.invalid;
            else ++stats.outside;
            return;
        }
        if (c[0].weight[0] != 1 || c[1].weight[1] != 1) ++stats.clipped;
        a = project(c[0].position, c[0].weight), e = project(c[1].position, c[1].weight);
    }
    const int64_t dx = e.X - a.X, dy = e.Y - a.Y;
    if (dx == 0 && dy == 0) { ++stats.zero_area; return; }
    const bool x_major = (dx < 0 ? -dx : dx) >= (dy < 0 ? -dy : dy);

    PrimitiveSetup& s = out.emplace_back();   // built in place; removed again if dropped
    s.area_shape = AreaShape::Polygon;
    int64_t bxmin, bymin, bxmax, bymax;   // fixed-point bounding box of the shape
    if (state_.line_smooth) {
        // GL 1.5 §3.4.2 (antialiasing): the rectangle of width w (not rounded) and the segment's
        // length, centred on the segment. Ends: (P - A).d >= 0 and (B - P).d >= 0, exact integers.
        // Sides: |(P - A) x d| <= (w/2) |d|, irrational: c = floor(C) keeps the integer test exact
        // at every fixed-point position (E is an integer there) and area_offset = C - floor(C)
        // carries the exact side for the area.
        const double len = std::sqrt(double(dx) * double(dx) + double(dy) * double(dy));
        const double half = 0.5 * state_.line_width * double(kSubPixel) * len;   // E units
        const double half_floor = std::floor(half);
        auto set = [&](int i, int64_t ea, int64_t eb, int64_t ec, double off) {
            s.a[i] = ea; s.b[i] = eb; s.c[i] = ec; s.area_offset[i] = off;
        };
        set(0, dx, dy, -(dx * a.X + dy * a.Y), 0.0);
        set(1, -dx, -dy, dx * e.X + dy * e.Y, 0.0);
        set(2, -dy, dx, (dy * a.X - dx * a.Y) + int64_t(half_floor), half - half_floor);
        set(3, dy, -dx, (dx * a.Y - dy * a.X) + int64_t(half_floor), half - half_floor);
        s.edge_count = 4;
        // Bounding box of the four corners A, B +- n (w/2), one unit outwards for rounding.
        const double ox = std::fabs(double(dy)) * (0.5 * state_.line_width * kSubPixel / len);
        const double oy = std::fabs(double(dx)) * (0.5 * state_.line_width * kSubPixel / len);
        bxmin = int64_t(std::floor(double(std::min(a.X, e.X)) - ox)) - 1;
        bxmax = int64_t(std::ceil(double(std::max(a.X, e.X)) + ox)) + 1;
        bymin = int64_t(std::floor(double(std::min(a.Y, e.Y)) - oy)) - 1;
        bymax = int64_t(std::ceil(double(std::max(a.Y, e.Y)) + oy)) + 1;
    } else {
        // ES 3.0 §3.5.2: the width of non-antialiased lines is rounded to the nearest integer
        // (0 counts as 1). A line of width w is the width-1 line of the segment offset by
        // -(w-1)/2 in the minor direction, each fragment replaced by w fragments in the minor
        // direction. In the minor direction that is the band of half-width w/2 around the segment
        // with the tie rule (exactly the diamond rule's choice, including centres on the band's
        // border, which the eps perturbation of §3.5.1 resolves the same way); along the major
        // axis the diamond-exit rule decides which end pixels the offset segment produces.
        const int64_t w = std::max<int64_t>(1, floor_int(state_.line_width + 0.5));
        const int64_t h = w * (kSubPixel / 2);
        int64_t px[4], py[4];
        if (x_major) {
            px[0] = a.X; py[0] = a.Y - h; px[1] = e.X; py[1] = e.Y - h;
            px[2] = e.X; py[2] = e.Y + h; px[3] = a.X; py[3] = a.Y + h;
        } else {
            px[0] = a.X + h; py[0] = a.Y; px[1] = e.X + h; py[1] = e.Y;
            px[2] = e.X - h; py[2] = e.Y; px[3] = a.X - h; py[3] = a.Y;
        }
        // The parallelogram's signed area is 2h * dx (x-major) or 2h * dy (y-major), never 0: the
        // corners are counter-clockwise as listed when it is positive, else reversed.
        if (x_major ? dx < 0 : dy < 0) {
            std::swap(px[0], px[3]); std::swap(py[0], py[3]);
            std::swap(px[1], px[2]); std::swap(py[1], py[2]);
        }
        const int64_t hx = x_major ? 0 : h, hy = x_major ? h : 0;
        bxmin = std::min(a.X, e.X) - hx; bxmax = std::max(a.X, e.X) + hx;
        bymin = std::min(a.Y, e.Y) - hy; bymax = std::max(a.Y, e.Y) + hy;
        if (state_.samples == 1 && state_.line_rule == LineRule::DiamondExit) {
            // The two band edges (parallel to the segment: edges 0 and 2 of the parallelogram);
            // instead of its end edges, the bounding box's major-axis range [lo, hi): the pixel
            // boundaries around the first and last major-axis pixel the diamond-exit rule
            // produces. Two edges: the rasterizer tests half as many per pixel.
            const int64_t shift = (w - 1) * (kSubPixel / 2);
            const int64_t sax = x_major ? a.X : a.X - shift, say = x_major ? a.Y - shift : a.Y;
            const int64_t sbx = x_major ? e.X : e.X - shift, sby = x_major ? e.Y - shift : e.Y;
            int64_t first, last;
            if (!diamond_exit_columns(sax, say, sbx, sby, x_major, first, last)) {
                ++stats.zero_area;
                out.pop_back();
                return;
            }
            const int64_t lo = first * kSubPixel, hi = (last + 1) * kSubPixel;   // [lo, hi)
            make_edge(s, 0, px[0], py[0], px[1], py[1]);
            make_edge(s, 1, px[2], py[2], px[3], py[3]);
            s.edge_count = 2;
            // The end pixels lie within 1/2 pixel (major) of the offset segment's ends, so the
            // band there lies within 1/2 pixel (minor, |slope| <= 1) of the original bounds.
            if (x_major) {
                bxmin = lo; bxmax = hi - 1;
                bymin -= kSubPixel / 2; bymax += kSubPixel / 2;
            } else {
                bymin = lo; bymax = hi - 1;
                bxmin -= kSubPixel / 2; bxmax += kSubPixel / 2;
            }
        } else {
            for (int i = 0; i < 4; ++i) make_edge(s, i, px[i], py[i], px[(i + 1) & 3], py[(i + 1) & 3]);
            s.edge_count = 4;
        }
    }
    if (!finish_bbox(s, bxmin, bymin, bxmax, bymax)) {
        ++stats.outside;
        out.pop_back();
        return;
    }
    // ES 3.0 §3.5.1 eq. 3.7: values along the line use t = ((p - pa) . (pb - pa)) / |pb - pa|^2,
    // which is a plane in window space.
    s.origin_x = a.X;
    s.origin_y = a.Y;
    const double fx = double(dx) / kSubPixel, fy = double(dy) / kSubPixel;
    const double inv_len2 = 1.0 / (fx * fx + fy * fy);
    auto along = [&](double va, double vb) {
        Plane p;
        p.a = (vb - va) * fx * inv_len2;
        p.b = (vb - va) * fy * inv_len2;
        p.c = va;
        return p;
    };
    s.depth = along(a.z, e.z);
    s.depth_offset = 0;
    s.inv_w = along(a.inv_w, e.inv_w);
    for (int k = 0; k < 3; ++k) s.weight[k] = along(a.weight[k] * a.inv_w, e.weight[k] * e.inv_w);
    s.vertex[0] = i0; s.vertex[1] = i1; s.vertex[2] = i1;
    s.primitive = primitive;
    s.kind = PrimitiveKind::Line;
    s.front_facing = true;
    s.point_x = s.point_y = s.point_size = 0;
    ++stats.emitted;
}

}  // namespace softgl
