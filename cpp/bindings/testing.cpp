#include <cstring>
// softgl._core.testing: direct access to single pipeline stages for tests. Conversions only.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "softgl/pipeline/blend.h"
#include "softgl/pipeline/depth_stencil.h"

namespace py = pybind11;

void bind_testing(py::module_& m) {
    auto t = m.def_submodule("testing", "single pipeline stages, for tests");
    t.def("blend_unorm8",
          [](const std::array<uint32_t, 6>& funcs_and_equations, const std::array<float, 4>& constant,
             const std::array<bool, 4>& mask, bool has_alpha,
             py::array_t<float, py::array::c_style | py::array::forcecast> src,
             py::array_t<uint8_t, py::array::c_style | py::array::forcecast> dst) {
              softgl::State state;
              state.blend.enabled = true;
              state.blend.src_rgb = funcs_and_equations[0];
              state.blend.dst_rgb = funcs_and_equations[1];
              state.blend.src_alpha = funcs_and_equations[2];
              state.blend.dst_alpha = funcs_and_equations[3];
              state.blend.equation_rgb = funcs_and_equations[4];
              state.blend.equation_alpha = funcs_and_equations[5];
              state.blend.color = constant;
              state.color_mask = mask;
              const softgl::BlendOp op = softgl::BlendOp::from_state(state, has_alpha);
              if (src.ndim() != 2 || src.shape(1) != 4 || dst.ndim() != 2 || dst.shape(1) != 4 ||
                  src.shape(0) != dst.shape(0))
                  throw py::value_error("src must be (N, 4) float32 and dst (N, 4) uint8");
              py::array_t<uint8_t> out({dst.shape(0), py::ssize_t(4)});
              std::memcpy(out.mutable_data(), dst.data(), size_t(dst.nbytes()));
              for (py::ssize_t i = 0; i < src.shape(0); ++i)
                  softgl::blend_unorm8(op, src.data(i, 0), out.mutable_data(i, 0));
              return out;
          });
}
