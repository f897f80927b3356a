// The early depth test (ES 3.0 §4.1.6, run before shading when the shader neither discards nor
// writes depth) of a run of quads, for the common case: 24-bit depth words, no stencil. Each
// covered sample compares depth_word(Depth24, prim.depth_at(sample)) with the stored word, and on
// a pass with depth writes enabled stores it. The pixels of one primitive are distinct, so they
// are independent. One sample per pixel: the AVX2 level tests a quad's four pixels at once, the
// AVX-512 level a row of up to four side-by-side quads (two pixel rows of 8). Four samples per
// pixel (MSAA 4x): the AVX2 level tests a pixel's four samples at once, the AVX-512 level a
// quad's pixel row (two pixels, 8 sample words); other sample counts run the scalar level. All
// give the same words and decisions as the scalar level (DESIGN §3).
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
    const SamplePattern* pattern = nullptr;   // the samples per pixel and their positions
    GLenum func = gl::LESS;
    bool write = true;
    uint32_t* depth = nullptr;                // word of sample s of pixel (x, y): depth[(y * pitch + x) * samples + s]
    size_t pitch = 0;
};

// Tests the covered samples (quad_pixel_mask) of quads[0, n); survived[4*i + j] is the mask of
// the samples of pixel j of quads[i] that are covered and pass. Returns the number that failed.
size_t early_depth_test_at(SimdLevel level, const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived);
inline size_t early_depth_test(const EarlyDepth& t, const Quad* quads, size_t n, uint16_t* survived) {
    return early_depth_test_at(best_simd_level(), t, quads, n, survived);
}

}  // namespace softgl
