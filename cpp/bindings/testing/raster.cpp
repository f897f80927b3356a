// softgl._core.testing hooks for pipeline/raster.
#include <array>

#include <pybind11/stl.h>

#include "hooks.h"

using namespace softgl;
using softgl::bindings::Array;

namespace {

// rasterize_at one instruction-set level: edges (n, 3) int64 rows (a, b, c) (n = 2, 3 or 4), bbox
// and tile (x0, y0, x1, y1) in pixels; blocks_only: always the block walk (RasterWalk::Blocks).
// Returns (quads (m, 3) uint64 rows (x, y, coverage), (blocks_rejected, blocks_accepted,
// blocks_partial, quads)).
auto rasterize_edges(int level, Array<int64_t> edges, std::array<int32_t, 4> bbox, std::array<int32_t, 4> tile,
                     int samples, bool blocks_only) {
    if (edges.ndim() != 2 || edges.shape(1) != 3 || edges.shape(0) < 2 || edges.shape(0) > 4)
        throw py::value_error("edges (2, 3 or 4, 3)");
    PrimitiveSetup p{};
    p.edge_count = uint8_t(edges.shape(0));
    for (int i = 0; i < p.edge_count; ++i) p.a[i] = edges.at(i, 0), p.b[i] = edges.at(i, 1), p.c[i] = edges.at(i, 2);
    p.x0 = bbox[0], p.y0 = bbox[1], p.x1 = bbox[2], p.y1 = bbox[3];
    std::vector<Quad> quads;
    RasterStats stats;
    rasterize_at(SimdLevel(level), p, {tile[0], tile[1], tile[2], tile[3]}, sample_pattern(samples), quads, stats,
                 blocks_only ? RasterWalk::Blocks : RasterWalk::Any);
    py::array_t<uint64_t> out({py::ssize_t(quads.size()), py::ssize_t(3)});
    for (size_t i = 0; i < quads.size(); ++i) {
        *out.mutable_data(i, 0) = uint64_t(int64_t(quads[i].x));
        *out.mutable_data(i, 1) = uint64_t(int64_t(quads[i].y));
        *out.mutable_data(i, 2) = quads[i].coverage;
    }
    return py::make_tuple(out, py::make_tuple(stats.blocks_rejected, stats.blocks_accepted, stats.blocks_partial,
                                              stats.quads));
}

}  // namespace

void bind_testing_raster(py::module_& t) {
    t.def("rasterize_edges", &rasterize_edges, py::arg("level"), py::arg("edges"), py::arg("bbox"), py::arg("tile"),
          py::arg("samples"), py::arg("blocks_only") = false);
}
