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

// diamond_exit_span of each segment of `segments` (n, 4) int64, fixed-point (ax, ay, bx, by) with
// distinct ends, by `method` ("auto" or "scan"). Returns (n, 3) int64: produced (0 or 1), first, last.
py::array_t<int64_t> diamond_exit_spans(Array<int64_t> segments, const std::string& method) {
    if (segments.ndim() != 2 || segments.shape(1) != 4) throw py::value_error("segments (n, 4)");
    if (method != "auto" && method != "scan") throw py::value_error("method must be 'auto' or 'scan'");
    const DiamondExitMethod m = method == "scan" ? DiamondExitMethod::Scan : DiamondExitMethod::Auto;
    const size_t n = size_t(segments.shape(0));
    const int64_t* const s = segments.data();
    // Inside the guard band (viewport.h) plus the wide-line shift, as setup's snapped ends are.
    constexpr int64_t kLimit = (int64_t(1) << 28) + (int64_t(1) << 16);
    for (size_t i = 0; i < 4 * n; ++i)
        if (s[i] < -kLimit || s[i] > kLimit) throw py::value_error("coordinate outside the guard band");
    for (size_t i = 0; i < n; ++i)
        if (s[4 * i] == s[4 * i + 2] && s[4 * i + 1] == s[4 * i + 3]) throw py::value_error("a segment's ends are equal");
    py::array_t<int64_t> out({n, size_t(3)});
    for (size_t i = 0; i < n; ++i) {
        int64_t first = 0, last = 0;
        const bool produced = diamond_exit_span(s[4 * i], s[4 * i + 1], s[4 * i + 2], s[4 * i + 3], first, last, m);
        out.mutable_at(i, 0) = produced, out.mutable_at(i, 1) = produced ? first : 0, out.mutable_at(i, 2) = produced ? last : 0;
    }
    return out;
}

}  // namespace

void bind_testing_setup(py::module_& t) {
    t.def("project_vertices", &project_vertices, py::arg("level"), py::arg("positions"), py::arg("width"),
          py::arg("height"), py::arg("viewport"));
    t.def("diamond_exit_spans", &diamond_exit_spans, py::arg("segments"), py::arg("method") = "auto");
}
