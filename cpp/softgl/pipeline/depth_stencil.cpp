#include "softgl/pipeline/depth_stencil.h"

namespace softgl {

DepthStencilOp DepthStencilOp::from_state(const State& s, bool has_depth, bool has_stencil) {
    DepthStencilOp op;
    // ES 3.0 §4.1.5-4.1.6: without the buffer the test always passes and nothing is written.
    op.depth_test = s.depth_test && has_depth;
    op.depth_func = s.depth_func;
    op.depth_write = s.depth_mask;
    op.stencil_test = s.stencil_test && has_stencil;
    op.front = s.stencil_front;
    op.back = s.stencil_back;
    return op;
}

namespace {

uint8_t stencil_result(GLenum op, uint8_t value, uint8_t ref) {
    switch (op) {
        case gl::ZERO: return 0;
        case gl::REPLACE: return ref;
        case gl::INCR: return value == 255 ? 255 : uint8_t(value + 1);
        case gl::DECR: return value == 0 ? 0 : uint8_t(value - 1);
        case gl::INVERT: return uint8_t(~value);
        case gl::INCR_WRAP: return uint8_t(value + 1);
        case gl::DECR_WRAP: return uint8_t(value - 1);
        default: return value;   // KEEP
    }
}

void apply_stencil_op(const StencilFace& face, GLenum op, uint8_t* stencil) {
    const uint8_t ref = uint8_t(face.ref), mask = uint8_t(face.write_mask);
    const uint8_t result = stencil_result(op, *stencil, ref);
    *stencil = uint8_t((*stencil & ~mask) | (result & mask));
}

}  // namespace

bool depth_stencil_test(const DepthStencilOp& op, bool front_facing, uint32_t depth,
                        uint32_t* depth_buffer, uint8_t* stencil_buffer) {
    const StencilFace& face = front_facing ? op.front : op.back;
    if (op.stencil_test) {
        // ES 3.0 §4.1.5: (ref & mask) func (stencil & mask).
        const uint32_t mask = face.value_mask & 0xFFu;
        if (!compare(face.func, uint32_t(face.ref) & mask, uint32_t(*stencil_buffer) & mask)) {
            apply_stencil_op(face, face.fail, stencil_buffer);
            return false;
        }
    }
    if (op.depth_test) {
        if (!compare(op.depth_func, depth, *depth_buffer)) {
            if (op.stencil_test) apply_stencil_op(face, face.depth_fail, stencil_buffer);
            return false;
        }
        if (op.depth_write) *depth_buffer = depth;
    }
    if (op.stencil_test) apply_stencil_op(face, face.depth_pass, stencil_buffer);
    return true;
}

}  // namespace softgl
