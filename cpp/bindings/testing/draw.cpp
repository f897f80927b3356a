// softgl._core.testing hooks for the draw as a whole (pipeline/draw with the C++ passthrough
// shaders), primitive assembly, and reading back a context's depth and stencil samples.
#include <cstring>
#include <memory>

#include <pybind11/stl.h>

#include "bindings/exclusive.h"   // the Context caster every binding file shares
#include "hooks.h"
#include "softgl/api/context.h"
#include "softgl/pipeline/assemble.h"
#include "softgl/pipeline/draw.h"
#include "softgl/pipeline/passthrough_shaders.h"

using namespace softgl;
using softgl::bindings::Array;

namespace {

// Attribute `location` of `vao` reads `size` floats per vertex from a new buffer holding `bytes`.
void attach(VertexArray& vao, int location, const void* data, size_t bytes, int size) {
    auto buffer = std::make_shared<Buffer>();
    buffer->data.assign(static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + bytes);
    auto& a = vao.attribs[size_t(location)];
    a.enabled = true;
    a.size = size;
    a.buffer = std::move(buffer);
}

py::dict stats_dict(const DrawStats& stats) {
    py::dict d;
    d["vertices_shaded"] = stats.vertices_shaded;
    d["primitives"] = stats.primitives;
    d["primitives_culled"] = stats.primitives_culled;
    d["quads"] = stats.quads;
    d["fragments_shaded"] = stats.fragments_shaded;
    d["fragments_killed_early"] = stats.fragments_killed_early;
    d["fragments_killed_late"] = stats.fragments_killed_late;
    d["fragments_discarded"] = stats.fragments_discarded;
    d["fragments_hidden"] = stats.fragments_hidden;
    d["samples_written"] = stats.samples_written;
    d["samples_blended"] = stats.samples_blended;
    d["draws_skipped_no_output"] = stats.draws_skipped_no_output;
    d["draws_early_depth"] = stats.draws_early_depth;
    d["draws_plain_write"] = stats.draws_plain_write;
    d["draws_blend_table"] = stats.draws_blend_table;
    return d;
}

// A draw through the whole pipeline with the C++ passthrough shaders, using the context's state
// and drawing buffer: positions (N, 4) and colors (N, 4) float32 as attributes 0 and 1, point
// sizes (N,) as attribute 2.
py::dict draw_passthrough(Context& ctx, uint32_t mode, Array<float> positions, Array<float> colors, py::object indices,
                          float discard_below, bool depth_from_red, uint32_t instances, py::object point_sizes) {
    const size_t n = size_t(positions.shape(0));
    if (positions.ndim() != 2 || positions.shape(1) != 4 || colors.ndim() != 2 || colors.shape(1) != 4 ||
        size_t(colors.shape(0)) != n)
        throw py::value_error("positions and colors must be (N, 4)");
    VertexArray vao;
    attach(vao, 0, positions.data(), n * 16, 4);
    attach(vao, 1, colors.data(), n * 16, 4);
    int point_size_location = -1;
    if (!point_sizes.is_none()) {
        auto ps = point_sizes.cast<Array<float>>();
        if (size_t(ps.size()) != n) throw py::value_error("point_sizes must have N values");
        attach(vao, 2, ps.data(), n * 4, 1);
        point_size_location = 2;
    }
    std::vector<uint32_t> index_list;
    DrawCall call;
    call.mode = mode;
    call.instance_count = instances;
    if (!indices.is_none()) {
        index_list = indices.cast<std::vector<uint32_t>>();
        for (uint32_t i : index_list)
            if (i >= n) throw py::value_error("index out of range");
        call.indices = index_list.data();
        call.count = uint32_t(index_list.size());
    } else {
        call.count = uint32_t(n);
    }
    PassthroughVertexShader vs(point_size_location);
    ColorFragmentShader fs(discard_below, depth_from_red);
    DrawStats stats;
    {
        py::gil_scoped_release release;
        RenderTarget target = RenderTarget::for_default(ctx.framebuffer());
        DrawInputs in{ctx.state(), vao, ctx.current_attribs(), vs, fs, target, ctx.pool(), ctx.tuning()};
        draw(in, call, stats);
    }
    return stats_dict(stats);
}

// Every sample of the context's drawing buffer as (h, w, samples): read(fb, x, y, s).
template <class T, class Read>
py::array_t<T> read_samples(Context& ctx, Read read) {
    auto& fb = ctx.framebuffer();
    const int S = fb.config().samples;
    py::array_t<T> out({py::ssize_t(fb.height()), py::ssize_t(fb.width()), py::ssize_t(S)});
    for (int y = 0; y < fb.height(); ++y)
        for (int x = 0; x < fb.width(); ++x)
            for (int s = 0; s < S; ++s) *out.mutable_data(y, x, s) = read(fb, x, y, s);
    return out;
}

}  // namespace

void bind_testing_draw(py::module_& t) {
    t.def("draw_passthrough", &draw_passthrough, py::arg("ctx"), py::arg("mode"), py::arg("positions"),
          py::arg("colors"), py::arg("indices") = py::none(), py::arg("discard_below") = -1.0f,
          py::arg("depth_from_red") = false, py::arg("instances") = 1, py::arg("point_sizes") = py::none());
    t.def("read_depth", [](Context& ctx) {
        return read_samples<uint32_t>(ctx, [](const auto& fb, int x, int y, int s) { return fb.depth_sample(x, y, s); });
    });
    t.def("read_stencil", [](Context& ctx) {
        return read_samples<uint8_t>(ctx, [](const auto& fb, int x, int y, int s) { return fb.stencil_sample(x, y, s); });
    });
    // The RGBA8 drawing buffer's colour samples, unresolved: (height, width, samples, 4) bytes.
    t.def("read_color_samples", [](Context& ctx) {
        DefaultFramebuffer& fb = ctx.framebuffer();
        if (fb.is_float()) throw py::value_error("read_color_samples reads an RGBA8 drawing buffer");
        const int S = fb.config().samples;
        py::array_t<uint8_t> out({py::ssize_t(fb.height()), py::ssize_t(fb.width()), py::ssize_t(S), py::ssize_t(4)});
        std::memcpy(out.mutable_data(), fb.color_sample(0, 0, 0), size_t(out.nbytes()));
        return out;
    });
    t.def("assemble", [](uint32_t mode, uint32_t count) {
        std::vector<uint32_t> out;
        assemble(mode, count, out);
        return out;
    });
    t.def("primitive_vertex_range", [](uint32_t mode, uint32_t count, uint32_t p0, uint32_t p1) {
        const VertexRange r = primitive_vertex_range(mode, count, p0, p1);
        return py::make_tuple(r.begin, r.end, r.and_zero);
    });
}
