// Bindings of textures, samplers, framebuffers and renderbuffers: conversions only (WebGL's
// overloads dispatched on the argument count; NumPy arrays as ArrayBufferViews and as image
// sources). Added to the existing Context class.
#include <cstring>
#include <optional>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "array_intake.h"
#include "convert.h"
#include "softgl/api/context.h"
#include "exclusive.h"
#include "signatures.h"
#include "webidl.h"

namespace py = pybind11;
using softgl::Context;
using softgl::GLenum;
using softgl::TexSource;
using softgl::bindings::IdlInt32;
using softgl::bindings::IdlUint32;
using softgl::bindings::webidl;
namespace gl = softgl::gl;

namespace {

using softgl::bindings::Arg;
using softgl::bindings::number_sequence;
namespace kinds = softgl::bindings;
using softgl::bindings::to_python;




// Holds the converted pixels of one call.
struct Pixels {
    TexSource source;
    py::object keep;                // the array the source points into (array_intake.h)
    std::vector<uint8_t> rgba8;     // image sources, converted to RGBA rows
    std::vector<float> rgba32f;
};

// An ArrayBufferView argument (array_intake.h): None, or a NumPy array (from element src_offset).
void view_source(Context& c, const char* call, const char* param, py::handle obj, GLenum type, int64_t src_offset,
                 Pixels& px, bool* ok) {
    *ok = true;
    if (obj.is_none()) return;
    // WebGL 2's GLintptr overloads: a byte offset into the PIXEL_UNPACK_BUFFER.
    if (c.version() >= 2 && !py::isinstance<py::array>(obj) && PyIndex_Check(obj.ptr()) && !PyBool_Check(obj.ptr())) {
        if (src_offset != 0) throw py::type_error(std::string(call) + ": a buffer offset takes no srcOffset");
        px.source.kind = TexSource::Kind::UnpackBuffer;
        px.source.offset = softgl::bindings::byte_offset(call, param, obj);
        return;
    }
    const softgl::bindings::ClientArray arr = softgl::bindings::pixel_source(call, param, obj, type);
    if (src_offset < 0 || src_offset > arr.count) {
        c.record_error(gl::INVALID_VALUE, call, "srcOffset exceeds the array");
        *ok = false;
        return;
    }
    px.keep = arr.array;
    px.source.kind = TexSource::Kind::View;
    px.source.data = arr.data + src_offset * arr.itemsize;
    px.source.bytes = size_t((arr.count - src_offset) * arr.itemsize);
    px.source.array_type = arr.type;
}

// An image source: an H x W (grey) or H x W x C array (C = 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA)
// of uint8 (0..255) or floats (any float dtype, taken as float32). Row 0 is the image's first row,
// which WebGL uploads to texel row 0.
void image_source(const char* call, py::handle obj, Pixels& px) {
    using softgl::bindings::refuse;
    const std::string accepts = "an image: a NumPy array of shape (H, W) or (H, W, C), C = 1 to 4, of uint8 or floats";
    if (!py::isinstance<py::array>(obj)) refuse(call, "source", accepts, obj, "use np.asarray(source, np.uint8)");
    py::array arr = py::reinterpret_borrow<py::array>(obj);
    if (arr.ndim() != 2 && arr.ndim() != 3)
        refuse(call, "source", accepts, obj, "its shape is " + py::str(arr.attr("shape")).cast<std::string>());
    const py::ssize_t h = arr.shape(0), w = arr.shape(1), ch = arr.ndim() == 3 ? arr.shape(2) : 1;
    if (ch < 1 || ch > 4) refuse(call, "source", accepts, obj, "it has " + std::to_string(ch) + " channels");
    const char kind = arr.dtype().kind();
    const bool bytes = kind == 'u' && arr.itemsize() == 1;
    if (!bytes && kind != 'f') refuse(call, "source", accepts, obj, "use source.astype(np.uint8) or np.float32");
    const size_t n = size_t(h) * size_t(w);
    auto expand = [&](auto* out, auto get, auto one) {
        for (size_t i = 0; i < n; ++i) {
            auto v = [&](py::ssize_t c) { return get(i * size_t(ch) + size_t(c)); };
            if (ch == 1) out[i * 4] = out[i * 4 + 1] = out[i * 4 + 2] = v(0), out[i * 4 + 3] = one;
            else if (ch == 2) out[i * 4] = out[i * 4 + 1] = out[i * 4 + 2] = v(0), out[i * 4 + 3] = v(1);
            else for (int c = 0; c < 4; ++c) out[i * 4 + size_t(c)] = c < ch ? v(c) : one;
        }
    };
    if (bytes) {
        auto a = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(arr);
        const uint8_t* d = a.data();
        px.rgba8.resize(n * 4);
        expand(px.rgba8.data(), [&](size_t k) { return d[k]; }, uint8_t(255));
        px.source.data = px.rgba8.data();
        px.source.bytes = px.rgba8.size();
        px.source.image_type = gl::UNSIGNED_BYTE;
    } else {
        auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(arr);
        const float* d = a.data();
        px.rgba32f.resize(n * 4);
        expand(px.rgba32f.data(), [&](size_t k) { return d[k]; }, 1.0f);
        px.source.data = reinterpret_cast<const uint8_t*>(px.rgba32f.data());
        px.source.bytes = px.rgba32f.size() * 4;
        px.source.image_type = gl::FLOAT;
    }
    px.source.kind = TexSource::Kind::Image;
    px.source.width = int32_t(w);
    px.source.height = int32_t(h);
}

// A sequence<GLenum> (drawBuffers, invalidateFramebuffer): numbers taken modulo 2^32, as WebIDL does.
std::vector<uint32_t> enum_list(const char* call, const char* param, py::handle obj) {
    auto a = number_sequence<uint32_t>(call, param, obj);
    return std::vector<uint32_t>(a.data(), a.data() + a.size());
}

}  // namespace

void bind_textures(py::module_& m) {
    using softgl::Framebuffer;
    using softgl::Object;
    using softgl::Renderbuffer;
    using softgl::Sampler;
    using softgl::Texture;
    py::class_<Texture, Object, std::shared_ptr<Texture>>(m, "WebGLTexture");
    py::class_<Sampler, Object, std::shared_ptr<Sampler>>(m, "WebGLSampler");
    py::class_<Framebuffer, Object, std::shared_ptr<Framebuffer>>(m, "WebGLFramebuffer");
    py::class_<Renderbuffer, Object, std::shared_ptr<Renderbuffer>>(m, "WebGLRenderbuffer");

    auto cls = softgl::bindings::context_class(m);
    cls.def("createTexture", &Context::create_texture)
        .def("bindTexture", webidl(&Context::bind_texture))
        .def("deleteTexture", &Context::delete_texture)
        .def("isTexture", &Context::is_texture)
        .def("texParameteri", [](Context& c, IdlUint32 t, IdlUint32 p, IdlInt32 v) { c.tex_parameter("texParameteri", t.value, p.value, double(v.value)); })
        .def("texParameterf", [](Context& c, IdlUint32 t, IdlUint32 p, float v) { c.tex_parameter("texParameterf", t.value, p.value, double(v)); })
        .def("getTexParameter", [](Context& c, IdlUint32 t, IdlUint32 p) { return to_python(c.get_tex_parameter(t.value, p.value)); })
        .def("generateMipmap", webidl(&Context::generate_mipmap))
        // WebGL's overloads: (..., width, height, border, format, type, pixels[, srcOffset]) and an
        // image source (..., format, type, source).
        .def("texImage2D", [](Context& c, IdlUint32 target, IdlInt32 level, IdlInt32 internal, IdlInt32 width,
                              IdlInt32 height, IdlInt32 border, IdlUint32 format, IdlUint32 type,
                              Arg<kinds::PixelsOrOffset> pixels, std::optional<int64_t> src_offset) {
            const char* call = "texImage2D";
            if (src_offset && c.version() < 2) throw py::type_error("texImage2D: srcOffset needs WebGL 2");
            Pixels px;
            bool ok;
            view_source(c, call, "pixels", pixels, type.value, src_offset.value_or(0), px, &ok);
            if (!ok) return;
            c.tex_image(call, target.value, level.value, GLenum(internal.value), width.value, height.value, 1,
                        border.value, format.value, type.value, px.source);
        })
        .def("texImage2D", [](Context& c, IdlUint32 target, IdlInt32 level, IdlInt32 internal, IdlUint32 format,
                              IdlUint32 type, Arg<kinds::Image> source) {
            const char* call = "texImage2D";
            Pixels px;
            image_source(call, source, px);
            c.tex_image(call, target.value, level.value, GLenum(internal.value), 0, 0, 1, 0,
                        format.value, type.value, px.source);
        })
        .def("texSubImage2D", [](Context& c, IdlUint32 target, IdlInt32 level, IdlInt32 x, IdlInt32 y, IdlInt32 width,
                                 IdlInt32 height, IdlUint32 format, IdlUint32 type, Arg<kinds::PixelsOrOffset> pixels,
                                 std::optional<int64_t> src_offset) {
            const char* call = "texSubImage2D";
            Pixels px;
            bool ok;
            view_source(c, call, "pixels", pixels, type.value, src_offset.value_or(0), px, &ok);
            if (!ok) return;
            c.tex_sub_image(call, target.value, level.value, x.value, y.value, 0, width.value, height.value, 1,
                            format.value, type.value, px.source);
        })
        .def("texSubImage2D", [](Context& c, IdlUint32 target, IdlInt32 level, IdlInt32 x, IdlInt32 y, IdlUint32 format,
                                 IdlUint32 type, Arg<kinds::Image> source) {
            const char* call = "texSubImage2D";
            Pixels px;
            image_source(call, source, px);
            c.tex_sub_image(call, target.value, level.value, x.value, y.value, 0, 0, 0, 1,
                            format.value, type.value, px.source);
        })
        .def("texImage3D", [](Context& c, IdlUint32 target, IdlInt32 level, IdlInt32 internal, IdlInt32 w, IdlInt32 h,
                              IdlInt32 d, IdlInt32 border, IdlUint32 format, IdlUint32 type, Arg<kinds::PixelsOrOffset> pixels, int64_t src_offset) {
            Pixels px;
            bool ok;
            view_source(c, "texImage3D", "srcData", pixels, type.value, src_offset, px, &ok);
            if (ok) c.tex_image("texImage3D", target.value, level.value, GLenum(internal.value), w.value, h.value, d.value,
                                border.value, format.value, type.value, px.source);
        })
        .def("texSubImage3D", [](Context& c, IdlUint32 target, IdlInt32 level, IdlInt32 x, IdlInt32 y, IdlInt32 z, IdlInt32 w,
                                 IdlInt32 h, IdlInt32 d, IdlUint32 format, IdlUint32 type, Arg<kinds::PixelsOrOffset> pixels, int64_t src_offset) {
            Pixels px;
            bool ok;
            view_source(c, "texSubImage3D", "srcData", pixels, type.value, src_offset, px, &ok);
            if (ok) c.tex_sub_image("texSubImage3D", target.value, level.value, x.value, y.value, z.value, w.value, h.value,
                                    d.value, format.value, type.value, px.source);
        })
        .def("texStorage2D", [](Context& c, IdlUint32 target, IdlInt32 levels, IdlUint32 internal, IdlInt32 w, IdlInt32 h) {
            c.tex_storage("texStorage2D", target.value, levels.value, internal.value, w.value, h.value, 1);
        })
        .def("texStorage3D", [](Context& c, IdlUint32 target, IdlInt32 levels, IdlUint32 internal, IdlInt32 w, IdlInt32 h, IdlInt32 d) {
            c.tex_storage("texStorage3D", target.value, levels.value, internal.value, w.value, h.value, d.value);
        })
        .def("copyTexImage2D", webidl(&Context::copy_tex_image_2d))
        .def("copyTexSubImage2D", [](Context& c, IdlUint32 target, IdlInt32 level, IdlInt32 xo, IdlInt32 yo, IdlInt32 x,
                                     IdlInt32 y, IdlInt32 w, IdlInt32 h) {
            c.copy_tex_sub_image("copyTexSubImage2D", target.value, level.value, xo.value, yo.value, 0, x.value, y.value, w.value, h.value);
        })
        .def("copyTexSubImage3D", [](Context& c, IdlUint32 target, IdlInt32 level, IdlInt32 xo, IdlInt32 yo, IdlInt32 zo,
                                     IdlInt32 x, IdlInt32 y, IdlInt32 w, IdlInt32 h) {
            c.copy_tex_sub_image("copyTexSubImage3D", target.value, level.value, xo.value, yo.value, zo.value, x.value, y.value, w.value, h.value);
        })
        // Sampler objects (WebGL 2)
        .def("createSampler", &Context::create_sampler)
        .def("deleteSampler", &Context::delete_sampler)
        .def("isSampler", &Context::is_sampler)
        .def("bindSampler", [](Context& c, IdlUint32 unit, const std::shared_ptr<Sampler>& s) { c.bind_sampler(unit.value, s); })
        .def("samplerParameteri", [](Context& c, const std::shared_ptr<Sampler>& s, IdlUint32 p, IdlInt32 v) {
            c.sampler_parameter("samplerParameteri", s, p.value, double(v.value));
        })
        .def("samplerParameterf", [](Context& c, const std::shared_ptr<Sampler>& s, IdlUint32 p, float v) {
            c.sampler_parameter("samplerParameterf", s, p.value, double(v));
        })
        .def("getSamplerParameter", [](Context& c, const std::shared_ptr<Sampler>& s, IdlUint32 p) {
            return to_python(c.get_sampler_parameter(s, p.value));
        })
        // Framebuffers and renderbuffers
        .def("createFramebuffer", &Context::create_framebuffer)
        .def("bindFramebuffer", webidl(&Context::bind_framebuffer))
        .def("deleteFramebuffer", &Context::delete_framebuffer)
        .def("isFramebuffer", &Context::is_framebuffer)
        .def("createRenderbuffer", &Context::create_renderbuffer)
        .def("bindRenderbuffer", webidl(&Context::bind_renderbuffer))
        .def("deleteRenderbuffer", &Context::delete_renderbuffer)
        .def("isRenderbuffer", &Context::is_renderbuffer)
        .def("renderbufferStorage", [](Context& c, IdlUint32 target, IdlUint32 internal, IdlInt32 w, IdlInt32 h) {
            c.renderbuffer_storage("renderbufferStorage", target.value, 0, internal.value, w.value, h.value);
        })
        .def("renderbufferStorageMultisample", [](Context& c, IdlUint32 target, IdlInt32 samples, IdlUint32 internal, IdlInt32 w, IdlInt32 h) {
            c.renderbuffer_storage("renderbufferStorageMultisample", target.value, samples.value, internal.value, w.value, h.value);
        })
        .def("getRenderbufferParameter", [](Context& c, IdlUint32 t, IdlUint32 p) { return to_python(c.get_renderbuffer_parameter(t.value, p.value)); })
        .def("framebufferTexture2D", [](Context& c, IdlUint32 target, IdlUint32 attachment, IdlUint32 textarget,
                                        const std::shared_ptr<Texture>& t, IdlInt32 level) {
            c.framebuffer_texture("framebufferTexture2D", target.value, attachment.value, textarget.value, t, level.value, 0);
        })
        .def("framebufferTextureLayer", [](Context& c, IdlUint32 target, IdlUint32 attachment, const std::shared_ptr<Texture>& t,
                                           IdlInt32 level, IdlInt32 layer) {
            c.framebuffer_texture("framebufferTextureLayer", target.value, attachment.value, 0, t, level.value, layer.value);
        })
        .def("framebufferRenderbuffer", webidl(&Context::framebuffer_renderbuffer))
        .def("checkFramebufferStatus", webidl(&Context::check_framebuffer_status))
        .def("getFramebufferAttachmentParameter", [](Context& c, IdlUint32 t, IdlUint32 a, IdlUint32 p) {
            return to_python(c.get_framebuffer_attachment_parameter(t.value, a.value, p.value));
        })
        .def("readBuffer", webidl(&Context::read_buffer))
        .def("blitFramebuffer", [](Context& c, IdlInt32 sx0, IdlInt32 sy0, IdlInt32 sx1, IdlInt32 sy1, IdlInt32 dx0, IdlInt32 dy0,
                                   IdlInt32 dx1, IdlInt32 dy1, IdlUint32 mask, IdlUint32 filter) {
            softgl::bindings::ExclusiveWithoutGil release(c);
            c.blit_framebuffer(sx0.value, sy0.value, sx1.value, sy1.value, dx0.value, dy0.value, dx1.value, dy1.value, mask.value, filter.value);
        })
        .def("clearBufferfv", [](Context& c, IdlUint32 buffer, IdlInt32 drawbuffer, Arg<kinds::Floats> values, int64_t off) {
            auto a = number_sequence<float>("clearBufferfv", "values", values);
            if (off < 0 || off > int64_t(a.size())) return c.record_error(gl::INVALID_VALUE, "clearBufferfv", "srcOffset exceeds the values");
            c.clear_buffer("clearBufferfv", buffer.value, drawbuffer.value, 'f', a.data() + off, size_t(a.size() - off), 0, 0);
        })
        .def("clearBufferiv", [](Context& c, IdlUint32 buffer, IdlInt32 drawbuffer, Arg<kinds::Ints> values, int64_t off) {
            auto a = number_sequence<int32_t>("clearBufferiv", "values", values);
            if (off < 0 || off > int64_t(a.size())) return c.record_error(gl::INVALID_VALUE, "clearBufferiv", "srcOffset exceeds the values");
            c.clear_buffer("clearBufferiv", buffer.value, drawbuffer.value, 'i', a.data() + off, size_t(a.size() - off), 0, 0);
        })
        .def("clearBufferuiv", [](Context& c, IdlUint32 buffer, IdlInt32 drawbuffer, Arg<kinds::Ints> values, int64_t off) {
            auto a = number_sequence<uint32_t>("clearBufferuiv", "values", values);
            if (off < 0 || off > int64_t(a.size())) return c.record_error(gl::INVALID_VALUE, "clearBufferuiv", "srcOffset exceeds the values");
            c.clear_buffer("clearBufferuiv", buffer.value, drawbuffer.value, 'u', a.data() + off, size_t(a.size() - off), 0, 0);
        })
        .def("clearBufferfi", [](Context& c, IdlUint32 buffer, IdlInt32 drawbuffer, float depth, IdlInt32 stencil) {
            c.clear_buffer("clearBufferfi", buffer.value, drawbuffer.value, 's', nullptr, 0, depth, stencil.value);
        })
        .def("drawBuffers", [](Context& c, Arg<kinds::Ints> buffers) { c.draw_buffers("drawBuffers", enum_list("drawBuffers", "buffers", buffers)); })
        .def("_drawBuffersWEBGL", [](Context& c, Arg<kinds::Ints> list) {
            const std::vector<uint32_t> buffers = enum_list("drawBuffersWEBGL", "buffers", list);
            if (!c.extension_enabled("WEBGL_draw_buffers"))
                return c.record_error(gl::INVALID_OPERATION, "drawBuffersWEBGL", "WEBGL_draw_buffers is not enabled");
            c.draw_buffers("drawBuffersWEBGL", buffers);
        })
        .def("invalidateFramebuffer", [](Context& c, IdlUint32 target, Arg<kinds::Ints> attachments) {
            c.invalidate_framebuffer("invalidateFramebuffer", target.value,
                                     enum_list("invalidateFramebuffer", "attachments", attachments));
        })
        .def("invalidateSubFramebuffer", [](Context& c, IdlUint32 target, Arg<kinds::Ints> list, IdlInt32 x,
                                            IdlInt32 y, IdlInt32 w, IdlInt32 h) {
            const std::vector<uint32_t> attachments = enum_list("invalidateSubFramebuffer", "attachments", list);
            if (w.value < 0 || h.value < 0) return c.record_error(gl::INVALID_VALUE, "invalidateSubFramebuffer", "width and height must not be negative");
            c.invalidate_framebuffer("invalidateSubFramebuffer", target.value, attachments);
        });
}
