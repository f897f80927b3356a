#include "softgl/core/simd.h"

#if defined(__x86_64__)
#include <cpuid.h>
#endif

namespace softgl {

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
SimdLevel best_simd_level() {
    static const SimdLevel level = [] {
        __builtin_cpu_init();
        if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
            __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
            return SimdLevel::AVX512;
        // The AVX2 kernels also convert halves with F16C (the sampler's 16-bit float textures);
        // every CPU with AVX2 has it. Read from CPUID leaf 1 (ECX bit 29): clang 14's
        // __builtin_cpu_supports does not know "f16c".
        unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
        const bool f16c = __get_cpuid(1, &eax, &ebx, &ecx, &edx) && (ecx & bit_F16C);
        return __builtin_cpu_supports("avx2") && f16c ? SimdLevel::AVX2 : SimdLevel::SSE2;
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
