// softgl._core.raster_coverage and raster_area: testing/benchmark entries to the geometric pipeline
// (the probes in cpp/testing), and pipeline/coverage's disk_rect_area and sampled_error_bound.
// Conversions only.
#include <cstring>
#include <optional>
#include <string>
#include <tuple>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "softgl/pipeline/coverage.h"
#include "testing/area_probe.h"
#include "testing/coverage_probe.h"

namespace py = pybind11;
using namespace softgl;
using testing::ProbeInput;

namespace {

using Floats = py::array_t<float, py::array::c_style | py::array::forcecast>;
using Indices = py::array_t<uint32_t, py::array::c_style | py::array::forcecast>;
using Rect = std::tuple<int32_t, int32_t, int32_t, int32_t>;

template <class T>
py::array_t<T> to_array(const std::vector<T>& v, std::vector<py::ssize_t> shape) {
    py::array_t<T> a(shape);
    std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
    return a;
}

// The probes' primitives: positions (N, 4) in clip coordinates, optional indices, the primitive
// kind by name, optional point sizes (one per vertex). The arrays must outlive the result.
ProbeInput probe_input(const Floats& positions, const std::optional<Indices>& indices, const std::string& primitive,
                       const std::optional<Floats>& point_sizes, bool record) {
    if (positions.ndim() != 2 || positions.shape(1) != 4)
        throw py::value_error("positions must have shape (N, 4)");
    ProbeInput in;
    in.positions = positions.data();
    in.vertex_count = size_t(positions.shape(0));
    int per;
    if (primitive == "triangles") { in.kind = PrimitiveKind::Triangle; per = 3; }
    else if (primitive == "lines") { in.kind = PrimitiveKind::Line; per = 2; }
    else if (primitive == "points") { in.kind = PrimitiveKind::Point; per = 1; }
    else throw py::value_error("primitive must be 'triangles', 'lines' or 'points'");
    if (indices) {
        if (indices->size() % per) throw py::value_error("index count is not a multiple of the primitive size");
        in.indices = indices->data();
        in.primitive_count = size_t(indices->size()) / per;
    } else {
        in.primitive_count = in.vertex_count / per;
    }
    if (point_sizes) {
        if (size_t(point_sizes->size()) != in.vertex_count) throw py::value_error("one point size per vertex");
        in.point_sizes = point_sizes->data();
    }
    in.record = record;
    return in;
}

void set_scissor(RasterState& st, const std::optional<Rect>& scissor) {
    if (scissor) st.set_scissor(std::get<0>(*scissor), std::get<1>(*scissor), std::get<2>(*scissor), std::get<3>(*scissor));
}

py::dict raster_stats(const RasterStats& s) {
    py::dict d;
    d["blocks_rejected"] = s.blocks_rejected; d["blocks_accepted"] = s.blocks_accepted;
    d["blocks_partial"] = s.blocks_partial; d["quads"] = s.quads;
    return d;
}

RasterState coverage_state(int32_t width, int32_t height, const std::optional<Rect>& viewport,
                           std::tuple<double, double> depth_range, std::optional<uint32_t> cull_face,
                           uint32_t front_face, std::optional<std::tuple<double, double>> polygon_offset,
                           int depth_bits, int samples, const std::optional<Rect>& scissor, double line_width,
                           const std::string& line_rule, bool sample_bounds) {
    RasterState st = RasterState::for_target(width, height);
    if (viewport) std::tie(st.viewport.x, st.viewport.y, st.viewport.width, st.viewport.height) = *viewport;
    std::tie(st.viewport.depth_near, st.viewport.depth_far) = depth_range;
    set_scissor(st, scissor);
    st.cull_face = cull_face.has_value();
    if (cull_face) st.cull_face_mode = *cull_face;
    st.front_face = front_face;
    st.polygon_offset_fill = polygon_offset.has_value();
    if (polygon_offset) std::tie(st.polygon_offset_factor, st.polygon_offset_units) = *polygon_offset;
    st.depth_bits = depth_bits;
    st.samples = samples;
    st.line_width = line_width;
    st.sample_bounds = sample_bounds;
    if (line_rule == "diamond_exit") st.line_rule = LineRule::DiamondExit;
    else if (line_rule == "half_open") st.line_rule = LineRule::HalfOpen;
    else throw py::value_error("line_rule must be 'diamond_exit' or 'half_open'");
    return st;
}

py::dict raster_coverage(int32_t width, int32_t height, Floats positions, std::optional<Indices> indices,
                         const std::string& primitive, std::optional<Rect> viewport,
                         std::tuple<double, double> depth_range, std::optional<uint32_t> cull_face,
                         uint32_t front_face, std::optional<std::tuple<double, double>> polygon_offset,
                         int depth_bits, int samples, unsigned threads, std::optional<Rect> scissor,
                         std::optional<Floats> point_sizes, double line_width, bool record,
                         const std::string& line_rule, bool sample_bounds) {
    const ProbeInput in = probe_input(positions, indices, primitive, point_sizes, record);
    const RasterState st = coverage_state(width, height, viewport, depth_range, cull_face, front_face, polygon_offset,
                                          depth_bits, samples, scissor, line_width, line_rule, sample_bounds);
    testing::ProbeResult r;
    {
        py::gil_scoped_release release;
        ThreadPool pool(threads);
        r = testing::coverage_probe(in, st, pool);
    }
    const py::ssize_t H = record ? height : 0, W = record ? width : 0, S = samples;
    py::dict out;
    out["count"] = to_array(r.count, {H, W, S});
    out["depth"] = to_array(r.depth, {H, W, S});
    out["last"] = to_array(r.last, {H, W});
    out["front"] = to_array(r.front, {H, W});
    out["weights"] = to_array(r.weights, {H, W, 3});
    out["point_coord"] = to_array(r.point_coord, {H, W, 2});
    py::dict setup;
    setup["primitives"] = r.setup.primitives; setup["invalid"] = r.setup.invalid;
    setup["outside"] = r.setup.outside; setup["clipped"] = r.setup.clipped;
    setup["culled"] = r.setup.culled; setup["zero_area"] = r.setup.zero_area;
    setup["emitted"] = r.setup.emitted;
    out["setup"] = setup;
    py::dict raster = raster_stats(r.raster);
    raster["tiles_skipped"] = r.tiles_skipped;
    out["raster"] = raster;
    out["samples_covered"] = r.samples_covered;
    out["seconds"] = py::make_tuple(r.seconds_setup, r.seconds_bin, r.seconds_raster);
    return out;
}

py::dict raster_area(int32_t width, int32_t height, Floats positions, std::optional<Indices> indices,
                     const std::string& primitive, bool sampled, int grid, double line_width, bool line_smooth,
                     std::optional<Floats> point_sizes, const std::string& point_shape, unsigned threads,
                     bool record, std::optional<Rect> scissor) {
    const ProbeInput in = probe_input(positions, indices, primitive, point_sizes, record);
    RasterState st = RasterState::for_target(width, height);
    set_scissor(st, scissor);
    st.line_width = line_width;
    st.line_smooth = line_smooth;
    if (point_shape == "disk") { st.point_smooth = true; st.point_smooth_square = false; }
    else if (point_shape == "square") { st.point_smooth = true; st.point_smooth_square = true; }
    else throw py::value_error("point_shape must be 'disk' or 'square'");
    AreaOptions opt;
    opt.sampled = sampled;
    opt.grid = grid;
    testing::AreaProbeResult r;
    {
        py::gil_scoped_release release;
        ThreadPool pool(threads);
        r = testing::area_probe(in, st, opt, pool);
    }
    const py::ssize_t H = record ? height : 0, W = record ? width : 0;
    py::dict out;
    out["coverage"] = to_array(r.coverage, {H, W});
    out["fragments"] = to_array(r.fragments, {H, W});
    out["total"] = r.total;
    out["fragment_count"] = r.fragment_count;
    py::dict setup;
    setup["primitives"] = r.setup.primitives; setup["outside"] = r.setup.outside;
    setup["zero_area"] = r.setup.zero_area; setup["emitted"] = r.setup.emitted;
    out["setup"] = setup;
    out["raster"] = raster_stats(r.raster);
    out["seconds"] = py::make_tuple(r.seconds_setup, r.seconds_bin, r.seconds_raster);
    return out;
}

}  // namespace

void bind_probes(py::module_& m) {
    m.def("raster_coverage", &raster_coverage, py::arg("width"), py::arg("height"),
          py::arg("positions"), py::arg("indices") = py::none(), py::arg("primitive") = "triangles",
          py::arg("viewport") = py::none(), py::arg("depth_range") = std::make_tuple(0.0, 1.0),
          py::arg("cull_face") = py::none(), py::arg("front_face") = 0x901u,
          py::arg("polygon_offset") = py::none(), py::arg("depth_bits") = 24,
          py::arg("samples") = 1, py::arg("threads") = 1u, py::arg("scissor") = py::none(),
          py::arg("point_sizes") = py::none(), py::arg("line_width") = 1.0, py::arg("record") = true,
          py::arg("line_rule") = "diamond_exit", py::arg("sample_bounds") = false,
          "Coverage of primitives given in clip coordinates (testing/benchmarks): per-sample hit "
          "counts and depth of the last primitive, per-pixel last primitive, facing, weights. "
          "Arrays are [y][x], row 0 = bottom. Enum arguments take GL values. record=False: only samples_covered and stats (benchmarks).");
    m.def("raster_area", &raster_area, py::arg("width"), py::arg("height"), py::arg("positions"),
          py::arg("indices") = py::none(), py::arg("primitive") = "triangles",
          py::arg("sampled") = false, py::arg("grid") = 8, py::arg("line_width") = 1.0,
          py::arg("line_smooth") = true, py::arg("point_sizes") = py::none(),
          py::arg("point_shape") = "disk", py::arg("threads") = 1u, py::arg("record") = true,
          py::arg("scissor") = py::none(),
          "Area coverage (SOFTGL_smooth, pipeline/coverage) of primitives in clip coordinates, "
          "full-target viewport: per-pixel sum of coverage fractions and fragment counts, [y][x], "
          "row 0 = bottom. sampled=True: grid x grid sample estimate (hint FASTEST). Testing/benchmarks.");
    m.def("disk_rect_area", &disk_rect_area, py::arg("cx"), py::arg("cy"), py::arg("r"),
          py::arg("x0"), py::arg("y0"), py::arg("x1"), py::arg("y1"),
          "Exact area of a disk intersected with a rectangle (pipeline/coverage; testing).");
    m.def("sampled_error_bound", &sampled_error_bound, py::arg("grid"), py::arg("edges"),
          "Documented worst-case |sampled - exact| per pixel (edges < 0: a circle).");
}
