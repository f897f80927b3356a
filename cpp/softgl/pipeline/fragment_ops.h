// Per-fragment colour operations specialised on the blend state (docs/architecture.md, "Fast paths"): the draw picks one
// kernel per draw from a canonical key, and every kernel gives exactly the bytes of the reference
// blend_unorm8 (blend.cpp), which stays the definition. tests/pipeline/test_fragment_ops.py
// checks the equality over every factor/equation combination, all 256 destination values and
// out-of-range, NaN and infinite source values.
//
// Why they are exact:
//  * unorm8 -> float uses a table of float(i) / 255.0f, the same division the reference does; the
//    AVX-512 lanes convert i * 0x01010101 rounding up, which is float(i) / 255.0f * 2^32 exactly,
//    and scale by 2^-32 exactly (folded into ONE_MINUS_SRC_ALPHA; fragment_ops.cpp has the proof).
//  * float -> unorm8 is float_to_unorm8 with floor replaced by truncation, which is the same for
//    the non-negative values it sees (the argument is clamped first), and avoids a libm call. The
//    AVX2 lanes compute the same floor(v*255 + 0.5) exactly in integers from v's exponent and
//    significand, the AVX-512 lanes with one FMA into the integer range of floats
//    (fragment_ops.cpp; checked against float_to_unorm8 on every float in [0, 1]).
//  * with one colour in every lane, the AVX-512 kernel looks each channel's result up in a table
//    of the kernel's own results over the 256 destination values (the result of a lane depends
//    on nothing else then).
//  * the blend arithmetic is the reference's, operation for operation, in float (no contraction:
//    the build uses -ffp-contract=off).
#pragma once
#include <cstdint>
#include <cstring>

#include "softgl/core/simd.h"
#include "softgl/surface/blend.h"
#include "softgl/surface/formats.h"

namespace softgl {

// float(i) / 255.0f for every unorm8 value.
const float* unorm8_to_float_table();

// Identical to float_to_unorm8 for every float (NaN -> 0).
inline uint8_t unorm8_from_float(float v) {
    if (!(v > 0.0f)) return 0;
    if (v >= 1.0f) return 255;
    return uint8_t(uint32_t(double(v) * 255.0 + 0.5));
}

enum class ColorKernel : uint8_t {
    Plain,       // blending off or ONE, ZERO, FUNC_ADD: no destination read
    AlphaOver,   // SRC_ALPHA, ONE_MINUS_SRC_ALPHA on rgb and alpha, FUNC_ADD on both
    Additive,    // ONE, ONE, FUNC_ADD on both
    Generic,     // anything else: the reference blend_unorm8
};

ColorKernel color_kernel(const BlendOp& op);

// One sample: the shader's colour (any floats) into dst (RGBA8), as blend_unorm8(op, src, dst).
template <ColorKernel K>
inline void write_color(const BlendOp& op, bool all_channels, const float* table, const float src[4],
                        uint8_t dst[4]) {
    if constexpr (K == ColorKernel::Generic) {
        (void)all_channels; (void)table;
        blend_unorm8(op, src, dst);
    } else {
        float s[4], out[4];
        for (int c = 0; c < 4; ++c) s[c] = clamp01(src[c]);
        if constexpr (K == ColorKernel::Plain) {
            for (int c = 0; c < 4; ++c) out[c] = s[c];
        } else if constexpr (K == ColorKernel::AlphaOver) {
            // factor(SRC_ALPHA) = s[3], factor(ONE_MINUS_SRC_ALPHA) = 1 - s[3]; s*sf + d*df.
            const float sf = s[3], df = 1.0f - s[3];
            for (int c = 0; c < 4; ++c) {
                const float d = (c == 3 && !op.has_alpha) ? 1.0f : table[dst[c]];
                out[c] = s[c] * sf + d * df;
            }
        } else {   // Additive: s*1 + d*1
            for (int c = 0; c < 4; ++c) {
                const float d = (c == 3 && !op.has_alpha) ? 1.0f : table[dst[c]];
                out[c] = s[c] * 1.0f + d * 1.0f;
            }
        }
        if (all_channels) {
            uint8_t v[4] = {unorm8_from_float(out[0]), unorm8_from_float(out[1]), unorm8_from_float(out[2]),
                            unorm8_from_float(out[3])};
            std::memcpy(dst, v, 4);
        } else {
            for (int c = 0; c < 4; ++c)
                if (op.write[size_t(c)]) dst[c] = unorm8_from_float(out[c]);
        }
    }
}

// Runs the kernel chosen for `op` on n colours (src: n x 4 floats, dst: n x 4 bytes); for tests.
void write_colors(const BlendOp& op, const float* src, uint8_t* dst, size_t n);

}  // namespace softgl

namespace softgl {

// The same kernels over n lanes at once, structure of arrays: red[l] = src[l], green[l] =
// src[stride + l], ...; dst[l] holds lane l's RGBA8 pixel (byte c = channel c) and receives the
// result. Bit for bit write_color<K> on every lane (SSE2 where available: the same IEEE
// operations, four lanes at a time). Generic is not offered here.
void write_color_lanes(ColorKernel kernel, const BlendOp& op, const float* src, size_t stride, uint32_t* dst,
                       size_t n);

// write_color_lanes runs the best level the CPU supports (core/simd.h); the explicit form is for
// the tests that prove the levels equal.
void write_color_lanes_at(SimdLevel level, ColorKernel kernel, const BlendOp& op, const float* src, size_t stride,
                          uint32_t* dst, size_t n);

// The lane kernel on the lanes of quads[0 .. n) (lane 4i + j: pixel j of quads[i], masks[lane] its
// coverage of 0 or 1; src as write_color_lanes) over the single-sampled RGBA8 buffer `buffer`,
// their covered pixels blended there; returns the number of pixels written. Bit for bit
// load_chunk_pixels, write_color_lanes_at and store_chunk_pixels (pipeline/chunk_pixels.h), which
// it runs itself without `in_place` (Tuning::blend_in_place) or below AVX2; with it, the AVX2 (with
// FMA) and AVX-512 levels read and write the quads' rows straight from registers, with no lane copies.
// `scratch` holds 4n lanes; quads_in_place counts the quads blended in place. Not for Generic.
struct ChunkPixels;
struct Quad;
uint64_t write_color_quads_at(SimdLevel level, bool in_place, ColorKernel kernel, const BlendOp& op, const float* src,
                              size_t stride, const ChunkPixels& buffer, const Quad* quads, const uint16_t* masks,
                              size_t n, uint32_t* scratch, uint64_t& quads_in_place);

// For a fragment shader that only copies a smooth vec4 varying to its colour (FragmentShader::copies):
// the colour kernel on that varying's interpolated values, v.words[first .. first + 3], for the
// lanes of quads[0 .. n) (lane 4*i + j is pixel j of quads[i]; dst as write_color_lanes). Bit for
// bit interpolate_varyings followed by write_color_lanes; the AVX-512 level fuses the two so the
// values go from registers into pixels instead of through the varying arrays (other levels run
// the two in turn). Not for Generic.
// Bit i of `rows` (n <= 64 then) marks quads i .. i + 3 as four whole quads side by side inside
// the single-sampled RGBA8 buffer `color` (pitch in pixels): their pixels are read and written
// there, two rows of eight, and their lanes in dst are left as they were.
struct VaryingInterpolation;
struct Quad;
struct PixelRows {
    uint8_t* color = nullptr;   // pixel (0, 0)
    size_t pitch = 0;           // pixels from one row to the next
    uint64_t rows = 0;
};
void write_interpolated_color_lanes_at(SimdLevel level, ColorKernel kernel, const BlendOp& op,
                                       const VaryingInterpolation& v, size_t first, const Quad* quads, size_t n,
                                       uint32_t* dst, const PixelRows& rows = {});
void write_interpolated_color_lanes(ColorKernel kernel, const BlendOp& op, const VaryingInterpolation& v, size_t first,
                                    const Quad* quads, size_t n, uint32_t* dst, const PixelRows& rows);

// A constant source colour (a uniform-only shader: docs/architecture.md, "Fast paths") blended by factors and equations
// under which channel c's result depends on destination channel c alone: ES 3.0 table 4.2's rgb
// factors read only d[c], except DST_ALPHA, ONE_MINUS_DST_ALPHA and SRC_ALPHA_SATURATE (d[3]),
// which are constant (d[3] = 1) without destination alpha; alpha's factors read only d[3]. Then
// a 256-entry byte table per channel, the reference kernel's results on every destination byte,
// blends by lookup, exactly.
bool blend_is_per_channel(const BlendOp& op);
struct BlendTable {
    alignas(64) uint8_t bytes[4][256];   // bytes[c][d]: channel c's result over destination byte d
    unsigned channels = 0xF;             // bit c: channel c is written (the others' entries are d)
};
// Runs the colour kernel (write_color_lanes_at, the scalar level's bytes at up to AVX2) on
// colour[] over the destinations d * 0x01010101, d = 0..255; channels the colour mask leaves out
// come out as the identity.
void build_blend_table(ColorKernel kernel, const BlendOp& op, const float colour[4], BlendTable& table);
// The table applied to the lanes of quads[0 .. n) (dst as write_color_lanes) and, in place, to
// the rows of four `rows` marks (as write_interpolated_color_lanes: their lanes are left as they
// were). AVX-512 VBMI looks up 64 bytes at a time where the CPU has it; every level gives the
// same bytes.
void apply_blend_table_at(SimdLevel level, const BlendTable& table, const Quad* quads, size_t n, uint32_t* dst,
                          const PixelRows& rows);
void apply_blend_table(const BlendTable& table, const Quad* quads, size_t n, uint32_t* dst, const PixelRows& rows);
// The table applied in place to every pixel of [x0, x1) x [y0, y1) of the single-sampled RGBA8
// buffer `color` (pitch in pixels): a primitive that covers a whole part of a tile (whole_rect.h), with
// no quads built or gathered. The same bytes as apply_blend_table_at on that part's quads.
struct PixelRect {
    uint8_t* color = nullptr;   // pixel (0, 0)
    size_t pitch = 0;           // pixels from one row to the next
    int32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};
void apply_blend_table_to_rect_at(SimdLevel level, const BlendTable& table, const PixelRect& rect);
void apply_blend_table_to_rect(const BlendTable& table, const PixelRect& rect);

}  // namespace softgl
