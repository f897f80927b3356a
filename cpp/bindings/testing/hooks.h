// softgl._core.testing: single pipeline stages for tests, one file per stage in this folder, each
// with a bind_testing_<stage>(t) that adds its hooks to the submodule t. This header holds what
// several stages' hooks share: the array conversions and the colour hooks' blend state.
// Conversions only; behaviour lives in cpp/softgl. A hook is a C++ function named as in Python, or
// <name>_hook where the stage function it wraps has that name.
#pragma once
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "softgl/pipeline/interpolate.h"
#include "softgl/pipeline/raster.h"
#include "softgl/pipeline/setup.h"
#include "softgl/surface/blend.h"

namespace py = pybind11;

void bind_testing_draw(py::module_& t);
void bind_testing_transforms(py::module_& t);
void bind_testing_setup(py::module_& t);
void bind_testing_clip(py::module_& t);
void bind_testing_raster(py::module_& t);
void bind_testing_early_depth(py::module_& t);
void bind_testing_interpolate(py::module_& t);
void bind_testing_fragment_ops(py::module_& t);
void bind_testing_blend_table(py::module_& t);
void bind_testing_sampler(py::module_& t);

namespace softgl::bindings {

// An input array of T in C order (converted from whatever the caller passed).
template <class T>
using Array = py::array_t<T, py::array::c_style | py::array::forcecast>;

// A fresh copy of `a`, same shape: hooks return the buffers they wrote into, the inputs unchanged.
template <class T>
py::array_t<T> copy_of(const Array<T>& a) {
    py::array_t<T> out(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()));
    std::memcpy(out.mutable_data(), a.data(), size_t(a.nbytes()));
    return out;
}

// Quads from rows (x, y) of lower-left pixels, each with `coverage`, or from rows (x, y, coverage).
template <class T>
std::vector<Quad> to_quads(const Array<T>& rows, uint64_t coverage = 0) {
    std::vector<Quad> quads(size_t(rows.shape(0)));
    for (size_t i = 0; i < quads.size(); ++i)
        quads[i] = Quad(int32_t(rows.at(i, 0)), int32_t(rows.at(i, 1)),
                        rows.shape(1) > 2 ? uint64_t(rows.at(i, 2)) : coverage);
    return quads;
}

// PixelRows' rows of four (bit i: quads i .. i + 3) must lie inside the image: the kernels write
// there unchecked. quads (n, 2) int32 lower-left pixels, image (h, w).
void check_rows_inside(const Array<int32_t>& quads, size_t n, uint64_t rows, py::ssize_t height, py::ssize_t width);

// The colour hooks' blend state: funcs_and_equations (srcRGB, dstRGB, srcA, dstA, eqRGB, eqA).
BlendOp blend_op(bool enabled, const std::array<uint32_t, 6>& fe, const std::array<bool, 4>& mask, bool has_alpha,
                 const std::array<float, 4>& constant = {0, 0, 0, 0});

// The interpolation hooks' inputs: planes (4, 3) float64 rows (a, b, c) of weight[0..2] and inv_w,
// origin in 1/256 pixel, quads (n, 2) int32 lower-left pixels, values (vertices, words) float32,
// the planes' base pixel. Filled in place: vi points into the other members.
struct InterpolationInputs {
    PrimitiveSetup prim{};
    std::vector<Quad> quads;
    std::vector<int> words;
    std::vector<float> values;
    VaryingInterpolation vi;

    InterpolationInputs(const Array<double>& planes, int64_t origin_x, int64_t origin_y, const Array<int32_t>& q,
                        const Array<float>& v, int32_t base_x, int32_t base_y);
    InterpolationInputs(const InterpolationInputs&) = delete;   // vi points into this object
};

}  // namespace softgl::bindings
