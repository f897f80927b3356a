// softgl._core.testing hooks for the per-fragment colour kernels (pipeline/fragment_ops.h) and the
// reference they must equal (blend_unorm8, surface/blend.h). Blend state as blend_op (hooks.h).
#include <array>
#include <utility>

#include <pybind11/stl.h>

#include "hooks.h"
#include "softgl/pipeline/chunk_pixels.h"
#include "softgl/pipeline/fragment_ops.h"
#include "softgl/surface/formats.h"

using namespace softgl;
using softgl::bindings::Array;
using softgl::bindings::blend_op;
using softgl::bindings::copy_of;

namespace {

// src (N, 4) float32 colours for dst (N, 4) uint8 pixels: returns the copy of dst to write into.
py::array_t<uint8_t> pixels_for(const Array<float>& src, const Array<uint8_t>& dst) {
    if (src.ndim() != 2 || src.shape(1) != 4 || dst.ndim() != 2 || dst.shape(1) != 4 || src.shape(0) != dst.shape(0))
        throw py::value_error("src must be (N, 4) float32 and dst (N, 4) uint8");
    return copy_of(dst);
}

// The reference: blend_unorm8 per pixel.
py::array_t<uint8_t> blend_unorm8_hook(const std::array<uint32_t, 6>& funcs_and_equations,
                                       const std::array<float, 4>& constant, const std::array<bool, 4>& mask,
                                       bool has_alpha, Array<float> src, Array<uint8_t> dst) {
    const BlendOp op = blend_op(true, funcs_and_equations, mask, has_alpha, constant);
    py::array_t<uint8_t> out = pixels_for(src, dst);
    for (py::ssize_t i = 0; i < src.shape(0); ++i) blend_unorm8(op, src.data(i, 0), out.mutable_data(i, 0));
    return out;
}

// For the proof that the specialised kernels equal blend_unorm8: lanes=false runs write_color<K>
// per pixel, lanes=true the structure-of-arrays kernel the draw uses for single-sampled targets
// (at `level`, -1: the best). Returns (pixels, the kernel).
std::pair<py::array_t<uint8_t>, int> fragment_ops_write(const std::array<uint32_t, 6>& fe,
                                                        const std::array<float, 4>& constant,
                                                        const std::array<bool, 4>& mask, bool has_alpha,
                                                        Array<float> src, Array<uint8_t> dst, bool lanes, int level) {
    const BlendOp op = blend_op(true, fe, mask, has_alpha, constant);
    py::array_t<uint8_t> out = pixels_for(src, dst);
    const size_t n = size_t(src.shape(0));
    if (!lanes) {
        write_colors(op, src.data(), out.mutable_data(), n);
    } else {
        std::vector<float> soa(4 * n);
        for (size_t i = 0; i < n; ++i)
            for (size_t c = 0; c < 4; ++c) soa[c * n + i] = src.data()[4 * i + c];
        std::vector<uint32_t> px(n);
        std::memcpy(px.data(), out.data(), 4 * n);
        if (level < 0) write_color_lanes(color_kernel(op), op, soa.data(), n, px.data(), n);
        else write_color_lanes_at(SimdLevel(level), color_kernel(op), op, soa.data(), n, px.data(), n);
        std::memcpy(out.mutable_data(), px.data(), 4 * n);
    }
    return std::make_pair(out, int(color_kernel(op)));
}

// The lane kernels' float -> unorm8 conversion against float_to_unorm8 (surface/formats.h) on the
// float bit patterns first, first + step, ... <= last: runs the Plain kernel at `level` on all
// four channels of each value and returns how many bytes differ. In C++ so that every float in
// [0, 1] (about 1.07e9) can be checked in seconds.
uint64_t unorm8_conversion_mismatches(int level, uint32_t first, uint32_t last, uint32_t step, bool in_place) {
    State state;   // blending off, every channel written
    const BlendOp op = BlendOp::from_state(state, true);
    constexpr size_t block = 4096;
    std::vector<float> src(block);
    std::vector<uint32_t> px(block);
    uint64_t mismatches = 0;
    py::gil_scoped_release release;
    for (uint64_t b = first; b <= last;) {
        size_t n = 0;
        for (; n < block && b <= last; ++n, b += step) {
            const uint32_t bits = uint32_t(b);
            std::memcpy(&src[n], &bits, 4);
        }
        if (!in_place) {
            // stride 0: the four channels of lane l all read src[l].
            write_color_lanes_at(SimdLevel(level), ColorKernel::Plain, op, src.data(), 0, px.data(), n);
            for (size_t i = 0; i < n; ++i) {
                const uint32_t want = float_to_unorm8(src[i]) * 0x01010101u;
                if (px[i] != want)
                    for (int c = 0; c < 4; ++c) mismatches += ((px[i] ^ want) >> (8 * c) & 0xFF) != 0;
            }
            continue;
        }
        // write_color_quads_at: quads side by side over two rows, channels 0-2 and then 3 written
        // (the other kept: the kernel reads the destination, as blend_in_place needs).
        const size_t quads = (n + 3) / 4, width = 2 * quads;
        for (size_t i = n; i < 4 * quads; ++i) src[i] = 0.0f;
        std::vector<Quad> q(quads);
        for (size_t i = 0; i < quads; ++i) q[i].x = int32_t(2 * i), q[i].y = 0;
        std::vector<uint16_t> masks(4 * quads, 1);
        std::vector<uint32_t> image(2 * width), scratch(4 * quads);
        for (int pass = 0; pass < 2; ++pass) {
            BlendOp masked = op;
            masked.write = {pass == 0, pass == 0, pass == 0, pass == 1};
            std::fill(image.begin(), image.end(), 0u);
            const ChunkPixels buffer{reinterpret_cast<uint8_t*>(image.data()), width, int32_t(width) - 1, 1};
            uint64_t in_place_quads = 0;
            write_color_quads_at(SimdLevel(level), true, ColorKernel::Plain, masked, src.data(), 0, buffer, q.data(),
                                 masks.data(), quads, scratch.data(), in_place_quads);
            for (size_t i = 0; i < n; ++i) {
                const uint32_t got = image[(i >> 1 & 1) * width + 2 * (i / 4) + (i & 1)];
                for (int c = 0; c < 4; ++c)
                    if (masked.write[size_t(c)]) mismatches += (got >> (8 * c) & 0xFF) != float_to_unorm8(src[i]);
            }
        }
    }
    return mismatches;
}

// The fused copy kernel (write_interpolated_color_lanes) at one level, or with fused=false the two
// stages it replaces (interpolate_varyings_at, then write_color_lanes_at): planes, origin, quads,
// values and base as interpolate_varyings; the colour is words first .. first + 3; blending as
// fragment_ops_write (enabled when `blend`); dst (4n,) uint32 pixels; rows (fused only):
// PixelRows' bits, for quads in `image` ((h, w) uint32 pixels). Returns (dst, image) after the call.
std::pair<py::array_t<uint32_t>, py::array_t<uint32_t>> interpolated_color_lanes(
    int level, bool fused, Array<double> planes, int64_t origin_x, int64_t origin_y, Array<int32_t> quads,
    Array<float> values, int32_t base_x, int32_t base_y, size_t first, bool blend, const std::array<uint32_t, 6>& fe,
    const std::array<bool, 4>& mask, bool has_alpha, Array<uint32_t> dst, uint64_t rows, Array<uint32_t> image) {
    const bindings::InterpolationInputs in(planes, origin_x, origin_y, quads, values, base_x, base_y);
    const size_t n = in.quads.size(), count = in.words.size();
    if (first + 4 > count || dst.ndim() != 1 || size_t(dst.shape(0)) != 4 * n || image.ndim() != 2 ||
        (rows && (!fused || n > 64)))
        throw py::value_error("values (vertices, words >= first + 4), dst (4n,), image (h, w); rows only "
                              "fused, with n <= 64");
    bindings::check_rows_inside(quads, n, rows, image.shape(0), image.shape(1));
    const BlendOp op = blend_op(blend, fe, mask, has_alpha);
    const ColorKernel kernel = color_kernel(op);
    if (kernel == ColorKernel::Generic) throw py::value_error("no fused kernel for Generic blending");
    py::array_t<uint32_t> out = copy_of(dst);
    const SimdLevel simd = SimdLevel(level);
    py::array_t<uint32_t> picture = copy_of(image);
    if (fused) {
        const PixelRows pixel_rows{reinterpret_cast<uint8_t*>(picture.mutable_data()), size_t(image.shape(1)), rows};
        write_interpolated_color_lanes_at(simd, kernel, op, in.vi, first, in.quads.data(), n, out.mutable_data(),
                                          pixel_rows);
    } else {
        std::vector<uint32_t> varyings(count * 4 * n);
        interpolate_varyings_at(simd, in.vi, in.quads.data(), n, varyings.data(), 4 * n);
        write_color_lanes_at(simd, kernel, op, reinterpret_cast<const float*>(varyings.data()) + first * 4 * n, 4 * n,
                             out.mutable_data(), 4 * n);
    }
    return std::make_pair(out, picture);
}

}  // namespace

void bind_testing_fragment_ops(py::module_& t) {
    t.def("fragment_ops_write", &fragment_ops_write, py::arg("funcs_and_equations"), py::arg("constant"),
          py::arg("mask"), py::arg("has_alpha"), py::arg("src"), py::arg("dst"), py::arg("lanes"),
          py::arg("level") = -1);
    t.def("unorm8_conversion_mismatches", &unorm8_conversion_mismatches, py::arg("level"), py::arg("first"),
          py::arg("last"), py::arg("step") = 1, py::arg("in_place") = false);
    t.def("interpolated_color_lanes", &interpolated_color_lanes, py::arg("level"), py::arg("fused"),
          py::arg("planes"), py::arg("origin_x"), py::arg("origin_y"), py::arg("quads"), py::arg("values"),
          py::arg("base_x"), py::arg("base_y"), py::arg("first"), py::arg("blend"), py::arg("funcs_and_equations"),
          py::arg("mask"), py::arg("has_alpha"), py::arg("dst"), py::arg("rows"), py::arg("image"));
    t.def("blend_unorm8", &blend_unorm8_hook);
}
