// The instruction sets softgl's lane kernels come in, and the one CPU detection that picks them.
// Every level gives the same bytes: the kernels use only IEEE operations that round identically
// at any vector width, in the same order, without FMA (docs/architecture.md, "Numeric rules").
// The module is built for any x86-64; the AVX2 and AVX-512 kernels are chosen at run time.
#pragma once
#include <cstdint>

namespace softgl {

// Scalar: plain C++; SSE2: the x86-64 baseline; AVX2; AVX512: AVX-512 F+BW+DQ+VL. A stage without
// a kernel for a level runs its best kernel below it (the GLSL executor's portable build serves
// Scalar and SSE2; stages without an AVX-512 kernel run their AVX2 one).
enum class SimdLevel : uint8_t { Scalar, SSE2, AVX2, AVX512 };
inline constexpr const char* kSimdLevelNames[] = {"scalar", "sse2", "avx2", "avx512"};

// The best level this CPU runs (detected once).
SimdLevel best_simd_level();

// Whether this CPU has AVX-512 VBMI (byte permutes, used by one blend-table kernel).
bool cpu_has_avx512_vbmi();

}  // namespace softgl
