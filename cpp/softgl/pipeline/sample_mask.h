// Multisample fragment operations, ES 3.0 §4.1.3 (only with SAMPLE_BUFFERS = 1): a temporary
// coverage mask from the fragment's alpha (SAMPLE_ALPHA_TO_COVERAGE) and from SAMPLE_COVERAGE_VALUE
// (optionally inverted) is ANDed with the fragment's coverage.
//
// The spec leaves the choice of bits to the implementation; softgl sets round(v · samples) bits,
// always the lowest-numbered samples first, so results are deterministic and monotonic in v.
#pragma once
#include <cstdint>

namespace softgl {

uint32_t coverage_from_value(float value, int samples);   // value clamped to [0, 1]; NaN -> 0 bits

}  // namespace softgl
