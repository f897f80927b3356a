// getParameter: every WebGL 1 / WebGL 2 parameter name, returned in WebGL's shape
// (WebGL 1.0 §5.14.3 and WebGL 2.0 §3.7.2 tables).
#include <cmath>

#include "softgl/api/context.h"

namespace softgl {

namespace {

Value i(int64_t v) { return Value(v); }
Value f(float v) { return Value(double(v)); }
Value b(bool v) { return Value(v); }
Value ints(std::vector<int32_t> v) { return Value(Int32Array{std::move(v)}); }
Value floats(std::vector<float> v) { return Value(Float32Array{std::move(v)}); }
Value rect(const Rect& r) { return ints({r.x, r.y, r.width, r.height}); }

// Limits of WebGL 2 features. Chosen at least at the ES 3.0 minimums (ES 3.0 §6.2, table 6.3x).
constexpr int32_t kMaxVertexUniformComponents = limits::kMaxVertexUniformVectors * 4;
constexpr int32_t kMaxFragmentUniformComponents = limits::kMaxFragmentUniformVectors * 4;
constexpr int32_t kMaxUniformBlocksPerStage = 12;
constexpr int32_t kMaxUniformBlockSize = 16384;
constexpr int32_t kMaxVaryingComponents = limits::kMaxVaryingVectors * 4;
constexpr int32_t kMaxDrawBuffers = 8;

// The fixed-function state of WebGL 1.
std::optional<Value> state_parameter(const State& s, GLenum pname) {
    switch (pname) {
        case gl::BLEND: return b(s.blend.enabled);
        case gl::CULL_FACE: return b(s.cull_face);
        case gl::DEPTH_TEST: return b(s.depth_test);
        case gl::DITHER: return b(s.dither);
        case gl::POLYGON_OFFSET_FILL: return b(s.polygon_offset_fill);
        case gl::SAMPLE_ALPHA_TO_COVERAGE: return b(s.sample_alpha_to_coverage);
        case gl::SAMPLE_COVERAGE: return b(s.sample_coverage);
        case gl::SCISSOR_TEST: return b(s.scissor_test);
        case gl::STENCIL_TEST: return b(s.stencil_test);

        // Blending
        case gl::BLEND_COLOR: return floats({s.blend.color.begin(), s.blend.color.end()});
        case gl::BLEND_SRC_RGB: return i(s.blend.src_rgb);
        case gl::BLEND_DST_RGB: return i(s.blend.dst_rgb);
        case gl::BLEND_SRC_ALPHA: return i(s.blend.src_alpha);
        case gl::BLEND_DST_ALPHA: return i(s.blend.dst_alpha);
        case gl::BLEND_EQUATION_RGB: return i(s.blend.equation_rgb);   // == BLEND_EQUATION
        case gl::BLEND_EQUATION_ALPHA: return i(s.blend.equation_alpha);

        // Depth
        case gl::DEPTH_FUNC: return i(s.depth_func);
        case gl::DEPTH_WRITEMASK: return b(s.depth_mask);
        case gl::DEPTH_RANGE: return floats({s.depth_range[0], s.depth_range[1]});
        case gl::DEPTH_CLEAR_VALUE: return f(s.clear_depth);

        // Stencil
        case gl::STENCIL_FUNC: return i(s.stencil_front.func);
        case gl::STENCIL_REF: return i(s.stencil_front.ref);
        case gl::STENCIL_VALUE_MASK: return i(s.stencil_front.value_mask);
        case gl::STENCIL_WRITEMASK: return i(s.stencil_front.write_mask);
        case gl::STENCIL_FAIL: return i(s.stencil_front.fail);
        case gl::STENCIL_PASS_DEPTH_FAIL: return i(s.stencil_front.depth_fail);
        case gl::STENCIL_PASS_DEPTH_PASS: return i(s.stencil_front.depth_pass);
        case gl::STENCIL_BACK_FUNC: return i(s.stencil_back.func);
        case gl::STENCIL_BACK_REF: return i(s.stencil_back.ref);
        case gl::STENCIL_BACK_VALUE_MASK: return i(s.stencil_back.value_mask);
        case gl::STENCIL_BACK_WRITEMASK: return i(s.stencil_back.write_mask);
        case gl::STENCIL_BACK_FAIL: return i(s.stencil_back.fail);
        case gl::STENCIL_BACK_PASS_DEPTH_FAIL: return i(s.stencil_back.depth_fail);
        case gl::STENCIL_BACK_PASS_DEPTH_PASS: return i(s.stencil_back.depth_pass);
        case gl::STENCIL_CLEAR_VALUE: return i(s.clear_stencil);

        // Color
        case gl::COLOR_CLEAR_VALUE: return floats({s.clear_color.begin(), s.clear_color.end()});
        case gl::COLOR_WRITEMASK:
            return Value(BoolList{{s.color_mask[0], s.color_mask[1], s.color_mask[2], s.color_mask[3]}});

        // Rasterization
        case gl::CULL_FACE_MODE: return i(s.cull_face_mode);
        case gl::FRONT_FACE: return i(s.front_face);
        case gl::LINE_WIDTH: return f(s.line_width);
        case gl::POLYGON_OFFSET_FACTOR: return f(s.polygon_offset_factor);
        case gl::POLYGON_OFFSET_UNITS: return f(s.polygon_offset_units);
        case gl::SAMPLE_COVERAGE_VALUE: return f(s.sample_coverage_value);
        case gl::SAMPLE_COVERAGE_INVERT: return b(s.sample_coverage_invert);
        case gl::SCISSOR_BOX: return rect(s.scissor);
        case gl::VIEWPORT: return rect(s.viewport);

        // Misc state
        case gl::ACTIVE_TEXTURE: return i(s.active_texture);
        case gl::GENERATE_MIPMAP_HINT: return i(s.generate_mipmap_hint);
        case gl::PACK_ALIGNMENT: return i(s.pixel_store.pack_alignment);
        case gl::UNPACK_ALIGNMENT: return i(s.pixel_store.unpack_alignment);
        case gl::UNPACK_FLIP_Y_WEBGL: return b(s.pixel_store.unpack_flip_y);
        case gl::UNPACK_PREMULTIPLY_ALPHA_WEBGL: return b(s.pixel_store.unpack_premultiply_alpha);
        case gl::UNPACK_COLORSPACE_CONVERSION_WEBGL: return i(s.pixel_store.unpack_colorspace_conversion);
        default: return std::nullopt;
    }
}

// WebGL 1's implementation limits.
std::optional<Value> limit_parameter(GLenum pname) {
    switch (pname) {
        case gl::ALIASED_LINE_WIDTH_RANGE: return floats({kAliasedLineWidthRange[0], kAliasedLineWidthRange[1]});
        case gl::ALIASED_POINT_SIZE_RANGE: return floats({limits::kPointSizeRange[0], limits::kPointSizeRange[1]});
        case gl::MAX_VIEWPORT_DIMS: return ints({limits::kMaxViewportDims, limits::kMaxViewportDims});
        case gl::MAX_TEXTURE_SIZE: return i(limits::kMaxTextureSize);
        case gl::MAX_CUBE_MAP_TEXTURE_SIZE: return i(limits::kMaxCubeMapTextureSize);
        case gl::MAX_RENDERBUFFER_SIZE: return i(limits::kMaxRenderbufferSize);
        case gl::MAX_VERTEX_ATTRIBS: return i(limits::kMaxVertexAttribs);
        case gl::MAX_TEXTURE_IMAGE_UNITS: return i(limits::kMaxTextureImageUnits);
        case gl::MAX_VERTEX_TEXTURE_IMAGE_UNITS: return i(limits::kMaxVertexTextureImageUnits);
        case gl::MAX_COMBINED_TEXTURE_IMAGE_UNITS: return i(limits::kMaxCombinedTextureImageUnits);
        case gl::MAX_VERTEX_UNIFORM_VECTORS: return i(limits::kMaxVertexUniformVectors);
        case gl::MAX_FRAGMENT_UNIFORM_VECTORS: return i(limits::kMaxFragmentUniformVectors);
        case gl::MAX_VARYING_VECTORS: return i(limits::kMaxVaryingVectors);
        case gl::SUBPIXEL_BITS: return i(limits::kSubpixelBits);
        case gl::COMPRESSED_TEXTURE_FORMATS: return Value(Uint32Array{});
        default: return std::nullopt;
    }
}

// The strings (WebGL 1.0 §5.14.3 prescribes the prefixes).
std::optional<Value> string_parameter(GLenum pname, bool v2) {
    switch (pname) {
        case gl::VENDOR: return Value(std::string("softgl"));
        case gl::RENDERER: return Value(std::string("softgl"));
        case gl::VERSION: return Value(std::string(v2 ? "WebGL 2.0 (softgl)" : "WebGL 1.0 (softgl)"));
        case gl::SHADING_LANGUAGE_VERSION:
            return Value(std::string(v2 ? "WebGL GLSL ES 3.00 (softgl)" : "WebGL GLSL ES 1.0 (softgl)"));
        default: return std::nullopt;
    }
}

// WebGL 2's additions to the state.
std::optional<Value> webgl2_state_parameter(const State& s, GLenum pname) {
    switch (pname) {
        case gl::RASTERIZER_DISCARD: return b(s.rasterizer_discard);
        case gl::FRAGMENT_SHADER_DERIVATIVE_HINT: return i(s.fragment_shader_derivative_hint);
        case gl::PACK_ROW_LENGTH: return i(s.pixel_store.pack_row_length);
        case gl::PACK_SKIP_PIXELS: return i(s.pixel_store.pack_skip_pixels);
        case gl::PACK_SKIP_ROWS: return i(s.pixel_store.pack_skip_rows);
        case gl::UNPACK_ROW_LENGTH: return i(s.pixel_store.unpack_row_length);
        case gl::UNPACK_IMAGE_HEIGHT: return i(s.pixel_store.unpack_image_height);
        case gl::UNPACK_SKIP_PIXELS: return i(s.pixel_store.unpack_skip_pixels);
        case gl::UNPACK_SKIP_ROWS: return i(s.pixel_store.unpack_skip_rows);
        case gl::UNPACK_SKIP_IMAGES: return i(s.pixel_store.unpack_skip_images);
        case gl::READ_BUFFER: return i(gl::BACK);
        case gl::TRANSFORM_FEEDBACK_ACTIVE: case gl::TRANSFORM_FEEDBACK_PAUSED: return b(false);
        default: return std::nullopt;
    }
}

// WebGL 2's implementation limits (ES 3.0 §6.2, table 6.3x).
std::optional<Value> webgl2_limit_parameter(GLenum pname) {
    switch (pname) {
        case gl::MAX_3D_TEXTURE_SIZE: return i(2048);
        case gl::MAX_ARRAY_TEXTURE_LAYERS: return i(2048);
        case gl::MAX_COLOR_ATTACHMENTS: return i(kMaxDrawBuffers);
        case gl::MAX_DRAW_BUFFERS: return i(kMaxDrawBuffers);
        case gl::MAX_ELEMENT_INDEX: return i(4294967295LL);
        case gl::MAX_ELEMENTS_INDICES: return i(1 << 20);
        case gl::MAX_ELEMENTS_VERTICES: return i(1 << 20);
        case gl::MAX_SAMPLES: return i(limits::kMaxSamples);
        case gl::MAX_TEXTURE_LOD_BIAS: return f(16.0f);
        case gl::MAX_PROGRAM_TEXEL_OFFSET: return i(7);
        case gl::MIN_PROGRAM_TEXEL_OFFSET: return i(-8);
        case gl::MAX_VERTEX_UNIFORM_COMPONENTS: return i(kMaxVertexUniformComponents);
        case gl::MAX_FRAGMENT_UNIFORM_COMPONENTS: return i(kMaxFragmentUniformComponents);
        case gl::MAX_VARYING_COMPONENTS: return i(kMaxVaryingComponents);
        case gl::MAX_VERTEX_OUTPUT_COMPONENTS: return i(kMaxVaryingComponents);
        case gl::MAX_FRAGMENT_INPUT_COMPONENTS: return i(kMaxVaryingComponents);
        case gl::MAX_VERTEX_UNIFORM_BLOCKS: return i(kMaxUniformBlocksPerStage);
        case gl::MAX_FRAGMENT_UNIFORM_BLOCKS: return i(kMaxUniformBlocksPerStage);
        case gl::MAX_COMBINED_UNIFORM_BLOCKS: return i(2 * kMaxUniformBlocksPerStage);
        case gl::MAX_UNIFORM_BUFFER_BINDINGS: return i(2 * kMaxUniformBlocksPerStage);
        case gl::MAX_UNIFORM_BLOCK_SIZE: return i(kMaxUniformBlockSize);
        case gl::MAX_COMBINED_VERTEX_UNIFORM_COMPONENTS:
            return i(int64_t(kMaxUniformBlocksPerStage) * kMaxUniformBlockSize / 4 + kMaxVertexUniformComponents);
        case gl::MAX_COMBINED_FRAGMENT_UNIFORM_COMPONENTS:
            return i(int64_t(kMaxUniformBlocksPerStage) * kMaxUniformBlockSize / 4 + kMaxFragmentUniformComponents);
        case gl::UNIFORM_BUFFER_OFFSET_ALIGNMENT: return i(16);
        case gl::MAX_TRANSFORM_FEEDBACK_INTERLEAVED_COMPONENTS: return i(64);
        case gl::MAX_TRANSFORM_FEEDBACK_SEPARATE_ATTRIBS: return i(4);
        case gl::MAX_TRANSFORM_FEEDBACK_SEPARATE_COMPONENTS: return i(4);
        case gl::MAX_SERVER_WAIT_TIMEOUT: return i(0);
        case gl::MAX_CLIENT_WAIT_TIMEOUT_WEBGL: return i(0);
        default: return std::nullopt;
    }
}

// SOFTGL_smooth's state.
std::optional<Value> smooth_parameter(const State& s, GLenum pname) {
    switch (pname) {
        case gl::POLYGON_SMOOTH: return b(s.smooth.polygon);
        case gl::LINE_SMOOTH: return b(s.smooth.line);
        case gl::POINT_SMOOTH: return b(s.smooth.point);
        case gl::POLYGON_SMOOTH_HINT: return i(s.smooth.polygon_hint);
        case gl::LINE_SMOOTH_HINT: return i(s.smooth.line_hint);
        case gl::POINT_SMOOTH_HINT: return i(s.smooth.point_hint);
        case gl::SMOOTH_LINE_WIDTH_RANGE: return floats({kSmoothLineWidthRange[0], kSmoothLineWidthRange[1]});
        default: return std::nullopt;
    }
}

// The fog extension's state.
std::optional<Value> fog_parameter(const State& s, GLenum pname) {
    switch (pname) {
        case gl::FOG: return b(s.fog.enabled);
        case gl::FOG_BLEND_AWARE_SOFTGL: return b(s.fog.blend_aware);
        case gl::FOG_MODE: return i(s.fog.mode);
        case gl::FOG_DENSITY: return f(s.fog.density);
        case gl::FOG_START: return f(s.fog.start);
        case gl::FOG_END: return f(s.fog.end);
        case gl::FOG_COLOR: return floats({s.fog.color.begin(), s.fog.color.end()});
        case gl::FOG_COORDINATE_SOURCE: return i(s.fog.coordinate_source);
        default: return std::nullopt;
    }
}

}  // namespace

template <class T>
static Value object(const std::shared_ptr<T>& p) {
    if (!p) return Value(Null{});
    return Value(std::shared_ptr<Object>(p));
}
template <class T>
static Value object(const InUse<T>& p) { return object(p.shared()); }

Value Context::vertex_array_binding() const {
    // The default vertex array reads as null (WebGL 2.0 §3.7.2).
    return vertex_array_ == default_vertex_array_ ? Value(Null{}) : object(vertex_array_);
}

// WebGL 1's object bindings and the drawing buffer's format.
std::optional<Value> Context::binding_parameter(GLenum pname) const {
    const auto& fb = framebuffer_.config();
    switch (pname) {
        case gl::ARRAY_BUFFER_BINDING: return object(array_buffer_);
        case gl::ELEMENT_ARRAY_BUFFER_BINDING: return object(vertex_array_->element_buffer);
        case gl::CURRENT_PROGRAM: return object(current_program_);
        // Objects softgl does not have yet (framebuffers, textures): always null.
        case gl::FRAMEBUFFER_BINDING: case gl::RENDERBUFFER_BINDING:
        case gl::TEXTURE_BINDING_2D: case gl::TEXTURE_BINDING_CUBE_MAP:
            return Value(Null{});

        // The drawing buffer
        case gl::RED_BITS: case gl::GREEN_BITS: case gl::BLUE_BITS: return i(framebuffer_.color_bits());
        case gl::ALPHA_BITS: return i(fb.alpha ? framebuffer_.color_bits() : 0);
        case gl::DEPTH_BITS: return i(fb.depth ? DefaultFramebuffer::kDepthBits : 0);
        case gl::STENCIL_BITS: return i(fb.stencil ? DefaultFramebuffer::kStencilBits : 0);
        case gl::SAMPLE_BUFFERS: return i(fb.samples > 1 ? 1 : 0);
        case gl::SAMPLES: return i(fb.samples > 1 ? fb.samples : 0);
        case gl::IMPLEMENTATION_COLOR_READ_FORMAT: return i(gl::RGBA);
        case gl::IMPLEMENTATION_COLOR_READ_TYPE: return i(drawing_buffer_read_type());
        default: return std::nullopt;
    }
}

// WebGL 2's object bindings.
std::optional<Value> Context::webgl2_binding_parameter(GLenum pname) const {
    switch (pname) {
        case gl::COPY_READ_BUFFER_BINDING: return object(copy_read_buffer_);
        case gl::COPY_WRITE_BUFFER_BINDING: return object(copy_write_buffer_);
        case gl::PIXEL_PACK_BUFFER_BINDING: return object(pixel_pack_buffer_);
        case gl::PIXEL_UNPACK_BUFFER_BINDING: return object(pixel_unpack_buffer_);
        case gl::UNIFORM_BUFFER_BINDING: return object(uniform_buffer_);
        case gl::TRANSFORM_FEEDBACK_BUFFER_BINDING: return object(transform_feedback_buffer_);
        case gl::VERTEX_ARRAY_BINDING: return vertex_array_binding();
        case gl::READ_FRAMEBUFFER_BINDING: case gl::SAMPLER_BINDING:
        case gl::TEXTURE_BINDING_2D_ARRAY: case gl::TEXTURE_BINDING_3D:
        case gl::TRANSFORM_FEEDBACK_BINDING:
            return Value(Null{});
        default: return std::nullopt;
    }
}

Value Context::get_parameter(GLenum pname) {
    const State& s = state_;
    // Texture, sampler, framebuffer and renderbuffer state (textures.cpp, framebuffers.cpp).
    if (std::optional<Value> v = texture_framebuffer_parameter(pname)) return *std::move(v);
    if (std::optional<Value> v = state_parameter(s, pname)) return *std::move(v);
    if (std::optional<Value> v = binding_parameter(pname)) return *std::move(v);
    if (std::optional<Value> v = limit_parameter(pname)) return *std::move(v);
    if (std::optional<Value> v = string_parameter(pname, version() >= 2)) return *std::move(v);
    if (version() >= 2) {
        if (std::optional<Value> v = webgl2_state_parameter(s, pname)) return *std::move(v);
        if (std::optional<Value> v = webgl2_binding_parameter(pname)) return *std::move(v);
        if (std::optional<Value> v = webgl2_limit_parameter(pname)) return *std::move(v);
    }
    if (ext_vertex_array_object_ && pname == gl::VERTEX_ARRAY_BINDING) return vertex_array_binding();
    // OES_standard_derivatives: FRAGMENT_SHADER_DERIVATIVE_HINT_OES (WebGL 2's value).
    if (ext_standard_derivatives_ && pname == gl::FRAGMENT_SHADER_DERIVATIVE_HINT)
        return Value(int64_t(s.fragment_shader_derivative_hint));
    if (ext_smooth_) {
        if (std::optional<Value> v = smooth_parameter(s, pname)) return *std::move(v);
    }
    if (ext_fog_) {
        if (std::optional<Value> v = fog_parameter(s, pname)) return *std::move(v);
    }
    error(gl::INVALID_ENUM, "getParameter", enum_name(pname) + " is not a parameter name of this context");
    return Value(Null{});
}

}  // namespace softgl
