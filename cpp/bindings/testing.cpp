#include <cstring>
// softgl._core.testing: direct access to single pipeline stages for tests. Conversions only.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "softgl/pipeline/assemble.h"
#include "softgl/pipeline/blend.h"
#include "softgl/pipeline/depth_stencil.h"

namespace py = pybind11;

namespace {

// A glm::mat4 as a (4, 4) array in math layout (m[row, col]); GLM stores columns.
py::array_t<float> from_glm(const glm::mat4& m) {
    py::array_t<float> out({4, 4});
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) *out.mutable_data(r, c) = m[c][r];
    return out;
}

glm::vec3 vec3(const std::array<float, 3>& v) { return glm::vec3(v[0], v[1], v[2]); }

}  // namespace

void bind_testing(py::module_& m) {
    auto t = m.def_submodule("testing", "single pipeline stages, for tests");
    t.def("assemble", [](uint32_t mode, uint32_t count) {
        std::vector<uint32_t> out;
        softgl::assemble(mode, count, out);
        return out;
    });
    // GLM as the reference for softgl.transforms (the C++ side's math library).
    t.def("glm_perspective", [](float fovy, float aspect, float n, float f) { return from_glm(glm::perspective(fovy, aspect, n, f)); });
    t.def("glm_ortho", [](float l, float r, float b, float tp, float n, float f) { return from_glm(glm::ortho(l, r, b, tp, n, f)); });
    t.def("glm_look_at", [](std::array<float, 3> eye, std::array<float, 3> center, std::array<float, 3> up) {
        return from_glm(glm::lookAt(vec3(eye), vec3(center), vec3(up)));
    });
    t.def("glm_translate", [](std::array<float, 3> v) { return from_glm(glm::translate(glm::mat4(1.0f), vec3(v))); });
    t.def("glm_scale", [](std::array<float, 3> v) { return from_glm(glm::scale(glm::mat4(1.0f), vec3(v))); });
    t.def("glm_rotate", [](float angle, std::array<float, 3> axis) { return from_glm(glm::rotate(glm::mat4(1.0f), angle, vec3(axis))); });
    t.def("glm_inverse_transpose", [](py::array_t<float, py::array::c_style | py::array::forcecast> a) {
        glm::mat4 m;
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) m[c][r] = *a.data(r, c);
        return from_glm(glm::transpose(glm::inverse(m)));
    });
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
