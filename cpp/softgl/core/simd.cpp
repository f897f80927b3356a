#include "softgl/core/simd.h"

namespace softgl {

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
SimdLevel best_simd_level() {
    static const SimdLevel level = [] {
        __builtin_cpu_init();
        if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
            __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
            return SimdLevel::AVX512;
        // The AVX2 kernels also convert halves with F16C (the sampler's 16-bit float textures);
        // every CPU with AVX2 has it.
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("f16c") ? SimdLevel::AVX2 : SimdLevel::SSE2;
    }();
    return level;
}

bool cpu_has_avx512_vbmi() {
    static const bool has = [] {
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx512vbmi") != 0;
    }();
    return has;
}
#else
SimdLevel best_simd_level() { return SimdLevel::Scalar; }
bool cpu_has_avx512_vbmi() { return false; }
#endif

}  // namespace softgl
