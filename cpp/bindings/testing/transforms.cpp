// softgl._core.testing.glm_*: GLM as the reference for softgl.transforms (the C++ side's math library).
#include <array>

#include <pybind11/stl.h>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "hooks.h"

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

void bind_testing_transforms(py::module_& t) {
    t.def("glm_perspective", [](float fovy, float aspect, float n, float f) { return from_glm(glm::perspective(fovy, aspect, n, f)); });
    t.def("glm_ortho", [](float l, float r, float b, float tp, float n, float f) { return from_glm(glm::ortho(l, r, b, tp, n, f)); });
    t.def("glm_look_at", [](std::array<float, 3> eye, std::array<float, 3> center, std::array<float, 3> up) {
        return from_glm(glm::lookAt(vec3(eye), vec3(center), vec3(up)));
    });
    t.def("glm_translate", [](std::array<float, 3> v) { return from_glm(glm::translate(glm::mat4(1.0f), vec3(v))); });
    t.def("glm_scale", [](std::array<float, 3> v) { return from_glm(glm::scale(glm::mat4(1.0f), vec3(v))); });
    t.def("glm_rotate", [](float angle, std::array<float, 3> axis) { return from_glm(glm::rotate(glm::mat4(1.0f), angle, vec3(axis))); });
    t.def("glm_inverse_transpose", [](softgl::bindings::Array<float> a) {
        glm::mat4 m;
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) m[c][r] = *a.data(r, c);
        return from_glm(glm::transpose(glm::inverse(m)));
    });
}
