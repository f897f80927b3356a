// Conversions between float colors and stored formats (ES 3.0 §2.1.6.1: unorm from float).
#pragma once
#include <cmath>
#include <cstdint>

namespace softgl {

// float -> unorm with `bits` bits: clamp to [0,1], then round to nearest. NaN becomes 0.
inline uint32_t float_to_unorm(float value, int bits) {
    const double max_value = double((uint64_t(1) << bits) - 1);
    if (!(value > 0.0f)) return 0;  // also catches NaN
    if (value >= 1.0f) return uint32_t(max_value);
    return uint32_t(std::floor(double(value) * max_value + 0.5));
}

inline uint8_t float_to_unorm8(float value) { return uint8_t(float_to_unorm(value, 8)); }

inline float clamp01(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }  // NaN -> 0

// Float colour buffers store every NaN as the one quiet NaN: which NaN an IEEE operation returns
// when both operands are NaN depends on operand order, which SIMD and scalar code may not share,
// so without this the stored bits of a NaN could differ between CPUs (docs/architecture.md, "Determinism").
inline float canonical_nan(float v) { return v != v ? std::nanf("") : v; }

}  // namespace softgl
