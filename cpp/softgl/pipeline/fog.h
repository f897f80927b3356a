// Fog (the SOFTGL_fog extension, OpenGL 1.x semantics, GL 1.5 §3.10): after the fragment shader
// and before blending, C' = f·Cs + (1 − f)·Cf on RGB, alpha unchanged, with the fog factor
//   LINEAR: f = (end − c) / (end − start)    EXP: f = exp(−density·c)    EXP2: f = exp(−(density·c)²)
// clamped to [0, 1]. The fog coordinate c is the eye distance along the view axis, taken from the
// fragment's clip w (1 / gl_FragCoord.w, exact for perspective projections), or the window depth
// gl_FragCoord.z when FOG_COORDINATE_SOURCE is WINDOW_DEPTH_SOFTGL (for orthographic projections,
// where w is 1 everywhere).
#pragma once
#include <array>

#include "softgl/core/state.h"

namespace softgl {

struct FogOp {
    bool enabled = false;
    GLenum mode = gl::EXP;
    float density = 1, start = 0, end = 1;
    std::array<float, 3> color{0, 0, 0};   // the color fragments fade toward
    bool window_depth = false;

    // Blend-aware fog fades additive geometry toward black and multiplicative geometry toward
    // white (what those blends leave unchanged) instead of toward the fog color.
    static FogOp from_state(const State& state);
};

float fog_coordinate(const FogOp& op, float frag_coord_z, float frag_coord_w);
float fog_factor(const FogOp& op, float c);
void apply_fog(const FogOp& op, float c, float rgba[4]);

}  // namespace softgl
