// softgl._core.testing hooks for pipeline/setup.
#include <array>

#include <pybind11/stl.h>

#include "hooks.h"

using namespace softgl;
using softgl::bindings::Array;

namespace {

// Setup::project_vertices at one instruction-set level: positions (n, 4) float32 clip coordinates,
// viewport (x, y, width, height) on a width x height target. Returns (XY (n, 2) int64, z_inv_w (n, 2)
// float64), the WindowPosition fields.
auto project_vertices(int level, Array<float> positions, int32_t width, int32_t height,
                      std::array<int32_t, 4> viewport) {
    if (positions.ndim() != 2 || positions.shape(1) != 4) throw py::value_error("positions (n, 4)");
    RasterState rs = RasterState::for_target(width, height);
    rs.viewport.x = viewport[0], rs.viewport.y = viewport[1];
    rs.viewport.width = viewport[2], rs.viewport.height = viewport[3];
    const size_t n = size_t(positions.shape(0));
    std::vector<WindowPosition> out(n);
    Setup(rs).project_vertices(positions.data(), n, out.data(), SimdLevel(level));
    py::array_t<int64_t> xy({n, size_t(2)});
    py::array_t<double> zw({n, size_t(2)});
    for (size_t i = 0; i < n; ++i) {
        xy.mutable_at(i, 0) = out[i].X, xy.mutable_at(i, 1) = out[i].Y;
        zw.mutable_at(i, 0) = out[i].z, zw.mutable_at(i, 1) = out[i].inv_w;
    }
    return py::make_tuple(xy, zw);
}

}  // namespace

void bind_testing_setup(py::module_& t) {
    t.def("project_vertices", &project_vertices, py::arg("level"), py::arg("positions"), py::arg("width"),
          py::arg("height"), py::arg("viewport"));
}
