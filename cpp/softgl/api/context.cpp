#include "softgl/api/context.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>

#include "softgl/api/blendlab.h"
#include "softgl/surface/formats.h"
#include "softgl/surface/texture.h"

namespace softgl {

namespace {

bool is_face(GLenum face) { return face == gl::FRONT || face == gl::BACK || face == gl::FRONT_AND_BACK; }

bool is_compare_func(GLenum func) { return func >= gl::NEVER && func <= gl::ALWAYS; }

bool is_stencil_op(GLenum op) {
    switch (op) {
        case gl::ZERO: case gl::KEEP: case gl::REPLACE: case gl::INCR: case gl::DECR:
        case gl::INVERT: case gl::INCR_WRAP: case gl::DECR_WRAP: return true;
        default: return false;
    }
}

bool is_constant_color(GLenum f) { return f == gl::CONSTANT_COLOR || f == gl::ONE_MINUS_CONSTANT_COLOR; }
bool is_constant_alpha(GLenum f) { return f == gl::CONSTANT_ALPHA || f == gl::ONE_MINUS_CONSTANT_ALPHA; }

std::string quote(GLenum value) { return enum_name(value); }

// WebGL 1.0 §5.14.12: the ArrayBufferView type that readPixels requires for each pixel type.
GLenum array_type_for(GLenum type) {
    switch (type) {
        case gl::UNSIGNED_SHORT_5_6_5: case gl::UNSIGNED_SHORT_4_4_4_4: case gl::UNSIGNED_SHORT_5_5_5_1:
        case gl::HALF_FLOAT:
            return gl::UNSIGNED_SHORT;
        case gl::UNSIGNED_INT_2_10_10_10_REV: case gl::UNSIGNED_INT_10F_11F_11F_REV:
        case gl::UNSIGNED_INT_5_9_9_9_REV:
            return gl::UNSIGNED_INT;
        default:
            return type;
    }
}

}  // namespace

static FramebufferConfig framebuffer_config(int32_t width, int32_t height, const ContextAttributes& a);
static ColorFormat color_format_of(const std::string& name);

std::string Context::check(int32_t width, int32_t height, const ContextAttributes& a) {
    if (a.version != 1 && a.version != 2)
        return "version must be 1 (WebGL 1) or 2 (WebGL 2), got " + std::to_string(a.version);
    if (a.samples != 0) {
        if (a.samples != 1 && a.samples != 2 && a.samples != 4 && a.samples != 8 && a.samples != 16)
            return "samples must be 1, 2, 4, 8 or 16, got " + std::to_string(a.samples);
        if (a.samples > 1 && !a.antialias) return "samples > 1 needs antialias=True";
    }
    if (a.threads < 0 || a.threads > 256) return "threads must be in [0, 256] (0 = one per core)";
    if (a.power_preference != "default" && a.power_preference != "low-power" &&
        a.power_preference != "high-performance")
        return "powerPreference must be 'default', 'low-power' or 'high-performance'";
    if (a.color_format != "rgba8" && a.color_format != "rgba16f" && a.color_format != "rgba32f")
        return "color_format must be 'rgba8', 'rgba16f' or 'rgba32f', got '" + a.color_format + "'";
    return DefaultFramebuffer::check(framebuffer_config(width, height, a));
}

static ColorFormat color_format_of(const std::string& name) {
    if (name == "rgba16f") return ColorFormat::RGBA16F;
    if (name == "rgba32f") return ColorFormat::RGBA32F;
    return ColorFormat::RGBA8;
}

static FramebufferConfig framebuffer_config(int32_t width, int32_t height, const ContextAttributes& a) {
    FramebufferConfig config;
    config.color_format = color_format_of(a.color_format);
    config.width = width;
    config.height = height;
    config.samples = a.samples ? a.samples : (a.antialias ? 4 : 1);
    config.alpha = a.alpha;
    config.depth = a.depth;
    config.stencil = a.stencil;
    return config;
}

static std::atomic<uintptr_t> next_context_id{1};

Context::Context(int32_t width, int32_t height, const ContextAttributes& attributes)
    : id_(next_context_id++), attributes_(attributes), framebuffer_(framebuffer_config(width, height, attributes), memory_account_) {
    // WebGL: antialias is a request; report what the drawing buffer really has.
    attributes_.antialias = framebuffer_.config().samples > 1;
    attributes_.samples = framebuffer_.config().samples;
    state_.viewport = Rect{0, 0, width, height};
    state_.scissor = Rect{0, 0, width, height};
    default_vertex_array_ = std::make_shared<VertexArray>();
    default_vertex_array_->owner = identity();
    vertex_array_ = default_vertex_array_;
}

// ---------------------------------------------------------------------------- extensions

std::vector<std::string> Context::get_supported_extensions() const {
    std::vector<std::string> names;
    names = texture_extension_names();   // textures.cpp
    if (version() == 1) {   // all of these are core in WebGL 2
        names.push_back("ANGLE_instanced_arrays");
        names.push_back("EXT_blend_minmax");
        names.push_back("EXT_frag_depth");
        names.push_back("EXT_shader_texture_lod");
        names.push_back("OES_element_index_uint");
        names.push_back("OES_standard_derivatives");
        names.push_back("OES_vertex_array_object");
    }
    names.push_back("SOFTGL_fog");      // softgl's own: they never change pure WebGL code
    names.push_back("SOFTGL_smooth");
    if (!framebuffer_.is_float()) {   // they record and resolve RGBA8 drawing-buffer colours
        names.push_back("SOFTGL_exact_transparency");
        names.push_back("SOFTGL_introspection");
    }
    return names;
}

bool Context::enable_extension(const std::string& name) {
    if (enable_texture_extension(name)) return true;   // textures.cpp
    if (name == "SOFTGL_fog") return ext_fog_ = true;
    if (name == "SOFTGL_smooth") return ext_smooth_ = true;
    if (framebuffer_.is_float() && (name == "SOFTGL_exact_transparency" || name == "SOFTGL_introspection"))
        return false;   // RGBA8 drawing buffers only (see get_supported_extensions)
    if (name == "SOFTGL_exact_transparency") return blendlab().ext_exact = true;
    if (name == "SOFTGL_introspection") return blendlab().ext_introspection = true;
    if (version() != 1) return false;
    if (name == "EXT_blend_minmax") return ext_blend_minmax_ = true;
    if (name == "OES_vertex_array_object") return ext_vertex_array_object_ = true;
    if (name == "ANGLE_instanced_arrays") return ext_instanced_arrays_ = true;
    if (name == "OES_element_index_uint") return ext_element_index_uint_ = true;
    // Shader extensions: what they add is the GLSL ES 1.00 directive (compile_shader).
    if (name == "OES_standard_derivatives") return ext_standard_derivatives_ = true;
    if (name == "EXT_frag_depth") return ext_frag_depth_ = true;
    if (name == "EXT_shader_texture_lod") return ext_shader_texture_lod_ = true;
    return false;
}

bool Context::extension_enabled(const std::string& name) const {
    if (texture_extension_enabled(name)) return true;   // textures.cpp
    if (name == "EXT_blend_minmax") return ext_blend_minmax_;
    if (name == "OES_vertex_array_object") return ext_vertex_array_object_;
    if (name == "ANGLE_instanced_arrays") return ext_instanced_arrays_;
    if (name == "OES_element_index_uint") return ext_element_index_uint_;
    if (name == "OES_standard_derivatives") return ext_standard_derivatives_;
    if (name == "EXT_frag_depth") return ext_frag_depth_;
    if (name == "EXT_shader_texture_lod") return ext_shader_texture_lod_;
    if (name == "SOFTGL_fog") return ext_fog_;
    if (name == "SOFTGL_smooth") return ext_smooth_;
    if (name == "SOFTGL_exact_transparency") return blendlab_ && blendlab_->ext_exact;
    if (name == "SOFTGL_introspection") return blendlab_ && blendlab_->ext_introspection;
    return false;
}

// ---------------------------------------------------------------------------- capabilities

bool* Context::capability(GLenum cap) {
    switch (cap) {
        case gl::BLEND: return &state_.blend.enabled;
        case gl::CULL_FACE: return &state_.cull_face;
        case gl::DEPTH_TEST: return &state_.depth_test;
        case gl::DITHER: return &state_.dither;
        case gl::POLYGON_OFFSET_FILL: return &state_.polygon_offset_fill;
        case gl::SAMPLE_ALPHA_TO_COVERAGE: return &state_.sample_alpha_to_coverage;
        case gl::SAMPLE_COVERAGE: return &state_.sample_coverage;
        case gl::SCISSOR_TEST: return &state_.scissor_test;
        case gl::STENCIL_TEST: return &state_.stencil_test;
        case gl::RASTERIZER_DISCARD: return version() >= 2 ? &state_.rasterizer_discard : nullptr;
        case gl::FOG: return ext_fog_ ? &state_.fog.enabled : nullptr;
        case gl::FOG_BLEND_AWARE_SOFTGL: return ext_fog_ ? &state_.fog.blend_aware : nullptr;
        case gl::POLYGON_SMOOTH: return ext_smooth_ ? &state_.smooth.polygon : nullptr;
        case gl::LINE_SMOOTH: return ext_smooth_ ? &state_.smooth.line : nullptr;
        case gl::POINT_SMOOTH: return ext_smooth_ ? &state_.smooth.point : nullptr;
        default: return blendlab_ ? blendlab_->capability(cap) : nullptr;   // blend lab capabilities
    }
}

void Context::set_capability(const char* call, GLenum cap, bool value) {
    bool* flag = capability(cap);
    if (!flag) return error(gl::INVALID_ENUM, call, quote(cap) + " is not a capability of this context");
    *flag = value;
}

bool Context::is_enabled(GLenum cap) {
    bool* flag = capability(cap);
    if (!flag) {
        error(gl::INVALID_ENUM, "isEnabled", quote(cap) + " is not a capability of this context");
        return false;
    }
    return *flag;
}

// ---------------------------------------------------------------------------- blending

bool Context::valid_blend_factor(GLenum f, bool is_destination) const {
    switch (f) {
        case gl::ZERO: case gl::ONE: case gl::SRC_COLOR: case gl::ONE_MINUS_SRC_COLOR:
        case gl::DST_COLOR: case gl::ONE_MINUS_DST_COLOR: case gl::SRC_ALPHA:
        case gl::ONE_MINUS_SRC_ALPHA: case gl::DST_ALPHA: case gl::ONE_MINUS_DST_ALPHA:
        case gl::CONSTANT_COLOR: case gl::ONE_MINUS_CONSTANT_COLOR: case gl::CONSTANT_ALPHA:
        case gl::ONE_MINUS_CONSTANT_ALPHA:
            return true;
        case gl::SRC_ALPHA_SATURATE:
            // ES 2.0 allows it only as a source factor; ES 3.0 §4.1.7 for both.
            return !is_destination || version() >= 2;
        default:
            return false;
    }
}

bool Context::check_blend_factors(const char* call, GLenum src_rgb, GLenum dst_rgb,
                                  GLenum src_alpha, GLenum dst_alpha) {
    const GLenum factors[4] = {src_rgb, dst_rgb, src_alpha, dst_alpha};
    for (int i = 0; i < 4; ++i)
        if (!valid_blend_factor(factors[i], i % 2 == 1)) {
            error(gl::INVALID_ENUM, call, quote(factors[i]) + " is not a valid " +
                  (i % 2 ? "destination" : "source") + " blend factor here");
            return false;
        }
    // WebGL 1.0 §6.13: constant color and constant alpha cannot be paired (RGB factors only).
    if ((is_constant_color(src_rgb) && is_constant_alpha(dst_rgb)) ||
        (is_constant_alpha(src_rgb) && is_constant_color(dst_rgb))) {
        error(gl::INVALID_OPERATION, call,
              "a constant color factor cannot be combined with a constant alpha factor in WebGL");
        return false;
    }
    return true;
}

void Context::blend_func(GLenum sfactor, GLenum dfactor) {
    if (!check_blend_factors("blendFunc", sfactor, dfactor, sfactor, dfactor)) return;
    state_.blend.src_rgb = state_.blend.src_alpha = sfactor;
    state_.blend.dst_rgb = state_.blend.dst_alpha = dfactor;
}

void Context::blend_func_separate(GLenum src_rgb, GLenum dst_rgb, GLenum src_alpha, GLenum dst_alpha) {
    if (!check_blend_factors("blendFuncSeparate", src_rgb, dst_rgb, src_alpha, dst_alpha)) return;
    state_.blend.src_rgb = src_rgb;
    state_.blend.dst_rgb = dst_rgb;
    state_.blend.src_alpha = src_alpha;
    state_.blend.dst_alpha = dst_alpha;
}

bool Context::valid_blend_equation(GLenum mode) const {
    switch (mode) {
        case gl::FUNC_ADD: case gl::FUNC_SUBTRACT: case gl::FUNC_REVERSE_SUBTRACT: return true;
        case gl::MIN: case gl::MAX: return version() >= 2 || ext_blend_minmax_;
        default: return false;
    }
}

void Context::blend_equation(GLenum mode) {
    if (!valid_blend_equation(mode))
        return error(gl::INVALID_ENUM, "blendEquation", quote(mode) + " is not a valid blend equation here");
    state_.blend.equation_rgb = state_.blend.equation_alpha = mode;
}

void Context::blend_equation_separate(GLenum mode_rgb, GLenum mode_alpha) {
    for (GLenum mode : {mode_rgb, mode_alpha})
        if (!valid_blend_equation(mode))
            return error(gl::INVALID_ENUM, "blendEquationSeparate",
                         quote(mode) + " is not a valid blend equation here");
    state_.blend.equation_rgb = mode_rgb;
    state_.blend.equation_alpha = mode_alpha;
}

void Context::blend_color(float r, float g, float b, float a) {
    // ES 2.0 §4.1.6 clamps the constant color when it is specified; ES 3.0 keeps it as given and
    // clamps it at use for fixed-point buffers only (§4.1.7). In WebGL 1 the float colour buffer
    // extensions lift the clamp on input (EXT_color_buffer_half_float, WEBGL_color_buffer_float).
    const bool float_buffers = texture_extension_enabled("WEBGL_color_buffer_float") ||
                               texture_extension_enabled("EXT_color_buffer_half_float");
    if (version() == 1 && !float_buffers) state_.blend.color = {clamp01(r), clamp01(g), clamp01(b), clamp01(a)};
    else state_.blend.color = {r, g, b, a};
}

// ---------------------------------------------------------------------------- depth and stencil

void Context::depth_func(GLenum func) {
    if (!is_compare_func(func))
        return error(gl::INVALID_ENUM, "depthFunc", quote(func) + " is not a comparison function");
    state_.depth_func = func;
}

void Context::depth_range(float z_near, float z_far) {
    // WebGL 1.0 §6.12 (also WebGL 2): near > far is INVALID_OPERATION; values clamp to [0, 1].
    if (z_near > z_far)
        return error(gl::INVALID_OPERATION, "depthRange", "zNear > zFar is not allowed in WebGL");
    state_.depth_range = {clamp01(z_near), clamp01(z_far)};
}

void Context::clear_depth(float depth) { state_.clear_depth = clamp01(depth); }

static int32_t clamp_stencil_ref(int32_t ref) {
    // ES 3.0 §4.1.5: the reference value is clamped to [0, 2^s - 1] (s = 8 bits).
    return std::clamp(ref, 0, (1 << DefaultFramebuffer::kStencilBits) - 1);
}

void Context::stencil_func(GLenum func, int32_t ref, uint32_t mask) {
    stencil_func_separate(gl::FRONT_AND_BACK, func, ref, mask);
}

void Context::stencil_func_separate(GLenum face, GLenum func, int32_t ref, uint32_t mask) {
    const char* call = "stencilFuncSeparate";
    if (!is_face(face)) return error(gl::INVALID_ENUM, call, quote(face) + " is not a face");
    if (!is_compare_func(func)) return error(gl::INVALID_ENUM, call, quote(func) + " is not a comparison function");
    for (StencilFace* f : {&state_.stencil_front, &state_.stencil_back}) {
        if ((f == &state_.stencil_front && face == gl::BACK) || (f == &state_.stencil_back && face == gl::FRONT))
            continue;
        f->func = func;
        f->ref = clamp_stencil_ref(ref);
        f->value_mask = mask;
    }
}

void Context::stencil_op(GLenum fail, GLenum zfail, GLenum zpass) {
    stencil_op_separate(gl::FRONT_AND_BACK, fail, zfail, zpass);
}

void Context::stencil_op_separate(GLenum face, GLenum fail, GLenum zfail, GLenum zpass) {
    const char* call = "stencilOpSeparate";
    if (!is_face(face)) return error(gl::INVALID_ENUM, call, quote(face) + " is not a face");
    for (GLenum op : {fail, zfail, zpass})
        if (!is_stencil_op(op)) return error(gl::INVALID_ENUM, call, quote(op) + " is not a stencil operation");
    for (StencilFace* f : {&state_.stencil_front, &state_.stencil_back}) {
        if ((f == &state_.stencil_front && face == gl::BACK) || (f == &state_.stencil_back && face == gl::FRONT))
            continue;
        f->fail = fail;
        f->depth_fail = zfail;
        f->depth_pass = zpass;
    }
}

void Context::stencil_mask(uint32_t mask) { stencil_mask_separate(gl::FRONT_AND_BACK, mask); }

void Context::stencil_mask_separate(GLenum face, uint32_t mask) {
    if (!is_face(face)) return error(gl::INVALID_ENUM, "stencilMaskSeparate", quote(face) + " is not a face");
    if (face != gl::BACK) state_.stencil_front.write_mask = mask;
    if (face != gl::FRONT) state_.stencil_back.write_mask = mask;
}

// ---------------------------------------------------------------------------- rasterization

void Context::cull_face(GLenum mode) {
    if (!is_face(mode)) return error(gl::INVALID_ENUM, "cullFace", quote(mode) + " is not a face");
    state_.cull_face_mode = mode;
}

void Context::front_face(GLenum mode) {
    if (mode != gl::CW && mode != gl::CCW)
        return error(gl::INVALID_ENUM, "frontFace", quote(mode) + " is neither CW nor CCW");
    state_.front_face = mode;
}

void Context::line_width(float width) {
    // WebGL: NaN or <= 0 is INVALID_VALUE; the value is kept as given (clamped when drawing).
    if (!(width > 0.0f))
        return error(gl::INVALID_VALUE, "lineWidth", "width must be a positive number");
    state_.line_width = width;
}

void Context::polygon_offset(float factor, float units) {
    state_.polygon_offset_factor = factor;
    state_.polygon_offset_units = units;
}

void Context::sample_coverage(float value, bool invert) {
    state_.sample_coverage_value = clamp01(value);
    state_.sample_coverage_invert = invert;
}

void Context::scissor(int32_t x, int32_t y, int32_t width, int32_t height) {
    if (width < 0 || height < 0)
        return error(gl::INVALID_VALUE, "scissor", "width and height must not be negative");
    state_.scissor = Rect{x, y, width, height};
}

void Context::viewport(int32_t x, int32_t y, int32_t width, int32_t height) {
    if (width < 0 || height < 0)
        return error(gl::INVALID_VALUE, "viewport", "width and height must not be negative");
    // ES 3.0 §2.12.1: width and height are clamped to MAX_VIEWPORT_DIMS.
    state_.viewport = Rect{x, y, std::min(width, limits::kMaxViewportDims),
                           std::min(height, limits::kMaxViewportDims)};
}

// ---------------------------------------------------------------------------- misc state

void Context::hint(GLenum target, GLenum mode) {
    GLenum* slot = nullptr;
    if (target == gl::GENERATE_MIPMAP_HINT) slot = &state_.generate_mipmap_hint;
    else if (target == gl::FRAGMENT_SHADER_DERIVATIVE_HINT && (version() >= 2 || ext_standard_derivatives_))
        slot = &state_.fragment_shader_derivative_hint;
    else if (ext_smooth_ && target == gl::POLYGON_SMOOTH_HINT) slot = &state_.smooth.polygon_hint;
    else if (ext_smooth_ && target == gl::LINE_SMOOTH_HINT) slot = &state_.smooth.line_hint;
    else if (ext_smooth_ && target == gl::POINT_SMOOTH_HINT) slot = &state_.smooth.point_hint;
    if (!slot) return error(gl::INVALID_ENUM, "hint", quote(target) + " is not a hint target here");
    if (mode != gl::DONT_CARE && mode != gl::FASTEST && mode != gl::NICEST)
        return error(gl::INVALID_ENUM, "hint", quote(mode) + " is not a hint mode");
    *slot = mode;
}

void Context::pixel_store_i(GLenum pname, int32_t param) {
    const char* call = "pixelStorei";
    PixelStore& ps = state_.pixel_store;
    switch (pname) {
        case gl::PACK_ALIGNMENT:
        case gl::UNPACK_ALIGNMENT:
            if (param != 1 && param != 2 && param != 4 && param != 8)
                return error(gl::INVALID_VALUE, call, "alignment must be 1, 2, 4 or 8");
            (pname == gl::PACK_ALIGNMENT ? ps.pack_alignment : ps.unpack_alignment) = param;
            return;
        case gl::UNPACK_FLIP_Y_WEBGL: ps.unpack_flip_y = param != 0; return;
        case gl::UNPACK_PREMULTIPLY_ALPHA_WEBGL: ps.unpack_premultiply_alpha = param != 0; return;
        case gl::UNPACK_COLORSPACE_CONVERSION_WEBGL:
            if (GLenum(param) != gl::NONE && GLenum(param) != gl::BROWSER_DEFAULT_WEBGL)
                return error(gl::INVALID_VALUE, call, "must be NONE or BROWSER_DEFAULT_WEBGL");
            ps.unpack_colorspace_conversion = GLenum(param);
            return;
        default: break;
    }
    int32_t* slot = nullptr;
    if (version() >= 2) {
        switch (pname) {
            case gl::PACK_ROW_LENGTH: slot = &ps.pack_row_length; break;
            case gl::PACK_SKIP_PIXELS: slot = &ps.pack_skip_pixels; break;
            case gl::PACK_SKIP_ROWS: slot = &ps.pack_skip_rows; break;
            case gl::UNPACK_ROW_LENGTH: slot = &ps.unpack_row_length; break;
            case gl::UNPACK_IMAGE_HEIGHT: slot = &ps.unpack_image_height; break;
            case gl::UNPACK_SKIP_PIXELS: slot = &ps.unpack_skip_pixels; break;
            case gl::UNPACK_SKIP_ROWS: slot = &ps.unpack_skip_rows; break;
            case gl::UNPACK_SKIP_IMAGES: slot = &ps.unpack_skip_images; break;
            default: break;
        }
    }
    if (!slot) return error(gl::INVALID_ENUM, call, quote(pname) + " is not a pixel storage parameter here");
    if (param < 0) return error(gl::INVALID_VALUE, call, "the value must not be negative");
    *slot = param;
}

void Context::active_texture(GLenum texture) {
    if (texture < gl::TEXTURE0 || texture >= gl::TEXTURE0 + uint32_t(limits::kMaxCombinedTextureImageUnits))
        return error(gl::INVALID_ENUM, "activeTexture",
                     quote(texture) + " is not TEXTURE0 .. TEXTURE" +
                         std::to_string(limits::kMaxCombinedTextureImageUnits - 1));
    state_.active_texture = texture;
}

// ---------------------------------------------------------------------------- framebuffer ops

void Context::clear(uint32_t mask) {
    const uint32_t all = gl::COLOR_BUFFER_BIT | gl::DEPTH_BUFFER_BIT | gl::STENCIL_BUFFER_BIT;
    if (mask & ~all)
        return error(gl::INVALID_VALUE, "clear", "mask has bits other than COLOR, DEPTH and STENCIL_BUFFER_BIT");
    if (state_.rasterizer_discard) return;  // ES 3.0 §4.2.3: clears are discarded too
    if (clear_framebuffer_object(mask)) return;   // a bound framebuffer object (framebuffers.cpp)
    // ES 2.0 §4.2.3: clear honours the scissor, the color mask, depth mask and stencil write mask,
    // and ignores the viewport.
    const Rect region = state_.scissor_test ? state_.scissor
                                            : Rect{0, 0, framebuffer_.width(), framebuffer_.height()};
    if ((mask & gl::COLOR_BUFFER_BIT) && default_draw_buffer_ != gl::NONE)
        framebuffer_.clear_color(region, state_.clear_color, state_.color_mask);
    if (blendlab_) blendlab_->on_clear(region, mask, framebuffer_);   // forget captured/logged fragments
    if ((mask & gl::DEPTH_BUFFER_BIT) && state_.depth_mask) framebuffer_.clear_depth(region, state_.clear_depth);
    if (mask & gl::STENCIL_BUFFER_BIT)
        framebuffer_.clear_stencil(region, state_.clear_stencil, state_.stencil_front.write_mask);
}

GLenum Context::drawing_buffer_read_type() const {
    switch (framebuffer_.config().color_format) {
        // WebGL 1 has no HALF_FLOAT enum outside OES_texture_half_float: FLOAT there.
        case ColorFormat::RGBA16F: return version() >= 2 ? gl::HALF_FLOAT : gl::FLOAT;
        case ColorFormat::RGBA32F: return gl::FLOAT;
        default: return gl::UNSIGNED_BYTE;
    }
}

size_t Context::pack_size(int32_t width, int32_t height, int pixel_bytes) const {
    if (width <= 0 || height <= 0) return 0;
    const PixelStore& ps = state_.pixel_store;
    const uint64_t pixel = uint64_t(pixel_bytes);
    const uint64_t row_pixels = ps.pack_row_length > 0 ? uint64_t(ps.pack_row_length) : uint64_t(width);
    const uint64_t align = uint64_t(ps.pack_alignment);
    const uint64_t stride = (row_pixels * pixel + align - 1) / align * align;
    // ES 3.0 §4.3.1: the last row is not padded.
    return size_t((uint64_t(ps.pack_skip_rows) + uint64_t(height) - 1) * stride +
                  (uint64_t(ps.pack_skip_pixels) + uint64_t(width)) * pixel);
}

bool Context::read_pixels(int32_t x, int32_t y, int32_t width, int32_t height, GLenum format,
                          GLenum type, GLenum dst_type, uint8_t* dst, size_t dst_bytes, bool packed) {
    const char* call = "readPixels";
    // WebGL 2.0 §3.7.10: with a PIXEL_PACK_BUFFER bound, pixels go there (offset form) only.
    if (pixel_pack_buffer_ && !reading_to_pack_buffer_) {
        error(gl::INVALID_OPERATION, call, "a buffer is bound to PIXEL_PACK_BUFFER: pass a byte offset into it");
        return false;
    }
    if (reading_framebuffer_object())   // framebuffers.cpp: any readable attachment format
        return read_pixels_framebuffer_object(x, y, width, height, format, type, dst_type, dst, dst_bytes, packed);
    const bool format_known = format == gl::RGBA || format == gl::RGB || format == gl::ALPHA ||
                              (version() >= 2 && (format == gl::RED || format == gl::RG ||
                                                  format == gl::RED_INTEGER || format == gl::RG_INTEGER ||
                                                  format == gl::RGB_INTEGER || format == gl::RGBA_INTEGER));
    bool type_known = type == gl::UNSIGNED_BYTE || type == gl::UNSIGNED_SHORT_5_6_5 ||
                      type == gl::UNSIGNED_SHORT_4_4_4_4 || type == gl::UNSIGNED_SHORT_5_5_5_1;
    if (framebuffer_.is_float()) type_known = type_known || type == gl::FLOAT;   // float drawing buffers
    if (version() >= 2)
        type_known = type_known || type == gl::BYTE || type == gl::SHORT || type == gl::UNSIGNED_SHORT ||
                     type == gl::INT || type == gl::UNSIGNED_INT || type == gl::FLOAT ||
                     type == gl::HALF_FLOAT || type == gl::UNSIGNED_INT_2_10_10_10_REV ||
                     type == gl::UNSIGNED_INT_10F_11F_11F_REV || type == gl::UNSIGNED_INT_5_9_9_9_REV;
    if (!format_known) { error(gl::INVALID_ENUM, call, quote(format) + " is not a pixel format here"); return false; }
    if (!type_known) { error(gl::INVALID_ENUM, call, quote(type) + " is not a pixel type here"); return false; }
    if (width < 0 || height < 0) { error(gl::INVALID_VALUE, call, "width and height must not be negative"); return false; }
    // WebGL 1.0 §5.14.12, ES 3.0 §4.3.2: RGBA/UNSIGNED_BYTE for a normalized buffer, RGBA/FLOAT
    // for a float one, or the implementation-chosen pair (IMPLEMENTATION_COLOR_READ_*: the same,
    // except RGBA/HALF_FLOAT for an RGBA16F drawing buffer in WebGL 2).
    const bool float_buffer = framebuffer_.is_float();
    const GLenum canonical = float_buffer ? gl::FLOAT : gl::UNSIGNED_BYTE;
    if (!(format == gl::RGBA && (type == canonical || type == drawing_buffer_read_type()))) {
        const std::string fmt = float_buffer ? "a float (" + attributes_.color_format + ")" : "an RGBA8";
        error(gl::INVALID_OPERATION, call, quote(format) + "/" + quote(type) + " cannot be read from " + fmt +
              " drawing buffer; use RGBA/" + quote(canonical) +
              (drawing_buffer_read_type() != canonical ? " or RGBA/" + quote(drawing_buffer_read_type()) : ""));
        return false;
    }
    const int pixel = type == gl::FLOAT ? 16 : type == gl::HALF_FLOAT ? 8 : 4;
    const PixelStore& store = state_.pixel_store;
    if (packed && store.pack_row_length > 0 && int64_t(store.pack_skip_pixels) + width > store.pack_row_length) {
        // WebGL 2.0 §5.35: a row that would not fit in PACK_ROW_LENGTH is an error, not an overlap.
        error(gl::INVALID_OPERATION, call, "PACK_SKIP_PIXELS + width exceeds PACK_ROW_LENGTH");
        return false;
    }
    if (dst_type != array_type_for(type)) {
        error(gl::INVALID_OPERATION, call, "the destination array's element type does not match " + quote(type));
        return false;
    }
    const size_t needed = packed ? pack_size(width, height, pixel) : size_t(width) * size_t(height) * size_t(pixel);
    if (dst_bytes < needed) {
        error(gl::INVALID_OPERATION, call, "the destination holds " + std::to_string(dst_bytes) +
              " bytes, " + std::to_string(needed) + " are needed");
        return false;
    }
    if (width == 0 || height == 0) return true;
    std::ptrdiff_t stride = std::ptrdiff_t(width) * pixel;
    uint8_t* origin = dst;
    if (packed) {
        const PixelStore& ps = state_.pixel_store;
        const int64_t row_pixels = ps.pack_row_length > 0 ? ps.pack_row_length : width;
        stride = std::ptrdiff_t((row_pixels * pixel + ps.pack_alignment - 1) / ps.pack_alignment * ps.pack_alignment);
        origin = dst + ps.pack_skip_rows * stride + std::ptrdiff_t(ps.pack_skip_pixels) * pixel;
    }
    if (type == gl::UNSIGNED_BYTE) {
        // A multisampled buffer is resolved as it is copied: in bands of rows on the pool when
        // the read is large (each row belongs to one band, so the bytes do not depend on the
        // thread count: docs/architecture.md, "Threads").
        constexpr int64_t kBandRows = 16, kPoolPixels = 1 << 15;
        const int64_t y0 = std::max<int64_t>(y, 0), y1 = std::min<int64_t>(int64_t(y) + height, framebuffer_.height());
        if (framebuffer_.config().samples == 1 || y1 - y0 <= kBandRows || int64_t(width) * (y1 - y0) < kPoolPixels) {
            framebuffer_.read_rgba8(x, y, width, height, origin, stride);
            return true;
        }
        const size_t bands = size_t((y1 - y0 + kBandRows - 1) / kBandRows);
        pool().parallel_for(bands, [&](size_t b, unsigned) {
            const int64_t first = y0 + int64_t(b) * kBandRows, rows = std::min(kBandRows, y1 - first);
            framebuffer_.read_rgba8(x, int32_t(first), width, int32_t(rows), origin + (first - y) * stride, stride);
        });
        return true;
    }
    // Float drawing buffers: resolved floats, as float32 or (implementation pair) binary16 bits.
    // Rows may be only 2-byte aligned (PACK_ALIGNMENT), so pixels are copied byte-wise.
    std::vector<float> row(size_t(width) * 4);
    for (int32_t r = 0; r < height; ++r) {
        const int64_t sy = int64_t(y) + r;
        if (sy < 0 || sy >= framebuffer_.height()) continue;   // outside the buffer: left as it is
        std::fill(row.begin(), row.end(), 0.0f);
        framebuffer_.read_float(x, int32_t(sy), width, 1, row.data(), std::ptrdiff_t(width) * 4);
        uint8_t* out = origin + std::ptrdiff_t(r) * stride;
        for (int32_t c = 0; c < width; ++c) {
            const int64_t sx = int64_t(x) + c;
            if (sx < 0 || sx >= framebuffer_.width()) continue;
            if (type == gl::FLOAT) {
                std::memcpy(out + std::ptrdiff_t(c) * 16, &row[size_t(c) * 4], 16);
            } else {
                uint16_t h[4];
                for (int k = 0; k < 4; ++k) h[k] = float_to_half(row[size_t(c) * 4 + size_t(k)]);
                std::memcpy(out + std::ptrdiff_t(c) * 8, h, 8);
            }
        }
    }
    return true;
}

void Context::read_pixels_to_pack_buffer(int32_t x, int32_t y, int32_t width, int32_t height, GLenum format,
                                         GLenum type, int64_t offset) {
    const char* call = "readPixels";
    if (!pixel_pack_buffer_) return error(gl::INVALID_OPERATION, call, "an offset needs a buffer bound to PIXEL_PACK_BUFFER");
    if (offset < 0) return error(gl::INVALID_VALUE, call, "the offset must not be negative");
    const GLenum array_type = array_type_for(type);
    const int64_t size = array_type == gl::UNSIGNED_BYTE || array_type == gl::BYTE ? 1
                       : array_type == gl::SHORT || array_type == gl::UNSIGNED_SHORT ? 2 : 4;
    // ES 3.0 §4.3.1: the offset must be a multiple of the type's size.
    if (offset % size != 0)
        return error(gl::INVALID_OPERATION, call, "the offset is not a multiple of " + std::to_string(size) + " bytes (" + quote(type) + ")");
    std::vector<uint8_t>& data = pixel_pack_buffer_->data;
    if (uint64_t(offset) > data.size()) return error(gl::INVALID_OPERATION, call, "the offset is past the end of the PIXEL_PACK_BUFFER");
    reading_to_pack_buffer_ = true;
    read_pixels(x, y, width, height, format, type, array_type, data.data() + offset, data.size() - size_t(offset), true);
    reading_to_pack_buffer_ = false;
}

ThreadPool& Context::pool() {
    if (!pool_) pool_ = std::make_unique<ThreadPool>(unsigned(std::max(0, attributes_.threads)));
    pool_->set_spin_nanoseconds(int64_t(tuning_.pool_spin_microseconds) * 1000);
    return *pool_;
}

void Context::present() {
    if (attributes_.preserve_drawing_buffer) return;
    framebuffer_ = DefaultFramebuffer(framebuffer_.config(), memory_account_);
    if (blendlab_) blendlab_->on_present(framebuffer_);
}

std::string Context::resize(int32_t width, int32_t height) {
    FramebufferConfig config = framebuffer_.config();
    config.width = width;
    config.height = height;
    std::string why = DefaultFramebuffer::check(config, framebuffer_.memory_bytes(), memory_account_.get());
    if (!why.empty()) return why;
    try {
        framebuffer_ = DefaultFramebuffer(config, memory_account_);
    } catch (const std::bad_alloc&) {
        return "could not allocate the " + std::to_string(DefaultFramebuffer::bytes_needed(config)) +
               "-byte drawing buffer";
    }
    if (blendlab_) blendlab_->on_present(framebuffer_);
    return "";
}

}  // namespace softgl
