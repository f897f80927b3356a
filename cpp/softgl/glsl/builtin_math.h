// The scalar semantics of GLSL ES operators and built-in functions, one definition each: the
// executor's lane loops call these per lane, and the checker folds constant expressions with
// them, so a constant-folded value has the bits run time gives (NaN, ±Inf and ±0 included).
// exp2, exp, log2, log, pow, sin and cos are core/vector_math.h's; the IR optimizer folds calls
// of them (and of every other built-in the checker leaves) by running the executor itself.
// ES 3.00 §8 defines min, max and clamp by comparisons, which fixes what NaN does:
// min(x, y) = y < x ? y : x returns x when either is NaN; max likewise; clamp = min(max(x, lo), hi).
//
// `static inline`: each file gets its own copy, compiled with that file's flags (the executor
// is built with -fno-math-errno and vectorises these inside its per-SIMD-level loops).
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace softgl::glsl {

// ---- float ----
static inline float f_sign(float x) { return x > 0.0f ? 1.0f : (x < 0.0f ? -1.0f : x); }
static inline float f_min(float x, float y) { return y < x ? y : x; }   // min(x, y) = y < x ? y : x
static inline float f_max(float x, float y) { return x < y ? y : x; }   // max(x, y) = x < y ? y : x
static inline float f_clamp(float x, float lo, float hi) { return f_min(f_max(x, lo), hi); }
static inline float f_mod(float x, float y) { return x - y * std::floor(x / y); }
static inline float f_mix(float x, float y, float a) { return x * (1.0f - a) + y * a; }
static inline float f_step(float edge, float x) { return x < edge ? 0.0f : 1.0f; }
static inline float f_smoothstep(float e0, float e1, float x) {
    float t = f_clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

// ---- signed and unsigned integers (two's complement, wrapping) ----
static inline int32_t i_abs(int32_t x) { return x < 0 ? static_cast<int32_t>(0u - static_cast<uint32_t>(x)) : x; }
static inline int32_t i_min(int32_t x, int32_t y) { return y < x ? y : x; }
static inline int32_t i_max(int32_t x, int32_t y) { return x < y ? y : x; }
static inline int32_t i_clamp(int32_t x, int32_t lo, int32_t hi) { return i_min(i_max(x, lo), hi); }
static inline uint32_t u_min(uint32_t x, uint32_t y) { return y < x ? y : x; }
static inline uint32_t u_max(uint32_t x, uint32_t y) { return x < y ? y : x; }
static inline uint32_t u_clamp(uint32_t x, uint32_t lo, uint32_t hi) { return u_min(u_max(x, lo), hi); }
static inline int32_t i_div(int32_t a, int32_t b) {
    if (b == 0) return 0;  // undefined in GLSL; softgl returns 0 (a constant expression reports an error)
    if (a == std::numeric_limits<int32_t>::min() && b == -1) return a;
    return a / b;
}
static inline int32_t i_mod(int32_t a, int32_t b) {
    if (b == 0 || (a == std::numeric_limits<int32_t>::min() && b == -1)) return 0;
    return a % b;
}
static inline uint32_t u_div(uint32_t a, uint32_t b) { return b == 0 ? 0u : a / b; }
static inline uint32_t u_mod(uint32_t a, uint32_t b) { return b == 0 ? 0u : a % b; }
// Shifts by 32 or more are undefined (ES 3.00 §5.9); softgl uses the count modulo 32, as x86 does.
static inline uint32_t shift_left(uint32_t x, uint32_t n) { return x << (n & 31u); }
static inline int32_t shift_right_arithmetic(int32_t x, uint32_t n) { return x >> (n & 31u); }
static inline uint32_t shift_right_logical(uint32_t x, uint32_t n) { return x >> (n & 31u); }

// ---- conversions ----
// Float -> integer conversions saturate; NaN gives INT_MIN (int) or 0 (uint).
static inline int32_t f_to_i(float x) {
    if (!(std::fabs(x) < 2147483648.0f)) return x > 0 ? std::numeric_limits<int32_t>::max() : std::numeric_limits<int32_t>::min();
    return static_cast<int32_t>(x);
}
static inline uint32_t f_to_u(float x) {
    if (!(x > -1.0f)) return 0;
    if (!(x < 4294967296.0f)) return std::numeric_limits<uint32_t>::max();
    return static_cast<uint32_t>(x);
}

// ---- ES 3.00 §8.4 packing ----
static inline uint32_t float_to_half(float value) {
    uint32_t bits;
    std::memcpy(&bits, &value, 4);
    uint32_t sign = (bits >> 16) & 0x8000u;
    uint32_t exponent = (bits >> 23) & 0xffu;
    uint32_t mantissa = bits & 0x7fffffu;
    if (exponent == 0xff) return sign | 0x7c00u | (mantissa ? 0x200u : 0u);
    int e = static_cast<int>(exponent) - 127 + 15;
    if (e >= 31) return sign | 0x7c00u;
    if (e <= 0) {
        if (e < -10) return sign;
        mantissa |= 0x800000u;
        int shift = 14 - e;
        uint32_t half = mantissa >> shift;
        uint32_t rest = mantissa & ((1u << shift) - 1);
        uint32_t halfway = 1u << (shift - 1);
        if (rest > halfway || (rest == halfway && (half & 1u))) ++half;
        return sign | half;
    }
    uint32_t half = sign | (static_cast<uint32_t>(e) << 10) | (mantissa >> 13);
    uint32_t rest = mantissa & 0x1fffu;
    if (rest > 0x1000u || (rest == 0x1000u && (half & 1u))) ++half;  // round to nearest even
    return half;
}
static inline float half_to_float(uint32_t h) {
    uint32_t sign = (h & 0x8000u) << 16;
    uint32_t exponent = (h >> 10) & 0x1fu;
    uint32_t mantissa = h & 0x3ffu;
    uint32_t bits;
    if (exponent == 0) {
        if (mantissa == 0) bits = sign;
        else {
            int e = -1;
            do { ++e; mantissa <<= 1; } while (!(mantissa & 0x400u));
            bits = sign | (static_cast<uint32_t>(127 - 15 - e) << 23) | ((mantissa & 0x3ffu) << 13);
        }
    } else if (exponent == 31) {
        bits = sign | 0x7f800000u | (mantissa << 13);
    } else {
        bits = sign | ((exponent + 127 - 15) << 23) | (mantissa << 13);
    }
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}
// NaN (undefined in ES 3.00 §8.4) packs to 0: casting it is undefined in C++, and the
// vector conversions of each SIMD level give different bits for it.
static inline uint32_t pack_snorm16(float x) {
    const float v = std::round(f_clamp(x, -1.0f, 1.0f) * 32767.0f);
    return v == v ? static_cast<uint32_t>(static_cast<int32_t>(v)) & 0xffffu : 0u;
}
static inline uint32_t pack_unorm16(float x) {
    const float v = std::round(f_clamp(x, 0.0f, 1.0f) * 65535.0f);
    return v == v ? static_cast<uint32_t>(v) : 0u;
}
static inline float unpack_snorm16(uint32_t v) {
    return f_clamp(static_cast<float>(static_cast<int16_t>(static_cast<uint16_t>(v))) / 32767.0f, -1.0f, 1.0f);
}
static inline float unpack_unorm16(uint32_t v) { return static_cast<float>(v & 0xffffu) / 65535.0f; }

}  // namespace softgl::glsl
