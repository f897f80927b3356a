// Conversions shared by the binding files: WebGL values to Python (arrays from Python: array_intake.h).
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "softgl/api/context.h"

namespace softgl::bindings {

namespace py = pybind11;

// A getParameter-style value in the Python form WebGL's JS value maps to (docs/architecture.md, "Layers").
inline py::object to_python(const softgl::Value& value) {
    struct Visitor {
        py::object operator()(const softgl::Null&) const { return py::none(); }
        py::object operator()(bool v) const { return py::bool_(v); }
        py::object operator()(int64_t v) const { return py::int_(v); }
        py::object operator()(double v) const { return py::float_(v); }
        py::object operator()(const std::string& v) const { return py::str(v); }
        py::object operator()(const softgl::Int32Array& v) const {
            return py::array_t<int32_t>(py::ssize_t(v.values.size()), v.values.data());
        }
        py::object operator()(const softgl::Uint32Array& v) const {
            return py::array_t<uint32_t>(py::ssize_t(v.values.size()), v.values.data());
        }
        py::object operator()(const softgl::Float32Array& v) const {
            return py::array_t<float>(py::ssize_t(v.values.size()), v.values.data());
        }
        py::object operator()(const std::shared_ptr<softgl::Object>& v) const { return py::cast(v); }
        py::object operator()(const softgl::BoolList& v) const {
            py::list out;
            for (bool b : v.values) out.append(py::bool_(b));
            return out;
        }
    };
    return std::visit(Visitor{}, value);
}

}  // namespace softgl::bindings
