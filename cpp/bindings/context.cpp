#include <cstring>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "softgl/api/context.h"
#include "webidl.h"

namespace py = pybind11;
using softgl::Context;
using softgl::ContextAttributes;
using softgl::GLenum;
using softgl::bindings::webidl;
namespace gl = softgl::gl;

namespace {

py::object to_python(const softgl::Value& value) {
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

// The WebGL typed-array kind of a NumPy dtype (Uint8Array <-> uint8, ...); 0 if none.
GLenum array_type_of(const py::dtype& dt) {
    const char kind = dt.kind();
    const auto size = dt.itemsize();
    if (kind == 'u' && size == 1) return gl::UNSIGNED_BYTE;
    if (kind == 'i' && size == 1) return gl::BYTE;
    if (kind == 'u' && size == 2) return gl::UNSIGNED_SHORT;
    if (kind == 'i' && size == 2) return gl::SHORT;
    if (kind == 'u' && size == 4) return gl::UNSIGNED_INT;
    if (kind == 'i' && size == 4) return gl::INT;
    if (kind == 'f' && size == 4) return gl::FLOAT;
    return 0;
}

py::dtype dtype_for(GLenum type) {
    switch (type) {
        case gl::FLOAT: return py::dtype::of<float>();
        case gl::BYTE: return py::dtype::of<int8_t>();
        case gl::SHORT: return py::dtype::of<int16_t>();
        case gl::INT: return py::dtype::of<int32_t>();
        case gl::UNSIGNED_INT: case gl::UNSIGNED_INT_2_10_10_10_REV:
        case gl::UNSIGNED_INT_10F_11F_11F_REV: case gl::UNSIGNED_INT_5_9_9_9_REV:
            return py::dtype::of<uint32_t>();
        case gl::UNSIGNED_SHORT: case gl::UNSIGNED_SHORT_5_6_5: case gl::UNSIGNED_SHORT_4_4_4_4:
        case gl::UNSIGNED_SHORT_5_5_5_1: case gl::HALF_FLOAT:
            return py::dtype::of<uint16_t>();
        default: return py::dtype::of<uint8_t>();
    }
}

void vertex_attrib_fv(Context& c, const char* call, uint32_t index, const std::vector<float>& v, int n) {
    // WebGL 1.0 §5.14.10: an array shorter than the call's size is INVALID_VALUE.
    if (int(v.size()) < n) return c.record_error(gl::INVALID_VALUE, call, "needs " + std::to_string(n) + " values");
    c.vertex_attrib_f(call, index, v.data(), n);
}

py::object read_pixels(Context& ctx, softgl::bindings::IdlInt32 x_, softgl::bindings::IdlInt32 y_,
                       softgl::bindings::IdlInt32 w_, softgl::bindings::IdlInt32 h_,
                       softgl::bindings::IdlUint32 format_, softgl::bindings::IdlUint32 type_,
                       py::object pixels) {
    const int32_t x = x_.value, y = y_.value, w = w_.value, h = h_.value;
    const GLenum format = format_.value, type = type_.value;
    if (pixels.is_none()) {
        // Return a new (h, w, 4) array, zero outside the drawing buffer. Negative sizes and bad
        // enums are reported by the core before anything is allocated.
        if (w < 0 || h < 0 || format != gl::RGBA) {
            ctx.read_pixels(x, y, w, h, format, type, type, nullptr, 0, false);
            return py::none();
        }
        py::array out(dtype_for(type), std::vector<py::ssize_t>{h, w, 4});
        std::memset(out.mutable_data(), 0, size_t(out.nbytes()));
        if (!ctx.read_pixels(x, y, w, h, format, type, array_type_of(out.dtype()),
                             static_cast<uint8_t*>(out.mutable_data()), size_t(out.nbytes()), false))
            return py::none();
        return std::move(out);
    }
    if (!py::isinstance<py::array>(pixels))
        throw py::type_error("readPixels: pixels must be a NumPy array (the ArrayBufferView) or None");
    py::array arr = pixels.cast<py::array>();
    if (!(arr.flags() & py::array::c_style) || !arr.writeable())
        throw py::type_error("readPixels: pixels must be a writeable C-contiguous NumPy array");
    ctx.read_pixels(x, y, w, h, format, type, array_type_of(arr.dtype()),
                    static_cast<uint8_t*>(arr.mutable_data()), size_t(arr.nbytes()), true);
    return pixels;
}

// A read-only byte view of a buffer-protocol object (NumPy array, bytes, ...), optionally the
// element range [src_offset, src_offset + length) as in WebGL 2's ArrayBufferView overloads.
struct ByteSpan {
    const uint8_t* data = nullptr;
    int64_t size = 0;
    bool ok = true;
};

ByteSpan byte_span(Context& ctx, const char* call, const py::buffer& source, int64_t src_offset,
                   int64_t length) {
    py::buffer_info info = source.request();
    if (info.ndim > 1) {
        // Only C-contiguous data is accepted, as a typed array is one contiguous block.
        py::ssize_t expected = info.itemsize;
        for (py::ssize_t d = info.ndim - 1; d >= 0; --d) {
            if (info.strides[size_t(d)] != expected)
                throw py::type_error(std::string(call) + ": data must be C-contiguous");
            expected *= info.shape[size_t(d)];
        }
    } else if (info.ndim == 1 && info.strides[0] != info.itemsize && info.shape[0] > 1) {
        throw py::type_error(std::string(call) + ": data must be contiguous");
    }
    const int64_t count = int64_t(info.size), item = int64_t(info.itemsize);
    ByteSpan span;
    if (src_offset < 0 || length < 0 || src_offset > count || (length && src_offset + length > count)) {
        ctx.record_error(gl::INVALID_VALUE, call, "srcOffset/length exceed the source array");
        span.ok = false;
        return span;
    }
    span.data = static_cast<const uint8_t*>(info.ptr) + src_offset * item;
    span.size = (length ? length : count - src_offset) * item;
    return span;
}

template <class T>
py::object object_or_none(const std::shared_ptr<T>& p) {
    return p ? py::cast(p) : py::none();
}

}  // namespace

void bind_context(py::module_& m) {
    using softgl::Buffer;
    using softgl::Object;
    using softgl::VertexArray;
    using softgl::bindings::IdlInt32;
    using softgl::bindings::IdlUint32;
    py::class_<Object, std::shared_ptr<Object>>(m, "WebGLObject");
    py::class_<Buffer, Object, std::shared_ptr<Buffer>>(m, "WebGLBuffer");
    py::class_<VertexArray, Object, std::shared_ptr<VertexArray>>(m, "WebGLVertexArrayObject");

    py::class_<ContextAttributes>(m, "ContextAttributes")
        .def(py::init<>())
        .def_readwrite("alpha", &ContextAttributes::alpha)
        .def_readwrite("depth", &ContextAttributes::depth)
        .def_readwrite("stencil", &ContextAttributes::stencil)
        .def_readwrite("antialias", &ContextAttributes::antialias)
        .def_readwrite("premultipliedAlpha", &ContextAttributes::premultiplied_alpha)
        .def_readwrite("preserveDrawingBuffer", &ContextAttributes::preserve_drawing_buffer)
        .def_readwrite("failIfMajorPerformanceCaveat", &ContextAttributes::fail_if_major_performance_caveat)
        .def_readwrite("desynchronized", &ContextAttributes::desynchronized)
        .def_readwrite("powerPreference", &ContextAttributes::power_preference)
        .def_readwrite("version", &ContextAttributes::version)
        .def_readwrite("samples", &ContextAttributes::samples)
        .def_readwrite("threads", &ContextAttributes::threads);

    m.def("check_context", &Context::check, "Why a context of this size and attributes cannot be made ('' if it can)");
    m.def("error_name", &softgl::error_name);
    m.def("enum_name", &softgl::enum_name);

    py::class_<Context>(m, "Context")
        .def(py::init<int32_t, int32_t, const ContextAttributes&>())
        .def("_set_error_listener",
             [](Context& c, py::function f) {
                 c.errors().set_listener([f](GLenum code, const char* call, const std::string& why) {
                     f(code, call, why);
                 });
             })
        .def("_attributes", [](const Context& c) { return c.attributes(); })
        .def("_present", &Context::present)
        .def_property_readonly("drawingBufferWidth", &Context::drawing_buffer_width)
        .def_property_readonly("drawingBufferHeight", &Context::drawing_buffer_height)
        .def("getError", webidl(&Context::get_error))
        .def("isContextLost", webidl(&Context::is_context_lost))
        .def("getSupportedExtensions", webidl(&Context::get_supported_extensions))
        .def("_enable_extension", webidl(&Context::enable_extension))
        .def("enable", webidl(&Context::enable))
        .def("disable", webidl(&Context::disable))
        .def("isEnabled", webidl(&Context::is_enabled))
        .def("blendFunc", webidl(&Context::blend_func))
        .def("blendFuncSeparate", webidl(&Context::blend_func_separate))
        .def("blendEquation", webidl(&Context::blend_equation))
        .def("blendEquationSeparate", webidl(&Context::blend_equation_separate))
        .def("blendColor", webidl(&Context::blend_color))
        .def("depthFunc", webidl(&Context::depth_func))
        .def("depthMask", webidl(&Context::depth_mask))
        .def("depthRange", webidl(&Context::depth_range))
        .def("clearColor", webidl(&Context::clear_color))
        .def("clearDepth", webidl(&Context::clear_depth))
        .def("clearStencil", webidl(&Context::clear_stencil))
        .def("colorMask", webidl(&Context::color_mask))
        .def("stencilFunc", webidl(&Context::stencil_func))
        .def("stencilFuncSeparate", webidl(&Context::stencil_func_separate))
        .def("stencilOp", webidl(&Context::stencil_op))
        .def("stencilOpSeparate", webidl(&Context::stencil_op_separate))
        .def("stencilMask", webidl(&Context::stencil_mask))
        .def("stencilMaskSeparate", webidl(&Context::stencil_mask_separate))
        .def("cullFace", webidl(&Context::cull_face))
        .def("frontFace", webidl(&Context::front_face))
        .def("lineWidth", webidl(&Context::line_width))
        .def("polygonOffset", webidl(&Context::polygon_offset))
        .def("sampleCoverage", webidl(&Context::sample_coverage))
        .def("scissor", webidl(&Context::scissor))
        .def("viewport", webidl(&Context::viewport))
        .def("hint", webidl(&Context::hint))
        .def("pixelStorei", webidl(&Context::pixel_store_i))
        .def("activeTexture", webidl(&Context::active_texture))
        .def("getParameter", [](Context& c, softgl::bindings::IdlUint32 pname) { return to_python(c.get_parameter(pname.value)); })
        .def("clear", webidl(&Context::clear))
        .def("flush", [](Context&) {})    // drawing is synchronous: nothing is ever pending
        .def("finish", [](Context&) {})
        // Buffers
        .def("createBuffer", &Context::create_buffer)
        .def("bindBuffer", webidl(&Context::bind_buffer))
        .def("deleteBuffer", &Context::delete_buffer)
        .def("isBuffer", &Context::is_buffer)
        .def("bufferData",
             [](Context& c, IdlUint32 target, py::object data, IdlUint32 usage, int64_t src_offset, int64_t length) {
                 if (py::isinstance<py::int_>(data))
                     return c.buffer_data_size(target.value, data.cast<int64_t>(), usage.value);
                 if (data.is_none()) return c.buffer_data(target.value, nullptr, -1, usage.value);
                 ByteSpan span = byte_span(c, "bufferData", data.cast<py::buffer>(), src_offset, length);
                 if (span.ok) c.buffer_data(target.value, span.data ? span.data : reinterpret_cast<const uint8_t*>(""), span.size, usage.value);
             },
             py::arg("target"), py::arg("data"), py::arg("usage"), py::arg("srcOffset") = 0, py::arg("length") = 0)
        .def("bufferSubData",
             [](Context& c, IdlUint32 target, int64_t offset, py::buffer data, int64_t src_offset, int64_t length) {
                 ByteSpan span = byte_span(c, "bufferSubData", data, src_offset, length);
                 if (span.ok) c.buffer_sub_data(target.value, offset, span.data, span.size);
             },
             py::arg("target"), py::arg("dstByteOffset"), py::arg("srcData"), py::arg("srcOffset") = 0,
             py::arg("length") = 0)
        .def("copyBufferSubData", webidl(&Context::copy_buffer_sub_data))
        .def("getBufferSubData",
             [](Context& c, IdlUint32 target, int64_t offset, py::array dst, int64_t dst_offset, int64_t length) {
                 if (!(dst.flags() & py::array::c_style) || !dst.writeable())
                     throw py::type_error("getBufferSubData: dstBuffer must be a writeable C-contiguous array");
                 const int64_t count = int64_t(dst.size()), item = int64_t(dst.itemsize());
                 if (dst_offset < 0 || length < 0 || dst_offset > count || (length && dst_offset + length > count))
                     return c.record_error(gl::INVALID_VALUE, "getBufferSubData", "dstOffset/length exceed the array");
                 const int64_t n = length ? length : count - dst_offset;
                 c.get_buffer_sub_data(target.value, offset,
                                       static_cast<uint8_t*>(dst.mutable_data()) + dst_offset * item, n * item);
             },
             py::arg("target"), py::arg("srcByteOffset"), py::arg("dstBuffer"), py::arg("dstOffset") = 0,
             py::arg("length") = 0)
        .def("getBufferParameter", [](Context& c, IdlUint32 target, IdlUint32 pname) {
            return to_python(c.get_buffer_parameter(target.value, pname.value));
        })
        // Vertex attributes
        .def("vertexAttribPointer", webidl(&Context::vertex_attrib_pointer))
        .def("vertexAttribIPointer", webidl(&Context::vertex_attrib_i_pointer))
        .def("enableVertexAttribArray", webidl(&Context::enable_vertex_attrib_array))
        .def("disableVertexAttribArray", webidl(&Context::disable_vertex_attrib_array))
        .def("vertexAttrib1f", [](Context& c, IdlUint32 i, float x) { float v[] = {x}; c.vertex_attrib_f("vertexAttrib1f", i.value, v, 1); })
        .def("vertexAttrib2f", [](Context& c, IdlUint32 i, float x, float y) { float v[] = {x, y}; c.vertex_attrib_f("vertexAttrib2f", i.value, v, 2); })
        .def("vertexAttrib3f", [](Context& c, IdlUint32 i, float x, float y, float z) { float v[] = {x, y, z}; c.vertex_attrib_f("vertexAttrib3f", i.value, v, 3); })
        .def("vertexAttrib4f", [](Context& c, IdlUint32 i, float x, float y, float z, float w) { float v[] = {x, y, z, w}; c.vertex_attrib_f("vertexAttrib4f", i.value, v, 4); })
        .def("vertexAttrib1fv", [](Context& c, IdlUint32 i, std::vector<float> v) { vertex_attrib_fv(c, "vertexAttrib1fv", i.value, v, 1); })
        .def("vertexAttrib2fv", [](Context& c, IdlUint32 i, std::vector<float> v) { vertex_attrib_fv(c, "vertexAttrib2fv", i.value, v, 2); })
        .def("vertexAttrib3fv", [](Context& c, IdlUint32 i, std::vector<float> v) { vertex_attrib_fv(c, "vertexAttrib3fv", i.value, v, 3); })
        .def("vertexAttrib4fv", [](Context& c, IdlUint32 i, std::vector<float> v) { vertex_attrib_fv(c, "vertexAttrib4fv", i.value, v, 4); })
        .def("vertexAttribI4i", webidl(&Context::vertex_attrib_i4i))
        .def("vertexAttribI4ui", webidl(&Context::vertex_attrib_i4ui))
        .def("vertexAttribI4iv", [](Context& c, IdlUint32 i, std::vector<int32_t> v) {
            if (v.size() < 4) return c.record_error(gl::INVALID_VALUE, "vertexAttribI4iv", "needs 4 values");
            c.vertex_attrib_i4i(i.value, v[0], v[1], v[2], v[3]);
        })
        .def("vertexAttribI4uiv", [](Context& c, IdlUint32 i, std::vector<uint32_t> v) {
            if (v.size() < 4) return c.record_error(gl::INVALID_VALUE, "vertexAttribI4uiv", "needs 4 values");
            c.vertex_attrib_i4ui(i.value, v[0], v[1], v[2], v[3]);
        })
        .def("vertexAttribDivisor", webidl(&Context::vertex_attrib_divisor))
        .def("getVertexAttrib", [](Context& c, IdlUint32 index, IdlUint32 pname) {
            return to_python(c.get_vertex_attrib(index.value, pname.value));
        })
        .def("getVertexAttribOffset", webidl(&Context::get_vertex_attrib_offset))
        // Vertex array objects
        .def("createVertexArray", &Context::create_vertex_array)
        .def("bindVertexArray", &Context::bind_vertex_array)
        .def("deleteVertexArray", &Context::delete_vertex_array)
        .def("isVertexArray", &Context::is_vertex_array)
        .def("readPixels", &read_pixels, py::arg("x"), py::arg("y"), py::arg("width"),
             py::arg("height"), py::arg("format"), py::arg("type"), py::arg("pixels") = py::none());
}
