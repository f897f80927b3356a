// Framebuffer and renderbuffer objects: WebGL 1.0 §5.14.6-7 / §6.6 and WebGL 2.0 §3.7.4-5 over
// ES 2.0 §4.4 and ES 3.0 §4.4 (attachments, completeness), with drawing into attachments
// (render targets), clear/clearBuffer*, readPixels of any readable attachment, copyTexImage2D,
// copyTexSubImage2D/3D and blitFramebuffer (ES 3.0 §4.3.3).
#include <algorithm>
#include <cmath>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "softgl/api/context.h"
#include "softgl/surface/formats.h"

namespace softgl {

using namespace gl_ext;

namespace {

std::string quote(GLenum v) { return enum_name(v); }

template <class T>
Value object_value(const std::shared_ptr<T>& p) {
    if (!p) return Value(Null{});
    return Value(std::shared_ptr<Object>(p));
}
template <class T>
Value object_value(const InUse<T>& p) { return object_value(p.shared()); }

bool is_cube_face(GLenum target) {
    return target >= gl::TEXTURE_CUBE_MAP_POSITIVE_X && target <= gl::TEXTURE_CUBE_MAP_NEGATIVE_Z;
}

// Reads pixel (x, y) of a colour source as float RGBA, multisample resolved by the mean.
struct ColorSource {
    DefaultFramebuffer* fb = nullptr;
    const Image* img = nullptr;
    size_t offset = 0;
    int32_t width = 0, height = 0;
    void read(int32_t x, int32_t y, float out[4]) const {
        if (fb) return fb->read_pixel(x, y, out);   // any colour format, resolved by the mean
        const size_t S = size_t(img->samples);
        const size_t t = offset + (size_t(y) * size_t(img->width) + size_t(x)) * S;
        if (!img->integer.empty()) {
            uint32_t bits[4];
            img->read_integer(t, bits);   // bit patterns (no resolve)
            std::memcpy(out, bits, 16);
            return;
        }
        if (S == 1) return img->read_color(t, out);
        double sum[4] = {0, 0, 0, 0};
        for (size_t s = 0; s < S; ++s) {
            float v[4];
            img->read_color(t + s, v);
            for (int c = 0; c < 4; ++c) sum[c] += double(v[c]);
        }
        for (int c = 0; c < 4; ++c) out[c] = float(sum[c] / double(S));
    }
};

// Writes float RGBA into every sample of pixel (x, y) of a colour destination (no blending).
void write_plain(DefaultFramebuffer* fb, Image* img, size_t offset, int32_t x, int32_t y, const float rgba[4],
                 const std::array<bool, 4>& mask) {
    if (fb) return fb->write_pixel(x, y, rgba, mask);   // any colour format
    BlendOp op;
    op.write = mask;
    for (int s = 0; s < img->samples; ++s) write_image_color(*img, offset, op, rgba, x, y, s);
}

size_t layer_offset(const Image& img, int32_t layer) {
    return size_t(layer) * size_t(img.width) * size_t(img.height) * size_t(img.samples);
}

}  // namespace

Image* Attachment::image() const {
    if (renderbuffer) return renderbuffer->image.defined() ? &renderbuffer->image : nullptr;
    if (texture) {
        Image* img = const_cast<Image*>(texture->find(face, level));
        return img;
    }
    return nullptr;
}

// ---------------------------------------------------------------------------- objects

std::shared_ptr<Framebuffer> Context::create_framebuffer() {
    auto f = std::make_shared<Framebuffer>();
    f->owner = identity();
    return f;
}

std::shared_ptr<Framebuffer>* Context::framebuffer_binding(GLenum target) {
    if (target == gl::FRAMEBUFFER || (version() >= 2 && target == gl::DRAW_FRAMEBUFFER)) return &draw_framebuffer_;
    if (version() >= 2 && target == gl::READ_FRAMEBUFFER) return &read_framebuffer_;
    return nullptr;
}

void Context::bind_framebuffer(GLenum target, const std::shared_ptr<Framebuffer>& fb) {
    const char* call = "bindFramebuffer";
    if (!framebuffer_binding(target)) return error(gl::INVALID_ENUM, call, quote(target) + " is not a framebuffer target here");
    if (!check_object(call, fb.get())) return;
    if (fb) fb->ever_bound = true;
    if (target == gl::FRAMEBUFFER) draw_framebuffer_ = read_framebuffer_ = fb;
    else *framebuffer_binding(target) = fb;
}

void Context::delete_framebuffer(const std::shared_ptr<Framebuffer>& fb) {
    if (!fb) return;
    if (fb->owner != identity()) return error(gl::INVALID_OPERATION, "deleteFramebuffer", "the object belongs to another context");
    if (fb->deleted) return;
    fb->deleted = true;
    if (draw_framebuffer_ == fb) draw_framebuffer_.reset();   // ES 3.0 §4.4.1: reverts to the default
    if (read_framebuffer_ == fb) read_framebuffer_.reset();
    // A deleted framebuffer can never be bound again, so its attachments are unobservable: it
    // lets go of them, which frees deleted images it alone kept (Object::mark_deleted).
    for (Attachment& a : fb->color) a = Attachment{};
    fb->depth = Attachment{};
    fb->stencil = Attachment{};
}

bool Context::is_framebuffer(const std::shared_ptr<Framebuffer>& fb) const {
    return fb && fb->owner == identity() && !fb->deleted && fb->ever_bound;
}

std::shared_ptr<Renderbuffer> Context::create_renderbuffer() {
    auto r = std::make_shared<Renderbuffer>();
    r->owner = identity();
    return r;
}

void Context::bind_renderbuffer(GLenum target, const std::shared_ptr<Renderbuffer>& rb) {
    const char* call = "bindRenderbuffer";
    if (target != gl::RENDERBUFFER) return error(gl::INVALID_ENUM, call, quote(target) + " is not RENDERBUFFER");
    if (!check_object(call, rb.get())) return;
    if (rb) rb->ever_bound = true;
    renderbuffer_ = rb;
}

void Context::delete_renderbuffer(const std::shared_ptr<Renderbuffer>& rb) {
    if (!rb) return;
    if (rb->owner != identity()) return error(gl::INVALID_OPERATION, "deleteRenderbuffer", "the object belongs to another context");
    if (rb->deleted) return;
    rb->mark_deleted();   // its image goes now, or when the last framebuffer lets go of it
    if (renderbuffer_ == rb) renderbuffer_.reset();
    detach_from_framebuffers(nullptr, rb.get());
}

bool Context::is_renderbuffer(const std::shared_ptr<Renderbuffer>& rb) const {
    return rb && rb->owner == identity() && !rb->deleted && rb->ever_bound;
}

void Context::detach_from_framebuffers(const Texture* t, const Renderbuffer* r) {
    // ES 3.0 §4.4.2.3 / §3.8.1: deleting an image object detaches it from the bound framebuffers.
    for (const auto& fb : {draw_framebuffer_, read_framebuffer_}) {
        if (!fb) continue;
        auto detach = [&](Attachment& a) {
            if ((t && a.texture.get() == t) || (r && a.renderbuffer.get() == r)) a = Attachment{};
        };
        for (Attachment& a : fb->color) detach(a);
        detach(fb->depth);
        detach(fb->stencil);
    }
}

// ---------------------------------------------------------------------------- renderbuffers

bool Context::color_renderable(const FormatInfo& f) const {
    const GLenum i = f.internal_format;
    if (version() == 1) {
        if (i == gl::RGBA8 || i == gl::RGB8 || i == gl::RGBA4 || i == gl::RGB5_A1 || i == gl::RGB565) return true;
        // WEBGL_color_buffer_float (implied by OES_texture_float, WebGL 1 extension registry) and
        // EXT_color_buffer_half_float.
        if (i == gl::RGBA32F || i == gl::RGB32F)
            return texture_extension_enabled("WEBGL_color_buffer_float") || texture_extension_enabled("OES_texture_float");
        if (i == gl::RGBA16F || i == gl::RGB16F)
            return texture_extension_enabled("EXT_color_buffer_half_float") || texture_extension_enabled("OES_texture_half_float");
        return false;
    }
    switch (i) {
        // ES 3.0 table 3.13
        case gl::R8: case gl::RG8: case gl::RGB8: case gl::RGB565: case gl::RGBA4: case gl::RGB5_A1:
        case gl::RGBA8: case gl::RGB10_A2: case gl::RGB10_A2UI: case gl::SRGB8_ALPHA8:
        case gl::R8I: case gl::R8UI: case gl::R16I: case gl::R16UI: case gl::R32I: case gl::R32UI:
        case gl::RG8I: case gl::RG8UI: case gl::RG16I: case gl::RG16UI: case gl::RG32I: case gl::RG32UI:
        case gl::RGBA8I: case gl::RGBA8UI: case gl::RGBA16I: case gl::RGBA16UI: case gl::RGBA32I: case gl::RGBA32UI:
            return true;
        // EXT_color_buffer_float
        case gl::R16F: case gl::RG16F: case gl::RGBA16F: case gl::R32F: case gl::RG32F: case gl::RGBA32F:
        case gl::R11F_G11F_B10F:
            return texture_extension_enabled("EXT_color_buffer_float");
        default: return false;
    }
}

void Context::renderbuffer_storage(const char* call, GLenum target, int32_t samples, GLenum internal_format,
                                   int32_t width, int32_t height) {
    if (target != gl::RENDERBUFFER) return error(gl::INVALID_ENUM, call, quote(target) + " is not RENDERBUFFER");
    if (!renderbuffer_) return error(gl::INVALID_OPERATION, call, "no renderbuffer is bound");
    GLenum effective = internal_format;
    if (internal_format == gl::DEPTH_STENCIL) effective = gl::DEPTH24_STENCIL8;   // WebGL's DEPTH_STENCIL
    const FormatInfo* f = format_info(effective);
    bool ok = false;
    if (f) {
        if (version() == 1)
            ok = effective == gl::RGBA4 || effective == gl::RGB565 || effective == gl::RGB5_A1 ||
                 effective == gl::DEPTH_COMPONENT16 || effective == gl::STENCIL_INDEX8 ||
                 (internal_format == gl::DEPTH_STENCIL) ||
                 ((effective == gl::RGBA32F || effective == gl::RGBA16F || effective == gl::RGB16F) && color_renderable(*f));
        else
            ok = color_renderable(*f) || f->kind() == SampleKind::Depth;
    }
    if (!ok) return error(gl::INVALID_ENUM, call, quote(internal_format) + " is not a renderbuffer format here");
    if (width < 0 || height < 0 || samples < 0) return error(gl::INVALID_VALUE, call, "sizes and samples must not be negative");
    if (width > limits::kMaxRenderbufferSize || height > limits::kMaxRenderbufferSize)
        return error(gl::INVALID_VALUE, call, "the size exceeds MAX_RENDERBUFFER_SIZE");
    if (samples > limits::kMaxSamples) return error(gl::INVALID_OPERATION, call, "samples exceeds MAX_SAMPLES");
    if (samples > 0 && f->is_integer()) return error(gl::INVALID_OPERATION, call, "integer formats cannot be multisampled");
    // The smallest supported count >= the request (ES 3.0 §4.4.2.1).
    int32_t actual = 1;
    if (samples > 0) for (int32_t n : {2, 4, 8, 16}) if (n >= samples) { actual = n; break; }
    // Charged before allocating, so the limit bounds all objects together (core/memory_ledger.h).
    // Renderbuffers are never sampled: kept encoded at the format's size (Image::packed).
    const uint64_t bytes = Image::allocation_bytes(f, width, height, 1, actual, true);
    MemoryReservation reservation(memory_account_);
    if (!reservation.reserve(bytes))
        return error(gl::OUT_OF_MEMORY, call, "a " + std::to_string(width) + "x" + std::to_string(height) + "x" +
                     std::to_string(actual) + "-sample renderbuffer needs " + std::to_string(bytes) +
                     " bytes, which " + reservation.over_limit(bytes));
    Image image;
    try {
        image.allocate(f, width, height, 1, actual, true);
    } catch (const std::bad_alloc&) {
        return error(gl::OUT_OF_MEMORY, call, "could not allocate " + std::to_string(bytes) + " bytes");
    }
    Renderbuffer& rb = *renderbuffer_;
    rb.internal_format = internal_format;
    rb.samples = samples > 0 ? actual : 0;
    rb.image = std::move(image);
    rb.reservation = std::move(reservation);
    ++rb.generation;
}

Value Context::get_renderbuffer_parameter(GLenum target, GLenum pname) {
    const char* call = "getRenderbufferParameter";
    if (target != gl::RENDERBUFFER) { error(gl::INVALID_ENUM, call, quote(target) + " is not RENDERBUFFER"); return Value(Null{}); }
    if (!renderbuffer_) { error(gl::INVALID_OPERATION, call, "no renderbuffer is bound"); return Value(Null{}); }
    const Renderbuffer& rb = *renderbuffer_;
    const FormatInfo* f = rb.image.format;
    auto bits = [&](int c) -> int64_t { return f && f->kind() != SampleKind::Depth ? f->bits[size_t(c)] : 0; };
    switch (pname) {
        case gl::RENDERBUFFER_WIDTH: return Value(int64_t(rb.image.width));
        case gl::RENDERBUFFER_HEIGHT: return Value(int64_t(rb.image.height));
        case gl::RENDERBUFFER_INTERNAL_FORMAT: return Value(int64_t(rb.internal_format));
        case gl::RENDERBUFFER_RED_SIZE: return Value(bits(0));
        case gl::RENDERBUFFER_GREEN_SIZE: return Value(bits(1));
        case gl::RENDERBUFFER_BLUE_SIZE: return Value(bits(2));
        case gl::RENDERBUFFER_ALPHA_SIZE: return Value(bits(3));
        case gl::RENDERBUFFER_DEPTH_SIZE: return Value(int64_t(f ? f->depth_bits() : 0));
        case gl::RENDERBUFFER_STENCIL_SIZE: return Value(int64_t(f && f->has_stencil ? 8 : 0));
        default: break;
    }
    if (version() >= 2 && pname == gl::RENDERBUFFER_SAMPLES) return Value(int64_t(rb.samples));
    error(gl::INVALID_ENUM, call, quote(pname) + " is not a renderbuffer parameter");
    return Value(Null{});
}

// ---------------------------------------------------------------------------- attachments

Attachment* Context::attachment_slot(Framebuffer& fb, GLenum attachment, bool* both) {
    *both = false;
    if (attachment == gl::DEPTH_ATTACHMENT) return &fb.depth;
    if (attachment == gl::STENCIL_ATTACHMENT) return &fb.stencil;
    if (attachment == gl::DEPTH_STENCIL_ATTACHMENT) { *both = true; return &fb.depth; }
    const int max_color = multiple_draw_buffers() ? kMaxColorAttachments : 1;
    if (attachment >= gl::COLOR_ATTACHMENT0 && attachment < gl::COLOR_ATTACHMENT0 + uint32_t(max_color))
        return &fb.color[attachment - gl::COLOR_ATTACHMENT0];
    return nullptr;
}

void Context::framebuffer_texture(const char* call, GLenum target, GLenum attachment, GLenum textarget,
                                  const std::shared_ptr<Texture>& texture, int32_t level, int32_t layer) {
    std::shared_ptr<Framebuffer>* slot = framebuffer_binding(target);
    if (!slot) return error(gl::INVALID_ENUM, call, quote(target) + " is not a framebuffer target here");
    const bool layered = textarget == 0;   // framebufferTextureLayer
    if (!layered && textarget != gl::TEXTURE_2D && !is_cube_face(textarget))
        return error(gl::INVALID_ENUM, call, quote(textarget) + " is not a texture target for attachments");
    Framebuffer* fb = (target == gl::READ_FRAMEBUFFER ? read_framebuffer_ : draw_framebuffer_).get();
    if (!fb) return error(gl::INVALID_OPERATION, call, "the default framebuffer cannot have attachments");
    bool both = false;
    Attachment* a = attachment_slot(*fb, attachment, &both);
    if (!a) return error(gl::INVALID_ENUM, call, quote(attachment) + " is not an attachment point here");
    if (!check_object(call, texture.get())) return;
    Attachment value;
    if (texture) {
        if (layered) {
            if (texture->target != gl::TEXTURE_3D && texture->target != gl::TEXTURE_2D_ARRAY)
                return error(gl::INVALID_OPERATION, call, "the texture is not a 3D or 2D array texture");
            if (layer < 0 || layer >= 2048) return error(gl::INVALID_VALUE, call, "layer is out of range");
        } else {
            const GLenum wanted = textarget == gl::TEXTURE_2D ? gl::TEXTURE_2D : gl::TEXTURE_CUBE_MAP;
            if (texture->target != wanted)
                return error(gl::INVALID_OPERATION, call, "textarget does not match the texture's target");
        }
        const int32_t max_level = version() == 1 ? 0 : 14;   // WebGL 1.0 §6.? level must be 0
        if (level < 0 || level > max_level) return error(gl::INVALID_VALUE, call, "level is out of range");
        value.texture = texture;
        value.face = is_cube_face(textarget) ? int(textarget - gl::TEXTURE_CUBE_MAP_POSITIVE_X) : 0;
        value.level = level;
        value.layer = layered ? layer : 0;
    }
    *a = value;
    if (both) fb->stencil = value;
}

void Context::framebuffer_renderbuffer(GLenum target, GLenum attachment, GLenum rb_target,
                                       const std::shared_ptr<Renderbuffer>& rb) {
    const char* call = "framebufferRenderbuffer";
    if (!framebuffer_binding(target)) return error(gl::INVALID_ENUM, call, quote(target) + " is not a framebuffer target here");
    if (rb_target != gl::RENDERBUFFER) return error(gl::INVALID_ENUM, call, quote(rb_target) + " is not RENDERBUFFER");
    Framebuffer* fb = (target == gl::READ_FRAMEBUFFER ? read_framebuffer_ : draw_framebuffer_).get();
    if (!fb) return error(gl::INVALID_OPERATION, call, "the default framebuffer cannot have attachments");
    bool both = false;
    Attachment* a = attachment_slot(*fb, attachment, &both);
    if (!a) return error(gl::INVALID_ENUM, call, quote(attachment) + " is not an attachment point here");
    if (!check_object(call, rb.get())) return;
    Attachment value;
    value.renderbuffer = rb;
    *a = value;
    if (both) fb->stencil = value;
}

GLenum Context::framebuffer_status(const Framebuffer& fb, std::string* why) const {
    auto fail = [&](GLenum code, const std::string& reason) { if (why) *why = reason; return code; };
    int32_t w = -1, h = -1, samples = -1;
    bool any = false, sizes_differ = false;
    auto check = [&](const Attachment& a, int kind) -> GLenum {   // kind 0 colour, 1 depth, 2 stencil
        if (a.empty()) return 0;
        const Image* img = a.image();
        if (!img || img->width == 0 || img->height == 0)
            return fail(gl::FRAMEBUFFER_INCOMPLETE_ATTACHMENT, "an attachment has no image (or a zero size)");
        const FormatInfo& f = *img->format;
        if (kind == 0 && !color_renderable(f)) return fail(gl::FRAMEBUFFER_INCOMPLETE_ATTACHMENT, "a colour attachment's format is not colour-renderable");
        if (kind == 1 && !f.is_depth()) return fail(gl::FRAMEBUFFER_INCOMPLETE_ATTACHMENT, "the depth attachment has no depth");
        if (kind == 2 && !f.has_stencil) return fail(gl::FRAMEBUFFER_INCOMPLETE_ATTACHMENT, "the stencil attachment has no stencil");
        if (a.texture && a.layer >= img->depth) return fail(gl::FRAMEBUFFER_INCOMPLETE_ATTACHMENT, "the attached layer does not exist");
        const int32_t s = a.renderbuffer ? a.renderbuffer->samples : 0;
        if (any && (img->width != w || img->height != h)) sizes_differ = true;
        if (any && s != samples) return fail(gl::FRAMEBUFFER_INCOMPLETE_MULTISAMPLE, "the attachments have different sample counts");
        w = any ? std::min(w, img->width) : img->width;
        h = any ? std::min(h, img->height) : img->height;
        samples = s;
        any = true;
        return 0;
    };
    for (const Attachment& a : fb.color) if (GLenum e = check(a, 0)) return e;
    if (GLenum e = check(fb.depth, 1)) return e;
    if (GLenum e = check(fb.stencil, 2)) return e;
    if (!any) return fail(gl::FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT, "nothing is attached");
    if (version() == 1 && sizes_differ) return fail(gl::FRAMEBUFFER_INCOMPLETE_DIMENSIONS, "the attachments have different sizes");
    // WebGL 1.0 §6.6 / WebGL 2.0 §5.? : depth and stencil must be one image when both are attached.
    if (!fb.depth.empty() && !fb.stencil.empty() &&
        (fb.depth.texture != fb.stencil.texture || fb.depth.renderbuffer != fb.stencil.renderbuffer ||
         fb.depth.level != fb.stencil.level || fb.depth.layer != fb.stencil.layer))
        return fail(gl::FRAMEBUFFER_UNSUPPORTED, "separate depth and stencil images are not supported");
    if (version() == 1) {
        // WebGL 1.0 §6.6: a DEPTH_STENCIL image must go to DEPTH_STENCIL_ATTACHMENT and vice versa.
        const Image* d = fb.depth.image();
        if (d && d->format->has_stencil && fb.stencil.empty())
            return fail(gl::FRAMEBUFFER_INCOMPLETE_ATTACHMENT, "a depth-stencil image is attached to DEPTH_ATTACHMENT only");
    }
    return gl::FRAMEBUFFER_COMPLETE;
}

GLenum Context::check_framebuffer_status(GLenum target) {
    std::shared_ptr<Framebuffer>* slot = framebuffer_binding(target);
    if (!slot) { error(gl::INVALID_ENUM, "checkFramebufferStatus", quote(target) + " is not a framebuffer target here"); return 0; }
    const std::shared_ptr<Framebuffer>& fb = target == gl::READ_FRAMEBUFFER ? read_framebuffer_ : draw_framebuffer_;
    if (!fb) return gl::FRAMEBUFFER_COMPLETE;
    return framebuffer_status(*fb, nullptr);
}

Value Context::get_framebuffer_attachment_parameter(GLenum target, GLenum attachment, GLenum pname) {
    const char* call = "getFramebufferAttachmentParameter";
    if (!framebuffer_binding(target)) { error(gl::INVALID_ENUM, call, quote(target) + " is not a framebuffer target here"); return Value(Null{}); }
    const std::shared_ptr<Framebuffer>& fb = target == gl::READ_FRAMEBUFFER ? read_framebuffer_ : draw_framebuffer_;
    if (!fb) {
        if (version() == 1) { error(gl::INVALID_OPERATION, call, "the default framebuffer has no attachment objects"); return Value(Null{}); }
        // WebGL 2: BACK, DEPTH, STENCIL of the drawing buffer.
        const bool ok = attachment == gl::BACK || attachment == gl::DEPTH || attachment == gl::STENCIL;
        if (!ok) { error(gl::INVALID_ENUM, call, quote(attachment) + " is not an attachment of the default framebuffer"); return Value(Null{}); }
        const auto& c = framebuffer_.config();
        const bool present = attachment == gl::BACK || (attachment == gl::DEPTH && c.depth) || (attachment == gl::STENCIL && c.stencil);
        if (pname == gl::FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) return Value(int64_t(present ? gl::FRAMEBUFFER_DEFAULT : gl::NONE));
        if (!present) { error(gl::INVALID_OPERATION, call, "the attachment does not exist"); return Value(Null{}); }
        switch (pname) {
            case gl::FRAMEBUFFER_ATTACHMENT_RED_SIZE: case gl::FRAMEBUFFER_ATTACHMENT_GREEN_SIZE:
            case gl::FRAMEBUFFER_ATTACHMENT_BLUE_SIZE: return Value(int64_t(attachment == gl::BACK ? framebuffer_.color_bits() : 0));
            case gl::FRAMEBUFFER_ATTACHMENT_ALPHA_SIZE: return Value(int64_t(attachment == gl::BACK && c.alpha ? framebuffer_.color_bits() : 0));
            case gl::FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE: return Value(int64_t(attachment == gl::DEPTH ? 24 : 0));
            case gl::FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE: return Value(int64_t(attachment == gl::STENCIL ? 8 : 0));
            case gl::FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE:
                return Value(int64_t(attachment == gl::STENCIL ? gl::UNSIGNED_INT
                                     : attachment == gl::BACK && framebuffer_.is_float() ? gl::FLOAT : gl::UNSIGNED_NORMALIZED));
            case gl::FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING: return Value(int64_t(gl::LINEAR));
            default: break;
        }
        error(gl::INVALID_ENUM, call, quote(pname) + " is not an attachment parameter here");
        return Value(Null{});
    }
    bool both = false;
    Attachment* a = attachment_slot(*fb, attachment, &both);
    if (!a) { error(gl::INVALID_ENUM, call, quote(attachment) + " is not an attachment point here"); return Value(Null{}); }
    if (both && (fb->depth.texture != fb->stencil.texture || fb->depth.renderbuffer != fb->stencil.renderbuffer)) {
        error(gl::INVALID_OPERATION, call, "depth and stencil attachments differ"); return Value(Null{});
    }
    const GLenum type = a->texture ? gl::TEXTURE : a->renderbuffer ? gl::RENDERBUFFER : gl::NONE;
    if (pname == gl::FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) return Value(int64_t(type));
    if (type == gl::NONE) {
        if (pname == gl::FRAMEBUFFER_ATTACHMENT_OBJECT_NAME) return Value(Null{});
        error(version() >= 2 ? gl::INVALID_OPERATION : gl::INVALID_ENUM, call, "nothing is attached there");
        return Value(Null{});
    }
    if (pname == gl::FRAMEBUFFER_ATTACHMENT_OBJECT_NAME)
        return a->texture ? object_value(a->texture) : object_value(a->renderbuffer);
    if (a->texture) {
        switch (pname) {
            case gl::FRAMEBUFFER_ATTACHMENT_TEXTURE_LEVEL: return Value(int64_t(a->level));
            case gl::FRAMEBUFFER_ATTACHMENT_TEXTURE_CUBE_MAP_FACE:
                return Value(int64_t(a->texture->target == gl::TEXTURE_CUBE_MAP ? gl::TEXTURE_CUBE_MAP_POSITIVE_X + uint32_t(a->face) : 0));
            default: break;
        }
        if (version() >= 2 && pname == gl::FRAMEBUFFER_ATTACHMENT_TEXTURE_LAYER) return Value(int64_t(a->layer));
    }
    if (version() >= 2) {
        const Image* img = a->image();
        const FormatInfo* f = img ? img->format : nullptr;
        auto bits = [&](int c) -> int64_t { return f && f->kind() != SampleKind::Depth ? f->bits[size_t(c)] : 0; };
        switch (pname) {
            case gl::FRAMEBUFFER_ATTACHMENT_RED_SIZE: return Value(bits(0));
            case gl::FRAMEBUFFER_ATTACHMENT_GREEN_SIZE: return Value(bits(1));
            case gl::FRAMEBUFFER_ATTACHMENT_BLUE_SIZE: return Value(bits(2));
            case gl::FRAMEBUFFER_ATTACHMENT_ALPHA_SIZE: return Value(bits(3));
            case gl::FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE: return Value(int64_t(f ? f->depth_bits() : 0));
            case gl::FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE: return Value(int64_t(f && f->has_stencil ? 8 : 0));
            case gl::FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE: {
                if (both) { error(gl::INVALID_OPERATION, call, "ask DEPTH or STENCIL for the component type"); return Value(Null{}); }
                if (!f) return Value(int64_t(gl::NONE));
                GLenum t = gl::UNSIGNED_NORMALIZED;
                if (f->encoding == Encoding::Int) t = gl::INT;
                else if (f->encoding == Encoding::Uint || (attachment == gl::STENCIL_ATTACHMENT)) t = gl::UNSIGNED_INT;
                else if (f->is_float() || f->encoding == Encoding::Depth32F) t = gl::FLOAT;
                else if (f->encoding == Encoding::Snorm) t = gl::SIGNED_NORMALIZED;
                return Value(int64_t(t));
            }
            case gl::FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING:
                return Value(int64_t(f && f->encoding == Encoding::Srgb ? gl::SRGB : gl::LINEAR));
            default: break;
        }
    }
    error(gl::INVALID_ENUM, call, quote(pname) + " is not an attachment parameter here");
    return Value(Null{});
}

// ---------------------------------------------------------------------------- drawing into FBOs

RenderTarget Context::draw_target() {
    if (!draw_framebuffer_) return RenderTarget::for_default(framebuffer_);
    Framebuffer& fb = *draw_framebuffer_;
    std::array<RenderTarget::Color, RenderTarget::kMaxColors> colors{};
    int32_t w = -1, h = -1, samples = 1;
    auto extent = [&](const Attachment& a) {
        const Image* img = a.image();
        if (!img) return;
        w = w < 0 ? img->width : std::min(w, img->width);
        h = h < 0 ? img->height : std::min(h, img->height);
        samples = img->samples;
    };
    for (const Attachment& a : fb.color) extent(a);
    extent(fb.depth);
    extent(fb.stencil);
    for (int i = 0; i < RenderTarget::kMaxColors; ++i) {
        const GLenum b = fb.draw_buffers[size_t(i)];
        if (b < gl::COLOR_ATTACHMENT0 || b >= gl::COLOR_ATTACHMENT0 + uint32_t(kMaxColorAttachments)) continue;
        const Attachment& a = fb.color[b - gl::COLOR_ATTACHMENT0];
        if (Image* img = a.image()) colors[size_t(i)] = {img, layer_offset(*img, a.layer)};
    }
    Image* depth = fb.depth.image();
    Image* stencil = fb.stencil.image();
    return RenderTarget::for_images(std::max(w, 0), std::max(h, 0), samples, colors, depth,
                                    depth ? layer_offset(*depth, fb.depth.layer) : 0, stencil,
                                    stencil ? layer_offset(*stencil, fb.stencil.layer) : 0);
}

bool Context::check_draw_framebuffer(const char* call, const uint32_t used_units[4]) {
    if (!draw_framebuffer_) return true;
    std::string why;
    if (framebuffer_status(*draw_framebuffer_, &why) != gl::FRAMEBUFFER_COMPLETE) {
        error(gl::INVALID_FRAMEBUFFER_OPERATION, call, "the draw framebuffer is incomplete: " + why);
        return false;
    }
    // WebGL 1.0 §6.26: a texture level that is both sampled and attached is a feedback loop.
    const Framebuffer& fb = *draw_framebuffer_;
    for (int dim = 0; dim < 4; ++dim)
        for (int unit = 0; unit < kSamplerUnits; ++unit) {
            if (!(used_units[dim] & (1u << unit))) continue;
            const BoundTexture& bt = draw_sampler_.units[size_t(unit)][size_t(dim)];
            if (!bt.texture) continue;
            auto loops = [&](const Attachment& a) {
                return a.texture.get() == bt.texture && a.level >= bt.base && a.level <= bt.q;
            };
            bool loop = loops(fb.depth) || loops(fb.stencil);
            for (const Attachment& a : fb.color) loop = loop || loops(a);
            if (loop) {
                error(gl::INVALID_OPERATION, call, "feedback loop: texture unit " + std::to_string(unit) +
                      " samples a texture attached to the draw framebuffer");
                return false;
            }
        }
    for (const Attachment& a : fb.color) if (a.texture) ++a.texture->generation;   // the draw writes them
    return true;
}

bool Context::clear_framebuffer_object(uint32_t mask) {
    if (!draw_framebuffer_) return false;
    std::string why;
    if (framebuffer_status(*draw_framebuffer_, &why) != gl::FRAMEBUFFER_COMPLETE) {
        error(gl::INVALID_FRAMEBUFFER_OPERATION, "clear", "the draw framebuffer is incomplete: " + why);
        return true;
    }
    RenderTarget target = draw_target();
    Framebuffer& fb = *draw_framebuffer_;
    Rect r{0, 0, target.width(), target.height()};
    if (state_.scissor_test) {
        const int64_t x0 = std::max<int64_t>(state_.scissor.x, 0), y0 = std::max<int64_t>(state_.scissor.y, 0);
        const int64_t x1 = std::min<int64_t>(int64_t(state_.scissor.x) + state_.scissor.width, target.width());
        const int64_t y1 = std::min<int64_t>(int64_t(state_.scissor.y) + state_.scissor.height, target.height());
        r = Rect{int32_t(x0), int32_t(y0), int32_t(std::max<int64_t>(0, x1 - x0)), int32_t(std::max<int64_t>(0, y1 - y0))};
    }
    if (mask & gl::COLOR_BUFFER_BIT) {
        for (int i = 0; i < kMaxColorAttachments; ++i) {
            const GLenum b = fb.draw_buffers[size_t(i)];
            if (b < gl::COLOR_ATTACHMENT0 || b >= gl::COLOR_ATTACHMENT0 + uint32_t(kMaxColorAttachments)) continue;
            const Attachment& a = fb.color[b - gl::COLOR_ATTACHMENT0];
            Image* img = a.image();
            // ES 3.0 §4.2.3: clearing integer buffers with clear() is undefined; softgl leaves them.
            if (!img || img->format->is_integer()) continue;
            clear_image_color(*img, layer_offset(*img, a.layer), r, state_.clear_color.data(), state_.color_mask);
            ++(a.texture ? a.texture->generation : a.renderbuffer->generation);
        }
    }
    if ((mask & gl::DEPTH_BUFFER_BIT) && state_.depth_mask && target.config().depth)
        clear_image_depth(*target.depth_image(), target.depth_offset(), r, target.depth_word(state_.clear_depth));
    if ((mask & gl::STENCIL_BUFFER_BIT) && target.config().stencil)
        clear_image_stencil(*target.stencil_image(), target.stencil_offset(), r,
                            uint8_t(uint32_t(state_.clear_stencil) & 0xFFu), uint8_t(state_.stencil_front.write_mask & 0xFFu));
    return true;
}

// ---------------------------------------------------------------------------- reading

// The colour buffer readPixels / copyTexImage / blit read from: false (error recorded) if none.
bool Context::read_source(const char* call, ColorReadSource& out) {
    out = ColorReadSource{};
    if (!read_framebuffer_) {
        out.fb = &framebuffer_;
        out.width = framebuffer_.width();
        out.height = framebuffer_.height();
        return true;
    }
    std::string why;
    if (framebuffer_status(*read_framebuffer_, &why) != gl::FRAMEBUFFER_COMPLETE) {
        error(gl::INVALID_FRAMEBUFFER_OPERATION, call, "the read framebuffer is incomplete: " + why);
        return false;
    }
    const GLenum rb = read_framebuffer_->read_buffer;
    if (rb == gl::NONE) { error(gl::INVALID_OPERATION, call, "the read buffer is NONE"); return false; }
    const Attachment& a = read_framebuffer_->color[rb - gl::COLOR_ATTACHMENT0];
    Image* img = a.image();
    if (!img) { error(gl::INVALID_OPERATION, call, "nothing is attached to the read buffer"); return false; }
    out.img = img;
    out.offset = layer_offset(*img, a.layer);
    out.width = img->width;
    out.height = img->height;
    return true;
}

bool Context::read_pixels_framebuffer_object(int32_t x, int32_t y, int32_t width, int32_t height, GLenum format,
                                             GLenum type, GLenum dst_type, uint8_t* dst, size_t dst_bytes, bool packed) {
    const char* call = "readPixels";
    ColorReadSource src;
    if (!read_source(call, src)) return false;
    if (width < 0 || height < 0) { error(gl::INVALID_VALUE, call, "width and height must not be negative"); return false; }
    const Image& img = *src.img;
    if (img.samples > 1) { error(gl::INVALID_OPERATION, call, "the read framebuffer is multisampled"); return false; }
    const FormatInfo& f = *img.format;
    // ES 3.0 §4.3.2: RGBA with UNSIGNED_BYTE (normalized), FLOAT (float), INT/UNSIGNED_INT (integer).
    GLenum want_format = gl::RGBA, want_type = gl::UNSIGNED_BYTE;
    if (f.is_float()) want_type = gl::FLOAT;
    if (f.encoding == Encoding::Int) want_format = gl::RGBA_INTEGER, want_type = gl::INT;
    if (f.encoding == Encoding::Uint) want_format = gl::RGBA_INTEGER, want_type = gl::UNSIGNED_INT;
    if (format != want_format || type != want_type) {
        error(gl::INVALID_OPERATION, call, quote(format) + "/" + quote(type) + " cannot be read from a " +
              quote(f.internal_format) + " attachment; use " + quote(want_format) + "/" + quote(want_type));
        return false;
    }
    const GLenum array_type = type == gl::FLOAT ? gl::FLOAT : type == gl::INT ? gl::INT : type == gl::UNSIGNED_INT ? gl::UNSIGNED_INT : gl::UNSIGNED_BYTE;
    if (dst_type != array_type) { error(gl::INVALID_OPERATION, call, "the destination array's element type does not match " + quote(type)); return false; }
    const PixelStore& ps = state_.pixel_store;
    const int64_t pixel = type == gl::UNSIGNED_BYTE ? 4 : 16;
    const int64_t row_pixels = packed && ps.pack_row_length > 0 ? ps.pack_row_length : width;
    const int64_t align = packed ? ps.pack_alignment : 1;
    const int64_t stride = (row_pixels * pixel + align - 1) / align * align;
    const int64_t skip_rows = packed ? ps.pack_skip_rows : 0, skip_pixels = packed ? ps.pack_skip_pixels : 0;
    if (packed && ps.pack_row_length > 0 && skip_pixels + width > ps.pack_row_length) {
        error(gl::INVALID_OPERATION, call, "PACK_SKIP_PIXELS + width exceeds PACK_ROW_LENGTH"); return false;
    }
    const uint64_t needed = width && height ? uint64_t((skip_rows + height - 1) * stride + (skip_pixels + width) * pixel) : 0;
    if (dst_bytes < needed) {
        error(gl::INVALID_OPERATION, call, "the destination holds " + std::to_string(dst_bytes) + " bytes, " +
              std::to_string(needed) + " are needed");
        return false;
    }
    for (int32_t row = 0; row < height; ++row) {
        const int64_t sy = int64_t(y) + row;
        if (sy < 0 || sy >= src.height) continue;
        if (img.bytes() && type == gl::UNSIGNED_BYTE) {
            // Byte storage reads back as it is (float_to_unorm8(k / 255) is k).
            const int64_t x0 = std::max<int64_t>(x, 0), x1 = std::min<int64_t>(int64_t(x) + width, src.width);
            if (x0 < x1)
                std::memcpy(dst + (skip_rows + row) * stride + (skip_pixels + x0 - x) * pixel,
                            &img.rgba8[src.offset + size_t(sy) * size_t(img.width) + size_t(x0)], size_t(x1 - x0) * 4);
            continue;
        }
        for (int32_t col = 0; col < width; ++col) {
            const int64_t sx = int64_t(x) + col;
            if (sx < 0 || sx >= src.width) continue;   // outside the buffer: left as it is
            uint8_t* out = dst + (skip_rows + row) * stride + (skip_pixels + col) * pixel;
            const size_t t = src.offset + size_t(sy) * size_t(img.width) + size_t(sx);
            if (f.is_integer()) {
                uint32_t bits[4];
                img.read_integer(t, bits);
                std::memcpy(out, bits, 16);
            } else if (type == gl::FLOAT) {
                float v[4];
                img.read_color(t, v);
                std::memcpy(out, v, 16);
            } else {
                float texel[4];
                img.read_color(t, texel);
                for (int c = 0; c < 4; ++c) {
                    float v = texel[c];
                    // ES 3.0 §4.3.2: sRGB values are returned encoded (no conversion on read).
                    if (f.encoding == Encoding::Srgb && c < 3) v = linear_to_srgb(v);
                    out[c] = float_to_unorm8(v);
                }
            }
        }
    }
    return true;
}

// ---------------------------------------------------------------------------- copyTexImage

void Context::copy_tex_image_2d(GLenum target, int32_t level, GLenum internal_format, int32_t x, int32_t y,
                                int32_t width, int32_t height, int32_t border) {
    const char* call = "copyTexImage2D";
    if (target != gl::TEXTURE_2D && !is_cube_face(target)) return error(gl::INVALID_ENUM, call, quote(target) + " is not a 2D image target");
    int face = 0;
    Texture* t = bound_texture(call, target, &face);
    if (!t) return;
    if (level < 0 || level > 14) return error(gl::INVALID_VALUE, call, "level is out of range");
    if (width < 0 || height < 0 || width > (limits::kMaxTextureSize >> level) || height > (limits::kMaxTextureSize >> level))
        return error(gl::INVALID_VALUE, call, "the size is out of range");
    if (border != 0) return error(gl::INVALID_VALUE, call, "border must be 0");
    if (is_cube_face(target) && width != height) return error(gl::INVALID_VALUE, call, "cube map faces must be square");
    if (version() == 1 && level > 0 && (!is_power_of_two(width) || !is_power_of_two(height)))
        return error(gl::INVALID_VALUE, call, "levels above 0 must have power-of-two sizes in WebGL 1");
    if (t->immutable) return error(gl::INVALID_OPERATION, call, "the texture is immutable");
    // ES 3.0 table 3.15: the internal format from the read buffer (unsized: by base format).
    GLenum effective = 0;
    switch (internal_format) {
        case gl::RGBA: effective = gl::RGBA8; break;
        case gl::RGB: effective = gl::RGB8; break;
        case gl::LUMINANCE_ALPHA: effective = LUMINANCE8_ALPHA8; break;
        case gl::LUMINANCE: effective = LUMINANCE8; break;
        case gl::ALPHA: effective = ALPHA8; break;
        default:
            if (version() >= 2) {
                const FormatInfo* fi = format_info(internal_format);
                if (fi && fi->kind() == SampleKind::Float && !is_pseudo_format(internal_format)) effective = internal_format;
            }
    }
    if (!effective) return error(gl::INVALID_ENUM, call, quote(internal_format) + " cannot be a copyTexImage2D format");
    ColorReadSource src;
    if (!read_source(call, src)) return;
    if (src.img && src.img->samples > 1) return error(gl::INVALID_OPERATION, call, "the read framebuffer is multisampled");
    if (src.img && src.img->format->is_integer()) return error(gl::INVALID_OPERATION, call, "integer read buffers cannot be copied");
    const FormatInfo* fi = format_info(effective);
    // ES 2.0 §3.7.2: the new format's components must exist in the read buffer (alpha).
    const bool src_alpha = src.fb ? src.fb->config().alpha : src.img->format->bits[3] != 0;
    if (fi->bits[3] && !src_alpha) return error(gl::INVALID_OPERATION, call, "the read buffer has no alpha");
    // Charged (core/memory_ledger.h) before allocating; the old image stays if either fails.
    const Image* old = t->find(face, level);
    const uint64_t bytes = Image::allocation_bytes(fi, width, height, 1, 1);
    const uint64_t before = t->memory.bytes(), released = old ? old->storage_bytes() : 0;
    if (!t->memory.resize(before - std::min(before, released) + bytes))
        return error(gl::OUT_OF_MEMORY, call, "a " + std::to_string(width) + "x" + std::to_string(height) +
                     " image needs " + std::to_string(bytes) + " bytes, which " +
                     t->memory.over_limit(bytes - std::min(bytes, released)));
    Image fresh;
    try {
        fresh.allocate(fi, width, height, 1);
    } catch (const std::bad_alloc&) {
        t->memory.force(before);
        return error(gl::OUT_OF_MEMORY, call, "could not allocate " + std::to_string(bytes) + " bytes");
    }
    ColorSource cs{src.fb, src.img, src.offset, src.width, src.height};
    for (int32_t row = 0; row < height; ++row)
        for (int32_t col = 0; col < width; ++col) {
            const int64_t sx = int64_t(x) + col, sy = int64_t(y) + row;
            // WebGL 1.0 §5.14.8: texels outside the read buffer are 0.
            float rgba[4] = {0, 0, 0, 0};
            if (sx >= 0 && sy >= 0 && sx < src.width && sy < src.height) cs.read(int32_t(sx), int32_t(sy), rgba);
            else if (!fi->bits[3]) rgba[3] = 1;
            float stored[4];
            if (fi->base_format == gl::LUMINANCE || fi->base_format == gl::LUMINANCE_ALPHA) rgba[1] = rgba[2] = rgba[0];
            if (fi->base_format == gl::ALPHA) rgba[0] = rgba[1] = rgba[2] = 0;
            const size_t at = size_t(row) * size_t(width) + size_t(col);
            if (fresh.bytes()) {
                fresh.rgba8[at] = quantize_unorm8(*fi, rgba);
                continue;
            }
            quantize_color(*fi, rgba, stored);
            fresh.store_color(at, stored);
        }
    t->image(face, level) = std::move(fresh);
    ++t->generation;
}

void Context::copy_tex_sub_image(const char* call, GLenum target, int32_t level, int32_t xoffset, int32_t yoffset,
                                 int32_t zoffset, int32_t x, int32_t y, int32_t width, int32_t height) {
    const bool three_d = std::string(call).find("3D") != std::string::npos;
    const bool target_ok = three_d ? (target == gl::TEXTURE_3D || target == gl::TEXTURE_2D_ARRAY)
                                   : (target == gl::TEXTURE_2D || is_cube_face(target));
    if (!target_ok) return error(gl::INVALID_ENUM, call, quote(target) + " is not a target of " + call);
    int face = 0;
    Texture* t = bound_texture(call, target, &face);
    if (!t) return;
    if (level < 0 || xoffset < 0 || yoffset < 0 || zoffset < 0 || width < 0 || height < 0)
        return error(gl::INVALID_VALUE, call, "level, offsets and sizes must not be negative");
    Image* img = const_cast<Image*>(t->find(face, level));
    if (!img) return error(gl::INVALID_OPERATION, call, "the level has no image");
    if (int64_t(xoffset) + width > img->width || int64_t(yoffset) + height > img->height || zoffset >= img->depth)
        return error(gl::INVALID_VALUE, call, "the region extends past the image");
    if (img->format->kind() != SampleKind::Float) return error(gl::INVALID_OPERATION, call, "the texture format cannot be copied into");
    ColorReadSource src;
    if (!read_source(call, src)) return;
    if (src.img && src.img->samples > 1) return error(gl::INVALID_OPERATION, call, "the read framebuffer is multisampled");
    if (src.img && src.img->format->is_integer()) return error(gl::INVALID_OPERATION, call, "integer read buffers cannot be copied");
    if (src.img && src.img == img) {
        // Copying a level into itself is a feedback loop (WebGL 1.0 §6.26).
        return error(gl::INVALID_OPERATION, call, "the texture level is the read buffer");
    }
    ColorSource cs{src.fb, src.img, src.offset, src.width, src.height};
    const FormatInfo& fi = *img->format;
    for (int32_t row = 0; row < height; ++row)
        for (int32_t col = 0; col < width; ++col) {
            const int64_t sx = int64_t(x) + col, sy = int64_t(y) + row;
            // WebGL 1.0 §5.14.8: texels whose source lies outside the read buffer are left unchanged... in
            // WebGL they are set to 0; softgl does the same.
            float rgba[4] = {0, 0, 0, 0};
            if (sx >= 0 && sy >= 0 && sx < src.width && sy < src.height) cs.read(int32_t(sx), int32_t(sy), rgba);
            if (fi.base_format == gl::LUMINANCE || fi.base_format == gl::LUMINANCE_ALPHA) rgba[1] = rgba[2] = rgba[0];
            const size_t tt = (size_t(zoffset) * size_t(img->height) + size_t(yoffset + row)) * size_t(img->width) + size_t(xoffset + col);
            if (img->bytes()) {
                img->rgba8[tt] = quantize_unorm8(fi, rgba);
                continue;
            }
            float stored[4];
            quantize_color(fi, rgba, stored);
            img->store_color(tt, stored);
        }
    ++t->generation;
}

// ---------------------------------------------------------------------------- WebGL 2 framebuffer ops

void Context::read_buffer(GLenum src) {
    const char* call = "readBuffer";
    if (!read_framebuffer_) {
        if (src != gl::BACK && src != gl::NONE) {
            const bool attachment = src >= gl::COLOR_ATTACHMENT0 && src < gl::COLOR_ATTACHMENT0 + 32;
            return error(attachment ? gl::INVALID_OPERATION : gl::INVALID_ENUM, call, "the default framebuffer reads BACK or NONE");
        }
        default_read_buffer_ = src;
        return;
    }
    if (src == gl::BACK) return error(gl::INVALID_OPERATION, call, "BACK is for the default framebuffer");
    if (src != gl::NONE && (src < gl::COLOR_ATTACHMENT0 || src >= gl::COLOR_ATTACHMENT0 + uint32_t(kMaxColorAttachments)))
        return error(gl::INVALID_ENUM, call, quote(src) + " is not a read buffer");
    read_framebuffer_->read_buffer = src;
}

void Context::clear_buffer(const char* call, GLenum buffer, int32_t drawbuffer, char kind, const void* values,
                           size_t count, float depth, int32_t stencil) {
    // ES 3.0 §4.2.3: ClearBuffer* clear one buffer, with the scissor and masks, no other ops.
    RenderTarget target = draw_target();
    size_t needed = buffer == gl::COLOR ? 4 : 1;
    if (buffer == gl::DEPTH_STENCIL) needed = 0;
    switch (buffer) {
        case gl::COLOR:
            if (kind == 's') return error(gl::INVALID_ENUM, call, "COLOR is not a buffer of clearBufferfi");
            if (drawbuffer < 0 || drawbuffer >= kMaxColorAttachments) return error(gl::INVALID_VALUE, call, "drawbuffer is out of range");
            break;
        case gl::DEPTH:
            if (kind != 'f') return error(gl::INVALID_ENUM, call, "DEPTH is cleared with clearBufferfv");
            if (drawbuffer != 0) return error(gl::INVALID_VALUE, call, "drawbuffer must be 0");
            break;
        case gl::STENCIL:
            if (kind != 'i') return error(gl::INVALID_ENUM, call, "STENCIL is cleared with clearBufferiv");
            if (drawbuffer != 0) return error(gl::INVALID_VALUE, call, "drawbuffer must be 0");
            break;
        case gl::DEPTH_STENCIL:
            if (kind != 's') return error(gl::INVALID_ENUM, call, "DEPTH_STENCIL is cleared with clearBufferfi");
            if (drawbuffer != 0) return error(gl::INVALID_VALUE, call, "drawbuffer must be 0");
            break;
        default: return error(gl::INVALID_ENUM, call, quote(buffer) + " is not a clearBuffer buffer");
    }
    if (count < needed) return error(gl::INVALID_VALUE, call, "needs " + std::to_string(needed) + " values");
    if (draw_framebuffer_) {
        std::string why;
        if (framebuffer_status(*draw_framebuffer_, &why) != gl::FRAMEBUFFER_COMPLETE)
            return error(gl::INVALID_FRAMEBUFFER_OPERATION, call, "the draw framebuffer is incomplete: " + why);
    }
    if (state_.rasterizer_discard) return;
    Rect r{0, 0, target.width(), target.height()};
    if (state_.scissor_test) {
        const int64_t x0 = std::max<int64_t>(state_.scissor.x, 0), y0 = std::max<int64_t>(state_.scissor.y, 0);
        const int64_t x1 = std::min<int64_t>(int64_t(state_.scissor.x) + state_.scissor.width, target.width());
        const int64_t y1 = std::min<int64_t>(int64_t(state_.scissor.y) + state_.scissor.height, target.height());
        r = Rect{int32_t(x0), int32_t(y0), int32_t(std::max<int64_t>(0, x1 - x0)), int32_t(std::max<int64_t>(0, y1 - y0))};
    }
    const int S = target.config().samples;
    if (buffer == gl::COLOR) {
        if (!draw_framebuffer_) {
            if (drawbuffer != 0 || default_draw_buffer_ == gl::NONE) return;   // only draw buffer 0 (BACK) exists
            if (kind != 'f') return error(gl::INVALID_OPERATION, call, "the drawing buffer is cleared with clearBufferfv");
            const float* v = static_cast<const float*>(values);
            return framebuffer_.clear_color(r, {v[0], v[1], v[2], v[3]}, state_.color_mask);
        }
        const GLenum b = draw_framebuffer_->draw_buffers[size_t(drawbuffer)];
        if (b < gl::COLOR_ATTACHMENT0 || b >= gl::COLOR_ATTACHMENT0 + uint32_t(kMaxColorAttachments)) return;
        const Attachment& a = draw_framebuffer_->color[b - gl::COLOR_ATTACHMENT0];
        Image* img = a.image();
        if (!img) return;
        const FormatInfo& f = *img->format;
        const char wanted = f.encoding == Encoding::Int ? 'i' : f.encoding == Encoding::Uint ? 'u' : 'f';
        if (kind != wanted)
            return error(gl::INVALID_OPERATION, call, "the buffer's format needs clearBuffer" + std::string(wanted == 'f' ? "fv" : wanted == 'i' ? "iv" : "uiv"));
        float rgba[4];
        std::memcpy(rgba, values, 16);   // float values, or integer bits for write_image_color
        clear_image_color(*img, layer_offset(*img, a.layer), r, rgba, state_.color_mask);
        ++(a.texture ? a.texture->generation : a.renderbuffer->generation);
        return;
    }
    const bool do_depth = buffer == gl::DEPTH || buffer == gl::DEPTH_STENCIL;
    const bool do_stencil = buffer == gl::STENCIL || buffer == gl::DEPTH_STENCIL;
    if (do_depth && state_.depth_mask && target.config().depth) {
        const float d = buffer == gl::DEPTH ? static_cast<const float*>(values)[0] : depth;
        const uint32_t word = target.depth_word(clamp01(d));
        // A row's samples are contiguous in the drawing buffer and in an image alike.
        for (int32_t y = r.y; y < r.y + r.height && r.width > 0; ++y)
            std::fill_n(target.depth_samples(r.x, y), size_t(r.width) * size_t(S), word);
    }
    if (do_stencil && target.config().stencil) {
        const int32_t sv = buffer == gl::STENCIL ? static_cast<const int32_t*>(values)[0] : stencil;
        const uint8_t bits = uint8_t(uint32_t(sv) & 0xFFu), wm = uint8_t(state_.stencil_front.write_mask & 0xFFu);
        for (int32_t y = r.y; y < r.y + r.height && r.width > 0; ++y) {
            uint8_t* p = target.stencil_samples(r.x, y);
            for (size_t i = 0; i < size_t(r.width) * size_t(S); ++i) p[i] = uint8_t((p[i] & ~wm) | (bits & wm));
        }
    }
}

namespace {

// The colour half of a blit: where it reads and which images it writes (ES 3.0 §4.3.3).
struct BlitColor {
    ColorSource source;
    DefaultFramebuffer* drawing_buffer = nullptr;          // written when it is the draw framebuffer
    std::vector<std::pair<Image*, size_t>> images;         // attached images written, at their layer
    bool writes() const { return drawing_buffer || !images.empty(); }
    void write(int32_t x, int32_t y, const float rgba[4]) const {
        const std::array<bool, 4> all_channels{true, true, true, true};
        if (drawing_buffer) write_plain(drawing_buffer, nullptr, 0, x, y, rgba, all_channels);
        for (const auto& d : images) write_plain(nullptr, d.first, d.second, x, y, rgba, all_channels);
    }
};

// Picks the colour source (the read buffer) and destinations (the draw buffers) of a blit into
// `out`; returns why the blit is an INVALID_OPERATION ("" if it is not). Without a source
// image nothing is written.
std::string blit_color_targets(const Framebuffer* read, const Framebuffer* draw, DefaultFramebuffer& drawing_buffer,
                               GLenum filter, BlitColor& out) {
    bool have_source = true;
    if (read) {
        const GLenum rb = read->read_buffer;
        const Attachment* a = rb == gl::NONE ? nullptr : &read->color[rb - gl::COLOR_ATTACHMENT0];
        Image* img = a ? a->image() : nullptr;
        if (!img) have_source = false;
        else out.source = ColorSource{nullptr, img, layer_offset(*img, a->layer), img->width, img->height};
    } else {
        out.source = ColorSource{&drawing_buffer, nullptr, 0, drawing_buffer.width(), drawing_buffer.height()};
    }
    if (!draw) {
        out.drawing_buffer = &drawing_buffer;
    } else {
        for (GLenum b : draw->draw_buffers) {
            if (b < gl::COLOR_ATTACHMENT0 || b >= gl::COLOR_ATTACHMENT0 + uint32_t(kMaxColorAttachments)) continue;
            const Attachment& a = draw->color[b - gl::COLOR_ATTACHMENT0];
            if (Image* img = a.image()) out.images.push_back({img, layer_offset(*img, a.layer)});
            if (a.texture) ++a.texture->generation;   // the blit writes it
        }
    }
    if (!have_source) {
        out.images.clear();
        out.drawing_buffer = nullptr;
        return "";
    }
    const bool src_int = out.source.img && out.source.img->format->is_integer();
    for (const auto& d : out.images) {
        if (d.first->format->is_integer() != src_int) return "integer and non-integer colour buffers cannot be blitted together";
        if (d.first == out.source.img) return "the source and destination images are the same";
    }
    if (out.drawing_buffer && src_int) return "integer buffers cannot be blitted to the drawing buffer";
    if (src_int && filter == gl::LINEAR) return "integer buffers must be blitted with NEAREST";
    return "";
}

// The colour a blit reads at (u, v) in source pixels into `rgba`; false when (u, v) lies outside
// the source (nothing is written there).
bool blit_read_color(const ColorSource& cs, double u, double v, GLenum filter, float rgba[4]) {
    if (filter == gl::NEAREST) {
        const int64_t ix = int64_t(std::floor(u)), iy = int64_t(std::floor(v));
        const bool inside = ix >= 0 && iy >= 0 && ix < cs.width && iy < cs.height;
        if (inside) cs.read(int32_t(ix), int32_t(iy), rgba);
        return inside;
    }
    // Bilinear with the source clamped to its edges.
    const double uu = u - 0.5, vv = v - 0.5;
    const int64_t i0 = int64_t(std::floor(uu)), j0 = int64_t(std::floor(vv));
    const float a = float(uu - std::floor(uu)), b = float(vv - std::floor(vv));
    const bool inside = std::floor(u) >= 0 && std::floor(v) >= 0 && std::floor(u) < cs.width && std::floor(v) < cs.height;
    float t[4][4];
    for (int k = 0; k < 4; ++k) {
        const int32_t ix = int32_t(std::clamp<int64_t>(i0 + (k & 1), 0, cs.width - 1));
        const int32_t iy = int32_t(std::clamp<int64_t>(j0 + (k >> 1), 0, cs.height - 1));
        cs.read(ix, iy, t[k]);
    }
    for (int c = 0; c < 4; ++c)
        rgba[c] = (1 - a) * (1 - b) * t[0][c] + a * (1 - b) * t[1][c] + (1 - a) * b * t[2][c] + a * b * t[3][c];
    return inside;
}

// One side of the depth / stencil half of a blit. The drawing buffer's depth is 24-bit unorm
// and its stencil 8 bits, so it blits with DEPTH_COMPONENT24 / DEPTH24_STENCIL8 images.
struct DepthStencilSide {
    DefaultFramebuffer* fb = nullptr;   // the drawing buffer, or
    Image* depth = nullptr;             // the attached images (null: none)
    Image* stencil = nullptr;
    size_t depth_offset = 0, stencil_offset = 0;
    bool has_depth() const { return fb ? fb->config().depth : depth != nullptr; }
    bool has_stencil() const { return fb ? fb->config().stencil : stencil != nullptr; }
    Encoding depth_encoding() const { return fb ? Encoding::Depth24 : depth->format->encoding; }
    int32_t width() const { return fb ? fb->width() : depth ? depth->width : stencil ? stencil->width : 0; }
    int32_t height() const { return fb ? fb->height() : depth ? depth->height : stencil ? stencil->height : 0; }
    // Sample 0 of a multisampled source (ES 3.0 §4.3.3: depth/stencil resolves pick one sample).
    uint32_t depth_at(int64_t ix, int64_t iy) const {
        if (fb) return fb->depth_sample(int32_t(ix), int32_t(iy), 0);
        return depth->depth_words[depth_offset + (size_t(iy) * size_t(depth->width) + size_t(ix)) * size_t(depth->samples)];
    }
    uint8_t stencil_at(int64_t ix, int64_t iy) const {
        if (fb) return fb->stencil_sample(int32_t(ix), int32_t(iy), 0);
        return stencil->stencil[stencil_offset + (size_t(iy) * size_t(stencil->width) + size_t(ix)) * size_t(stencil->samples)];
    }
    // A destination is single-sampled (blit_framebuffer checks it) or the drawing buffer.
    void write_depth(int32_t x, int32_t y, uint32_t word) const {
        if (!fb) depth->depth_words[depth_offset + size_t(y) * size_t(depth->width) + size_t(x)] = word;
        else if (uint32_t* d = fb->depth_samples(x, y)) std::fill_n(d, fb->config().samples, word);
    }
    void write_stencil(int32_t x, int32_t y, uint8_t value) const {
        if (!fb) stencil->stencil[stencil_offset + size_t(y) * size_t(stencil->width) + size_t(x)] = value;
        else if (uint8_t* d = fb->stencil_samples(x, y)) std::fill_n(d, fb->config().samples, value);
    }
};

DepthStencilSide depth_stencil_side(const Framebuffer* f, DefaultFramebuffer& drawing_buffer) {
    DepthStencilSide d;
    if (!f) { d.fb = &drawing_buffer; return d; }
    if ((d.depth = f->depth.image())) d.depth_offset = layer_offset(*d.depth, f->depth.layer);
    if ((d.stencil = f->stencil.image())) d.stencil_offset = layer_offset(*d.stencil, f->stencil.layer);
    return d;
}

// Depth / stencil formats must match (ES 3.0 §4.3.3): why they do not ("" if they do).
std::string depth_stencil_mismatch(const DepthStencilSide& src, const DepthStencilSide& dst, bool depth, bool stencil) {
    if (depth) {
        const bool same = (src.fb || dst.fb) ? src.depth_encoding() == dst.depth_encoding()
                                             : src.depth->format == dst.depth->format;
        if (!same) return "the depth formats differ";
        if (!src.fb && src.depth == dst.depth) return "the source and destination images are the same";
    }
    if (stencil) {
        if (!src.fb && !dst.fb && src.stencil->format != dst.stencil->format) return "the stencil formats differ";
        if (!src.fb && src.stencil == dst.stencil) return "the source and destination images are the same";
    }
    return "";
}

// ---- the 1:1 blit (docs/architecture.md, "Fast paths")
// When both rectangles have the same signed extents (no scaling, no flip), the general loop's
// source position for destination pixel (x, y) is exactly (x + ox + 0.5, y + oy + 0.5): NEAREST
// reads pixel (x + ox, y + oy), and so does LINEAR, whose weights are then (1, 0, 0, 0) (for
// finite, non-negative sources: 0 * t is +0 and t + 0 is t). The rows below do the general
// loop's arithmetic on that pixel without the doubles, the filter and the per-pixel dispatch.
struct BlitRows {
    int64_t ox = 0, oy = 0;            // source pixel = destination pixel + (ox, oy)
    int64_t x0 = 0, x1 = 0, y0 = 0, y1 = 0;   // destination pixels whose source pixel is inside
};

// Whether this blit can take the rows: a 1:1 copy (possibly a resolve) whose colour source is an
// attached image distinct from every destination (a drawing-buffer source goes the general way),
// LINEAR only for sources without negative zeros, infinities or NaNs (unorm and sRGB formats).
bool blit_rows_apply(const BlitColor& color, GLenum filter, int64_t sx0, int64_t sy0, int64_t sx1, int64_t sy1,
                     int64_t dx0, int64_t dy0, int64_t dx1, int64_t dy1) {
    if (sx1 - sx0 != dx1 - dx0 || sy1 - sy0 != dy1 - dy0) return false;
    if (!color.writes()) return true;
    const Image* src = color.source.img;
    if (!src) return false;
    if (filter == gl::LINEAR && src->format->encoding != Encoding::Unorm && src->format->encoding != Encoding::Srgb)
        return false;
    if (color.drawing_buffer && color.drawing_buffer->config().samples != 1) return false;
    for (const auto& d : color.images)
        if (d.first->samples != 1) return false;
    return true;
}

// unorm(k, 8) = k / 255 as float for every byte k.
const std::array<float, 256>& unorm8_values() {
    static const std::array<float, 256> values = [] {
        std::array<float, 256> v{};
        for (uint32_t k = 0; k < 256; ++k) v[k] = float(k) / 255.0f;
        return v;
    }();
    return values;
}

// Source row (iy, columns ix0 .. ix0 + n) of a colour image as float RGBA into `out`, resolved
// exactly as ColorSource::read does: the mean of the samples in double, in sample order
// (integer formats: sample 0's bits).
template <int S>
void resolve_row(const float* in, size_t n, float* out) {
    for (size_t i = 0; i < n; ++i, in += 4 * S, out += 4)
        for (int c = 0; c < 4; ++c) {
            double sum = 0;
            for (int s = 0; s < S; ++s) sum += double(in[s * 4 + c]);
            out[c] = float(sum / double(S));
        }
}

// resolve_row of byte samples: each byte k read as the float k / 255 holds, summed in double.
template <int S>
void resolve_byte_row(const uint8_t* in, size_t n, float* out) {
    static const std::array<double, 256> value = [] {
        std::array<double, 256> v{};
        for (uint32_t k = 0; k < 256; ++k) v[k] = double(float(k) / 255.0f);
        return v;
    }();
#if defined(__SSE2__)
    (void)value;
    // The four channels at once: float(k) / 255.0f (correctly rounded, as the table), widened to
    // double and summed per channel in sample order: the same operations on the same values.
    const __m128i zero = _mm_setzero_si128();
    const __m128 k255 = _mm_set1_ps(255.0f);
    const __m128d count = _mm_set1_pd(double(S));
    for (size_t i = 0; i < n; ++i, in += 4 * S, out += 4) {
        __m128d lo = _mm_setzero_pd(), hi = _mm_setzero_pd();
        for (int s = 0; s < S; ++s) {
            int32_t word;
            std::memcpy(&word, in + 4 * s, 4);
            const __m128i k = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(word), zero), zero);
            const __m128 v = _mm_div_ps(_mm_cvtepi32_ps(k), k255);
            lo = _mm_add_pd(lo, _mm_cvtps_pd(v));
            hi = _mm_add_pd(hi, _mm_cvtps_pd(_mm_movehl_ps(v, v)));
        }
        _mm_storeu_ps(out, _mm_movelh_ps(_mm_cvtpd_ps(_mm_div_pd(lo, count)), _mm_cvtpd_ps(_mm_div_pd(hi, count))));
    }
#else
    for (size_t i = 0; i < n; ++i, in += 4 * S, out += 4) {
        double sum[4] = {0, 0, 0, 0};   // per channel, samples in order
        for (int s = 0; s < S; ++s)
            for (int c = 0; c < 4; ++c) sum[c] += value[in[s * 4 + c]];
        for (int c = 0; c < 4; ++c) out[c] = float(sum[c] / double(S));
    }
#endif
}

void read_source_row(const ColorSource& cs, int64_t ix0, int64_t iy, size_t n, float* out) {
    const Image& img = *cs.img;
    const size_t S = size_t(img.samples);
    const size_t t = cs.offset + (size_t(iy) * size_t(img.width) + size_t(ix0)) * S;
    if (!img.integer.empty()) {
        for (size_t i = 0; i < n; ++i) {
            uint32_t bits[4];
            img.read_integer(t + i * S, bits);
            std::memcpy(&out[i * 4], bits, 16);
        }
        return;
    }
    if (img.bytes()) {
        // The same floats (k / 255) and, for multisample sources, the same double means in sample
        // order as the float rows below.
        const uint8_t* in = reinterpret_cast<const uint8_t*>(&img.rgba8[t]);
        switch (S) {
            case 1: {
                const std::array<float, 256>& value = unorm8_values();
                for (size_t i = 0; i < n * 4; ++i) out[i] = value[in[i]];
                return;
            }
            case 2: return resolve_byte_row<2>(in, n, out);
            case 4: return resolve_byte_row<4>(in, n, out);
            case 8: return resolve_byte_row<8>(in, n, out);
            default:
                for (size_t i = 0; i < n; ++i, in += 4 * S, out += 4)
                    for (int c = 0; c < 4; ++c) {
                        double sum = 0;
                        for (size_t s = 0; s < S; ++s) sum += double(unorm8_values()[in[s * 4 + size_t(c)]]);
                        out[c] = float(sum / double(S));
                    }
                return;
        }
    }
    if (!img.narrow.empty() || !img.packed.empty() || img.color_channels() < 4) {
        // Image::narrow, Image::packed, or floats of fewer than 4 channels: each sample's floats (k / 255, or
        // read_color's with the absent channels' defaults), their mean in double in sample order.
        for (size_t i = 0; i < n; ++i) {
            double sum[4] = {0, 0, 0, 0};
            for (size_t s = 0; s < S; ++s) {
                float v[4];
                img.read_color(t + i * S + s, v);
                for (int c = 0; c < 4; ++c) sum[c] += double(v[c]);
            }
            for (int c = 0; c < 4; ++c) out[i * 4 + size_t(c)] = float(sum[c] / double(S));
        }
        return;
    }
    const float* in = &img.color[t * 4];
    switch (S) {
        case 1: return resolve_row<1>(in, n, out);
        case 2: return resolve_row<2>(in, n, out);
        case 4: return resolve_row<4>(in, n, out);
        case 8: return resolve_row<8>(in, n, out);
        default:
            for (size_t i = 0; i < n; ++i, in += 4 * S, out += 4)
                for (int c = 0; c < 4; ++c) {
                    double sum = 0;
                    for (size_t s = 0; s < S; ++s) sum += double(in[s * 4 + size_t(c)]);
                    out[c] = float(sum / double(S));
                }
    }
}

// float_to_unorm8 (surface/formats.h) with the floor as a truncation: the same byte, since
// v * 255 + 0.5 is positive wherever the floor is reached.
inline uint8_t unorm8_of(float v) {
    if (!(v > 0.0f)) return 0;
    if (v >= 1.0f) return 255;
    return uint8_t(uint32_t(double(v) * 255.0 + 0.5));
}

// Writes n float RGBA pixels at destination (x0, y) as the general loop's write_plain does.
void write_row(const BlitColor& color, int64_t x0, int64_t y, size_t n, const float* rgba) {
    if (DefaultFramebuffer* fb = color.drawing_buffer) {   // single-sampled (blit_rows_apply)
        const bool alpha = fb->config().alpha;
        if (!fb->is_float()) {
            uint8_t* p = fb->color_sample(int32_t(x0), int32_t(y), 0);
            for (size_t i = 0; i < n; ++i, p += 4, rgba += 4) {
                p[0] = unorm8_of(rgba[0]);
                p[1] = unorm8_of(rgba[1]);
                p[2] = unorm8_of(rgba[2]);
                if (alpha) p[3] = unorm8_of(rgba[3]);
            }
            rgba -= 4 * n;
        } else {
            float* p = fb->color_sample_f(int32_t(x0), int32_t(y), 0);
            for (size_t i = 0; i < n * 4; ++i)
                if (alpha || i % 4 != 3) p[i] = fb->quantize(rgba[i]);
        }
    }
    const BlendOp plain;   // blending off, every channel written
    for (const auto& d : color.images) {
        if (d.first->format->internal_format == gl::RGBA8) {
            // write_image_color's RGBA8 plain write: the bytes float_to_unorm8 gives.
            uint8_t* p = reinterpret_cast<uint8_t*>(
                &d.first->rgba8[d.second + size_t(y) * size_t(d.first->width) + size_t(x0)]);
            for (size_t i = 0; i < n * 4; ++i) p[i] = unorm8_of(rgba[i]);
            continue;
        }
        for (size_t i = 0; i < n; ++i)
            write_image_color(*d.first, d.second, plain, &rgba[i * 4], int32_t(x0 + int64_t(i)), int32_t(y), 0);
    }
}

// Whether a row can go from bytes to bytes (byte_row): a source in byte storage and only RGBA8
// destinations (the RGBA8 drawing buffer, RGBA8 images).
bool blit_bytes(const BlitColor& color) {
    const Image* src = color.source.img;
    if (!src || !src->integer.empty() || !src->bytes()) return false;
    if (color.drawing_buffer && color.drawing_buffer->is_float()) return false;
    for (const auto& d : color.images)
        if (d.first->format->internal_format != gl::RGBA8) return false;
    return true;
}

// read_source_row and write_row for blit_bytes, without the floats: the byte write_row would
// store for a channel is unorm8_of(float(Σ double(k_s / 255) / S)) over the samples' bytes k_s.
// Each k / 255 as a float is a multiple of 2^-31 in [0, 1], so the double sum of at most 16 is
// exact, and so is the division by S (a power of two): the value is Σk / 255S within 2^-25 (the
// floats' rounding), then within 2^-24 after the rounding to float; times 255, within 2^-16 of
// Σk / S, and unorm8_of computes floor(v * 255 + 0.5) exactly in double. Σk / S is a multiple of
// 1/S (S <= 16), so unless it lies exactly halfway between two integers that floor is the
// rounded mean resolve_rgba8 gives; the halfway pixels (resolve_rgba8's ties) take the float
// path, pixel by pixel.
void byte_row(const BlitColor& color, int64_t sx0, int64_t sy, int64_t x0, int64_t y, size_t n, uint8_t* rgba,
              uint32_t* ties) {
    const ColorSource& cs = color.source;
    const Image& img = *cs.img;
    const size_t t = cs.offset + (size_t(sy) * size_t(img.width) + size_t(sx0)) * size_t(img.samples);
    const size_t tie_count = resolve_rgba8(reinterpret_cast<const uint8_t*>(&img.rgba8[t]), img.samples, n, rgba, ties);
    for (size_t k = 0; k < tie_count; ++k) {
        float f[4];
        read_source_row(cs, sx0 + ties[k], sy, 1, f);
        for (int c = 0; c < 4; ++c) rgba[size_t(ties[k]) * 4 + size_t(c)] = unorm8_of(f[c]);
    }
    if (DefaultFramebuffer* fb = color.drawing_buffer) {   // single-sampled (blit_rows_apply)
        uint8_t* p = fb->color_sample(int32_t(x0), int32_t(y), 0);
        if (fb->config().alpha) std::memcpy(p, rgba, n * 4);
        else for (size_t i = 0; i < n; ++i) std::memcpy(p + 4 * i, rgba + 4 * i, 3);
    }
    for (const auto& d : color.images)
        std::memcpy(&d.first->rgba8[d.second + size_t(y) * size_t(d.first->width) + size_t(x0)], rgba, n * 4);
}

// One thread's row buffers for blit_rows, allocated before any row is written, so that an
// allocation failure (std::bad_alloc) leaves the destination as it was.
struct BlitRowBuffers {
    std::vector<float> row;
    std::vector<uint8_t> byte_pixels;
    std::vector<uint32_t> ties;
    BlitRowBuffers(const BlitRows& rc, const BlitColor& color) {
        const size_t width = size_t(std::max<int64_t>(rc.x1 - rc.x0, 0));
        const bool bytes = color.writes() && blit_bytes(color);
        row.resize(bytes ? 0 : width * 4);
        byte_pixels.resize(bytes ? width * 4 : 0);
        ties.resize(bytes ? width : 0);
    }
};

// Destination rows [y_begin, y_end) of a 1:1 blit: colour within `rc`, depth / stencil within
// `rd` (their sources may differ in size).
void blit_rows(const BlitRows& rc, const BlitRows& rd, const BlitColor& color, const DepthStencilSide& ds_src,
               const DepthStencilSide& ds_dst, bool depth, bool stencil, int64_t y_begin, int64_t y_end,
               BlitRowBuffers& buffers) {
    const bool bytes = color.writes() && blit_bytes(color);
    std::vector<float>& row = buffers.row;
    std::vector<uint8_t>& byte_pixels = buffers.byte_pixels;
    std::vector<uint32_t>& ties = buffers.ties;
    for (int64_t y = y_begin; y < y_end; ++y) {
        if (color.writes() && rc.x0 < rc.x1 && y >= rc.y0 && y < rc.y1) {
            const size_t n = size_t(rc.x1 - rc.x0);
            if (bytes) {
                byte_row(color, rc.x0 + rc.ox, y + rc.oy, rc.x0, y, n, byte_pixels.data(), ties.data());
            } else {
                read_source_row(color.source, rc.x0 + rc.ox, y + rc.oy, n, row.data());
                write_row(color, rc.x0, y, n, row.data());
            }
        }
        if ((depth || stencil) && y >= rd.y0 && y < rd.y1)
            for (int64_t x = rd.x0; x < rd.x1; ++x) {
                if (depth) ds_dst.write_depth(int32_t(x), int32_t(y), ds_src.depth_at(x + rd.ox, y + rd.oy));
                if (stencil) ds_dst.write_stencil(int32_t(x), int32_t(y), ds_src.stencil_at(x + rd.ox, y + rd.oy));
            }
    }
}

// The part of the clipped destination rectangle [cx0, cx1) x [cy0, cy1) whose source pixel,
// at offset (ox, oy), lies in a width x height source.
BlitRows blit_rows_within(int64_t cx0, int64_t cy0, int64_t cx1, int64_t cy1, int64_t ox, int64_t oy,
                          int64_t width, int64_t height) {
    BlitRows r;
    r.ox = ox, r.oy = oy;
    r.x0 = std::max(cx0, -ox), r.x1 = std::min(cx1, width - ox);
    r.y0 = std::max(cy0, -oy), r.y1 = std::min(cy1, height - oy);
    return r;
}

}  // namespace

void Context::blit_framebuffer(int32_t sx0, int32_t sy0, int32_t sx1, int32_t sy1, int32_t dx0, int32_t dy0,
                               int32_t dx1, int32_t dy1, uint32_t mask, GLenum filter) {
    const char* call = "blitFramebuffer";
    const uint32_t all = gl::COLOR_BUFFER_BIT | gl::DEPTH_BUFFER_BIT | gl::STENCIL_BUFFER_BIT;
    if (mask & ~all) return error(gl::INVALID_VALUE, call, "mask has unknown bits");
    if (filter != gl::NEAREST && filter != gl::LINEAR) return error(gl::INVALID_ENUM, call, quote(filter) + " is not a blit filter");
    if (filter == gl::LINEAR && (mask & (gl::DEPTH_BUFFER_BIT | gl::STENCIL_BUFFER_BIT)))
        return error(gl::INVALID_OPERATION, call, "depth and stencil blits must use NEAREST");
    std::string why;
    if (read_framebuffer_ && framebuffer_status(*read_framebuffer_, &why) != gl::FRAMEBUFFER_COMPLETE)
        return error(gl::INVALID_FRAMEBUFFER_OPERATION, call, "the read framebuffer is incomplete: " + why);
    if (draw_framebuffer_ && framebuffer_status(*draw_framebuffer_, &why) != gl::FRAMEBUFFER_COMPLETE)
        return error(gl::INVALID_FRAMEBUFFER_OPERATION, call, "the draw framebuffer is incomplete: " + why);
    RenderTarget dst = draw_target();
    const bool read_default = !read_framebuffer_;
    const int32_t read_samples = read_default ? framebuffer_.config().samples : [&] {
        for (const Attachment& a : read_framebuffer_->color) if (const Image* i = a.image()) return i->samples;
        if (const Image* i = read_framebuffer_->depth.image()) return i->samples;
        return 1;
    }();
    const bool scaled = std::abs(int64_t(sx1) - sx0) != std::abs(int64_t(dx1) - dx0) ||
                        std::abs(int64_t(sy1) - sy0) != std::abs(int64_t(dy1) - dy0);
    if (dst.config().samples > 1) return error(gl::INVALID_OPERATION, call, "the draw framebuffer is multisampled");
    if (read_samples > 1 && (scaled || sx0 != dx0 || sy0 != dy0 || sx1 != dx1 || sy1 != dy1))
        return error(gl::INVALID_OPERATION, call, "a multisample resolve needs identical rectangles");

    BlitColor color;
    if (mask & gl::COLOR_BUFFER_BIT) {
        why = blit_color_targets(read_framebuffer_.get(), draw_framebuffer_.get(), framebuffer_, filter, color);
        if (!why.empty()) return error(gl::INVALID_OPERATION, call, why);
    }
    const DepthStencilSide ds_src = depth_stencil_side(read_framebuffer_.get(), framebuffer_);
    const DepthStencilSide ds_dst = depth_stencil_side(draw_framebuffer_.get(), framebuffer_);
    const bool ds = (mask & (gl::DEPTH_BUFFER_BIT | gl::STENCIL_BUFFER_BIT)) != 0;
    const bool blit_depth = (mask & gl::DEPTH_BUFFER_BIT) && ds_src.has_depth() && ds_dst.has_depth();
    const bool blit_stencil = (mask & gl::STENCIL_BUFFER_BIT) && ds_src.has_stencil() && ds_dst.has_stencil();
    why = depth_stencil_mismatch(ds_src, ds_dst, blit_depth, blit_stencil);
    if (!why.empty()) return error(gl::INVALID_OPERATION, call, why);

    // ES 3.0 §4.3.3: each destination pixel centre maps linearly into the source rectangle.
    const int64_t x_lo = std::min(dx0, dx1), x_hi = std::max(dx0, dx1), y_lo = std::min(dy0, dy1), y_hi = std::max(dy0, dy1);
    const double scale_x = double(int64_t(sx1) - sx0) / double(int64_t(dx1) - dx0 == 0 ? 1 : int64_t(dx1) - dx0);
    const double scale_y = double(int64_t(sy1) - sy0) / double(int64_t(dy1) - dy0 == 0 ? 1 : int64_t(dy1) - dy0);
    if (x_lo == x_hi || y_lo == y_hi || sx0 == sx1 || sy0 == sy1) return;
    int64_t cx0 = std::max<int64_t>(x_lo, 0), cy0 = std::max<int64_t>(y_lo, 0);
    int64_t cx1 = std::min<int64_t>(x_hi, dst.width()), cy1 = std::min<int64_t>(y_hi, dst.height());
    if (state_.scissor_test) {
        cx0 = std::max<int64_t>(cx0, state_.scissor.x);
        cy0 = std::max<int64_t>(cy0, state_.scissor.y);
        cx1 = std::min<int64_t>(cx1, int64_t(state_.scissor.x) + state_.scissor.width);
        cy1 = std::min<int64_t>(cy1, int64_t(state_.scissor.y) + state_.scissor.height);
    }
    if (tuning_.blit_rows && blit_rows_apply(color, filter, sx0, sy0, sx1, sy1, dx0, dy0, dx1, dy1) &&
        !(ds && ds_src.fb && ds_dst.fb)) {
        const int64_t ox = int64_t(sx0) - dx0, oy = int64_t(sy0) - dy0;
        const BlitRows rc = blit_rows_within(cx0, cy0, cx1, cy1, ox, oy, color.source.width, color.source.height);
        const BlitRows rd = blit_rows_within(cx0, cy0, cx1, cy1, ox, oy, ds_src.width(), ds_src.height());
        // Bands of rows on the pool: each destination row is written by one band alone, so the
        // bytes do not depend on the thread count (docs/architecture.md, "Threads").
        const int64_t rows = cy1 - cy0, pixels = rows * std::max<int64_t>(cx1 - cx0, 0);
        constexpr int64_t kBandRows = 16, kPoolPixels = 1 << 15;
        if (rows <= 0) return;
        if (pixels < kPoolPixels || rows <= kBandRows) {
            BlitRowBuffers buffers(rc, color);
            return blit_rows(rc, rd, color, ds_src, ds_dst, blit_depth, blit_stencil, cy0, cy1, buffers);
        }
        const size_t bands = size_t((rows + kBandRows - 1) / kBandRows);
        // Every worker's buffers before the first band writes (nothing allocates after it).
        ThreadPool& workers = pool();
        std::vector<BlitRowBuffers> buffers;
        buffers.reserve(workers.size());
        for (unsigned w = 0; w < workers.size(); ++w) buffers.emplace_back(rc, color);
        workers.parallel_for(bands, [&](size_t b, unsigned worker) {
            const int64_t y0 = cy0 + int64_t(b) * kBandRows;
            blit_rows(rc, rd, color, ds_src, ds_dst, blit_depth, blit_stencil, y0, std::min(cy1, y0 + kBandRows),
                      buffers[worker]);
        });
        return;
    }
    for (int64_t y = cy0; y < cy1; ++y)
        for (int64_t x = cx0; x < cx1; ++x) {
            const double u = double(sx0) + (double(x) + 0.5 - double(dx0)) * scale_x;
            const double v = double(sy0) + (double(y) + 0.5 - double(dy0)) * scale_y;
            float rgba[4];
            if (color.writes() && blit_read_color(color.source, u, v, filter, rgba)) color.write(int32_t(x), int32_t(y), rgba);
            if (!ds) continue;
            const int64_t ix = int64_t(std::floor(u)), iy = int64_t(std::floor(v));
            if (ix < 0 || iy < 0 || ix >= ds_src.width() || iy >= ds_src.height()) continue;
            if (blit_depth) ds_dst.write_depth(int32_t(x), int32_t(y), ds_src.depth_at(ix, iy));
            if (blit_stencil) ds_dst.write_stencil(int32_t(x), int32_t(y), ds_src.stencil_at(ix, iy));
        }
}

void Context::invalidate_framebuffer(const char* call, GLenum target, const std::vector<GLenum>& attachments) {
    if (!framebuffer_binding(target)) return error(gl::INVALID_ENUM, call, quote(target) + " is not a framebuffer target here");
    const bool is_default = !(target == gl::READ_FRAMEBUFFER ? read_framebuffer_ : draw_framebuffer_);
    for (GLenum a : attachments) {
        const bool ok = is_default ? (a == gl::COLOR || a == gl::DEPTH || a == gl::STENCIL)
                                   : (a == gl::DEPTH_ATTACHMENT || a == gl::STENCIL_ATTACHMENT || a == gl::DEPTH_STENCIL_ATTACHMENT ||
                                      (a >= gl::COLOR_ATTACHMENT0 && a < gl::COLOR_ATTACHMENT0 + uint32_t(kMaxColorAttachments)));
        if (!ok) return error(gl::INVALID_ENUM, call, quote(a) + " is not an attachment to invalidate here");
    }
    // ES 3.0 §4.5: invalidation is a hint that the contents may be discarded; keeping them is
    // a valid implementation, and softgl does so.
}

// ---------------------------------------------------------------------------- drawBuffers

bool Context::multiple_draw_buffers() const {
    return version() >= 2 || texture_extension_enabled("WEBGL_draw_buffers");
}

void Context::draw_buffers(const char* call, const std::vector<GLenum>& buffers) {
    // ES 3.0 §4.2.1 (and EXT_draw_buffers, which WEBGL_draw_buffers mirrors).
    if (buffers.size() > size_t(kMaxColorAttachments))
        return error(gl::INVALID_VALUE, call, "more buffers than MAX_DRAW_BUFFERS (8)");
    for (GLenum b : buffers) {
        const bool known = b == gl::NONE || b == gl::BACK || (b >= gl::COLOR_ATTACHMENT0 && b <= gl::COLOR_ATTACHMENT0 + 15);
        if (!known) return error(gl::INVALID_ENUM, call, quote(b) + " is not a draw buffer");
    }
    if (!draw_framebuffer_) {
        if (buffers.size() != 1) return error(gl::INVALID_OPERATION, call, "the drawing buffer takes exactly one buffer (BACK or NONE)");
        if (buffers[0] != gl::BACK && buffers[0] != gl::NONE)
            return error(gl::INVALID_OPERATION, call, "the drawing buffer's draw buffer must be BACK or NONE");
        default_draw_buffer_ = buffers[0];
        return;
    }
    for (size_t i = 0; i < buffers.size(); ++i) {
        const GLenum b = buffers[i];
        if (b != gl::NONE && b != gl::COLOR_ATTACHMENT0 + uint32_t(i))
            return error(gl::INVALID_OPERATION, call, "buffer " + std::to_string(i) + " must be NONE or COLOR_ATTACHMENT" +
                         std::to_string(i) + ", not " + quote(b));
    }
    for (size_t i = 0; i < size_t(kMaxColorAttachments); ++i)
        draw_framebuffer_->draw_buffers[i] = i < buffers.size() ? buffers[i] : gl::NONE;
}

// ---------------------------------------------------------------------------- getParameter

std::optional<Value> Context::framebuffer_parameter(GLenum pname) {
    switch (pname) {
        case gl::FRAMEBUFFER_BINDING: return object_value(draw_framebuffer_);   // == DRAW_FRAMEBUFFER_BINDING
        case gl::RENDERBUFFER_BINDING: return object_value(renderbuffer_);
        default: break;
    }
    if (version() >= 2) {
        switch (pname) {
            case gl::READ_FRAMEBUFFER_BINDING: return object_value(read_framebuffer_);
            case gl::READ_BUFFER: return Value(int64_t(read_framebuffer_ ? read_framebuffer_->read_buffer : default_read_buffer_));
            default: break;
        }
    }
    if (multiple_draw_buffers()) {
        // DRAW_BUFFERi(_WEBGL), MAX_DRAW_BUFFERS(_WEBGL), MAX_COLOR_ATTACHMENTS(_WEBGL): same values.
        if (pname >= gl::DRAW_BUFFER0 && pname < gl::DRAW_BUFFER0 + uint32_t(kMaxColorAttachments)) {
            const size_t i = pname - gl::DRAW_BUFFER0;
            if (draw_framebuffer_) return Value(int64_t(draw_framebuffer_->draw_buffers[i]));
            return Value(int64_t(i == 0 ? default_draw_buffer_ : gl::NONE));
        }
        if (pname == gl::MAX_DRAW_BUFFERS || pname == gl::MAX_COLOR_ATTACHMENTS) return Value(int64_t(kMaxColorAttachments));
    }
    if (!draw_framebuffer_) return std::nullopt;   // the drawing buffer's values (parameters.cpp)
    // The bound framebuffer object's bit depths and read format (ES 3.0 §6.1.? state tables).
    RenderTarget t = draw_target();
    const Attachment& c0 = draw_framebuffer_->color[0];
    const Image* img = c0.image();
    const FormatInfo* f = img ? img->format : nullptr;
    auto bits = [&](int c) -> int64_t { return f && f->kind() != SampleKind::Depth ? f->bits[size_t(c)] : 0; };
    switch (pname) {
        case gl::RED_BITS: return Value(bits(0));
        case gl::GREEN_BITS: return Value(bits(1));
        case gl::BLUE_BITS: return Value(bits(2));
        case gl::ALPHA_BITS: return Value(bits(3));
        case gl::DEPTH_BITS: return Value(int64_t(t.config().depth ? t.depth_bits() : 0));
        case gl::STENCIL_BITS: return Value(int64_t(t.config().stencil ? 8 : 0));
        case gl::SAMPLE_BUFFERS: return Value(int64_t(t.config().samples > 1 ? 1 : 0));
        case gl::SAMPLES: return Value(int64_t(t.config().samples > 1 ? t.config().samples : 0));
        case gl::IMPLEMENTATION_COLOR_READ_FORMAT:
            return Value(int64_t(f && f->is_integer() ? gl::RGBA_INTEGER : gl::RGBA));
        case gl::IMPLEMENTATION_COLOR_READ_TYPE:
            return Value(int64_t(!f ? gl::UNSIGNED_BYTE : f->encoding == Encoding::Int ? gl::INT : f->encoding == Encoding::Uint ? gl::UNSIGNED_INT
                                 : f->is_float() ? gl::FLOAT : gl::UNSIGNED_BYTE));
        default: return std::nullopt;
    }
}

}  // namespace softgl
