// Bindings of the blend lab extensions (SOFTGL_exact_transparency, SOFTGL_introspection):
// methods added to the Context class made in context.cpp. Conversions only.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "softgl/api/blendlab.h"
#include "softgl/api/context.h"
#include "exclusive.h"
#include "signatures.h"
#include "webidl.h"

namespace py = pybind11;
using softgl::Context;

namespace {

// ZERO and ONE share their values with POINTS and LINES, so enum_name cannot name them.
std::string factor_name(softgl::GLenum f) { return f == 0 ? "ZERO" : f == 1 ? "ONE" : softgl::enum_name(f); }

py::object tristate(int v) { return v < 0 ? py::object(py::none()) : py::object(py::bool_(v == 1)); }

template <class T>
py::tuple tuple4(const T* v) { return py::make_tuple(v[0], v[1], v[2], v[3]); }

// Stored RGBA8 bytes as the blend equation reads them (ES 3.0 §2.1.6.1: b / 255), so every colour
// of a report is one kind of number; the bytes themselves are `out_bytes`.
py::tuple unorm4(const uint8_t* v) {
    return py::make_tuple(v[0] / 255.0, v[1] / 255.0, v[2] / 255.0, v[3] / 255.0);
}

py::dict report_dict(const softgl::FragmentReport& r, int32_t x, int32_t y) {
    py::dict d;
    d["x"] = x;
    d["y"] = y;
    d["draw"] = r.draw;
    d["primitive"] = r.primitive;
    d["sample"] = r.sample;
    d["depth"] = r.depth;
    d["coverage"] = r.coverage;
    d["shader_color"] = r.shaded ? py::object(tuple4(r.shader_color)) : py::object(py::none());
    py::dict tests;
    tests["scissor"] = tristate(r.scissor);
    tests["coverage_ops"] = tristate(r.coverage_ops);
    tests["stencil"] = tristate(r.stencil);
    tests["depth"] = tristate(r.depth_test);
    tests["discard"] = tristate(r.discard);
    d["tests"] = tests;
    d["early_tests"] = r.early_tests;
    d["fog"] = r.description && r.description->fog;
    d["captured"] = r.captured;
    if (r.blended) {
        const softgl::BlendOp& op = r.description->blend;
        py::dict b;
        b["enabled"] = !op.is_plain_write();
        b["src"] = tuple4(r.src);
        b["dst"] = unorm4(r.dst);
        b["src_factor"] = tuple4(r.src_factor);
        b["dst_factor"] = tuple4(r.dst_factor);
        b["factors"] = py::make_tuple(factor_name(op.src_rgb), factor_name(op.dst_rgb),
                                      factor_name(op.src_alpha), factor_name(op.dst_alpha));
        b["equation"] = py::make_tuple(softgl::enum_name(op.eq_rgb), softgl::enum_name(op.eq_alpha));
        b["out"] = unorm4(r.out);
        b["out_bytes"] = tuple4(r.out);
        d["blend"] = b;
    } else {
        d["blend"] = py::none();
    }
    if (r.captured) d["src"] = tuple4(r.src);
    d["fate"] = r.fate;
    return d;
}

py::dict memory(uint64_t limit, uint64_t stored, uint64_t needed, bool overflowed) {
    py::dict d;
    d["limit"] = limit;
    d["bytes_stored"] = stored;
    d["bytes_needed"] = needed;
    d["overflowed"] = overflowed;
    return d;
}

}  // namespace

void bind_blendlab(py::module_& m) {
    using softgl::bindings::IdlInt32;
    auto cls = softgl::bindings::context_class(m);
    cls.def("fragments",
            [](Context& c, IdlInt32 x, IdlInt32 y) -> py::object {
                std::vector<softgl::FragmentReport> reports;
                if (!c.blendlab().fragments(x.value, y.value, reports)) return py::list();
                py::list out;
                for (const auto& r : reports) out.append(report_dict(r, x.value, y.value));
                return std::move(out);
            });
    cls.def("_transparency_resolve", [](Context& c, uint32_t mode, int layers, int weight) -> py::object {
        const int32_t w = c.drawing_buffer_width(), h = c.drawing_buffer_height();
        py::array_t<double> image(std::vector<py::ssize_t>{h, w, 4});
        bool ok;
        {
            softgl::bindings::ExclusiveWithoutGil release(c);
            ok = c.blendlab().resolve(mode, layers, weight, c.framebuffer(), c.pool(), image.mutable_data());
        }
        return ok ? py::object(std::move(image)) : py::object(py::none());
    });
    cls.def("_transparency_depth_complexity", [](Context& c) -> py::object {
        py::array_t<uint32_t> out(std::vector<py::ssize_t>{c.drawing_buffer_height(), c.drawing_buffer_width()});
        bool ok;
        {
            softgl::bindings::ExclusiveWithoutGil release(c);
            ok = c.blendlab().depth_complexity(c.framebuffer(), c.pool(), out.mutable_data());
        }
        return ok ? py::object(std::move(out)) : py::object(py::none());
    });
    cls.def("_transparency_set_limit", [](Context& c, uint64_t bytes) { c.blendlab().abuffer().set_limit(bytes); });
    cls.def("_transparency_memory", [](Context& c) {
        softgl::ABuffer& a = c.blendlab().abuffer();
        py::dict d = memory(a.limit(), a.bytes_stored(), a.bytes_needed(), a.overflowed());
        d["fragments"] = a.fragment_count();
        return d;
    });
    cls.def("_introspection_set_limit", [](Context& c, uint64_t bytes) { c.blendlab().log().set_limit(bytes); });
    cls.def("_introspection_memory", [](Context& c) {
        softgl::IntrospectionLog& l = c.blendlab().log();
        return memory(l.limit(), l.bytes_stored(), l.bytes_stored(), l.overflowed());
    });
}
