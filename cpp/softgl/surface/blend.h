// Blending into a fixed-point (unorm8) color buffer, ES 3.0 §4.1.7: source, destination,
// constant color and factors are clamped to [0, 1]; the result is clamped and rounded.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>

#include "softgl/core/state.h"

namespace softgl {

struct BlendOp {
    bool enabled = false;
    GLenum src_rgb = gl::ONE, dst_rgb = gl::ZERO, src_alpha = gl::ONE, dst_alpha = gl::ZERO;
    GLenum eq_rgb = gl::FUNC_ADD, eq_alpha = gl::FUNC_ADD;
    std::array<float, 4> constant{0, 0, 0, 0};   // already clamped to [0, 1] (fixed-point buffers)
    std::array<float, 4> constant_unclamped{0, 0, 0, 0};   // as given: float buffers (ES 3.0 §4.1.7)
    std::array<bool, 4> write{true, true, true, true};
    bool has_alpha = true;                       // alpha:false -> destination alpha reads as 1

    static BlendOp from_state(const State& state, bool has_alpha);
    // ONE, ZERO with FUNC_ADD on both is a plain write (docs/architecture.md, "Fast paths"): no destination read.
    bool is_plain_write() const;
};

// Blends the shader's color `src` (any float values) into `dst` (RGBA8) in place.
void blend_unorm8(const BlendOp& op, const float src[4], uint8_t dst[4]);

// Textures and framebuffers: blending into a colour attachment stored as floats (render targets of
// any format). With `clamp` (fixed-point and sRGB formats, ES 3.0 §4.1.7) the source and
// destination (and the constant colour) are clamped to [0, 1] first; float formats blend unclamped. `out` is the blended,
// unquantized colour; channels the colour mask disables keep `dst`.
void blend_float(const BlendOp& op, const float src[4], const float dst[4], bool clamp, float out[4]);

// ES 3.0 table 4.2: the blend factor for channel c (0..3) from the clamped source s, destination d
// and constant k. A template so that the float path and the float64 references (A-buffer) share it.
template <class T>
T blend_factor(GLenum f, int c, const T s[4], const T d[4], const T k[4]) {
    const T one = T(1);
    switch (f) {
        case gl::ZERO: return T(0);
        case gl::ONE: return one;
        case gl::SRC_COLOR: return s[c];
        case gl::ONE_MINUS_SRC_COLOR: return one - s[c];
        case gl::DST_COLOR: return d[c];
        case gl::ONE_MINUS_DST_COLOR: return one - d[c];
        case gl::SRC_ALPHA: return s[3];
        case gl::ONE_MINUS_SRC_ALPHA: return one - s[3];
        case gl::DST_ALPHA: return d[3];
        case gl::ONE_MINUS_DST_ALPHA: return one - d[3];
        case gl::CONSTANT_COLOR: return k[c];
        case gl::ONE_MINUS_CONSTANT_COLOR: return one - k[c];
        case gl::CONSTANT_ALPHA: return k[3];
        case gl::ONE_MINUS_CONSTANT_ALPHA: return one - k[3];
        case gl::SRC_ALPHA_SATURATE: return c == 3 ? one : std::min(s[3], one - d[3]);
        default: return T(0);
    }
}

// ES 3.0 §4.1.7: the blend equations (MIN and MAX ignore the factors).
template <class T>
T blend_equation(GLenum eq, T s, T sf, T d, T df) {
    switch (eq) {
        case gl::FUNC_SUBTRACT: return s * sf - d * df;
        case gl::FUNC_REVERSE_SUBTRACT: return d * df - s * sf;
        case gl::MIN: return std::min(s, d);
        case gl::MAX: return std::max(s, d);
        default: return s * sf + d * df;
    }
}

}  // namespace softgl
