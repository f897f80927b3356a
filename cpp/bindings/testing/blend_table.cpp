// softgl._core.testing hooks for pipeline/fragment_ops' blend tables (draws of a constant colour):
// build_blend_table, then apply_blend_table_at or apply_blend_table_to_rect_at at one level.
// Blending as fragment_ops_write; rows: PixelRows' bits, for quads in `image` ((h, w) uint32 pixels).
#include <array>
#include <tuple>

#include <pybind11/stl.h>

#include "hooks.h"
#include "softgl/pipeline/fragment_ops.h"

using namespace softgl;
using softgl::bindings::Array;
using softgl::bindings::blend_op;
using softgl::bindings::copy_of;

namespace {

// The blend table of `op` for the constant colour `colour`, as a draw builds it; false (no table)
// when the blend is not per channel.
bool constant_blend_table(const BlendOp& op, const std::array<float, 4>& colour, BlendTable& table) {
    if (!blend_is_per_channel(op)) return false;
    build_blend_table(color_kernel(op), op, colour.data(), table);
    return true;
}

// quads (n, 2) int32 lower-left pixels, dst (4n,) uint32 their lanes. Returns (per_channel, dst,
// image) after the call (dst and image unchanged when the blend is not per channel).
std::tuple<bool, py::array_t<uint32_t>, py::array_t<uint32_t>> blend_table_lanes(
    int level, const std::array<uint32_t, 6>& fe, const std::array<float, 4>& constant, const std::array<bool, 4>& mask,
    bool has_alpha, const std::array<float, 4>& colour, Array<int32_t> quads, Array<uint32_t> dst, uint64_t rows,
    Array<uint32_t> image) {
    const size_t n = quads.ndim() == 2 ? size_t(quads.shape(0)) : 0;
    if (quads.ndim() != 2 || quads.shape(1) != 2 || dst.ndim() != 1 || size_t(dst.shape(0)) != 4 * n ||
        image.ndim() != 2 || n > 64)
        throw py::value_error("quads (n <= 64, 2), dst (4n,), image (h, w)");
    bindings::check_rows_inside(quads, n, rows, image.shape(0), image.shape(1));
    const BlendOp op = blend_op(true, fe, mask, has_alpha, constant);
    const std::vector<Quad> q = bindings::to_quads(quads);
    py::array_t<uint32_t> out = copy_of(dst);
    py::array_t<uint32_t> picture = copy_of(image);
    BlendTable table;
    const bool per_channel = constant_blend_table(op, colour, table);
    if (per_channel) {
        const PixelRows pixel_rows{reinterpret_cast<uint8_t*>(picture.mutable_data()), size_t(image.shape(1)), rows};
        apply_blend_table_at(SimdLevel(level), table, q.data(), n, out.mutable_data(), pixel_rows);
    }
    return std::make_tuple(per_channel, out, picture);
}

// The table applied in place to the pixels [x0, x1) x [y0, y1) of `image`. Returns (per_channel,
// image after the call).
std::tuple<bool, py::array_t<uint32_t>> blend_table_rect(int level, const std::array<uint32_t, 6>& fe,
                                                         const std::array<float, 4>& constant,
                                                         const std::array<bool, 4>& mask, bool has_alpha,
                                                         const std::array<float, 4>& colour,
                                                         const std::array<int32_t, 4>& rect, Array<uint32_t> image) {
    if (image.ndim() != 2 || rect[0] < 0 || rect[1] < 0 || rect[0] > rect[2] || rect[1] > rect[3] ||
        rect[2] > image.shape(1) || rect[3] > image.shape(0))
        throw py::value_error("image (h, w), rect (x0, y0, x1, y1) inside it");
    const BlendOp op = blend_op(true, fe, mask, has_alpha, constant);
    py::array_t<uint32_t> picture = copy_of(image);
    BlendTable table;
    const bool per_channel = constant_blend_table(op, colour, table);
    if (per_channel) {
        const PixelRect r{reinterpret_cast<uint8_t*>(picture.mutable_data()), size_t(image.shape(1)), rect[0], rect[1],
                          rect[2], rect[3]};
        apply_blend_table_to_rect_at(SimdLevel(level), table, r);
    }
    return std::make_tuple(per_channel, picture);
}

}  // namespace

void bind_testing_blend_table(py::module_& t) {
    t.def("blend_table_lanes", &blend_table_lanes, py::arg("level"), py::arg("funcs_and_equations"),
          py::arg("constant"), py::arg("mask"), py::arg("has_alpha"), py::arg("colour"), py::arg("quads"),
          py::arg("dst"), py::arg("rows"), py::arg("image"));
    t.def("blend_table_rect", &blend_table_rect, py::arg("level"), py::arg("funcs_and_equations"),
          py::arg("constant"), py::arg("mask"), py::arg("has_alpha"), py::arg("colour"), py::arg("rect"),
          py::arg("image"));
}
