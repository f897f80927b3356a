// A WebGL 1 / WebGL 2 rendering context: the entry points, their validation, and the state.
// Every entry point validates first and records the WebGL error without changing anything.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "softgl/api/errors.h"
#include "softgl/api/objects.h"
#include "softgl/api/programs.h"
#include "softgl/api/state.h"
#include "softgl/api/value.h"
#include "softgl/pipeline/draw.h"
#include "softgl/runtime/thread_pool.h"
#include "softgl/surface/framebuffer.h"

namespace softgl {

class BlendLab;       // blend lab extensions (api/blendlab.h)
class FragmentSink;

struct ContextAttributes {
    bool alpha = true;
    bool depth = true;
    bool stencil = false;
    bool antialias = true;
    bool premultiplied_alpha = true;
    bool preserve_drawing_buffer = false;
    bool fail_if_major_performance_caveat = false;
    bool desynchronized = false;
    std::string power_preference = "default";
    // softgl's own options
    int version = 2;     // 1 = WebGL 1, 2 = WebGL 2
    int samples = 0;     // 0 = 4 when antialias, else 1; otherwise 2, 4, 8 or 16 (needs antialias)
    int threads = 0;     // worker threads for drawing; 0 = one per core
};

// Limits softgl reports through getParameter.
namespace limits {
inline constexpr int32_t kMaxViewportDims = kMaxDrawingBufferSize;
inline constexpr int32_t kMaxTextureSize = 16384;
inline constexpr int32_t kMaxCubeMapTextureSize = 16384;
inline constexpr int32_t kMaxRenderbufferSize = 16384;
inline constexpr int32_t kMaxVertexAttribs = 16;
inline constexpr int32_t kMaxTextureImageUnits = 16;
inline constexpr int32_t kMaxVertexTextureImageUnits = 16;
inline constexpr int32_t kMaxCombinedTextureImageUnits = 32;
inline constexpr int32_t kMaxVertexUniformVectors = 1024;
inline constexpr int32_t kMaxFragmentUniformVectors = 1024;
inline constexpr int32_t kMaxVaryingVectors = 16;
inline constexpr float kPointSizeRange[2] = {1.0f, 1024.0f};
inline constexpr float kLineWidthRange[2] = {1.0f, 256.0f};
inline constexpr int32_t kSubpixelBits = 8;
inline constexpr int32_t kMaxSamples = 16;
}  // namespace limits

class Context {
public:
    // Empty when the attributes and size are acceptable; else the reason (nothing is allocated).
    static std::string check(int32_t width, int32_t height, const ContextAttributes& attributes);
    Context(int32_t width, int32_t height, const ContextAttributes& attributes);

    const ContextAttributes& attributes() const { return attributes_; }
    int version() const { return attributes_.version; }
    int32_t drawing_buffer_width() const { return framebuffer_.width(); }
    int32_t drawing_buffer_height() const { return framebuffer_.height(); }
    const State& state() const { return state_; }
    ThreadPool& pool();
    DrawStats& stats() { return stats_; }
    const std::array<CurrentAttrib, kMaxVertexAttribs>& current_attribs() const { return current_attribs_; }
    DefaultFramebuffer& framebuffer() { return framebuffer_; }
    ErrorState& errors() { return errors_; }
    // For errors found while converting arguments (e.g. a typed-array range out of bounds).
    void record_error(GLenum code, const char* call, const std::string& why) { error(code, call, why); }

    // Errors, extensions
    GLenum get_error() { return errors_.take(); }
    bool is_context_lost() const { return false; }
    std::vector<std::string> get_supported_extensions() const;
    bool enable_extension(const std::string& name);   // getExtension: false when unsupported
    bool extension_enabled(const std::string& name) const;

    // Capabilities
    void enable(GLenum cap) { set_capability("enable", cap, true); }
    void disable(GLenum cap) { set_capability("disable", cap, false); }
    bool is_enabled(GLenum cap);

    // Blending
    void blend_func(GLenum sfactor, GLenum dfactor);
    void blend_func_separate(GLenum src_rgb, GLenum dst_rgb, GLenum src_alpha, GLenum dst_alpha);
    void blend_equation(GLenum mode);
    void blend_equation_separate(GLenum mode_rgb, GLenum mode_alpha);
    void blend_color(float r, float g, float b, float a);

    // Depth, stencil, masks, clear values
    void depth_func(GLenum func);
    void depth_mask(bool flag) { state_.depth_mask = flag; }
    void depth_range(float z_near, float z_far);
    void clear_color(float r, float g, float b, float a) { state_.clear_color = {r, g, b, a}; }
    void clear_depth(float depth);
    void clear_stencil(int32_t s) { state_.clear_stencil = s; }
    void color_mask(bool r, bool g, bool b, bool a) { state_.color_mask = {r, g, b, a}; }
    void stencil_func(GLenum func, int32_t ref, uint32_t mask);
    void stencil_func_separate(GLenum face, GLenum func, int32_t ref, uint32_t mask);
    void stencil_op(GLenum fail, GLenum zfail, GLenum zpass);
    void stencil_op_separate(GLenum face, GLenum fail, GLenum zfail, GLenum zpass);
    void stencil_mask(uint32_t mask);
    void stencil_mask_separate(GLenum face, uint32_t mask);

    // Rasterization
    void cull_face(GLenum mode);
    void front_face(GLenum mode);
    void line_width(float width);
    void polygon_offset(float factor, float units);
    void sample_coverage(float value, bool invert);
    void scissor(int32_t x, int32_t y, int32_t width, int32_t height);
    void viewport(int32_t x, int32_t y, int32_t width, int32_t height);

    // Misc state
    void hint(GLenum target, GLenum mode);
    void pixel_store_i(GLenum pname, int32_t param);
    void active_texture(GLenum texture);
    Value get_parameter(GLenum pname);

    // Framebuffer operations
    void clear(uint32_t mask);
    // readPixels into `dst` (dst_bytes long, elements of GL type `dst_type`). With `packed` the
    // destination is laid out by the PACK_* parameters (as a WebGL ArrayBufferView); otherwise it
    // is a tightly packed h x w x 4 block. Returns false after recording an error.
    bool read_pixels(int32_t x, int32_t y, int32_t width, int32_t height, GLenum format,
                    GLenum type, GLenum dst_type, uint8_t* dst, size_t dst_bytes, bool packed);
    // Bytes that readPixels writes at most for this block with the current PACK_* parameters.
    size_t pack_size(int32_t width, int32_t height) const;

    // Buffers (buffers.cpp)
    std::shared_ptr<Buffer> create_buffer();
    void bind_buffer(GLenum target, const std::shared_ptr<Buffer>& buffer);
    void delete_buffer(const std::shared_ptr<Buffer>& buffer);
    bool is_buffer(const std::shared_ptr<Buffer>& buffer) const;
    void buffer_data_size(GLenum target, int64_t size, GLenum usage);
    void buffer_data(GLenum target, const uint8_t* data, int64_t size, GLenum usage);
    void buffer_sub_data(GLenum target, int64_t offset, const uint8_t* data, int64_t size);
    void copy_buffer_sub_data(GLenum read_target, GLenum write_target, int64_t read_offset,
                              int64_t write_offset, int64_t size);
    bool get_buffer_sub_data(GLenum target, int64_t offset, uint8_t* dst, int64_t size);
    Value get_buffer_parameter(GLenum target, GLenum pname);

    // Vertex attributes and vertex array objects (vertex_arrays.cpp)
    void vertex_attrib_pointer(uint32_t index, int32_t size, GLenum type, bool normalized,
                               int32_t stride, int64_t offset);
    void vertex_attrib_i_pointer(uint32_t index, int32_t size, GLenum type, int32_t stride, int64_t offset);
    void enable_vertex_attrib_array(uint32_t index);
    void disable_vertex_attrib_array(uint32_t index);
    void vertex_attrib_f(const char* call, uint32_t index, const float* values, int count);
    void vertex_attrib_i4i(uint32_t index, int32_t x, int32_t y, int32_t z, int32_t w);
    void vertex_attrib_i4ui(uint32_t index, uint32_t x, uint32_t y, uint32_t z, uint32_t w);
    void vertex_attrib_divisor(uint32_t index, uint32_t divisor);
    Value get_vertex_attrib(uint32_t index, GLenum pname);
    int64_t get_vertex_attrib_offset(uint32_t index, GLenum pname);
    std::shared_ptr<VertexArray> create_vertex_array();
    void bind_vertex_array(const std::shared_ptr<VertexArray>& vao);
    void delete_vertex_array(const std::shared_ptr<VertexArray>& vao);
    bool is_vertex_array(const std::shared_ptr<VertexArray>& vao) const;
    const VertexArray& vertex_array() const { return *vertex_array_; }
    const CurrentAttrib& current_attrib(int index) const { return current_attribs_[size_t(index)]; }

    // Shaders and programs (programs.cpp)
    std::shared_ptr<Shader> create_shader(GLenum type);
    void shader_source(const std::shared_ptr<Shader>& shader, const std::string& source);
    std::string get_shader_source(const std::shared_ptr<Shader>& shader);
    void compile_shader(const std::shared_ptr<Shader>& shader);
    Value get_shader_parameter(const std::shared_ptr<Shader>& shader, GLenum pname);
    std::string get_shader_info_log(const std::shared_ptr<Shader>& shader);
    void delete_shader(const std::shared_ptr<Shader>& shader);
    bool is_shader(const std::shared_ptr<Shader>& shader) const;
    std::shared_ptr<Program> create_program();
    void attach_shader(const std::shared_ptr<Program>& program, const std::shared_ptr<Shader>& shader);
    void detach_shader(const std::shared_ptr<Program>& program, const std::shared_ptr<Shader>& shader);
    std::vector<std::shared_ptr<Shader>> get_attached_shaders(const std::shared_ptr<Program>& program, bool* ok);
    void bind_attrib_location(const std::shared_ptr<Program>& program, uint32_t index, const std::string& name);
    void link_program(const std::shared_ptr<Program>& program);
    void validate_program(const std::shared_ptr<Program>& program);
    void use_program(const std::shared_ptr<Program>& program);
    void delete_program(const std::shared_ptr<Program>& program);
    bool is_program(const std::shared_ptr<Program>& program) const;
    Value get_program_parameter(const std::shared_ptr<Program>& program, GLenum pname);
    std::string get_program_info_log(const std::shared_ptr<Program>& program);
    int32_t get_attrib_location(const std::shared_ptr<Program>& program, const std::string& name);
    std::shared_ptr<UniformLocation> get_uniform_location(const std::shared_ptr<Program>& program, const std::string& name);
    std::shared_ptr<ActiveInfo> get_active_attrib(const std::shared_ptr<Program>& program, uint32_t index);
    std::shared_ptr<ActiveInfo> get_active_uniform(const std::shared_ptr<Program>& program, uint32_t index);
    std::shared_ptr<PrecisionFormat> get_shader_precision_format(GLenum shader_type, GLenum precision_type);
    // uniform{1234}{f,i,ui}[v] and uniformMatrix*: `kind` is 'f', 'i' or 'u' (or 'm' for matrices
    // with `columns` x `rows`); values holds count * components numbers of that kind.
    void set_uniform(const char* call, const UniformLocation* location, char kind, int columns, int rows,
                     const void* values, size_t count, bool transpose);
    // getUniform: the value as WebGL returns it.
    Value get_uniform(const std::shared_ptr<Program>& program, const UniformLocation* location);
    const std::shared_ptr<Program>& current_program() const { return current_program_; }

    // Drawing (draw_calls.cpp)
    void draw_arrays(GLenum mode, int32_t first, int32_t count, int32_t instances, const char* call);
    void draw_elements(GLenum mode, int32_t count, GLenum type, int64_t offset, int32_t instances,
                       const char* call);
    void draw_range_elements(GLenum mode, uint32_t start, uint32_t end, int32_t count, GLenum type, int64_t offset);

    // SOFTGL_fog (fog.cpp): glFog{f,i,fv} with `count` values.
    void fog(const char* call, GLenum pname, const float* values, int count);

    // SOFTGL_exact_transparency and SOFTGL_introspection (transparency.cpp, api/blendlab.h):
    // made at the first getExtension of either; the draw hook is null while both are off.
    BlendLab& blendlab();
    FragmentSink* blendlab_sink();

    // The browser's compositing step: after the canvas is shown, a drawing buffer without
    // preserveDrawingBuffer is cleared to its initial contents (WebGL 1.0 §2.2).
    void present();

private:
    void set_capability(const char* call, GLenum cap, bool value);
    bool* capability(GLenum cap);
    bool valid_blend_factor(GLenum factor, bool is_destination) const;
    bool valid_blend_equation(GLenum mode) const;
    bool check_blend_factors(const char* call, GLenum src_rgb, GLenum dst_rgb, GLenum src_alpha,
                             GLenum dst_alpha);
    std::shared_ptr<Buffer>* buffer_binding(GLenum target);
    Value vertex_array_binding() const;
    Buffer* bound_buffer(const char* call, GLenum target);
    bool check_object(const char* call, const Object* object) const;
    void error(GLenum code, const char* call, const std::string& why) {
        errors_.record(code, call, why);
    }

    ContextAttributes attributes_;
    State state_;
    DefaultFramebuffer framebuffer_;
    ErrorState errors_;
    bool ext_blend_minmax_ = false;
    bool ext_vertex_array_object_ = false;
    bool ext_instanced_arrays_ = false;
    bool ext_element_index_uint_ = false;
    bool ext_fog_ = false;
    bool ext_smooth_ = false;
    std::shared_ptr<BlendLab> blendlab_;   // shared_ptr: deletable where BlendLab is incomplete

    // Object bindings
    std::shared_ptr<Buffer> array_buffer_, copy_read_buffer_, copy_write_buffer_,
        pixel_pack_buffer_, pixel_unpack_buffer_, uniform_buffer_, transform_feedback_buffer_;
    std::shared_ptr<VertexArray> default_vertex_array_, vertex_array_;
    std::array<CurrentAttrib, kMaxVertexAttribs> current_attribs_;

    std::shared_ptr<Program> current_program_;
    bool check_program(const char* call, const Program* program);
    bool check_shader(const char* call, const Shader* shader);
    void release_shader(const std::shared_ptr<Shader>& shader);
    bool validate_draw_state(const char* call);
    void run_draw(const DrawCall& call, uint32_t max_vertex);

    std::unique_ptr<ThreadPool> pool_;   // created at the first draw
    DrawStats stats_;
};

std::string enum_name(uint32_t value);   // "BLEND" or "0x1234"

}  // namespace softgl
