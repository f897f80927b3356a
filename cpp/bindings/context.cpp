#include <cstring>
#include <optional>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "softgl/core/memory_ledger.h"
#include "softgl/api/context.h"
#include "array_intake.h"
#include "exclusive.h"
#include "interruptible.h"
#include "convert.h"
#include "signatures.h"
#include "webidl.h"

namespace py = pybind11;
using softgl::Context;
using softgl::ContextAttributes;
using softgl::GLenum;
using softgl::bindings::webidl;
using softgl::bindings::to_python;
using softgl::bindings::array_type_of;
using softgl::bindings::Arg;
using softgl::bindings::ClientArray;
using softgl::bindings::dtype_for_pixel_type;
using softgl::bindings::number_sequence;
namespace gl = softgl::gl;

namespace {



void vertex_attrib_fv(Context& c, const char* call, uint32_t index, py::handle values, int n) {
    auto v = number_sequence<float>(call, "values", values);
    // WebGL 1.0 §5.14.10: an array shorter than the call's size is INVALID_VALUE.
    if (v.size() < n) return c.record_error(gl::INVALID_VALUE, call, "needs " + std::to_string(n) + " values");
    c.vertex_attrib_f(call, index, v.data(), n);
}

py::object read_pixels(Context& ctx, softgl::bindings::IdlInt32 x_, softgl::bindings::IdlInt32 y_,
                       softgl::bindings::IdlInt32 w_, softgl::bindings::IdlInt32 h_,
                       softgl::bindings::IdlUint32 format_, softgl::bindings::IdlUint32 type_,
                       Arg<softgl::bindings::PixelsOrOffset> pixels_arg) {
    py::object pixels = pixels_arg.obj;
    const int32_t x = x_.value, y = y_.value, w = w_.value, h = h_.value;
    const GLenum format = format_.value, type = type_.value;
    if (pixels.is_none()) {
        // Return a new (h, w, 4) array, zero outside the drawing buffer. Negative sizes and bad
        // enums are reported by the core before anything is allocated.
        if (w < 0 || h < 0 || (format != gl::RGBA && format != gl::RGBA_INTEGER)) {   // RGBA_INTEGER: integer FBOs
            ctx.read_pixels(x, y, w, h, format, type, type, nullptr, 0, false);
            return py::none();
        }
        const uint64_t bytes = uint64_t(w) * uint64_t(h) * 4u * uint64_t(dtype_for_pixel_type(type).itemsize());
        if (bytes > softgl::memory_budget()) {   // refuse before NumPy allocates anything
            ctx.record_error(gl::OUT_OF_MEMORY, "readPixels",
                             "a " + std::to_string(w) + "x" + std::to_string(h) + " result needs " +
                             std::to_string(bytes >> 20) + " MiB, more than half of this machine's memory");
            return py::none();
        }
        py::array out;
        try {
            out = py::array(dtype_for_pixel_type(type), std::vector<py::ssize_t>{h, w, 4});
        } catch (py::error_already_set& e) {
            if (!e.matches(PyExc_MemoryError)) throw;
            ctx.record_error(gl::OUT_OF_MEMORY, "readPixels", "could not allocate the result array");
            return py::none();
        }
        std::memset(out.mutable_data(), 0, size_t(out.nbytes()));
        if (!ctx.read_pixels(x, y, w, h, format, type, array_type_of(out.dtype()),
                             static_cast<uint8_t*>(out.mutable_data()), size_t(out.nbytes()), false))
            return py::none();
        return std::move(out);
    }
    // WebGL 2's GLintptr overload: a byte offset into the PIXEL_PACK_BUFFER.
    if (ctx.version() >= 2 && !py::isinstance<py::array>(pixels) && PyIndex_Check(pixels.ptr()) && !PyBool_Check(pixels.ptr())) {
        ctx.read_pixels_to_pack_buffer(x, y, w, h, format, type, softgl::bindings::byte_offset("readPixels", "pixels", pixels));
        return py::none();
    }
    const auto dst = softgl::bindings::destination_array(
        "readPixels", "pixels", pixels,
        "a writeable NumPy array of numbers, None (a new array) or, in WebGL 2, a byte offset into the PIXEL_PACK_BUFFER",
        "np.empty((height, width, 4), np." + py::str(dtype_for_pixel_type(type).attr("name")).cast<std::string>() + ") or None");
    if (ctx.read_pixels(x, y, w, h, format, type, dst.type, dst.data, size_t(dst.bytes()), true)) dst.commit();
    return pixels;
}

// The bytes of a source array (array_intake.h), optionally its element range
// [src_offset, src_offset + length) as in WebGL 2's ArrayBufferView overloads.
struct ByteSpan {
    const uint8_t* data = nullptr;
    int64_t size = 0;
    bool ok = true;
};

ByteSpan byte_span(Context& ctx, const char* call, const ClientArray& source, int64_t src_offset, int64_t length) {
    const int64_t count = source.count, item = source.itemsize;
    ByteSpan span;
    if (src_offset < 0 || length < 0 || src_offset > count || length > count - src_offset) {
        ctx.record_error(gl::INVALID_VALUE, call, "srcOffset/length exceed the source array");
        span.ok = false;
        return span;
    }
    span.data = source.data + src_offset * item;
    span.size = (length ? length : count - src_offset) * item;
    return span;
}

template <class T>
py::object object_or_none(const std::shared_ptr<T>& p) {
    return p ? py::cast(p) : py::none();
}

using softgl::bindings::ContextClass;
using softgl::bindings::IdlInt32;
using softgl::bindings::IdlUint32;

// The WebGL object types and the small info structs they return.
void bind_object_types(py::module_& m) {
    using softgl::Buffer;
    using softgl::Object;
    using softgl::VertexArray;
    py::class_<Object, std::shared_ptr<Object>>(m, "WebGLObject");
    py::class_<Buffer, Object, std::shared_ptr<Buffer>>(m, "WebGLBuffer");
    py::class_<VertexArray, Object, std::shared_ptr<VertexArray>>(m, "WebGLVertexArrayObject");
    py::class_<softgl::Shader, Object, std::shared_ptr<softgl::Shader>>(m, "WebGLShader");
    py::class_<softgl::Program, Object, std::shared_ptr<softgl::Program>>(m, "WebGLProgram");
    py::class_<softgl::UniformLocation, std::shared_ptr<softgl::UniformLocation>>(m, "WebGLUniformLocation");
    py::class_<softgl::ActiveInfo, std::shared_ptr<softgl::ActiveInfo>>(m, "WebGLActiveInfo")
        .def_readonly("size", &softgl::ActiveInfo::size)
        .def_readonly("type", &softgl::ActiveInfo::type)
        .def_readonly("name", &softgl::ActiveInfo::name)
        .def("__repr__", [](const softgl::ActiveInfo& a) {
            return "<WebGLActiveInfo name='" + a.name + "' size=" + std::to_string(a.size) + " type=" + softgl::enum_name(a.type) + ">";
        });
    py::class_<softgl::PrecisionFormat, std::shared_ptr<softgl::PrecisionFormat>>(m, "WebGLShaderPrecisionFormat")
        .def_readonly("rangeMin", &softgl::PrecisionFormat::range_min)
        .def_readonly("rangeMax", &softgl::PrecisionFormat::range_max)
        .def_readonly("precision", &softgl::PrecisionFormat::precision);
}

void bind_context_attributes(py::module_& m) {
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
        .def_readwrite("threads", &ContextAttributes::threads)
        .def_readwrite("color_format", &ContextAttributes::color_format);

    m.def("check_context", &Context::check, "Why a context of this size and attributes cannot be made ('' if it can)");
    m.def("set_memory_limit", &softgl::set_memory_limit, py::arg("bytes"),
          "Process-wide limit on the bytes GL objects hold (0: half of physical memory)");
    m.def("memory_limit", &softgl::memory_limit);
    m.def("memory_in_use", &softgl::memory_in_use, "Bytes that buffers, textures, renderbuffers and drawing buffers hold now");
    m.def("error_name", &softgl::error_name);
    m.def("enum_name", &softgl::enum_name);
}

// Errors, extensions, capabilities, the fixed-function state, getParameter, clear.
void bind_state(ContextClass& cls) {
    cls.def("_set_error_listener",
             [](Context& c, py::function f) {
                 c.errors().set_listener([f](GLenum code, const char* call, const std::string& why) {
                     // Draws and compiles run without the GIL; reporting needs it.
                     py::gil_scoped_acquire gil;
                     f(code, call, why);
                 });
             })
        // set_work_budget / work_budget (python/softgl/context.py): 0 leaves a limit unchanged.
        .def("_set_work_budget",
             [](Context& c, uint64_t draw, uint64_t compile) {
                 if (draw) c.work_limits().draw = draw;
                 if (compile) c.work_limits().compile = compile;
             })
        .def("_work_budget",
             [](Context& c) {
                 return py::make_tuple(c.work_limits().draw, c.work_limits().compile, c.work_budget().used());
             })
        // set_memory_budget / memory_budget (python/softgl/context.py): 0 restores the default.
        .def("_set_memory_budget", [](Context& c, uint64_t bytes) { c.memory_account().set_limit(bytes); })
        .def("_memory_budget",
             [](Context& c) {
                 c.charge_blend_lab();   // as it is now (it changes between draws: clears, resolves)
                 return py::make_tuple(c.memory_account().limit(), c.memory_account().in_use(),
                                       softgl::memory_limit(), softgl::memory_in_use());
             })
        .def("_attributes", [](const Context& c) { return c.attributes(); })
        .def("_present", &Context::present)
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
        .def("finish", [](Context&) {});
}

// Buffer objects and their data (WebGL 2's srcOffset/length overloads included).
void bind_buffers(ContextClass& cls) {
    cls.def("createBuffer", &Context::create_buffer)
        .def("bindBuffer", webidl(&Context::bind_buffer))
        .def("deleteBuffer", &Context::delete_buffer)
        .def("isBuffer", &Context::is_buffer)
        .def("bufferData",
             [](Context& c, IdlUint32 target, Arg<softgl::bindings::BufferDataSource> data_arg, IdlUint32 usage, int64_t src_offset, int64_t length) {
                 py::object data = data_arg.obj;
                 if (py::isinstance<py::int_>(data)) {
                     int64_t size = 0;
                     try {
                         size = data.cast<int64_t>();
                     } catch (const py::cast_error&) {
                         PyErr_SetString(PyExc_OverflowError, "bufferData: size does not fit a GLsizeiptr (64-bit)");
                         throw py::error_already_set();
                     }
                     return c.buffer_data_size(target.value, size, usage.value);
                 }
                 if (data.is_none()) return c.buffer_data(target.value, nullptr, -1, usage.value);
                 const ClientArray source = softgl::bindings::buffer_source(
                     "bufferData", "data", data,
                     "a size in bytes (int), None or an ArrayBuffer-like (a NumPy array of numbers, or bytes)");
                 ByteSpan span = byte_span(c, "bufferData", source, src_offset, length);
                 if (span.ok) c.buffer_data(target.value, span.data ? span.data : reinterpret_cast<const uint8_t*>(""), span.size, usage.value);
             })
        .def("bufferSubData",
             [](Context& c, IdlUint32 target, int64_t offset, Arg<softgl::bindings::BufferSource> data, int64_t src_offset, int64_t length) {
                 const ClientArray source = softgl::bindings::buffer_source("bufferSubData", "srcData", data);
                 ByteSpan span = byte_span(c, "bufferSubData", source, src_offset, length);
                 if (span.ok) c.buffer_sub_data(target.value, offset, span.data, span.size);
             })
        .def("copyBufferSubData", webidl(&Context::copy_buffer_sub_data))
        .def("getBufferSubData",
             [](Context& c, IdlUint32 target, int64_t offset, Arg<softgl::bindings::Destination> dst_buffer, int64_t dst_offset, int64_t length) {
                 const auto dst = softgl::bindings::destination_array("getBufferSubData", "dstBuffer", dst_buffer);
                 const int64_t count = dst.count, item = dst.itemsize;
                 if (dst_offset < 0 || length < 0 || dst_offset > count || length > count - dst_offset)
                     return c.record_error(gl::INVALID_VALUE, "getBufferSubData", "dstOffset/length exceed the array");
                 const int64_t n = length ? length : count - dst_offset;
                 if (c.get_buffer_sub_data(target.value, offset, dst.data + dst_offset * item, n * item)) dst.commit();
             })
        .def("getBufferParameter", [](Context& c, IdlUint32 target, IdlUint32 pname) {
            return to_python(c.get_buffer_parameter(target.value, pname.value));
        });
}

// Vertex attributes (arrays and constant values) and vertex array objects.
void bind_vertex_input(ContextClass& cls) {
    cls.def("vertexAttribPointer", webidl(&Context::vertex_attrib_pointer))
        .def("vertexAttribIPointer", webidl(&Context::vertex_attrib_i_pointer))
        .def("enableVertexAttribArray", webidl(&Context::enable_vertex_attrib_array))
        .def("disableVertexAttribArray", webidl(&Context::disable_vertex_attrib_array))
        .def("vertexAttrib1f", [](Context& c, IdlUint32 i, float x) { float v[] = {x}; c.vertex_attrib_f("vertexAttrib1f", i.value, v, 1); })
        .def("vertexAttrib2f", [](Context& c, IdlUint32 i, float x, float y) { float v[] = {x, y}; c.vertex_attrib_f("vertexAttrib2f", i.value, v, 2); })
        .def("vertexAttrib3f", [](Context& c, IdlUint32 i, float x, float y, float z) { float v[] = {x, y, z}; c.vertex_attrib_f("vertexAttrib3f", i.value, v, 3); })
        .def("vertexAttrib4f", [](Context& c, IdlUint32 i, float x, float y, float z, float w) { float v[] = {x, y, z, w}; c.vertex_attrib_f("vertexAttrib4f", i.value, v, 4); })
        .def("vertexAttrib1fv", [](Context& c, IdlUint32 i, Arg<softgl::bindings::Floats> v) { vertex_attrib_fv(c, "vertexAttrib1fv", i.value, v, 1); })
        .def("vertexAttrib2fv", [](Context& c, IdlUint32 i, Arg<softgl::bindings::Floats> v) { vertex_attrib_fv(c, "vertexAttrib2fv", i.value, v, 2); })
        .def("vertexAttrib3fv", [](Context& c, IdlUint32 i, Arg<softgl::bindings::Floats> v) { vertex_attrib_fv(c, "vertexAttrib3fv", i.value, v, 3); })
        .def("vertexAttrib4fv", [](Context& c, IdlUint32 i, Arg<softgl::bindings::Floats> v) { vertex_attrib_fv(c, "vertexAttrib4fv", i.value, v, 4); })
        .def("vertexAttribI4i", webidl(&Context::vertex_attrib_i4i))
        .def("vertexAttribI4ui", webidl(&Context::vertex_attrib_i4ui))
        .def("vertexAttribI4iv", [](Context& c, IdlUint32 i, Arg<softgl::bindings::Ints> values) {
            auto v = number_sequence<int32_t>("vertexAttribI4iv", "values", values);
            if (v.size() < 4) return c.record_error(gl::INVALID_VALUE, "vertexAttribI4iv", "needs 4 values");
            c.vertex_attrib_i4i(i.value, v.data()[0], v.data()[1], v.data()[2], v.data()[3]);
        })
        .def("vertexAttribI4uiv", [](Context& c, IdlUint32 i, Arg<softgl::bindings::Ints> values) {
            auto v = number_sequence<uint32_t>("vertexAttribI4uiv", "values", values);
            if (v.size() < 4) return c.record_error(gl::INVALID_VALUE, "vertexAttribI4uiv", "needs 4 values");
            c.vertex_attrib_i4ui(i.value, v.data()[0], v.data()[1], v.data()[2], v.data()[3]);
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
        .def("isVertexArray", &Context::is_vertex_array);
}

// Shaders, programs, their reflection and precision formats.
void bind_shaders_and_programs(ContextClass& cls) {
    cls.def("createShader", webidl(&Context::create_shader))
        .def("shaderSource", &Context::shader_source)
        .def("getShaderSource", [](Context& c, const std::shared_ptr<softgl::Shader>& s) -> py::object {
            std::string src = c.get_shader_source(s);
            return (s && s->owner == c.identity() && !s->deleted) ? py::object(py::str(src)) : py::object(py::none());
        })
        .def("compileShader", [](Context& c, const std::shared_ptr<softgl::Shader>& s) {
            softgl::bindings::run_interruptible(c, [&] { c.compile_shader(s); });
        })
        .def("getShaderParameter", [](Context& c, const std::shared_ptr<softgl::Shader>& s, IdlUint32 pname) {
            return to_python(c.get_shader_parameter(s, pname.value));
        })
        .def("getShaderInfoLog", [](Context& c, const std::shared_ptr<softgl::Shader>& s) -> py::object {
            std::string log = c.get_shader_info_log(s);
            return (s && s->owner == c.identity() && !s->deleted) ? py::object(py::str(log)) : py::object(py::none());
        })
        .def("deleteShader", &Context::delete_shader)
        .def("isShader", &Context::is_shader)
        .def("createProgram", &Context::create_program)
        .def("attachShader", &Context::attach_shader)
        .def("detachShader", &Context::detach_shader)
        .def("getAttachedShaders", [](Context& c, const std::shared_ptr<softgl::Program>& p) -> py::object {
            bool ok = false;
            auto shaders = c.get_attached_shaders(p, &ok);
            if (!ok) return py::none();
            return py::cast(shaders);
        })
        .def("bindAttribLocation", [](Context& c, const std::shared_ptr<softgl::Program>& p, IdlUint32 index, const std::string& name) {
            c.bind_attrib_location(p, index.value, name);
        })
        .def("linkProgram", [](Context& c, const std::shared_ptr<softgl::Program>& p) {
            softgl::bindings::run_interruptible(c, [&] { c.link_program(p); });
        })
        .def("validateProgram", &Context::validate_program)
        .def("useProgram", &Context::use_program)
        .def("deleteProgram", &Context::delete_program)
        .def("isProgram", &Context::is_program)
        .def("getProgramParameter", [](Context& c, const std::shared_ptr<softgl::Program>& p, IdlUint32 pname) {
            return to_python(c.get_program_parameter(p, pname.value));
        })
        .def("getProgramInfoLog", [](Context& c, const std::shared_ptr<softgl::Program>& p) -> py::object {
            std::string log = c.get_program_info_log(p);
            return (p && p->owner == c.identity() && !p->deleted) ? py::object(py::str(log)) : py::object(py::none());
        })
        .def("getAttribLocation", &Context::get_attrib_location)
        .def("getUniformLocation", &Context::get_uniform_location)
        .def("getActiveAttrib", [](Context& c, const std::shared_ptr<softgl::Program>& p, IdlUint32 i) { return c.get_active_attrib(p, i.value); })
        .def("getActiveUniform", [](Context& c, const std::shared_ptr<softgl::Program>& p, IdlUint32 i) { return c.get_active_uniform(p, i.value); })
        .def("getShaderPrecisionFormat", webidl(&Context::get_shader_precision_format));
}

// The scalar uniform setters and getUniform (the array forms: bind_uniform_arrays).
void bind_uniforms(ContextClass& cls) {
    cls.def("uniform1f", [](Context& c, const softgl::UniformLocation* l, float x) { float v[] = {x}; c.set_uniform("uniform1f", l, 'f', 1, 0, v, 1, false); })
        .def("uniform2f", [](Context& c, const softgl::UniformLocation* l, float x, float y) { float v[] = {x, y}; c.set_uniform("uniform2f", l, 'f', 2, 0, v, 1, false); })
        .def("uniform3f", [](Context& c, const softgl::UniformLocation* l, float x, float y, float z) { float v[] = {x, y, z}; c.set_uniform("uniform3f", l, 'f', 3, 0, v, 1, false); })
        .def("uniform4f", [](Context& c, const softgl::UniformLocation* l, float x, float y, float z, float w) { float v[] = {x, y, z, w}; c.set_uniform("uniform4f", l, 'f', 4, 0, v, 1, false); })
        .def("uniform1i", [](Context& c, const softgl::UniformLocation* l, IdlInt32 x) { int32_t v[] = {x.value}; c.set_uniform("uniform1i", l, 'i', 1, 0, v, 1, false); })
        .def("uniform2i", [](Context& c, const softgl::UniformLocation* l, IdlInt32 x, IdlInt32 y) { int32_t v[] = {x.value, y.value}; c.set_uniform("uniform2i", l, 'i', 2, 0, v, 1, false); })
        .def("uniform3i", [](Context& c, const softgl::UniformLocation* l, IdlInt32 x, IdlInt32 y, IdlInt32 z) { int32_t v[] = {x.value, y.value, z.value}; c.set_uniform("uniform3i", l, 'i', 3, 0, v, 1, false); })
        .def("uniform4i", [](Context& c, const softgl::UniformLocation* l, IdlInt32 x, IdlInt32 y, IdlInt32 z, IdlInt32 w) { int32_t v[] = {x.value, y.value, z.value, w.value}; c.set_uniform("uniform4i", l, 'i', 4, 0, v, 1, false); })
        .def("uniform1ui", [](Context& c, const softgl::UniformLocation* l, IdlUint32 x) { uint32_t v[] = {x.value}; c.set_uniform("uniform1ui", l, 'u', 1, 0, v, 1, false); })
        .def("uniform2ui", [](Context& c, const softgl::UniformLocation* l, IdlUint32 x, IdlUint32 y) { uint32_t v[] = {x.value, y.value}; c.set_uniform("uniform2ui", l, 'u', 2, 0, v, 1, false); })
        .def("uniform3ui", [](Context& c, const softgl::UniformLocation* l, IdlUint32 x, IdlUint32 y, IdlUint32 z) { uint32_t v[] = {x.value, y.value, z.value}; c.set_uniform("uniform3ui", l, 'u', 3, 0, v, 1, false); })
        .def("uniform4ui", [](Context& c, const softgl::UniformLocation* l, IdlUint32 x, IdlUint32 y, IdlUint32 z, IdlUint32 w) { uint32_t v[] = {x.value, y.value, z.value, w.value}; c.set_uniform("uniform4ui", l, 'u', 4, 0, v, 1, false); })
        .def("getUniform", [](Context& c, const std::shared_ptr<softgl::Program>& p, const softgl::UniformLocation* loc) {
            return to_python(c.get_uniform(p, loc));
        });
}

// Draw calls, the fog extension, draw statistics and readPixels.
void bind_drawing(ContextClass& cls) {
    cls.def("drawArrays", [](Context& c, IdlUint32 mode, IdlInt32 first, IdlInt32 count) {
            softgl::bindings::run_interruptible(c, [&] { c.draw_arrays(mode.value, first.value, count.value, 1, "drawArrays"); });
        })
        .def("drawElements", [](Context& c, IdlUint32 mode, IdlInt32 count, IdlUint32 type, int64_t offset) {
            softgl::bindings::run_interruptible(c, [&] { c.draw_elements(mode.value, count.value, type.value, offset, 1, "drawElements"); });
        })
        .def("drawArraysInstanced", [](Context& c, IdlUint32 mode, IdlInt32 first, IdlInt32 count, IdlInt32 instances) {
            softgl::bindings::run_interruptible(c, [&] { c.draw_arrays(mode.value, first.value, count.value, instances.value, "drawArraysInstanced"); });
        })
        .def("drawElementsInstanced", [](Context& c, IdlUint32 mode, IdlInt32 count, IdlUint32 type, int64_t offset, IdlInt32 instances) {
            softgl::bindings::run_interruptible(c, [&] { c.draw_elements(mode.value, count.value, type.value, offset, instances.value, "drawElementsInstanced"); });
        })
        .def("drawRangeElements", [](Context& c, IdlUint32 mode, IdlUint32 start, IdlUint32 end, IdlInt32 count, IdlUint32 type, int64_t offset) {
            softgl::bindings::run_interruptible(c, [&] { c.draw_range_elements(mode.value, start.value, end.value, count.value, type.value, offset); });
        })
        .def("_fog", [](Context& c, const std::string& call, IdlUint32 pname, Arg<softgl::bindings::Floats> given) {
            static thread_local std::string name;
            name = call;
            auto values = number_sequence<float>(name.c_str(), "params", given);
            if (values.size() == 0) return c.record_error(gl::INVALID_VALUE, "fogfv", "no values");
            c.fog(name.c_str(), pname.value, values.data(), int(values.size()));
        })
        .def("_stats", [](Context& c, bool reset) {
            const softgl::DrawStats& s = c.stats();
            py::dict d;
#define SOFTGL_STAT(name) d[#name] = s.name;
            SOFTGL_STAT(draws) SOFTGL_STAT(vertices_shaded) SOFTGL_STAT(primitives) SOFTGL_STAT(primitives_culled)
            SOFTGL_STAT(primitives_clipped) SOFTGL_STAT(primitives_outside) SOFTGL_STAT(primitives_invalid)
            SOFTGL_STAT(primitives_zero_area) SOFTGL_STAT(primitives_rasterized) SOFTGL_STAT(tiles_touched)
            SOFTGL_STAT(quads) SOFTGL_STAT(blocks_accepted_whole) SOFTGL_STAT(fragments_shaded)
            SOFTGL_STAT(fragments_killed_early) SOFTGL_STAT(fragments_killed_late) SOFTGL_STAT(fragments_discarded)
            SOFTGL_STAT(fragments_hidden) SOFTGL_STAT(tiles_hidden_surface) SOFTGL_STAT(primitives_depth_hidden)
            SOFTGL_STAT(samples_written) SOFTGL_STAT(samples_blended) SOFTGL_STAT(draws_skipped_no_output)
            SOFTGL_STAT(draws_early_depth) SOFTGL_STAT(draws_plain_write) SOFTGL_STAT(draws_blend_table)
            SOFTGL_STAT(texture_queries_fast)
            SOFTGL_STAT(draws_late_tests) SOFTGL_STAT(draws_per_lane_color) SOFTGL_STAT(draws_constant_color)
            SOFTGL_STAT(draws_copied_varying) SOFTGL_STAT(draws_with_rollback)
            SOFTGL_STAT(fragments_flat) SOFTGL_STAT(draws_flat_primitives) SOFTGL_STAT(draws_texture_copy)
            SOFTGL_STAT(draws_texel_words) SOFTGL_STAT(blocks_depth_in_place)
            SOFTGL_STAT(quads_blended_in_place)
            SOFTGL_STAT(seconds_vertex)
            SOFTGL_STAT(seconds_setup) SOFTGL_STAT(seconds_fragment)
#undef SOFTGL_STAT
            if (reset) c.stats() = softgl::DrawStats{};
            return d;
        }, py::arg("reset") = false)
        .def("readPixels", &read_pixels);
}

}  // namespace

void bind_context(py::module_& m) {
    bind_object_types(m);
    bind_context_attributes(m);
    ContextClass::Base base(m, "Context",
                            "softgl's C++ rendering context, the base of softgl.Context (make contexts with "
                            "softgl.Context(width, height, **attributes); see README.md and docs/).");
    base.def(py::init<int32_t, int32_t, const ContextAttributes&>(), py::arg("width"), py::arg("height"),
             py::arg("attributes"))
        .def_property_readonly("drawingBufferWidth", &Context::drawing_buffer_width,
                               "The drawing buffer's width in pixels.")
        .def_property_readonly("drawingBufferHeight", &Context::drawing_buffer_height,
                               "The drawing buffer's height in pixels.");
    ContextClass cls(base);
    bind_state(cls);
    bind_buffers(cls);
    bind_vertex_input(cls);
    bind_shaders_and_programs(cls);
    bind_uniforms(cls);
    bind_drawing(cls);
}

// The array forms of the uniform setters: uniform{1234}{f,i,ui}v and uniformMatrix*fv, taking
// any sequence or array (with WebGL 2's srcOffset/srcLength), checked for length like WebGL.
namespace {

template <class T>
void uniform_v(Context& c, const char* call, const softgl::UniformLocation* location, char kind, int columns,
               int rows, py::handle data, bool transpose, int64_t src_offset, int64_t src_length) {
    auto arr = number_sequence<T>(call, "data", data);
    const int64_t total = int64_t(arr.size());
    if (src_offset < 0 || src_length < 0 || src_offset > total || src_length > total - src_offset)
        return c.record_error(gl::INVALID_VALUE, call, "srcOffset/srcLength exceed the data");
    const int64_t n = src_length ? src_length : total - src_offset;
    const int per = kind == 'm' ? columns * rows : columns;
    if (n == 0 || n % per != 0)
        return c.record_error(gl::INVALID_VALUE, call, "the data length must be a positive multiple of " + std::to_string(per));
    c.set_uniform(call, location, kind, columns, rows, arr.data() + src_offset, size_t(n / per), transpose);
}

}  // namespace

void bind_uniform_arrays(py::module_& m) {
    ContextClass cls = softgl::bindings::context_class(m);
    const char* kinds = "fiu";
    for (int k = 0; k < 3; ++k) {
        for (int n = 1; n <= 4; ++n) {
            const char kind = kinds[k];
            std::string name = "uniform" + std::to_string(n) + (kind == 'f' ? "f" : kind == 'i' ? "i" : "ui") + "v";
            // One lambda per argument type, so the stubs show Sequence[float] or Sequence[int].
            auto setter = [kind, n, name](Context& c, const softgl::UniformLocation* l, py::handle data, int64_t off, int64_t len) {
                static thread_local std::string call;
                call = name;
                if (kind == 'f') uniform_v<float>(c, call.c_str(), l, 'f', n, 0, data, false, off, len);
                else if (kind == 'i') uniform_v<int32_t>(c, call.c_str(), l, 'i', n, 0, data, false, off, len);
                else uniform_v<uint32_t>(c, call.c_str(), l, 'u', n, 0, data, false, off, len);
            };
            if (kind == 'f')
                cls.def(name.c_str(), [setter](Context& c, const softgl::UniformLocation* l, Arg<softgl::bindings::Floats> data,
                                               int64_t off, int64_t len) { setter(c, l, data, off, len); });
            else
                cls.def(name.c_str(), [setter](Context& c, const softgl::UniformLocation* l, Arg<softgl::bindings::Ints> data,
                                               int64_t off, int64_t len) { setter(c, l, data, off, len); });
        }
    }
    for (int cols = 2; cols <= 4; ++cols)
        for (int rows = 2; rows <= 4; ++rows) {
            std::string name = "uniformMatrix" + std::to_string(cols) + (cols == rows ? "" : "x" + std::to_string(rows)) + "fv";
            cls.def(name.c_str(),
                    [cols, rows, name](Context& c, const softgl::UniformLocation* l, bool transpose, Arg<softgl::bindings::Floats> data, int64_t off, int64_t len) {
                        static thread_local std::string call;
                        call = name;
                        uniform_v<float>(c, call.c_str(), l, 'm', cols, rows, data, transpose, off, len);
                    });
        }
}
