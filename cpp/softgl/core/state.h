// The fixed-function state of a WebGL context, with ES 2.0 / 3.0 initial values (ES 3.0 §6.2 tables).
#pragma once
#include <array>
#include <cstdint>

#include "softgl/core/enums.h"
#include "softgl/core/softgl_enums.h"

namespace softgl {

// Line widths a draw can give (ES 3.0 §3.5.2: the width is clamped to the implementation's range).
// Aliased lines: [1, 1], what WebGL in Chromium reports for ALIASED_LINE_WIDTH_RANGE and draws
// (tests/webgl/reference/initial_parameters.json). SOFTGL_smooth's area-antialiased lines: GL
// 1.2's SMOOTH_LINE_WIDTH_RANGE (wide antialiased lines are what GL's line smoothing is for).
inline constexpr float kAliasedLineWidthRange[2] = {1.0f, 1.0f};
inline constexpr float kSmoothLineWidthRange[2] = {1.0f, 256.0f};

using GLenum = uint32_t;

struct StencilFace {
    GLenum func = gl::ALWAYS;
    int32_t ref = 0;
    uint32_t value_mask = 0xFFFFFFFFu;
    uint32_t write_mask = 0xFFFFFFFFu;
    GLenum fail = gl::KEEP;
    GLenum depth_fail = gl::KEEP;
    GLenum depth_pass = gl::KEEP;
};

struct Rect {
    int32_t x = 0, y = 0, width = 0, height = 0;
};

struct BlendState {
    bool enabled = false;
    GLenum src_rgb = gl::ONE, dst_rgb = gl::ZERO;
    GLenum src_alpha = gl::ONE, dst_alpha = gl::ZERO;
    GLenum equation_rgb = gl::FUNC_ADD, equation_alpha = gl::FUNC_ADD;
    std::array<float, 4> color{0, 0, 0, 0};
};

struct PixelStore {
    int32_t pack_alignment = 4, unpack_alignment = 4;
    bool unpack_flip_y = false, unpack_premultiply_alpha = false;
    GLenum unpack_colorspace_conversion = gl::BROWSER_DEFAULT_WEBGL;
    // WebGL 2
    int32_t pack_row_length = 0, pack_skip_pixels = 0, pack_skip_rows = 0;
    int32_t unpack_row_length = 0, unpack_image_height = 0, unpack_skip_pixels = 0,
            unpack_skip_rows = 0, unpack_skip_images = 0;
};

// SOFTGL_fog (GL 1.5 §3.10 initial values).
struct FogState {
    bool enabled = false;
    bool blend_aware = false;
    GLenum mode = gl::EXP;
    float density = 1, start = 0, end = 1;
    std::array<float, 4> color{0, 0, 0, 0};
    GLenum coordinate_source = gl::FRAGMENT_DEPTH;
};

// SOFTGL_smooth: GL 1.x smoothing (area-averaged antialiasing), GL 1.5 §3.3-3.5.
struct SmoothState {
    bool polygon = false, line = false, point = false;
    GLenum polygon_hint = gl::DONT_CARE, line_hint = gl::DONT_CARE, point_hint = gl::DONT_CARE;
};

struct State {
    FogState fog;
    SmoothState smooth;
    BlendState blend;

    bool cull_face = false;
    GLenum cull_face_mode = gl::BACK;
    GLenum front_face = gl::CCW;

    bool depth_test = false;
    GLenum depth_func = gl::LESS;
    bool depth_mask = true;
    std::array<float, 2> depth_range{0, 1};

    bool stencil_test = false;
    StencilFace stencil_front, stencil_back;

    bool scissor_test = false;
    Rect scissor, viewport;

    bool dither = true;
    bool polygon_offset_fill = false;
    float polygon_offset_factor = 0, polygon_offset_units = 0;
    bool sample_alpha_to_coverage = false, sample_coverage = false;
    float sample_coverage_value = 1;
    bool sample_coverage_invert = false;
    bool rasterizer_discard = false;

    std::array<float, 4> clear_color{0, 0, 0, 0};
    float clear_depth = 1;
    int32_t clear_stencil = 0;
    std::array<bool, 4> color_mask{true, true, true, true};

    float line_width = 1;   // as set; a draw clamps it to the range of its kind of line (below)
    GLenum generate_mipmap_hint = gl::DONT_CARE;
    GLenum fragment_shader_derivative_hint = gl::DONT_CARE;
    GLenum active_texture = gl::TEXTURE0;
    PixelStore pixel_store;
};

}  // namespace softgl
