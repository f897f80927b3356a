#include "softgl/pipeline/sample_mask.h"

#include <cmath>

#include "softgl/surface/formats.h"

namespace softgl {

uint32_t coverage_from_value(float value, int samples) {
    const int bits = int(std::floor(double(clamp01(value)) * samples + 0.5));
    return bits >= 32 ? 0xFFFFFFFFu : (1u << bits) - 1u;
}

}  // namespace softgl
