// The early depth test (ES 3.0 §4.1.6, run before shading when the shader neither discards nor
// writes depth) of a run of quads, for the common case: one sample per pixel, 24-bit depth words,
// no stencil. Each covered pixel compares depth_word(Depth24, prim.depth_at(sample)) with the
// stored word, and on a pass with depth writes enabled stores it. The pixels of one primitive are
// distinct, so they are independent: the AVX2 level tests a quad's four pixels at once, the
// AVX-512 level a row of up to four side-by-side quads (two pixel rows of 8), and both give the
// same words and decisions as the scalar level (DESIGN §3).
#pragma once
#include <cstddef>
#include <cstdint>

#include "softgl/api/state.h"
#include "softgl/pipeline/fragment_ops.h"
#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/setup.h"

namespace softgl {

struct EarlyDepth {
    const PrimitiveSetup* prim = nullptr;
    int32_t sample_x = 128, sample_y = 128;   // the sample's position in its pixel (1/256 pixel)
    GLenum func = gl::LESS;
    bool write = true;
    uint32_t* depth = nullptr;                // word of pixel (x, y): depth[y * pitch + x]
    size_t pitch = 0;
};

// Tests the covered pixels (sample 0 of quad_pixel_mask) of quads[0, n); survived[4*i + j] is 1
// when pixel j of quads[i] is covered and passes, else 0. Returns the number that failed.
size_t early_depth_test_at(SimdLevel level, const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived);
inline size_t early_depth_test(const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    return early_depth_test_at(best_simd_level(), t, quads, n, survived);
}

}  // namespace softgl
