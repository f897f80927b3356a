// Viewport and depth-range mapping from normalised device coordinates to window coordinates,
// ES 3.0 §2.12.1:  x_w = (p_x/2) x_d + o_x,  y_w = (p_y/2) y_d + o_y,  z_w = ((f-n)/2) z_d + (n+f)/2.
// Window coordinates have y up and the origin at the lower-left corner of the framebuffer.
#pragma once
#include <cstdint>

namespace softgl {

// Fixed-point window coordinates: 8 sub-pixel bits (docs/architecture.md, "Numeric rules").
inline constexpr int kSubPixelBits = 8;
inline constexpr int64_t kSubPixel = int64_t(1) << kSubPixelBits;

// Guard band, in pixels either side of the window origin. Triangles with a vertex beyond it are
// clipped to it (pipeline/clip), so every snapped coordinate fits in 29 signed bits (2^20 * 2^8),
// edge-function coefficients in 30 bits and edge-function values in 60 bits: exact in int64.
inline constexpr double kGuardBand = double(1 << 20);

struct Viewport {
    int32_t x = 0, y = 0, width = 0, height = 0;
    double depth_near = 0.0, depth_far = 1.0;   // depthRange, already clamped to [0,1]

    double scale_x() const { return 0.5 * width; }
    double scale_y() const { return 0.5 * height; }
    double offset_x() const { return x + 0.5 * width; }
    double offset_y() const { return y + 0.5 * height; }
    double scale_z() const { return 0.5 * (depth_far - depth_near); }
    double offset_z() const { return 0.5 * (depth_near + depth_far); }
};

}  // namespace softgl
