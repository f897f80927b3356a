// softgl._core: the pybind11 module. Conversions only; behaviour lives in cpp/softgl.
#include <pybind11/pybind11.h>

#include <string>

namespace py = pybind11;

void bind_enums(py::module_& m);
void bind_context(py::module_& m);
void bind_uniform_arrays(py::module_& m);
void bind_textures(py::module_& m);
void bind_testing(py::module_& m);
void bind_tuning(py::module_& m);
void bind_probes(py::module_& m);
void bind_glsl(py::module_& m);
void bind_blendlab(py::module_& m);
void bind_draw_plan(py::module_& m);
void bind_canvas(py::module_& m);

PYBIND11_MODULE(_core, m) {
    m.doc() = "softgl's C++ core (use the softgl package, not this module)";
    // The pybind11 that made the bindings: signatures (and so the stub, python/softgl/_core.pyi)
    // are spelled by it (tools/gen_stubs.py).
    m.attr("_pybind11_version") = std::to_string(PYBIND11_VERSION_MAJOR) + "." +
                                  std::to_string(PYBIND11_VERSION_MINOR) + "." + std::to_string(PYBIND11_VERSION_PATCH);
    bind_enums(m);
    bind_context(m);
    bind_uniform_arrays(m);
    bind_textures(m);
    bind_testing(m);
    bind_tuning(m);
    bind_probes(m);
    bind_glsl(m);
    bind_blendlab(m);
    bind_draw_plan(m);
    bind_canvas(m);
}
