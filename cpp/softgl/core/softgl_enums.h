// softgl's own enums, for its extensions beyond WebGL (docs/architecture.md, "The blend lab"): OpenGL's historical values where
// OpenGL has the concept (GL 1.x fog, smoothing), new values in an unused range otherwise.
#pragma once
#include <cstdint>

namespace softgl::gl {

// SOFTGL_fog: OpenGL 1.x fog (GL 1.5 §3.10) and the GL 1.4 fog coordinate source.
inline constexpr uint32_t FOG = 0x0B60;
inline constexpr uint32_t FOG_DENSITY = 0x0B62;
inline constexpr uint32_t FOG_START = 0x0B63;
inline constexpr uint32_t FOG_END = 0x0B64;
inline constexpr uint32_t FOG_MODE = 0x0B65;
inline constexpr uint32_t FOG_COLOR = 0x0B66;
inline constexpr uint32_t EXP = 0x0800;
inline constexpr uint32_t EXP2 = 0x0801;
// LINEAR (0x2601) is WebGL's texture filter enum, the same value as GL's fog mode.
inline constexpr uint32_t FOG_COORDINATE_SOURCE = 0x8450;
inline constexpr uint32_t FRAGMENT_DEPTH = 0x8452;          // eye distance, from clip w
inline constexpr uint32_t WINDOW_DEPTH_SOFTGL = 0x1D000;    // window z in [0, 1]
inline constexpr uint32_t FOG_BLEND_AWARE_SOFTGL = 0x1D001; // capability: fade toward what blending leaves unchanged

// SOFTGL_smooth: GL 1.x polygon/line/point smoothing (area-averaged antialiasing).
inline constexpr uint32_t POINT_SMOOTH = 0x0B10;
inline constexpr uint32_t LINE_SMOOTH = 0x0B20;
inline constexpr uint32_t POLYGON_SMOOTH = 0x0B41;
inline constexpr uint32_t POINT_SMOOTH_HINT = 0x0C51;
inline constexpr uint32_t LINE_SMOOTH_HINT = 0x0C52;
inline constexpr uint32_t POLYGON_SMOOTH_HINT = 0x0C53;
inline constexpr uint32_t SMOOTH_LINE_WIDTH_RANGE = 0x0B22;   // GL 1.2 table 6.30

}  // namespace softgl::gl

namespace softgl::gl {

// SOFTGL_exact_transparency (blend lab): capture blended fragments in an A-buffer, resolve them.
// No OpenGL equivalent exists, so the values are softgl's own (0x1D1xx).
inline constexpr uint32_t EXACT_TRANSPARENCY_SOFTGL = 0x1D100;      // capability
inline constexpr uint32_t TRANSPARENCY_EXACT_SOFTGL = 0x1D110;      // resolve modes
inline constexpr uint32_t DEPTH_PEELING_SOFTGL = 0x1D111;
inline constexpr uint32_t WEIGHTED_BLENDED_SOFTGL = 0x1D112;
// SOFTGL_introspection (blend lab): log every fragment for gl.fragments(x, y).
inline constexpr uint32_t INTROSPECTION_SOFTGL = 0x1D120;           // capability

}  // namespace softgl::gl
