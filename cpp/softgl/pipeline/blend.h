// Blending into a fixed-point (unorm8) color buffer, ES 3.0 §4.1.7: source, destination,
// constant color and factors are clamped to [0, 1]; the result is clamped and rounded.
#pragma once
#include <array>
#include <cstdint>

#include "softgl/api/state.h"

namespace softgl {

struct BlendOp {
    bool enabled = false;
    GLenum src_rgb = gl::ONE, dst_rgb = gl::ZERO, src_alpha = gl::ONE, dst_alpha = gl::ZERO;
    GLenum eq_rgb = gl::FUNC_ADD, eq_alpha = gl::FUNC_ADD;
    std::array<float, 4> constant{0, 0, 0, 0};   // already clamped to [0, 1]
    // BLEND_COLOR as given: float colour buffers use it unclamped (ES 3.0 §4.1.7).
    std::array<float, 4> constant_unclamped{0, 0, 0, 0};
    std::array<bool, 4> write{true, true, true, true};
    bool has_alpha = true;                       // alpha:false -> destination alpha reads as 1

    static BlendOp from_state(const State& state, bool has_alpha);
    // ONE, ZERO with FUNC_ADD on both is a plain write (DESIGN §4): no destination read.
    bool is_plain_write() const;
};

// Blends the shader's color `src` (any float values) into `dst` (RGBA8) in place.
void blend_unorm8(const BlendOp& op, const float src[4], uint8_t dst[4]);

// Textures and framebuffers: blending into a colour attachment stored as floats (render targets of
// any format). With `clamp` (fixed-point and sRGB formats, ES 3.0 §4.1.7) the source and
// destination are clamped to [0, 1] first; float formats blend unclamped. `out` is the blended,
// unquantized colour; channels the colour mask disables keep `dst`.
void blend_float(const BlendOp& op, const float src[4], const float dst[4], bool clamp, float out[4]);

}  // namespace softgl
