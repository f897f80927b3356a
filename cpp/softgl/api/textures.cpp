// Texture and sampler objects: WebGL 1.0 §5.14.8 and WebGL 2.0 §3.7.6 / §3.7.13 over ES 2.0 §3.7
// and ES 3.0 §3.8, with WebGL's extra rules (no default textures, typed-array type checks,
// zero-initialised images, NPOT limits in WebGL 1, draw-time checks of WebGL 1.0 §6.26 and
// WebGL 2.0 §5.22).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "softgl/api/context.h"

namespace softgl {

using namespace gl_ext;

namespace {

std::string quote(GLenum v) { return enum_name(v); }

bool is_cube_face(GLenum target) {
    return target >= gl::TEXTURE_CUBE_MAP_POSITIVE_X && target <= gl::TEXTURE_CUBE_MAP_NEGATIVE_Z;
}

struct Combo {
    GLenum internal, format, type, effective;
};

// ES 3.0 table 3.2 (sized) and table 3.3 (unsized) combinations of WebGL 2.
const Combo kCombosV2[] = {
    {gl::RGBA8, gl::RGBA, gl::UNSIGNED_BYTE, gl::RGBA8},
    {gl::RGB5_A1, gl::RGBA, gl::UNSIGNED_BYTE, gl::RGB5_A1},
    {gl::RGBA4, gl::RGBA, gl::UNSIGNED_BYTE, gl::RGBA4},
    {gl::SRGB8_ALPHA8, gl::RGBA, gl::UNSIGNED_BYTE, gl::SRGB8_ALPHA8},
    {gl::RGBA8_SNORM, gl::RGBA, gl::BYTE, gl::RGBA8_SNORM},
    {gl::RGBA4, gl::RGBA, gl::UNSIGNED_SHORT_4_4_4_4, gl::RGBA4},
    {gl::RGB5_A1, gl::RGBA, gl::UNSIGNED_SHORT_5_5_5_1, gl::RGB5_A1},
    {gl::RGB10_A2, gl::RGBA, gl::UNSIGNED_INT_2_10_10_10_REV, gl::RGB10_A2},
    {gl::RGB5_A1, gl::RGBA, gl::UNSIGNED_INT_2_10_10_10_REV, gl::RGB5_A1},
    {gl::RGBA16F, gl::RGBA, gl::HALF_FLOAT, gl::RGBA16F},
    {gl::RGBA32F, gl::RGBA, gl::FLOAT, gl::RGBA32F},
    {gl::RGBA16F, gl::RGBA, gl::FLOAT, gl::RGBA16F},
    {gl::RGBA8UI, gl::RGBA_INTEGER, gl::UNSIGNED_BYTE, gl::RGBA8UI},
    {gl::RGBA8I, gl::RGBA_INTEGER, gl::BYTE, gl::RGBA8I},
    {gl::RGBA16UI, gl::RGBA_INTEGER, gl::UNSIGNED_SHORT, gl::RGBA16UI},
    {gl::RGBA16I, gl::RGBA_INTEGER, gl::SHORT, gl::RGBA16I},
    {gl::RGBA32UI, gl::RGBA_INTEGER, gl::UNSIGNED_INT, gl::RGBA32UI},
    {gl::RGBA32I, gl::RGBA_INTEGER, gl::INT, gl::RGBA32I},
    {gl::RGB10_A2UI, gl::RGBA_INTEGER, gl::UNSIGNED_INT_2_10_10_10_REV, gl::RGB10_A2UI},
    {gl::RGB8, gl::RGB, gl::UNSIGNED_BYTE, gl::RGB8},
    {gl::RGB565, gl::RGB, gl::UNSIGNED_BYTE, gl::RGB565},
    {gl::SRGB8, gl::RGB, gl::UNSIGNED_BYTE, gl::SRGB8},
    {gl::RGB8_SNORM, gl::RGB, gl::BYTE, gl::RGB8_SNORM},
    {gl::RGB565, gl::RGB, gl::UNSIGNED_SHORT_5_6_5, gl::RGB565},
    {gl::R11F_G11F_B10F, gl::RGB, gl::UNSIGNED_INT_10F_11F_11F_REV, gl::R11F_G11F_B10F},
    {gl::RGB9_E5, gl::RGB, gl::UNSIGNED_INT_5_9_9_9_REV, gl::RGB9_E5},
    {gl::RGB16F, gl::RGB, gl::HALF_FLOAT, gl::RGB16F},
    {gl::R11F_G11F_B10F, gl::RGB, gl::HALF_FLOAT, gl::R11F_G11F_B10F},
    {gl::RGB9_E5, gl::RGB, gl::HALF_FLOAT, gl::RGB9_E5},
    {gl::RGB32F, gl::RGB, gl::FLOAT, gl::RGB32F},
    {gl::RGB16F, gl::RGB, gl::FLOAT, gl::RGB16F},
    {gl::R11F_G11F_B10F, gl::RGB, gl::FLOAT, gl::R11F_G11F_B10F},
    {gl::RGB9_E5, gl::RGB, gl::FLOAT, gl::RGB9_E5},
    {gl::RGB8UI, gl::RGB_INTEGER, gl::UNSIGNED_BYTE, gl::RGB8UI},
    {gl::RGB8I, gl::RGB_INTEGER, gl::BYTE, gl::RGB8I},
    {gl::RGB16UI, gl::RGB_INTEGER, gl::UNSIGNED_SHORT, gl::RGB16UI},
    {gl::RGB16I, gl::RGB_INTEGER, gl::SHORT, gl::RGB16I},
    {gl::RGB32UI, gl::RGB_INTEGER, gl::UNSIGNED_INT, gl::RGB32UI},
    {gl::RGB32I, gl::RGB_INTEGER, gl::INT, gl::RGB32I},
    {gl::RG8, gl::RG, gl::UNSIGNED_BYTE, gl::RG8},
    {gl::RG8_SNORM, gl::RG, gl::BYTE, gl::RG8_SNORM},
    {gl::RG16F, gl::RG, gl::HALF_FLOAT, gl::RG16F},
    {gl::RG32F, gl::RG, gl::FLOAT, gl::RG32F},
    {gl::RG16F, gl::RG, gl::FLOAT, gl::RG16F},
    {gl::RG8UI, gl::RG_INTEGER, gl::UNSIGNED_BYTE, gl::RG8UI},
    {gl::RG8I, gl::RG_INTEGER, gl::BYTE, gl::RG8I},
    {gl::RG16UI, gl::RG_INTEGER, gl::UNSIGNED_SHORT, gl::RG16UI},
    {gl::RG16I, gl::RG_INTEGER, gl::SHORT, gl::RG16I},
    {gl::RG32UI, gl::RG_INTEGER, gl::UNSIGNED_INT, gl::RG32UI},
    {gl::RG32I, gl::RG_INTEGER, gl::INT, gl::RG32I},
    {gl::R8, gl::RED, gl::UNSIGNED_BYTE, gl::R8},
    {gl::R8_SNORM, gl::RED, gl::BYTE, gl::R8_SNORM},
    {gl::R16F, gl::RED, gl::HALF_FLOAT, gl::R16F},
    {gl::R32F, gl::RED, gl::FLOAT, gl::R32F},
    {gl::R16F, gl::RED, gl::FLOAT, gl::R16F},
    {gl::R8UI, gl::RED_INTEGER, gl::UNSIGNED_BYTE, gl::R8UI},
    {gl::R8I, gl::RED_INTEGER, gl::BYTE, gl::R8I},
    {gl::R16UI, gl::RED_INTEGER, gl::UNSIGNED_SHORT, gl::R16UI},
    {gl::R16I, gl::RED_INTEGER, gl::SHORT, gl::R16I},
    {gl::R32UI, gl::RED_INTEGER, gl::UNSIGNED_INT, gl::R32UI},
    {gl::R32I, gl::RED_INTEGER, gl::INT, gl::R32I},
    {gl::DEPTH_COMPONENT16, gl::DEPTH_COMPONENT, gl::UNSIGNED_SHORT, gl::DEPTH_COMPONENT16},
    {gl::DEPTH_COMPONENT16, gl::DEPTH_COMPONENT, gl::UNSIGNED_INT, gl::DEPTH_COMPONENT16},
    {gl::DEPTH_COMPONENT24, gl::DEPTH_COMPONENT, gl::UNSIGNED_INT, gl::DEPTH_COMPONENT24},
    {gl::DEPTH_COMPONENT32F, gl::DEPTH_COMPONENT, gl::FLOAT, gl::DEPTH_COMPONENT32F},
    {gl::DEPTH24_STENCIL8, gl::DEPTH_STENCIL, gl::UNSIGNED_INT_24_8, gl::DEPTH24_STENCIL8},
    {gl::DEPTH32F_STENCIL8, gl::DEPTH_STENCIL, gl::FLOAT_32_UNSIGNED_INT_24_8_REV, gl::DEPTH32F_STENCIL8},
    {gl::RGBA, gl::RGBA, gl::UNSIGNED_BYTE, gl::RGBA8},
    {gl::RGBA, gl::RGBA, gl::UNSIGNED_SHORT_4_4_4_4, gl::RGBA4},
    {gl::RGBA, gl::RGBA, gl::UNSIGNED_SHORT_5_5_5_1, gl::RGB5_A1},
    {gl::RGB, gl::RGB, gl::UNSIGNED_BYTE, gl::RGB8},
    {gl::RGB, gl::RGB, gl::UNSIGNED_SHORT_5_6_5, gl::RGB565},
    {gl::LUMINANCE_ALPHA, gl::LUMINANCE_ALPHA, gl::UNSIGNED_BYTE, LUMINANCE8_ALPHA8},
    {gl::LUMINANCE, gl::LUMINANCE, gl::UNSIGNED_BYTE, LUMINANCE8},
    {gl::ALPHA, gl::ALPHA, gl::UNSIGNED_BYTE, ALPHA8},
};

bool known_format(GLenum f, int version) {
    switch (f) {
        case gl::RGBA: case gl::RGB: case gl::ALPHA: case gl::LUMINANCE: case gl::LUMINANCE_ALPHA:
        case gl::DEPTH_COMPONENT: case gl::DEPTH_STENCIL: return true;
        case gl::RED: case gl::RG: case gl::RED_INTEGER: case gl::RG_INTEGER: case gl::RGB_INTEGER:
        case gl::RGBA_INTEGER: return version >= 2;
        default: return false;
    }
}

bool known_type(GLenum t, int version) {
    switch (t) {
        case gl::UNSIGNED_BYTE: case gl::UNSIGNED_SHORT_5_6_5: case gl::UNSIGNED_SHORT_4_4_4_4:
        case gl::UNSIGNED_SHORT_5_5_5_1: case gl::FLOAT: case HALF_FLOAT_OES: case gl::UNSIGNED_SHORT:
        case gl::UNSIGNED_INT: case gl::UNSIGNED_INT_24_8: return true;
        case gl::BYTE: case gl::SHORT: case gl::INT: case gl::HALF_FLOAT: case gl::UNSIGNED_INT_2_10_10_10_REV:
        case gl::UNSIGNED_INT_10F_11F_11F_REV: case gl::UNSIGNED_INT_5_9_9_9_REV:
        case gl::FLOAT_32_UNSIGNED_INT_24_8_REV: return version >= 2;
        default: return false;
    }
}

// WebGL 1.0 §5.14.8 / WebGL 2.0 §3.7.6: the typed array each pixel type requires.
GLenum array_type_for_pixels(GLenum type) {
    switch (type) {
        case gl::UNSIGNED_BYTE: return gl::UNSIGNED_BYTE;
        case gl::BYTE: return gl::BYTE;
        case gl::SHORT: return gl::SHORT;
        case gl::INT: return gl::INT;
        case gl::FLOAT: return gl::FLOAT;
        case gl::UNSIGNED_SHORT: case gl::UNSIGNED_SHORT_5_6_5: case gl::UNSIGNED_SHORT_4_4_4_4:
        case gl::UNSIGNED_SHORT_5_5_5_1: case gl::HALF_FLOAT: case HALF_FLOAT_OES: return gl::UNSIGNED_SHORT;
        case gl::UNSIGNED_INT: case gl::UNSIGNED_INT_24_8: case gl::UNSIGNED_INT_2_10_10_10_REV:
        case gl::UNSIGNED_INT_10F_11F_11F_REV: case gl::UNSIGNED_INT_5_9_9_9_REV: return gl::UNSIGNED_INT;
        default: return 0;   // FLOAT_32_UNSIGNED_INT_24_8_REV: only null is allowed
    }
}

int32_t log2_floor(int32_t v) {
    int32_t n = 0;
    while (v > 1) v >>= 1, ++n;
    return n;
}

bool valid_wrap(GLenum v) { return v == gl::REPEAT || v == gl::CLAMP_TO_EDGE || v == gl::MIRRORED_REPEAT; }
bool valid_min_filter(GLenum v) {
    return v == gl::NEAREST || v == gl::LINEAR || v == gl::NEAREST_MIPMAP_NEAREST || v == gl::LINEAR_MIPMAP_NEAREST ||
           v == gl::NEAREST_MIPMAP_LINEAR || v == gl::LINEAR_MIPMAP_LINEAR;
}

// Sets one of the sampler-state parameters shared by textures and sampler objects; false when
// pname is not one of them. Records INVALID_ENUM for bad values.
bool set_sampler_param(Context& c, const char* call, SamplerParams& p, GLenum pname, double value, int version,
                       bool* bad) {
    const GLenum e = GLenum(int64_t(value));
    auto fail = [&](const std::string& why) { c.record_error(gl::INVALID_ENUM, call, why); *bad = true; return true; };
    if (pname == TEXTURE_MAX_ANISOTROPY_EXT && c.extension_enabled("EXT_texture_filter_anisotropic")) {
        // EXT_texture_filter_anisotropic: a value below 1.0 is INVALID_VALUE; larger ones are
        // kept as given (getTexParameter returns them) and clamped when sampling.
        if (!(value >= 1.0)) {
            c.record_error(gl::INVALID_VALUE, call, "TEXTURE_MAX_ANISOTROPY_EXT must be at least 1.0");
            *bad = true;
            return true;
        }
        p.max_anisotropy = float(value);
        return true;
    }
    switch (pname) {
        case gl::TEXTURE_MAG_FILTER:
            if (e != gl::NEAREST && e != gl::LINEAR) return fail(quote(e) + " is not a magnification filter");
            p.mag_filter = e; return true;
        case gl::TEXTURE_MIN_FILTER:
            if (!valid_min_filter(e)) return fail(quote(e) + " is not a minification filter");
            p.min_filter = e; return true;
        case gl::TEXTURE_WRAP_S: case gl::TEXTURE_WRAP_T:
            if (!valid_wrap(e)) return fail(quote(e) + " is not a wrap mode");
            (pname == gl::TEXTURE_WRAP_S ? p.wrap_s : p.wrap_t) = e; return true;
        default: break;
    }
    if (version < 2) return false;
    switch (pname) {
        case gl::TEXTURE_WRAP_R:
            if (!valid_wrap(e)) return fail(quote(e) + " is not a wrap mode");
            p.wrap_r = e; return true;
        case gl::TEXTURE_MIN_LOD: p.min_lod = float(value); return true;
        case gl::TEXTURE_MAX_LOD: p.max_lod = float(value); return true;
        case gl::TEXTURE_COMPARE_MODE:
            if (e != gl::NONE && e != gl::COMPARE_REF_TO_TEXTURE) return fail(quote(e) + " is not a compare mode");
            p.compare_mode = e; return true;
        case gl::TEXTURE_COMPARE_FUNC:
            if (e < gl::NEVER || e > gl::ALWAYS) return fail(quote(e) + " is not a comparison function");
            p.compare_func = e; return true;
        default: return false;
    }
}

std::optional<Value> get_sampler_param(const SamplerParams& p, GLenum pname, int version, bool anisotropic) {
    if (pname == TEXTURE_MAX_ANISOTROPY_EXT && anisotropic) return Value(double(p.max_anisotropy));
    switch (pname) {
        case gl::TEXTURE_MAG_FILTER: return Value(int64_t(p.mag_filter));
        case gl::TEXTURE_MIN_FILTER: return Value(int64_t(p.min_filter));
        case gl::TEXTURE_WRAP_S: return Value(int64_t(p.wrap_s));
        case gl::TEXTURE_WRAP_T: return Value(int64_t(p.wrap_t));
        default: break;
    }
    if (version < 2) return std::nullopt;
    switch (pname) {
        case gl::TEXTURE_WRAP_R: return Value(int64_t(p.wrap_r));
        case gl::TEXTURE_MIN_LOD: return Value(double(p.min_lod));
        case gl::TEXTURE_MAX_LOD: return Value(double(p.max_lod));
        case gl::TEXTURE_COMPARE_MODE: return Value(int64_t(p.compare_mode));
        case gl::TEXTURE_COMPARE_FUNC: return Value(int64_t(p.compare_func));
        default: return std::nullopt;
    }
}

template <class T>
Value object_value(const std::shared_ptr<T>& p) {
    if (!p) return Value(Null{});
    return Value(std::shared_ptr<Object>(p));
}

}  // namespace

// ---------------------------------------------------------------------------- extensions

std::vector<std::string> Context::texture_extension_names() const {
    if (version() == 1)
        return {"EXT_color_buffer_half_float", "EXT_texture_filter_anisotropic", "OES_texture_float",
                "OES_texture_float_linear", "OES_texture_half_float", "OES_texture_half_float_linear",
                "WEBGL_color_buffer_float", "WEBGL_depth_texture", "WEBGL_draw_buffers"};
    return {"EXT_color_buffer_float", "EXT_texture_filter_anisotropic", "OES_texture_float_linear"};
}

bool Context::enable_texture_extension(const std::string& name) {
    const auto names = texture_extension_names();
    if (std::find(names.begin(), names.end(), name) == names.end()) return false;
    if (!texture_extension_enabled(name)) texture_extensions_.push_back(name);
    return true;
}

bool Context::texture_extension_enabled(const std::string& name) const {
    return std::find(texture_extensions_.begin(), texture_extensions_.end(), name) != texture_extensions_.end();
}

CompletenessRules Context::completeness_rules() const {
    CompletenessRules r;
    r.webgl1 = version() == 1;
    r.float_linear = texture_extension_enabled("OES_texture_float_linear");
    r.half_float_linear = version() >= 2 || texture_extension_enabled("OES_texture_half_float_linear");
    return r;
}

// ---------------------------------------------------------------------------- objects and bindings

std::shared_ptr<Texture> Context::create_texture() {
    auto t = std::make_shared<Texture>();
    t->owner = identity();
    t->memory = MemoryReservation(memory_account_);
    return t;
}

std::shared_ptr<Texture>* Context::texture_binding(GLenum target) {
    TextureUnit& u = texture_units_[state_.active_texture - gl::TEXTURE0];
    switch (target) {
        case gl::TEXTURE_2D: return &u.tex_2d;
        case gl::TEXTURE_CUBE_MAP: return &u.cube;
        case gl::TEXTURE_3D: return version() >= 2 ? &u.tex_3d : nullptr;
        case gl::TEXTURE_2D_ARRAY: return version() >= 2 ? &u.array_2d : nullptr;
        default: return nullptr;
    }
}

void Context::bind_texture(GLenum target, const std::shared_ptr<Texture>& texture) {
    const char* call = "bindTexture";
    std::shared_ptr<Texture>* slot = texture_binding(target);
    if (!slot) return error(gl::INVALID_ENUM, call, quote(target) + " is not a texture target here");
    if (!check_object(call, texture.get())) return;
    if (texture) {
        // ES 3.0 §3.8.1: a texture keeps the target it was first bound to.
        if (texture->target && texture->target != target)
            return error(gl::INVALID_OPERATION, call, "the texture was first bound to " + quote(texture->target));
        if (!texture->target) {
            texture->target = target;
            if (target == gl::TEXTURE_3D || target == gl::TEXTURE_2D_ARRAY) texture->sampler.wrap_r = gl::REPEAT;
        }
        texture->ever_bound = true;
    }
    *slot = texture;
}

void Context::delete_texture(const std::shared_ptr<Texture>& texture) {
    if (!texture) return;
    if (texture->owner != identity()) return error(gl::INVALID_OPERATION, "deleteTexture", "the object belongs to another context");
    if (texture->deleted) return;
    // ES 3.0 §3.8.1: deleting unbinds it from every unit (and, §4.4.2.3, detaches it from the
    // bound framebuffers: framebuffers.cpp). Its images go at once unless a framebuffer that is
    // not bound keeps it attached (then when the last one lets go: Object::mark_deleted).
    texture->mark_deleted();
    for (TextureUnit& u : texture_units_)
        for (auto* slot : {&u.tex_2d, &u.cube, &u.tex_3d, &u.array_2d})
            if (*slot == texture) slot->reset();
    detach_from_framebuffers(texture.get(), nullptr);
}

bool Context::is_texture(const std::shared_ptr<Texture>& texture) const {
    return texture && texture->owner == identity() && !texture->deleted && texture->ever_bound;
}

Texture* Context::bound_texture(const char* call, GLenum target, int* face) {
    GLenum binding = target;
    *face = 0;
    if (is_cube_face(target)) {
        binding = gl::TEXTURE_CUBE_MAP;
        *face = int(target - gl::TEXTURE_CUBE_MAP_POSITIVE_X);
    }
    std::shared_ptr<Texture>* slot = texture_binding(binding);
    if (!slot) {
        error(gl::INVALID_ENUM, call, quote(target) + " is not a texture target here");
        return nullptr;
    }
    if (!*slot) {
        error(gl::INVALID_OPERATION, call, "no texture is bound to " + quote(binding));
        return nullptr;
    }
    return slot->get();
}

// ---------------------------------------------------------------------------- parameters

void Context::tex_parameter(const char* call, GLenum target, GLenum pname, double value) {
    std::shared_ptr<Texture>* slot = texture_binding(target);
    if (!slot) return error(gl::INVALID_ENUM, call, quote(target) + " is not a texture target here");
    if (!*slot) return error(gl::INVALID_OPERATION, call, "no texture is bound to " + quote(target));
    Texture& t = **slot;
    bool bad = false;
    if (set_sampler_param(*this, call, t.sampler, pname, value, version(), &bad)) return;
    if (version() >= 2) {
        switch (pname) {
            case gl::TEXTURE_BASE_LEVEL: case gl::TEXTURE_MAX_LEVEL: {
                const int64_t v = int64_t(value);
                if (v < 0) return error(gl::INVALID_VALUE, call, "the level must not be negative");
                (pname == gl::TEXTURE_BASE_LEVEL ? t.base_level : t.max_level) = int32_t(std::min<int64_t>(v, 1 << 30));
                return;
            }
            default: break;
        }
    }
    error(gl::INVALID_ENUM, call, quote(pname) + " is not a texture parameter here");
}

Value Context::get_tex_parameter(GLenum target, GLenum pname) {
    const char* call = "getTexParameter";
    std::shared_ptr<Texture>* slot = texture_binding(target);
    if (!slot) { error(gl::INVALID_ENUM, call, quote(target) + " is not a texture target here"); return Value(Null{}); }
    if (!*slot) { error(gl::INVALID_OPERATION, call, "no texture is bound to " + quote(target)); return Value(Null{}); }
    const Texture& t = **slot;
    if (auto v = get_sampler_param(t.sampler, pname, version(), extension_enabled("EXT_texture_filter_anisotropic"))) return *v;
    if (version() >= 2) {
        switch (pname) {
            case gl::TEXTURE_BASE_LEVEL: return Value(int64_t(t.base_level));
            case gl::TEXTURE_MAX_LEVEL: return Value(int64_t(t.max_level));
            case gl::TEXTURE_IMMUTABLE_FORMAT: return Value(t.immutable);
            case gl::TEXTURE_IMMUTABLE_LEVELS: return Value(int64_t(t.immutable_levels));
            default: break;
        }
    }
    error(gl::INVALID_ENUM, call, quote(pname) + " is not a texture parameter here");
    return Value(Null{});
}

// ---------------------------------------------------------------------------- images

bool Context::check_tex_format(const char* call, GLenum target, int32_t level, GLenum internal_format,
                               GLenum format, GLenum type, const FormatInfo** info) {
    const int v = version();
    if (!known_format(format, v)) { error(gl::INVALID_ENUM, call, quote(format) + " is not a pixel format here"); return false; }
    if (!known_type(type, v) || (type == HALF_FLOAT_OES && v >= 2)) {
        error(gl::INVALID_ENUM, call, quote(type) + " is not a pixel type here");
        return false;
    }
    GLenum effective = 0;
    if (v == 1) {
        // ES 2.0 §3.7.1: internalformat must equal format; the type picks the precision.
        if (!known_format(internal_format, 1)) { error(gl::INVALID_VALUE, call, quote(internal_format) + " is not an internal format"); return false; }
        if (internal_format != format) { error(gl::INVALID_OPERATION, call, "internalformat must equal format in WebGL 1"); return false; }
        const bool fl = texture_extension_enabled("OES_texture_float"), hf = texture_extension_enabled("OES_texture_half_float");
        const bool depth = texture_extension_enabled("WEBGL_depth_texture");
        struct V1 { GLenum format, type, effective; bool enabled; };
        const V1 table[] = {
            {gl::RGBA, gl::UNSIGNED_BYTE, gl::RGBA8, true}, {gl::RGBA, gl::UNSIGNED_SHORT_4_4_4_4, gl::RGBA4, true},
            {gl::RGBA, gl::UNSIGNED_SHORT_5_5_5_1, gl::RGB5_A1, true}, {gl::RGB, gl::UNSIGNED_BYTE, gl::RGB8, true},
            {gl::RGB, gl::UNSIGNED_SHORT_5_6_5, gl::RGB565, true},
            {gl::LUMINANCE_ALPHA, gl::UNSIGNED_BYTE, LUMINANCE8_ALPHA8, true}, {gl::LUMINANCE, gl::UNSIGNED_BYTE, LUMINANCE8, true},
            {gl::ALPHA, gl::UNSIGNED_BYTE, ALPHA8, true},
            {gl::RGBA, gl::FLOAT, gl::RGBA32F, fl}, {gl::RGB, gl::FLOAT, gl::RGB32F, fl},
            {gl::LUMINANCE_ALPHA, gl::FLOAT, LUMINANCE_ALPHA32F, fl}, {gl::LUMINANCE, gl::FLOAT, LUMINANCE32F, fl},
            {gl::ALPHA, gl::FLOAT, ALPHA32F, fl},
            {gl::RGBA, HALF_FLOAT_OES, gl::RGBA16F, hf}, {gl::RGB, HALF_FLOAT_OES, gl::RGB16F, hf},
            {gl::LUMINANCE_ALPHA, HALF_FLOAT_OES, LUMINANCE_ALPHA16F, hf}, {gl::LUMINANCE, HALF_FLOAT_OES, LUMINANCE16F, hf},
            {gl::ALPHA, HALF_FLOAT_OES, ALPHA16F, hf},
            {gl::DEPTH_COMPONENT, gl::UNSIGNED_SHORT, gl::DEPTH_COMPONENT16, depth},
            {gl::DEPTH_COMPONENT, gl::UNSIGNED_INT, gl::DEPTH_COMPONENT24, depth},
            {gl::DEPTH_STENCIL, UNSIGNED_INT_24_8_WEBGL, gl::DEPTH24_STENCIL8, depth},
        };
        bool type_known_here = false;
        for (const V1& e : table) {
            if (e.type == type && e.enabled) type_known_here = true;
            if (e.format == format && e.type == type && e.enabled) effective = e.effective;
        }
        if (!type_known_here) { error(gl::INVALID_ENUM, call, quote(type) + " is not a pixel type here (is its extension enabled?)"); return false; }
        if ((format == gl::DEPTH_COMPONENT || format == gl::DEPTH_STENCIL) && !depth) {
            error(gl::INVALID_ENUM, call, quote(format) + " needs WEBGL_depth_texture"); return false;
        }
    } else {
        bool internal_known = internal_format == gl::RGBA || internal_format == gl::RGB ||
                              internal_format == gl::LUMINANCE_ALPHA || internal_format == gl::LUMINANCE ||
                              internal_format == gl::ALPHA;
        const FormatInfo* fi = format_info(internal_format);
        if (fi && internal_format != gl::STENCIL_INDEX8 && !is_pseudo_format(internal_format))
            internal_known = true;
        if (!internal_known) { error(gl::INVALID_VALUE, call, quote(internal_format) + " is not a texture internal format"); return false; }
        for (const Combo& c : kCombosV2)
            if (c.internal == internal_format && c.format == format && c.type == type) effective = c.effective;
    }
    if (!effective) {
        error(gl::INVALID_OPERATION, call, quote(internal_format) + " cannot be specified with " + quote(format) + "/" + quote(type));
        return false;
    }
    const FormatInfo* fi = format_info(effective);
    if (fi->kind() == SampleKind::Depth) {
        // WEBGL_depth_texture / ES 3.0 §3.8.3: depth textures are 2D (and 2D arrays in WebGL 2);
        // WebGL 1 allows only level 0 and no data.
        if (target != gl::TEXTURE_2D && !(v >= 2 && target == gl::TEXTURE_2D_ARRAY)) {
            error(gl::INVALID_OPERATION, call, "depth formats need a TEXTURE_2D target"); return false;
        }
        if (v == 1 && level != 0) { error(gl::INVALID_OPERATION, call, "depth textures have only level 0 in WebGL 1"); return false; }
    }
    *info = fi;
    return true;
}

bool Context::check_tex_source(const char* call, const TexSource& given, GLenum format, GLenum type,
                               int32_t width, int32_t height, int32_t depth, PixelUnpack& u) {
    const PixelStore& ps = state_.pixel_store;
    u = PixelUnpack{};
    // WebGL 2.0 §3.7.6 / ES 3.0 §3.7.2: with a PIXEL_UNPACK_BUFFER bound, pixels come from it at
    // a byte offset, and only then; the offset must be a multiple of the type's size.
    TexSource src = given;
    if (src.kind == TexSource::Kind::UnpackBuffer) {
        if (!pixel_unpack_buffer_) { error(gl::INVALID_OPERATION, call, "an offset needs a buffer bound to PIXEL_UNPACK_BUFFER"); return false; }
        if (src.offset < 0) { error(gl::INVALID_VALUE, call, "the offset must not be negative"); return false; }
        const GLenum wanted = array_type_for_pixels(type);
        const int64_t size = wanted == gl::UNSIGNED_BYTE || wanted == gl::BYTE ? 1 : wanted == gl::SHORT || wanted == gl::UNSIGNED_SHORT ? 2 : 4;
        if (src.offset % size != 0) {
            error(gl::INVALID_OPERATION, call, "the offset is not a multiple of " + std::to_string(size) + " bytes (" + quote(type) + ")");
            return false;
        }
        const std::vector<uint8_t>& data = pixel_unpack_buffer_->data;
        if (uint64_t(src.offset) > data.size()) { error(gl::INVALID_OPERATION, call, "the offset is past the end of the PIXEL_UNPACK_BUFFER"); return false; }
        src.kind = TexSource::Kind::View;
        src.data = data.data() + src.offset;
        src.bytes = data.size() - size_t(src.offset);
        src.array_type = wanted;   // a buffer has no element type
    } else if (pixel_unpack_buffer_) {
        error(gl::INVALID_OPERATION, call, "a buffer is bound to PIXEL_UNPACK_BUFFER: pass a byte offset into it");
        return false;
    }
    u.flip_y = ps.unpack_flip_y;
    u.premultiply = ps.unpack_premultiply_alpha;
    if (src.kind == TexSource::Kind::Image) {
        // Image sources are tight RGBA rows; UNPACK_ALIGNMENT and the skips do not apply
        // (WebGL 2.0 §5.35 lets skips apply to images too; softgl's sources are whole arrays).
        u.data = src.data;
        u.bytes = src.bytes;
        u.format = gl::RGBA;
        u.type = src.image_type;
        u.alignment = 1;
        if (format == gl::DEPTH_COMPONENT || format == gl::DEPTH_STENCIL) {
            error(gl::INVALID_OPERATION, call, "depth formats cannot be uploaded from an image"); return false;
        }
        return true;
    }
    u.format = format;
    u.type = type;
    u.alignment = ps.unpack_alignment;
    if (version() >= 2) {
        u.row_length = ps.unpack_row_length;
        u.image_height = ps.unpack_image_height;
        u.skip_pixels = ps.unpack_skip_pixels;
        u.skip_rows = ps.unpack_skip_rows;
        u.skip_images = depth > 1 || ps.unpack_skip_images ? ps.unpack_skip_images : 0;
    }
    if (src.kind == TexSource::Kind::None) return true;
    if (format == gl::DEPTH_COMPONENT || format == gl::DEPTH_STENCIL) {
        if (version() == 1) { error(gl::INVALID_OPERATION, call, "WEBGL_depth_texture takes no pixel data (pass None)"); return false; }
    }
    const GLenum wanted = array_type_for_pixels(type);
    if (!wanted || src.array_type != wanted) {
        error(gl::INVALID_OPERATION, call, "the pixel array's element type does not match " + quote(type));
        return false;
    }
    if (u.row_length > 0 && u.skip_pixels + width > u.row_length) {
        error(gl::INVALID_OPERATION, call, "UNPACK_SKIP_PIXELS + width exceeds UNPACK_ROW_LENGTH"); return false;
    }
    const uint64_t needed = unpack_size(u, width, height, depth);
    if (src.bytes < needed) {
        std::string why = "the pixel array holds " + std::to_string(src.bytes) + " bytes, " + std::to_string(needed) +
                          " are needed";
        PixelUnpack tight = u;
        tight.alignment = 1;
        if (u.alignment > 1 && src.bytes >= unpack_size(tight, width, height, depth)) {
            // The shortfall is the row padding (ES 3.0 §3.7.2 / §3.8.3): say so, as it surprises.
            const uint64_t row = uint64_t(u.row_length > 0 ? u.row_length : width) * uint64_t(pixel_bytes(format, type));
            const uint64_t padded = (row + uint64_t(u.alignment) - 1) / uint64_t(u.alignment) * uint64_t(u.alignment);
            why += ": UNPACK_ALIGNMENT is " + std::to_string(u.alignment) + ", so each row of " + std::to_string(row) +
                   " bytes starts " + std::to_string(padded) + " bytes after the previous one (all rows but the last "
                   "are padded); pad the rows or call pixelStorei(UNPACK_ALIGNMENT, 1)";
        }
        error(gl::INVALID_OPERATION, call, why);
        return false;
    }
    u.data = src.data;
    u.bytes = src.bytes;
    return true;
}

void Context::tex_image(const char* call, GLenum target, int32_t level, GLenum internal_format, int32_t width,
                        int32_t height, int32_t depth, int32_t border, GLenum format, GLenum type, const TexSource& src) {
    const bool three_d = std::string(call).find("3D") != std::string::npos;
    const bool target_ok = three_d ? (target == gl::TEXTURE_3D || target == gl::TEXTURE_2D_ARRAY)
                                   : (target == gl::TEXTURE_2D || is_cube_face(target));
    if (!target_ok) return error(gl::INVALID_ENUM, call, quote(target) + " is not a target of " + call);
    int face = 0;
    Texture* t = bound_texture(call, target, &face);
    if (!t) return;
    if (src.kind == TexSource::Kind::Image) width = src.width, height = src.height, depth = 1;
    const int32_t max_size = target == gl::TEXTURE_2D ? limits::kMaxTextureSize
                           : target == gl::TEXTURE_3D || target == gl::TEXTURE_2D_ARRAY ? 2048 : limits::kMaxCubeMapTextureSize;
    if (level < 0 || level > log2_floor(max_size)) return error(gl::INVALID_VALUE, call, "level is out of range");
    if (width < 0 || height < 0 || depth < 0) return error(gl::INVALID_VALUE, call, "width, height and depth must not be negative");
    if (width > (max_size >> level) || height > (max_size >> level) ||
        (target == gl::TEXTURE_3D && depth > (max_size >> level)) || (target == gl::TEXTURE_2D_ARRAY && depth > 2048))
        return error(gl::INVALID_VALUE, call, "the size exceeds the maximum texture size for this level");
    if (is_cube_face(target) && width != height) return error(gl::INVALID_VALUE, call, "cube map faces must be square");
    if (border != 0) return error(gl::INVALID_VALUE, call, "border must be 0");
    if (version() == 1 && level > 0 && (!is_power_of_two(width) || !is_power_of_two(height)))
        return error(gl::INVALID_VALUE, call, "levels above 0 must have power-of-two sizes in WebGL 1");
    const FormatInfo* fi = nullptr;
    if (!check_tex_format(call, target, level, internal_format, format, type, &fi)) return;
    if (t->immutable) return error(gl::INVALID_OPERATION, call, "the texture is immutable (texStorage)");
    PixelUnpack u;
    if (!check_tex_source(call, src, format, type, width, height, depth, u)) return;
    // The new image is charged (core/memory_ledger.h) and built beside the old one, which stays
    // if either fails.
    const Image* old = t->find(face, level);
    const uint64_t bytes = Image::allocation_bytes(fi, width, height, depth, 1);
    const uint64_t before = t->memory.bytes();
    const uint64_t released = old ? old->storage_bytes() : 0;
    if (!t->memory.resize(before - std::min(before, released) + bytes))
        return error(gl::OUT_OF_MEMORY, call, "a " + std::to_string(width) + "x" + std::to_string(height) + "x" +
                     std::to_string(depth) + " image needs " + std::to_string(bytes) + " bytes, which " +
                     t->memory.over_limit(bytes - std::min(bytes, released)));
    try {
        Image fresh;
        fresh.allocate(fi, width, height, depth);
        if (u.data && width && height && depth) unpack_into(fresh, 0, 0, 0, width, height, depth, u);
        t->image(face, level) = std::move(fresh);
    } catch (const std::bad_alloc&) {
        t->memory.force(before);
        return error(gl::OUT_OF_MEMORY, call, "could not allocate " + std::to_string(bytes) + " bytes");
    }
    ++t->generation;
}

void Context::tex_sub_image(const char* call, GLenum target, int32_t level, int32_t x, int32_t y, int32_t z,
                            int32_t width, int32_t height, int32_t depth, GLenum format, GLenum type, const TexSource& src) {
    const bool three_d = std::string(call).find("3D") != std::string::npos;
    const bool target_ok = three_d ? (target == gl::TEXTURE_3D || target == gl::TEXTURE_2D_ARRAY)
                                   : (target == gl::TEXTURE_2D || is_cube_face(target));
    if (!target_ok) return error(gl::INVALID_ENUM, call, quote(target) + " is not a target of " + call);
    int face = 0;
    Texture* t = bound_texture(call, target, &face);
    if (!t) return;
    if (src.kind == TexSource::Kind::Image) width = src.width, height = src.height, depth = 1;
    if (!known_format(format, version())) return error(gl::INVALID_ENUM, call, quote(format) + " is not a pixel format here");
    if (!known_type(type, version()) || (type == HALF_FLOAT_OES && version() >= 2))
        return error(gl::INVALID_ENUM, call, quote(type) + " is not a pixel type here");
    if (level < 0) return error(gl::INVALID_VALUE, call, "level must not be negative");
    if (x < 0 || y < 0 || z < 0 || width < 0 || height < 0 || depth < 0)
        return error(gl::INVALID_VALUE, call, "offsets and sizes must not be negative");
    Image* img = const_cast<Image*>(t->find(face, level));
    if (!img) return error(gl::INVALID_OPERATION, call, "the level has no image to update");
    if (int64_t(x) + width > img->width || int64_t(y) + height > img->height || int64_t(z) + depth > img->depth)
        return error(gl::INVALID_VALUE, call, "the region extends past the image");
    // The format and type must be ones the level's internal format accepts (ES 3.0 §3.8.5;
    // in WebGL 1 the same format and type as the image was specified with).
    const FormatInfo* fi = nullptr;
    GLenum effective = 0;
    if (version() == 1) {
        const GLenum internal = format;
        bool saved_error = false;
        (void)saved_error;
        // Reuse the texImage table without recording errors for the probe: compare directly.
        struct P { GLenum f, t, e; };
        const P table[] = {
            {gl::RGBA, gl::UNSIGNED_BYTE, gl::RGBA8}, {gl::RGBA, gl::UNSIGNED_SHORT_4_4_4_4, gl::RGBA4},
            {gl::RGBA, gl::UNSIGNED_SHORT_5_5_5_1, gl::RGB5_A1}, {gl::RGB, gl::UNSIGNED_BYTE, gl::RGB8},
            {gl::RGB, gl::UNSIGNED_SHORT_5_6_5, gl::RGB565}, {gl::LUMINANCE_ALPHA, gl::UNSIGNED_BYTE, LUMINANCE8_ALPHA8},
            {gl::LUMINANCE, gl::UNSIGNED_BYTE, LUMINANCE8}, {gl::ALPHA, gl::UNSIGNED_BYTE, ALPHA8},
            {gl::RGBA, gl::FLOAT, gl::RGBA32F}, {gl::RGB, gl::FLOAT, gl::RGB32F}, {gl::LUMINANCE_ALPHA, gl::FLOAT, LUMINANCE_ALPHA32F},
            {gl::LUMINANCE, gl::FLOAT, LUMINANCE32F}, {gl::ALPHA, gl::FLOAT, ALPHA32F},
            {gl::RGBA, HALF_FLOAT_OES, gl::RGBA16F}, {gl::RGB, HALF_FLOAT_OES, gl::RGB16F},
            {gl::LUMINANCE_ALPHA, HALF_FLOAT_OES, LUMINANCE_ALPHA16F}, {gl::LUMINANCE, HALF_FLOAT_OES, LUMINANCE16F},
            {gl::ALPHA, HALF_FLOAT_OES, ALPHA16F},
        };
        for (const P& p : table)
            if (p.f == internal && p.t == type) effective = p.e;
    } else {
        for (const Combo& c : kCombosV2)
            if (c.format == format && c.type == type &&
                (c.internal == img->format->internal_format || (c.internal == format && c.effective == img->format->internal_format)))
                effective = img->format->internal_format;
    }
    if (effective != img->format->internal_format)
        return error(gl::INVALID_OPERATION, call, quote(format) + "/" + quote(type) + " does not match the image's format");
    fi = img->format;
    if (fi->kind() == SampleKind::Depth && version() == 1)
        return error(gl::INVALID_OPERATION, call, "depth textures cannot be updated in WebGL 1");
    PixelUnpack u;
    if (!check_tex_source(call, src, format, type, width, height, depth, u)) return;
    if (src.kind == TexSource::Kind::None)
        return error(gl::INVALID_VALUE, call, "pixels must not be null");   // WebGL 1.0 §5.14.8
    if (width && height && depth) unpack_into(*img, x, y, z, width, height, depth, u);
    ++t->generation;
}

void Context::tex_storage(const char* call, GLenum target, int32_t levels, GLenum internal_format,
                          int32_t width, int32_t height, int32_t depth) {
    const bool three_d = std::string(call).find("3D") != std::string::npos;
    const bool target_ok = three_d ? (target == gl::TEXTURE_3D || target == gl::TEXTURE_2D_ARRAY)
                                   : (target == gl::TEXTURE_2D || target == gl::TEXTURE_CUBE_MAP);
    if (!target_ok) return error(gl::INVALID_ENUM, call, quote(target) + " is not a target of " + call);
    std::shared_ptr<Texture>* slot = texture_binding(target);
    if (!*slot) return error(gl::INVALID_OPERATION, call, "no texture is bound to " + quote(target));
    Texture& t = **slot;
    const FormatInfo* fi = format_info(internal_format);
    // ES 3.0 §3.8.4: only sized internal formats (not WebGL 1's luminance/alpha pseudo formats).
    bool sized = false;
    for (const Combo& c : kCombosV2) if (c.internal == internal_format && c.internal != c.format) sized = true;
    if (!fi || !sized) return error(gl::INVALID_ENUM, call, quote(internal_format) + " is not a sized internal format");
    if (levels < 1 || width < 1 || height < 1 || depth < 1) return error(gl::INVALID_VALUE, call, "levels and sizes must be at least 1");
    if (target == gl::TEXTURE_CUBE_MAP && width != height) return error(gl::INVALID_VALUE, call, "cube map faces must be square");
    const int32_t max_size = target == gl::TEXTURE_2D ? limits::kMaxTextureSize : target == gl::TEXTURE_CUBE_MAP ? limits::kMaxCubeMapTextureSize : 2048;
    if (width > max_size || height > max_size || depth > (target == gl::TEXTURE_2D ? 1 : 2048))
        return error(gl::INVALID_VALUE, call, "the size exceeds the maximum texture size");
    const int32_t largest = target == gl::TEXTURE_3D ? std::max({width, height, depth}) : std::max(width, height);
    if (levels > log2_floor(largest) + 1) return error(gl::INVALID_OPERATION, call, "too many levels for this size");
    if (t.immutable) return error(gl::INVALID_OPERATION, call, "the texture is already immutable");
    if (fi->kind() == SampleKind::Depth && target != gl::TEXTURE_2D && target != gl::TEXTURE_2D_ARRAY)
        return error(gl::INVALID_OPERATION, call, "depth formats need TEXTURE_2D or TEXTURE_2D_ARRAY");
    // Charged (core/memory_ledger.h) and built before the old images go, which stay if either fails.
    uint64_t bytes = 0;
    for (int f = 0; f < t.faces(); ++f)
        for (int32_t l = 0; l < levels; ++l)
            bytes += Image::allocation_bytes(fi, std::max(1, width >> l), std::max(1, height >> l),
                                             target == gl::TEXTURE_3D ? std::max(1, depth >> l) : depth, 1);
    const uint64_t before = t.memory.bytes();
    if (!t.memory.resize(bytes))
        return error(gl::OUT_OF_MEMORY, call, "the " + std::to_string(levels) + " levels need " + std::to_string(bytes) +
                     " bytes, which " + t.memory.over_limit(bytes - std::min(bytes, before)));
    std::vector<std::vector<Image>> fresh(size_t(t.faces()));
    try {
        for (int f = 0; f < t.faces(); ++f)
            for (int32_t l = 0; l < levels; ++l) {
                const int32_t d = target == gl::TEXTURE_3D ? std::max(1, depth >> l) : depth;
                fresh[size_t(f)].emplace_back().allocate(fi, std::max(1, width >> l), std::max(1, height >> l), d);
            }
    } catch (const std::bad_alloc&) {
        t.memory.force(before);
        return error(gl::OUT_OF_MEMORY, call, "could not allocate " + std::to_string(bytes) + " bytes");
    }
    t.images = std::move(fresh);
    t.immutable = true;
    t.immutable_levels = levels;
    ++t.generation;
}

void Context::generate_mipmap(GLenum target) {
    const char* call = "generateMipmap";
    std::shared_ptr<Texture>* slot = texture_binding(target);
    if (!slot) return error(gl::INVALID_ENUM, call, quote(target) + " is not a texture target here");
    if (!*slot) return error(gl::INVALID_OPERATION, call, "no texture is bound to " + quote(target));
    Texture& t = **slot;
    const int32_t base = t.immutable ? std::clamp(t.base_level, 0, t.immutable_levels - 1) : t.base_level;
    const Image* b = t.find(0, base);
    if (!b) return error(gl::INVALID_OPERATION, call, "the base level has no image");
    for (int f = 1; f < t.faces(); ++f) {
        const Image* other = t.find(f, base);
        if (!other || other->width != b->width || other->height != b->height || other->format != b->format)
            return error(gl::INVALID_OPERATION, call, "the cube map is not cube complete");
    }
    if (target == gl::TEXTURE_CUBE_MAP && b->width != b->height)
        return error(gl::INVALID_OPERATION, call, "the cube map is not cube complete");
    if (version() == 1 && (!is_power_of_two(b->width) || !is_power_of_two(b->height)))
        return error(gl::INVALID_OPERATION, call, "non-power-of-two textures cannot have mipmaps in WebGL 1");
    // ES 3.0 §3.8.11: the format must be colour-renderable and texture-filterable (not integer, depth,
    // or unfilterable float); WebGL 1's unsized formats all qualify except depth.
    const FormatInfo& f = *b->format;
    const CompletenessRules rules = completeness_rules();
    bool ok = f.kind() == SampleKind::Float;
    if (f.encoding == Encoding::Float32 && !rules.float_linear) ok = false;
    if (version() >= 2 && (f.encoding == Encoding::Snorm || f.encoding == Encoding::Rgb9e5 ||
                           (f.base_format == gl::RGB && f.encoding == Encoding::Float16) ||
                           (f.is_float() && f.encoding != Encoding::Float16 && f.encoding != Encoding::Float11_11_10 &&
                            !rules.float_linear) ||
                           f.internal_format == gl::SRGB8))
        ok = false;
    if (!ok) return error(gl::INVALID_OPERATION, call, "mipmaps cannot be generated for this format");
    const uint64_t before = t.memory.bytes(), after = storage_bytes_after_mipmaps(t);
    if (!t.memory.resize(after))
        return error(gl::OUT_OF_MEMORY, call, "the mipmap levels need " + std::to_string(after - std::min(after, before)) +
                     " more bytes, which " + t.memory.over_limit(after - std::min(after, before)));
    try {
        generate_mipmaps(t);
    } catch (const std::bad_alloc&) {
        // Levels written before the failure stay (each is complete); the charge follows them.
        t.memory.force(t.storage_bytes());
        ++t.generation;
        return error(gl::OUT_OF_MEMORY, call, "could not allocate the mipmap levels");
    }
}

// ---------------------------------------------------------------------------- samplers

std::shared_ptr<Sampler> Context::create_sampler() {
    auto s = std::make_shared<Sampler>();
    s->owner = identity();
    s->ever_bound = true;   // ES 3.0 §3.8.2: a sampler exists as soon as it is generated
    return s;
}

void Context::delete_sampler(const std::shared_ptr<Sampler>& s) {
    if (!s) return;
    if (s->owner != identity()) return error(gl::INVALID_OPERATION, "deleteSampler", "the object belongs to another context");
    if (s->deleted) return;
    s->deleted = true;
    for (TextureUnit& u : texture_units_)
        if (u.sampler == s) u.sampler.reset();
}

bool Context::is_sampler(const std::shared_ptr<Sampler>& s) const { return s && s->owner == identity() && !s->deleted; }

void Context::bind_sampler(uint32_t unit, const std::shared_ptr<Sampler>& s) {
    const char* call = "bindSampler";
    if (unit >= uint32_t(limits::kMaxCombinedTextureImageUnits))
        return error(gl::INVALID_VALUE, call, "unit must be below MAX_COMBINED_TEXTURE_IMAGE_UNITS");
    if (!check_object(call, s.get())) return;
    texture_units_[unit].sampler = s;
}

void Context::sampler_parameter(const char* call, const std::shared_ptr<Sampler>& s, GLenum pname, double value) {
    if (!s) return error(gl::INVALID_VALUE, call, "the sampler is null");   // WebGL 2: null throws in JS; softgl reports
    if (!check_object(call, s.get())) return;
    bool bad = false;
    if (set_sampler_param(*this, call, s->params, pname, value, version(), &bad)) return;
    error(gl::INVALID_ENUM, call, quote(pname) + " is not a sampler parameter");
}

Value Context::get_sampler_parameter(const std::shared_ptr<Sampler>& s, GLenum pname) {
    const char* call = "getSamplerParameter";
    if (!s || !check_object(call, s.get())) return Value(Null{});
    if (auto v = get_sampler_param(s->params, pname, version(), extension_enabled("EXT_texture_filter_anisotropic"))) return *v;
    error(gl::INVALID_ENUM, call, quote(pname) + " is not a sampler parameter");
    return Value(Null{});
}

// ---------------------------------------------------------------------------- draw time

namespace {

struct SamplerType {
    glsl::SamplerDim dim;
    SampleKind kind;   // Float (incl. shadow), Int, Uint
    bool shadow;
};

bool sampler_type(uint32_t gl_type, SamplerType& out) {
    using D = glsl::SamplerDim;
    switch (gl_type) {
        case gl::SAMPLER_2D: out = {D::Tex2D, SampleKind::Float, false}; return true;
        case gl::SAMPLER_CUBE: out = {D::Cube, SampleKind::Float, false}; return true;
        case gl::SAMPLER_3D: out = {D::Tex3D, SampleKind::Float, false}; return true;
        case gl::SAMPLER_2D_ARRAY: out = {D::Tex2DArray, SampleKind::Float, false}; return true;
        case gl::SAMPLER_2D_SHADOW: out = {D::Tex2D, SampleKind::Float, true}; return true;
        case gl::SAMPLER_CUBE_SHADOW: out = {D::Cube, SampleKind::Float, true}; return true;
        case gl::SAMPLER_2D_ARRAY_SHADOW: out = {D::Tex2DArray, SampleKind::Float, true}; return true;
        case gl::INT_SAMPLER_2D: out = {D::Tex2D, SampleKind::Int, false}; return true;
        case gl::INT_SAMPLER_CUBE: out = {D::Cube, SampleKind::Int, false}; return true;
        case gl::INT_SAMPLER_3D: out = {D::Tex3D, SampleKind::Int, false}; return true;
        case gl::INT_SAMPLER_2D_ARRAY: out = {D::Tex2DArray, SampleKind::Int, false}; return true;
        case gl::UNSIGNED_INT_SAMPLER_2D: out = {D::Tex2D, SampleKind::Uint, false}; return true;
        case gl::UNSIGNED_INT_SAMPLER_CUBE: out = {D::Cube, SampleKind::Uint, false}; return true;
        case gl::UNSIGNED_INT_SAMPLER_3D: out = {D::Tex3D, SampleKind::Uint, false}; return true;
        case gl::UNSIGNED_INT_SAMPLER_2D_ARRAY: out = {D::Tex2DArray, SampleKind::Uint, false}; return true;
        default: return false;
    }
}

}  // namespace

bool Context::prepare_textures_and_targets(const char* call) {
    const Program& p = *current_program_;
    const CompletenessRules rules = completeness_rules();
    // Reset only the entries the last draw set (resetting all 128 per draw was most of a
    // one-point draw's validation time).
    for (int dim = 0; dim < 4; ++dim) {
        for (uint32_t m = draw_sampler_filled_[dim]; m; m &= m - 1)
            draw_sampler_.units[size_t(__builtin_ctz(m))][size_t(dim)] = BoundTexture{};
        draw_sampler_filled_[dim] = 0;
    }
    draw_sampler_.any_anisotropic = false;
    uint32_t used_units[4] = {0, 0, 0, 0};     // bit per unit, per sampler dimension
    uint32_t unit_type[limits::kMaxCombinedTextureImageUnits] = {};
    for (const auto& u : p.linked->reflection.uniforms) {
        SamplerType st;
        if (!u.is_sampler || !sampler_type(u.gl_type, st)) continue;
        for (int e = 0; e < u.size; ++e) {
            const int32_t unit = p.uniforms[size_t(u.offset + e * u.stride)].i;
            if (unit < 0 || unit >= limits::kMaxCombinedTextureImageUnits) continue;
            // ES 2.0 §2.10.4 / ES 3.0 §2.11.7: samplers of different types on one unit fail the draw.
            if (unit_type[unit] && unit_type[unit] != u.gl_type) {
                error(gl::INVALID_OPERATION, call, "two samplers of different types use texture unit " + std::to_string(unit));
                return false;
            }
            unit_type[unit] = u.gl_type;
            const int dim = dim_index(st.dim);
            used_units[dim] |= 1u << unit;
            const TextureUnit& tu = texture_units_[size_t(unit)];
            const std::shared_ptr<Texture>& tex = dim == 0 ? tu.tex_2d : dim == 1 ? tu.tex_3d : dim == 2 ? tu.cube : tu.array_2d;
            BoundTexture& bt = draw_sampler_.units[size_t(unit)][size_t(dim)];
            if (!tex || bt.texture) continue;
            const SamplerParams& params = tu.sampler && version() >= 2 ? tu.sampler->params : tex->sampler;
            if (!incompleteness(*tex, params, rules).empty()) continue;   // samples as (0, 0, 0, 1)
            const FormatInfo& f = *tex->find(0, tex->immutable ? std::clamp(tex->base_level, 0, tex->immutable_levels - 1) : tex->base_level)->format;
            // WebGL 2.0 §5.22: the texture's kind must match the sampler's (float, int, uint).
            const SampleKind kind = f.kind() == SampleKind::Depth ? SampleKind::Float : f.kind();
            if (kind != st.kind) {
                error(gl::INVALID_OPERATION, call, "the texture on unit " + std::to_string(unit) +
                      " does not match the sampler type of " + u.name);
                return false;
            }
            bt.texture = tex.get();
            draw_sampler_filled_[dim] |= 1u << unit;
            bt.params = params;
            draw_sampler_.any_anisotropic |= params.max_anisotropy > 1.0f;
            bt.base = tex->immutable ? std::clamp(tex->base_level, 0, tex->immutable_levels - 1) : tex->base_level;
            bt.q = needs_mipmaps(params.min_filter) ? max_sampled_level(*tex) : bt.base;
            bt.seamless_cube = version() >= 2;
            bt.depth_as_luminance = version() == 1;
            tex->refresh_sampling(bt.base, bt.q);   // the level table and byte copies for the sampler
        }
    }
    // Once every bound texture's level table is built: what each unit's lookups resolve per draw.
    draw_sampler_.plan_units(draw_sampler_filled_);
    return check_draw_framebuffer(call, used_units);
}

// ---------------------------------------------------------------------------- getParameter

std::optional<Value> Context::texture_framebuffer_parameter(GLenum pname) {
    const TextureUnit& u = texture_units_[state_.active_texture - gl::TEXTURE0];
    switch (pname) {
        case gl::TEXTURE_BINDING_2D: return object_value(u.tex_2d);
        case gl::TEXTURE_BINDING_CUBE_MAP: return object_value(u.cube);
        default: break;
    }
    if (pname == MAX_TEXTURE_MAX_ANISOTROPY_EXT && extension_enabled("EXT_texture_filter_anisotropic"))
        return Value(double(kMaxAnisotropy));
    if (version() >= 2) {
        switch (pname) {
            case gl::TEXTURE_BINDING_3D: return object_value(u.tex_3d);
            case gl::TEXTURE_BINDING_2D_ARRAY: return object_value(u.array_2d);
            case gl::SAMPLER_BINDING: return object_value(u.sampler);
            default: break;
        }
    }
    return framebuffer_parameter(pname);
}

}  // namespace softgl
