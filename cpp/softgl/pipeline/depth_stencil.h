// Stencil and depth tests with their buffer updates, ES 3.0 §4.1.4-4.1.6.
#pragma once
#include <cstdint>

#include "softgl/core/state.h"

namespace softgl {

struct DepthStencilOp {
    bool depth_test = false;        // enabled and a depth buffer exists
    GLenum depth_func = gl::LESS;
    bool depth_write = true;
    bool stencil_test = false;      // enabled and a stencil buffer exists
    StencilFace front, back;

    static DepthStencilOp from_state(const State& state, bool has_depth, bool has_stencil);
    bool touches_depth() const { return depth_test; }
};

// Whether `incoming` passes the comparison `func` against `stored` (ES 3.0 §4.1.5, §4.1.6). Inline:
// the early depth kernels ask it at every call and the per-lane tests at every sample.
inline bool compare(GLenum func, uint32_t incoming, uint32_t stored) {
    switch (func) {
        case gl::NEVER: return false;
        case gl::LESS: return incoming < stored;
        case gl::EQUAL: return incoming == stored;
        case gl::LEQUAL: return incoming <= stored;
        case gl::GREATER: return incoming > stored;
        case gl::NOTEQUAL: return incoming != stored;
        case gl::GEQUAL: return incoming >= stored;
        default: return true;   // ALWAYS
    }
}

// Runs the stencil then depth test for one sample. `depth` is the fragment's 24-bit depth;
// `depth_buffer`/`stencil_buffer` point at the sample's stored values (may be null when the
// buffer does not exist). Updates them as the spec says; returns whether the sample survives.
bool depth_stencil_test(const DepthStencilOp& op, bool front_facing, uint32_t depth,
                        uint32_t* depth_buffer, uint8_t* stencil_buffer);

}  // namespace softgl
