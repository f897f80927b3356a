#include "softgl/pipeline/fog.h"

#include <cmath>

#include "softgl/surface/formats.h"

namespace softgl {

namespace {

bool is_additive(const BlendState& b) {
    return b.equation_rgb == gl::FUNC_ADD && b.dst_rgb == gl::ONE &&
           (b.src_rgb == gl::ONE || b.src_rgb == gl::SRC_ALPHA);
}

bool is_multiplicative(const BlendState& b) {
    return b.equation_rgb == gl::FUNC_ADD &&
           ((b.src_rgb == gl::DST_COLOR && b.dst_rgb == gl::ZERO) ||
            (b.src_rgb == gl::ZERO && b.dst_rgb == gl::SRC_COLOR));
}

}  // namespace

FogOp FogOp::from_state(const State& s) {
    FogOp op;
    op.enabled = s.fog.enabled;
    op.mode = s.fog.mode;
    op.density = s.fog.density;
    op.start = s.fog.start;
    op.end = s.fog.end;
    op.window_depth = s.fog.coordinate_source == gl::WINDOW_DEPTH_SOFTGL;
    for (int c = 0; c < 3; ++c) op.color[size_t(c)] = clamp01(s.fog.color[size_t(c)]);
    if (s.fog.blend_aware && s.blend.enabled) {
        if (is_additive(s.blend)) op.color = {0, 0, 0};
        else if (is_multiplicative(s.blend)) op.color = {1, 1, 1};
    }
    return op;
}

float fog_coordinate(const FogOp& op, float frag_coord_z, float frag_coord_w) {
    return op.window_depth ? frag_coord_z : std::fabs(1.0f / frag_coord_w);
}

float fog_factor(const FogOp& op, float c) {
    float f;
    switch (op.mode) {
        case gl::LINEAR:
            // start == end leaves the factor undefined in GL; softgl treats it as a step at `end`.
            f = op.end == op.start ? (c < op.end ? 1.0f : 0.0f) : (op.end - c) / (op.end - op.start);
            break;
        case gl::EXP2: {
            const float dc = op.density * c;
            f = std::exp(-(dc * dc));
            break;
        }
        default:
            f = std::exp(-(op.density * c));
            break;
    }
    return clamp01(f);   // NaN (e.g. 0 · ∞) counts as fully fogged
}

void apply_fog(const FogOp& op, float c, float rgba[4]) {
    const float f = fog_factor(op, c);
    for (int k = 0; k < 3; ++k) rgba[k] = f * rgba[k] + (1.0f - f) * op.color[size_t(k)];
}

}  // namespace softgl
