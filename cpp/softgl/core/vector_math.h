// softgl's own exp2, log2, exp, log, pow, sin and cos: the GLSL built-ins (glsl/executor.cpp)
// and anything else that wants them in a lane loop. Written so that the compiler vectorises a
// loop calling them at every SIMD level (core/simd.h): no branches, no tables, no libm; float in
// and out, double inside. Every level runs the same IEEE double operations in the same order
// (the build has no FMA contraction), so the bits are the same at every width and on every CPU.
//
// Why double inside: a float input is exact in double, the polynomials reach 5e-11 relative or
// better, and the one rounding to float at the end makes each result the float nearest the
// exact value except when that value is within ~5e-11 of a half-way point: errors are at most
// 0.5012 ulp (docs/architecture.md, "Numeric rules", has the measured maxima). pow(x, y) is
// exp2(y·log2(x)) with log2 kept in double, so it is as accurate as exp2 (GLSL ES 3.00 §8.2
// allows far more) and pow(x, 1.0) == x. The one branch: sin and cos of an argument of 2^25 or
// more (rare) reduce lane by lane (sin_cos_lanes).
//
// Special values follow the formulas: exp2/exp of ±inf give inf/0, log2/log give -inf at ±0,
// NaN below 0, inf at inf; NaN in gives NaN out. pow is exp2(y·log2(x)) also where ES 3.00 §8.2
// leaves it undefined: NaN for x < 0 and for x = 0, y = 0; +inf for x = 0, y < 0; and
// pow(1, ±inf), pow(inf, 0) are NaN. sin and cos reduce exactly by multiples of π/2 over the
// whole float range (Cody-Waite below 2^25, Payne-Hanek above), are NaN at ±inf and keep -0.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>

// Forced inline: the executor's loops are compiled once per SIMD level and must get their own copies.
#define SOFTGL_VM_INLINE inline __attribute__((always_inline))
#define SOFTGL_VM_LAMBDA __attribute__((always_inline))

namespace softgl::vmath {
namespace detail {

SOFTGL_VM_INLINE uint64_t bits(double d) { uint64_t u; std::memcpy(&u, &d, 8); return u; }
SOFTGL_VM_INLINE double from_bits(uint64_t u) { double d; std::memcpy(&d, &u, 8); return d; }

// t + kRound - kRound rounds t (|t| < 2^51) to an integer; t + kRound holds it in its low bits.
constexpr double kRound = 0x1.8p52;

// 2^t for |t| <= 200 (NaN gives garbage: callers select it away). t = k + f, |f| <= 1/2; 2^f
// by a degree-7 polynomial fitted for relative error (< 5e-11 on [-1/2, 1/2]; tests/glsl/
// test_vector_math.py measures the result), then k added to the exponent field.
SOFTGL_VM_INLINE double exp2_kernel(double t) {
    const double shifted = t + kRound;
    const double f = t - (shifted - kRound);   // exact
    double p = 0x1.fe177b584965dp-17;
    p = p * f + 0x1.446a1fd0e54d0p-13;
    p = p * f + 0x1.5d8a708fbcbf6p-10;
    p = p * f + 0x1.3b29dc40e5263p-7;
    p = p * f + 0x1.c6b08aaf2786dp-5;
    p = p * f + 0x1.ebfbe0a4be6d2p-3;
    p = p * f + 0x1.62e42ff1162c0p-1;
    p = p * f + 1.0;                           // 2^k exactly at integers
    return from_bits(bits(p) + (bits(shifted) << 52));   // the low bits of `shifted` are k
}

// 2^t for any double t (±inf, NaN included), to be rounded to float: 2^±200 round to 0 / inf.
// (Selects in double keep every mask 64 bits wide, with no repacking between float and double.)
SOFTGL_VM_INLINE double exp2_any(double t) {
    const double c = t < -200.0 ? -200.0 : (t > 200.0 ? 200.0 : t);
    const double r = exp2_kernel(c);
    return t != t ? t : r;
}

// log2(d) or ln(d) for d > 0 finite, from d = 2^e·m with m in [√½, √2): log(m) = s·P(s²) with
// s = (m - 1)/(m + 1), |s| <= 0.172 and P fitted to 2·atanh(s)/s (relative error < 4e-13: pow's
// y·log2(x) needs it for large y).
// m - 1 and m + 1 are exact because d came from a float (24 significant bits). `base2` picks
// P/ln2 or P.
template <bool base2>
SOFTGL_VM_INLINE double log_kernel(double d) {
    const uint64_t b = bits(d);
    const uint64_t biased = (b + (0x3ff0000000000000ull - 0x3fe6a09e667f3bcdull)) >> 52;   // 0x3fe6...: √½
    const double m = from_bits(b - (biased << 52) + (1023ull << 52));
    const double e = from_bits(biased | 0x4330000000000000ull) - (0x1p52 + 1023.0);   // exact
    const double s = (m - 1.0) / (m + 1.0);
    const double z = s * s;
    if (base2) {
        double p = 0x1.1cb907ef54159p-2;
        p = p * z + 0x1.47f8c5921d83cp-2;
        p = p * z + 0x1.a61766f668933p-2;
        p = p * z + 0x1.2776c6c8ccfbfp-1;
        p = p * z + 0x1.ec709dc079194p-1;
        p = p * z + 0x1.71547652b8674p+1;
        return e + s * p;
    }
    double p = 0x1.8ab5a714829aap-3;
    p = p * z + 0x1.c6aa582db217cp-3;
    p = p * z + 0x1.24924c20eccc0p-2;
    p = p * z + 0x1.99999bfe19857p-2;
    p = p * z + 0x1.5555555325dbfp-1;
    p = p * z + 0x1.0000000000266p+1;
    return e * 0x1.62e42fefa39efp-1 + s * p;   // e·ln2 + ln(m)
}

// The logarithm of a float in double, with -inf at ±0, NaN below 0, and inf and NaN as given.
template <bool base2>
SOFTGL_VM_INLINE double log_of_float(float x) {
    const double d = x;
    const double special = d == 0.0 ? -INFINITY : (d < 0.0 ? NAN : d);
    const bool finite_positive = (d > 0.0) & (d < INFINITY);   // `&`: no branch, the loop vectorises
    const double r = log_kernel<base2>(finite_positive ? d : 1.0);
    return finite_positive ? r : special;
}

// sin(r) (odd) or cos(r) (odd) for |r| <= π/4 (plus a hair), Taylor to r^13 / r^14 (error
// < 3e-14), picked by quadrant q (sin x = ±sin r or ±cos r as q = 0..3) and signed.
SOFTGL_VM_INLINE double sin_quadrant(double r, uint64_t q) {
    const double r2 = r * r;
    double s = 0x1.6124613a86d09p-33;   // 1/13!
    s = s * r2 - 0x1.ae64567f544e4p-26;
    s = s * r2 + 0x1.71de3a556c734p-19;
    s = s * r2 - 0x1.a01a01a01a01ap-13;
    s = s * r2 + 0x1.1111111111111p-7;
    s = s * r2 - 0x1.5555555555555p-3;
    s = r + r * r2 * s;
    double c = -0x1.93974a8c07c9dp-37;  // -1/14!
    c = c * r2 + 0x1.1eed8eff8d898p-29;
    c = c * r2 - 0x1.27e4fb7789f5cp-22;
    c = c * r2 + 0x1.a01a01a01a01ap-16;
    c = c * r2 - 0x1.6c16c16c16c17p-10;
    c = c * r2 + 0x1.5555555555555p-5;
    c = c * r2 - 0.5;
    c = 1.0 + r2 * c;
    const double v = (q & 1) ? c : s;
    return from_bits(bits(v) ^ ((q & 2) << 62));
}

// Arguments below this reduce by Cody-Waite: k = round(x·2/π) < 2^25 and π/2 = C1 + C2 + C3
// with 27-bit C1 and C2, so k·C1 and k·C2 are exact and x - k·C1 is exact (Sterbenz).
constexpr float kSinCosFastLimit = 0x1p25f;

// sin(x) (quadrant offset 0) or cos(x) (offset 1) for |x| < kSinCosFastLimit, ±inf and NaN.
SOFTGL_VM_INLINE float sin_cos_fast(float x, uint64_t offset) {
    const double d = x;
    const double shifted = d * 0x1.45f306dc9c883p-1 + kRound;   // 2/π
    const double k = shifted - kRound;
    const double r = ((d - k * 0x1.921fb54000000p+0) - k * 0x1.10b4610000000p-30) - k * 0x1.a62633145c06ep-58;
    const float v = static_cast<float>(sin_quadrant(r, bits(shifted) + offset));
    const float signed_v = offset == 0 && x == 0.0f ? x : v;   // sin(-0) = -0
    return std::fabs(x) < INFINITY ? signed_v : x - x;           // NaN at ±inf; a NaN's own bits (see pow)
}

// The bits of 2/π after the binary point, 24 at a time.
constexpr uint32_t kTwoOverPi24[] = {0xa2f983, 0x6e4e44, 0x1529fc, 0x2757d1, 0xf534dd, 0xc0db62,
                                     0x95993c, 0x439041, 0xfe5163, 0xabdebb, 0xc561b7, 0x246e3a};

// sin or cos for finite |x| >= kSinCosFastLimit (Payne-Hanek, one lane at a time). x = M·2^E
// with a 24-bit integer M; x·2/π mod 4 = Σ M·c_j·2^(E-24(j+1)) mod 4 over the chunks c_j whose
// terms are not multiples of 4: four of them, each product exact in double; the two largest
// are reduced mod 4 exactly, and the rest added after k is taken so that f keeps its precision.
inline float sin_cos_large(float x, uint64_t offset) {
    uint32_t u;
    std::memcpy(&u, &x, 4);
    const double M = static_cast<double>((u & 0x7fffffu) | 0x800000u);
    const int E = static_cast<int>((u >> 23) & 0xffu) - 150;   // >= 2 here
    const int j0 = E <= 25 ? 0 : (E - 25 + 23) / 24;            // the first term below 2^2
    auto term = [&](int j) {   // M·c_j·2^(E-24(j+1)), exact: a 48-bit integer times a power of two
        return M * kTwoOverPi24[j] * from_bits(static_cast<uint64_t>(1023 + E - 24 * (j + 1)) << 52);
    };
    auto mod4 = [](double v) { return v - 4.0 * std::floor(v * 0.25); };   // exact
    const double high = mod4(mod4(term(j0)) + mod4(term(j0 + 1)));
    const double k = std::nearbyint(high + term(j0 + 2));
    const double f = ((high - k) + term(j0 + 2)) + term(j0 + 3);   // |x|·2/π mod 4 - k, |f| <= 1/2
    const double r = f * 0x1.921fb54442d18p+0;                      // π/2
    // x < 0: x·2/π = -(k + f) mod 4.
    const uint64_t q = static_cast<uint64_t>(k);
    return static_cast<float>(u >> 31 ? sin_quadrant(-r, (0u - q) + offset) : sin_quadrant(r, q + offset));
}

}  // namespace detail

// ---- one lane: call these inside loops the compiler vectorises ----
SOFTGL_VM_INLINE float exp2(float x) { return static_cast<float>(detail::exp2_any(x)); }
SOFTGL_VM_INLINE float exp(float x) { return static_cast<float>(detail::exp2_any(static_cast<double>(x) * 0x1.71547652b82fep+0)); }   // log2(e)
SOFTGL_VM_INLINE float log2(float x) { return static_cast<float>(detail::log_of_float<true>(x)); }
SOFTGL_VM_INLINE float log(float x) { return static_cast<float>(detail::log_of_float<false>(x)); }
SOFTGL_VM_INLINE float pow(float x, float y) {
    const double t = static_cast<double>(y) * detail::log_of_float<true>(x);
    // A NaN result is x's NaN, else y's, else the default quiet NaN: when both operands of an
    // IEEE operation are NaN the result's bits depend on their order, which the compiler may
    // commute differently in each build (and constant folding must give run time's bits).
    const float nan = x != x ? x : (y != y ? y : NAN);
    const float r = static_cast<float>(detail::exp2_any(t));
    return t != t ? nan : r;
}
// sin and cos of one lane whose |x| < 2^25 or is not finite (see sin_lanes for any x).
SOFTGL_VM_INLINE float sin_small(float x) { return detail::sin_cos_fast(x, 0); }
SOFTGL_VM_INLINE float cos_small(float x) { return detail::sin_cos_fast(x, 1); }
SOFTGL_VM_INLINE float sin(float x) { return std::fabs(x) >= detail::kSinCosFastLimit && std::fabs(x) < INFINITY ? detail::sin_cos_large(x, 0) : sin_small(x); }
SOFTGL_VM_INLINE float cos(float x) { return std::fabs(x) >= detail::kSinCosFastLimit && std::fabs(x) < INFINITY ? detail::sin_cos_large(x, 1) : cos_small(x); }

// ---- arrays of lanes (d may be a or b) ----
// d[l] = f(a[l]) (and b[l]) for l < n, in blocks of 16 lanes through local arrays: 16 is a
// multiple of every vector width, so each block is whole vectors with no scalar tail loop (the
// executor's batches of a few quads would otherwise spend most of their time in one), and
// local arrays cannot alias. A last block of at most 8 lanes runs as a block of 8; unused
// lanes compute from zeros and are dropped.
template <int kBlock, class F>
SOFTGL_VM_INLINE void map_block(float* d, const float* a, const float* b, int m, F f) {
    float x[kBlock] = {}, y[kBlock] = {}, z[kBlock];
    if (m == kBlock) { std::memcpy(x, a, sizeof x); if (b) std::memcpy(y, b, sizeof y); }
    else { std::memcpy(x, a, sizeof(float) * m); if (b) std::memcpy(y, b, sizeof(float) * m); }
    for (int k = 0; k < kBlock; ++k) z[k] = f(x[k], y[k]);
    if (m == kBlock) std::memcpy(d, z, sizeof z); else std::memcpy(d, z, sizeof(float) * m);
}

// f(x, y); b may be null for functions of one argument (y is then 0).
template <class F>
SOFTGL_VM_INLINE void map_lanes(float* d, const float* a, const float* b, int n, F f) {
    int l = 0;
    for (; l + 16 <= n; l += 16) map_block<16>(d + l, a + l, b ? b + l : nullptr, 16, f);
    if (n - l > 8) map_block<16>(d + l, a + l, b ? b + l : nullptr, n - l, f);
    else if (n > l) map_block<8>(d + l, a + l, b ? b + l : nullptr, n - l, f);
}

SOFTGL_VM_INLINE void exp2_lanes(float* d, const float* a, int n) { map_lanes(d, a, nullptr, n, [](float x, float) SOFTGL_VM_LAMBDA { return exp2(x); }); }
SOFTGL_VM_INLINE void exp_lanes(float* d, const float* a, int n) { map_lanes(d, a, nullptr, n, [](float x, float) SOFTGL_VM_LAMBDA { return exp(x); }); }
SOFTGL_VM_INLINE void log2_lanes(float* d, const float* a, int n) { map_lanes(d, a, nullptr, n, [](float x, float) SOFTGL_VM_LAMBDA { return log2(x); }); }
SOFTGL_VM_INLINE void log_lanes(float* d, const float* a, int n) { map_lanes(d, a, nullptr, n, [](float x, float) SOFTGL_VM_LAMBDA { return log(x); }); }
SOFTGL_VM_INLINE void pow_lanes(float* d, const float* a, const float* b, int n) {
    map_lanes(d, a, b, n, [](float x, float y) SOFTGL_VM_LAMBDA { return pow(x, y); });
}

// sin or cos of n lanes: whole blocks, or lane by lane when an argument is large (rare).
SOFTGL_VM_INLINE void sin_cos_lanes(float* d, const float* a, int n, bool cosine) {
    uint32_t large = 0;
    for (int l = 0; l < n; ++l) large |= (std::fabs(a[l]) >= detail::kSinCosFastLimit) & (std::fabs(a[l]) < INFINITY);
    if (large) { for (int l = 0; l < n; ++l) d[l] = cosine ? cos(a[l]) : sin(a[l]); return; }
    if (cosine) map_lanes(d, a, nullptr, n, [](float x, float) SOFTGL_VM_LAMBDA { return cos_small(x); });
    else map_lanes(d, a, nullptr, n, [](float x, float) SOFTGL_VM_LAMBDA { return sin_small(x); });
}

}  // namespace softgl::vmath
