// softgl._core.testing hooks for pipeline/setup.
#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <vector>

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

// Every field of the records, integers (n, 27) and doubles as their bits (n, 21): two setups'
// records compare exactly (PrimitiveSetup has padding, so not as raw bytes).
py::tuple record_fields(const std::vector<PrimitiveSetup>& prims) {
    const size_t n = prims.size();
    py::array_t<int64_t> ints({n, size_t(27)});
    py::array_t<uint64_t> bits({n, size_t(21)});
    for (size_t r = 0; r < n; ++r) {
        const PrimitiveSetup& p = prims[r];
        const int64_t iv[27] = {p.a[0], p.a[1], p.a[2], p.a[3], p.b[0], p.b[1], p.b[2], p.b[3], p.c[0], p.c[1],
                                p.c[2], p.c[3], p.x0, p.y0, p.x1, p.y1, p.origin_x, p.origin_y, p.vertex[0],
                                p.vertex[1], p.vertex[2], p.primitive, int64_t(p.kind), p.edge_count,
                                p.front_facing, int64_t(p.area_shape), 0};
        const double dv[21] = {p.depth.a, p.depth.b, p.depth.c, p.depth_offset, p.weight[0].a, p.weight[0].b,
                               p.weight[0].c, p.weight[1].a, p.weight[1].b, p.weight[1].c, p.weight[2].a,
                               p.weight[2].b, p.weight[2].c, p.inv_w.a, p.inv_w.b, p.inv_w.c, p.area_offset[0],
                               p.area_offset[1], p.area_offset[2], p.area_offset[3], double(p.point_size)};
        for (size_t k = 0; k < 27; ++k) ints.mutable_at(r, k) = iv[k];
        for (size_t k = 0; k < 21; ++k) std::memcpy(&bits.mutable_at(r, k), &dv[k], 8);
    }
    return py::make_tuple(ints, bits);
}

// Triangles (m, 3) of vertex indices into positions (n, 4) (clip coordinates) set up as a draw
// does: the vertices projected (Setup::project_vertices), then each triangle with
// Setup::triangle (the reference, batched=False) or all with Setup::triangles (batched=True) at
// instruction-set level `level`, numbered from first_primitive. Returns (ints, double bits, stats) of record_fields and the
// counters. cull: 0 (off), GL FRONT, BACK or FRONT_AND_BACK.
py::tuple setup_triangles(Array<float> positions, Array<uint32_t> triangles, int32_t width, int32_t height,
                          uint32_t cull, uint32_t front_face, bool polygon_offset, double factor, double units,
                          int samples, bool sample_bounds, uint32_t first_primitive, bool batched, int level) {
    if (positions.ndim() != 2 || positions.shape(1) != 4) throw py::value_error("positions (n, 4)");
    if (triangles.ndim() != 2 || triangles.shape(1) != 3) throw py::value_error("triangles (m, 3)");
    const size_t n = size_t(positions.shape(0)), m = size_t(triangles.shape(0));
    for (size_t i = 0; i < 3 * m; ++i)
        if (triangles.data()[i] >= n) throw py::value_error("vertex index out of range");
    RasterState rs = RasterState::for_target(width, height);
    rs.cull_face = cull != 0;
    if (cull) rs.cull_face_mode = cull;
    rs.front_face = front_face;
    rs.polygon_offset_fill = polygon_offset;
    rs.polygon_offset_factor = factor, rs.polygon_offset_units = units;
    rs.samples = samples;
    rs.sample_bounds = sample_bounds;
    Setup setup(rs);
    std::vector<WindowPosition> window(n);
    setup.project_vertices(positions.data(), n, window.data(), SimdLevel::Scalar);
    std::vector<PrimitiveSetup> prims;
    if (batched) {
        setup.triangles(positions.data(), window.data(), triangles.data(), m, first_primitive, prims,
                        std::min(SimdLevel(level), best_simd_level()));
    } else {
        for (size_t k = 0; k < m; ++k)
            setup.triangle(positions.data(), window.data(), triangles.data() + 3 * k, first_primitive + uint32_t(k), prims);
    }
    const SetupStats& st = setup.stats;
    py::dict stats;
    stats["primitives"] = st.primitives, stats["invalid"] = st.invalid, stats["outside"] = st.outside;
    stats["clipped"] = st.clipped, stats["culled"] = st.culled, stats["zero_area"] = st.zero_area;
    stats["emitted"] = st.emitted;
    const py::tuple fields = record_fields(prims);
    return py::make_tuple(fields[0], fields[1], stats);
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
    t.def("setup_triangles", &setup_triangles, py::arg("positions"), py::arg("triangles"), py::arg("width"),
          py::arg("height"), py::arg("cull") = 0, py::arg("front_face") = 0x901, py::arg("polygon_offset") = false,
          py::arg("factor") = 0.0, py::arg("units") = 0.0, py::arg("samples") = 1, py::arg("sample_bounds") = false,
          py::arg("first_primitive") = 0, py::arg("batched") = true, py::arg("level") = 0);
    t.def("diamond_exit_spans", &diamond_exit_spans, py::arg("segments"), py::arg("method") = "auto");
}
