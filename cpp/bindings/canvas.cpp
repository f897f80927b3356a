// Context._resize: the canvas's width/height setters (python/softgl/context.py, Canvas).
#include <pybind11/pybind11.h>

#include <string>

#include "exclusive.h"   // the Context caster every binding file shares
#include "softgl/api/context.h"

namespace py = pybind11;

void bind_canvas(py::module_& m) {
    auto context = py::reinterpret_borrow<py::class_<softgl::Context>>(m.attr("Context"));
    context.def("_resize", [](softgl::Context& ctx, int32_t width, int32_t height) {
        const std::string why = ctx.resize(width, height);
        if (!why.empty()) throw py::value_error("canvas size " + std::to_string(width) + "x" +
                                                std::to_string(height) + ": " + why);
    }, py::arg("width"), py::arg("height"));
}
