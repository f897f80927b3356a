#include <pybind11/pybind11.h>

#include "softgl/core/enums.h"

namespace py = pybind11;

void bind_enums(py::module_& m) {
    // [(name, value, first WebGL version)] -- the Python layer puts them on the module and classes.
    py::list table;
    for (const auto& e : softgl::gl::kEnumTable) table.append(py::make_tuple(e.name, e.value, e.version));
    m.attr("ENUMS") = table;
}
