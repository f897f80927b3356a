// A WebGL 1 / WebGL 2 rendering context: the entry points, their validation, and the state.
// Every entry point validates first and records the WebGL error without changing anything.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "softgl/api/errors.h"
#include "softgl/core/objects.h"
#include "softgl/api/programs.h"
#include "softgl/core/state.h"
#include "softgl/core/work_budget.h"
#include "softgl/api/textures.h"
#include "softgl/api/value.h"
#include "softgl/pipeline/draw.h"
#include "softgl/runtime/thread_pool.h"
#include "softgl/surface/framebuffer.h"
#include "softgl/surface/sampler.h"

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
    // The drawing buffer's colour format: "rgba8" (WebGL's), "rgba16f" or "rgba32f".
    std::string color_format = "rgba8";
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
inline constexpr int32_t kSubpixelBits = 8;
inline constexpr int32_t kMaxSamples = 16;
}  // namespace limits

class Context {
public:
    // Empty when the attributes and size are acceptable; else the reason (nothing is allocated).
    static std::string check(int32_t width, int32_t height, const ContextAttributes& attributes);
    Context(int32_t width, int32_t height, const ContextAttributes& attributes);

    const ContextAttributes& attributes() const { return attributes_; }
    // What objects record as their owner: unique for the life of the process, never reused by a
    // later context (a raw `this` could be, after this context is freed).
    const void* identity() const { return reinterpret_cast<const void*>(id_); }
    // Set while a call runs without the GIL (bindings/exclusive.h).
    std::atomic<uint64_t>& busy() { return busy_; }   // 0 or the using thread
    // The bytes this context's objects hold and its limit (docs/reliability.md, "Memory").
    MemoryAccount& memory_account() { return *memory_account_; }
    int version() const { return attributes_.version; }
    int32_t drawing_buffer_width() const { return framebuffer_.width(); }
    int32_t drawing_buffer_height() const { return framebuffer_.height(); }
    const State& state() const { return state_; }
    ThreadPool& pool();
    // The speed-path switches of this context's draws (core/tuning.h), from the process default.
    Tuning& tuning() { return tuning_; }
    // The work budget of the call running on this context (core/work_budget.h): the bindings ask
    // it to stop on Ctrl-C. Its limits per draw and per compile or link are settable.
    WorkBudget& work_budget() { return work_budget_; }
    struct WorkLimits {
        uint64_t draw = kDrawWorkBudgetDefault;
        uint64_t compile = kCompileWorkBudgetDefault;   // each compile and each link
    };
    WorkLimits& work_limits() { return work_limits_; }
    DrawStats& stats() { return stats_; }
    // The plan of the last draw that reached the pipeline (pipeline/draw_plan.h); null before one.
    const DrawPlan* last_draw_plan() const { return last_draw_plan_ ? &*last_draw_plan_ : nullptr; }
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
    // WebGL 2's readPixels(..., GLintptr offset): into the PIXEL_PACK_BUFFER at a byte offset.
    void read_pixels_to_pack_buffer(int32_t x, int32_t y, int32_t width, int32_t height, GLenum format,
                                    GLenum type, int64_t offset);
    // Bytes that readPixels writes at most for this block with the current PACK_* parameters.
    size_t pack_size(int32_t width, int32_t height, int pixel_bytes = 4) const;
    // The type of the implementation-chosen readPixels pair for the drawing buffer (ES 3.0
    // §4.3.2): UNSIGNED_BYTE for RGBA8, HALF_FLOAT / FLOAT for the float colour formats.
    GLenum drawing_buffer_read_type() const;

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
    // Charges the blend lab's A-buffer and fragment log as they are now to this context's memory
    // account (after every draw and when the budget is read: docs/reliability.md, "Memory").
    void charge_blend_lab();

    // ---- Textures and framebuffers (textures.cpp, framebuffers.cpp) --------------------------
    std::shared_ptr<Texture> create_texture();
    void bind_texture(GLenum target, const std::shared_ptr<Texture>& texture);
    void delete_texture(const std::shared_ptr<Texture>& texture);
    bool is_texture(const std::shared_ptr<Texture>& texture) const;
    void tex_parameter(const char* call, GLenum target, GLenum pname, double value);
    Value get_tex_parameter(GLenum target, GLenum pname);
    // texImage2D/3D (depth = 1 for 2D), texSubImage2D/3D, texStorage2D/3D.
    void tex_image(const char* call, GLenum target, int32_t level, GLenum internal_format, int32_t width,
                   int32_t height, int32_t depth, int32_t border, GLenum format, GLenum type, const TexSource& source);
    void tex_sub_image(const char* call, GLenum target, int32_t level, int32_t x, int32_t y, int32_t z,
                       int32_t width, int32_t height, int32_t depth, GLenum format, GLenum type, const TexSource& source);
    void tex_storage(const char* call, GLenum target, int32_t levels, GLenum internal_format, int32_t width,
                     int32_t height, int32_t depth);
    void generate_mipmap(GLenum target);
    void copy_tex_image_2d(GLenum target, int32_t level, GLenum internal_format, int32_t x, int32_t y,
                           int32_t width, int32_t height, int32_t border);
    void copy_tex_sub_image(const char* call, GLenum target, int32_t level, int32_t xoffset, int32_t yoffset,
                            int32_t zoffset, int32_t x, int32_t y, int32_t width, int32_t height);
    std::shared_ptr<Sampler> create_sampler();
    void delete_sampler(const std::shared_ptr<Sampler>& sampler);
    bool is_sampler(const std::shared_ptr<Sampler>& sampler) const;
    void bind_sampler(uint32_t unit, const std::shared_ptr<Sampler>& sampler);
    void sampler_parameter(const char* call, const std::shared_ptr<Sampler>& sampler, GLenum pname, double value);
    Value get_sampler_parameter(const std::shared_ptr<Sampler>& sampler, GLenum pname);
    std::vector<std::string> texture_extension_names() const;
    bool enable_texture_extension(const std::string& name);   // false: not one of these
    bool texture_extension_enabled(const std::string& name) const;
    // getParameter for the texture and framebuffer state; nullopt for other names.
    std::optional<Value> texture_framebuffer_parameter(GLenum pname);
    // At a draw: builds the units' sampler view and checks WebGL's draw-time rules for textures
    // and framebuffers (records the error and returns false when the draw must not happen).
    bool prepare_textures_and_targets(const char* call);
    glsl::TextureSampler* draw_sampler() { return &draw_sampler_; }
    RenderTarget draw_target();                               // framebuffers.cpp
    std::shared_ptr<Framebuffer> create_framebuffer();
    void bind_framebuffer(GLenum target, const std::shared_ptr<Framebuffer>& framebuffer);
    void delete_framebuffer(const std::shared_ptr<Framebuffer>& framebuffer);
    bool is_framebuffer(const std::shared_ptr<Framebuffer>& framebuffer) const;
    std::shared_ptr<Renderbuffer> create_renderbuffer();
    void bind_renderbuffer(GLenum target, const std::shared_ptr<Renderbuffer>& renderbuffer);
    void delete_renderbuffer(const std::shared_ptr<Renderbuffer>& renderbuffer);
    bool is_renderbuffer(const std::shared_ptr<Renderbuffer>& renderbuffer) const;
    // renderbufferStorage (samples 0) and renderbufferStorageMultisample.
    void renderbuffer_storage(const char* call, GLenum target, int32_t samples, GLenum internal_format,
                              int32_t width, int32_t height);
    Value get_renderbuffer_parameter(GLenum target, GLenum pname);
    // framebufferTexture2D (textarget != 0) and framebufferTextureLayer (textarget 0).
    void framebuffer_texture(const char* call, GLenum target, GLenum attachment, GLenum textarget,
                             const std::shared_ptr<Texture>& texture, int32_t level, int32_t layer);
    void framebuffer_renderbuffer(GLenum target, GLenum attachment, GLenum renderbuffer_target,
                                  const std::shared_ptr<Renderbuffer>& renderbuffer);
    GLenum check_framebuffer_status(GLenum target);
    Value get_framebuffer_attachment_parameter(GLenum target, GLenum attachment, GLenum pname);
    void read_buffer(GLenum src);
    // clearBuffer{fv,iv,uiv} (kind 'f', 'i', 'u'; `count` values) and clearBufferfi (kind 's').
    void clear_buffer(const char* call, GLenum buffer, int32_t drawbuffer, char kind, const void* values,
                      size_t count, float depth, int32_t stencil);
    void blit_framebuffer(int32_t sx0, int32_t sy0, int32_t sx1, int32_t sy1, int32_t dx0, int32_t dy0,
                          int32_t dx1, int32_t dy1, uint32_t mask, GLenum filter);
    void invalidate_framebuffer(const char* call, GLenum target, const std::vector<GLenum>& attachments);
    // drawBuffers (WebGL 2) and WEBGL_draw_buffers' drawBuffersWEBGL (WebGL 1), ES 3.0 §4.2.1.
    void draw_buffers(const char* call, const std::vector<GLenum>& buffers);
    // Whether colour attachments 1..7 and draw buffers exist (WebGL 2, or WEBGL_draw_buffers).
    bool multiple_draw_buffers() const;
    // The drawing buffer's draw buffer: BACK, or NONE after drawBuffers([NONE]).
    GLenum default_draw_buffer() const { return default_draw_buffer_; }
    // Hooks for clear() and readPixels(): handle a bound framebuffer object (true / the result).
    bool clear_framebuffer_object(uint32_t mask);
    bool reading_framebuffer_object() const { return read_framebuffer_ != nullptr; }
    bool read_pixels_framebuffer_object(int32_t x, int32_t y, int32_t width, int32_t height, GLenum format,
                                        GLenum type, GLenum dst_type, uint8_t* dst, size_t dst_bytes, bool packed);
    // ---- end textures and framebuffers ------------------------------------------------------

    // The browser's compositing step: after the canvas is shown, a drawing buffer without
    // preserveDrawingBuffer is cleared to its initial contents (WebGL 1.0 §2.2).
    void present();
    // The canvas's width or height was set: a new drawing buffer of that size, with its initial
    // contents, as a browser makes one (WebGL 1.0 §2.2); the viewport and scissor are kept.
    // Returns why the size is refused (and changes nothing), or "".
    std::string resize(int32_t width, int32_t height);

private:
    void set_capability(const char* call, GLenum cap, bool value);
    bool* capability(GLenum cap);
    bool valid_blend_factor(GLenum factor, bool is_destination) const;
    bool valid_blend_equation(GLenum mode) const;
    bool check_blend_factors(const char* call, GLenum src_rgb, GLenum dst_rgb, GLenum src_alpha,
                             GLenum dst_alpha);
    InUse<Buffer>* buffer_binding(GLenum target);   // the context's bind points, or the vertex array's element buffer
    void set_attrib_pointer(const char* call, uint32_t index, int32_t size, GLenum type, bool normalized,
                            bool integer, int32_t stride, int64_t offset);
    Value vertex_array_binding() const;
    // getParameter's object bindings (WebGL 1 with the drawing buffer's format, WebGL 2);
    // nullopt for other names (parameters.cpp).
    std::optional<Value> binding_parameter(GLenum pname) const;
    std::optional<Value> webgl2_binding_parameter(GLenum pname) const;
    Buffer* bound_buffer(const char* call, GLenum target);
    bool check_object(const char* call, const Object* object) const;
    void error(GLenum code, const char* call, const std::string& why) {
        errors_.record(code, call, why);
    }

    uintptr_t id_;   // from a process-wide counter, see identity()
    std::atomic<uint64_t> busy_{0};
    ContextAttributes attributes_;
    State state_;
    // This context's bytes and limit (core/memory_ledger.h); before framebuffer_, which charges it.
    std::shared_ptr<MemoryAccount> memory_account_ = std::make_shared<MemoryAccount>();
    DefaultFramebuffer framebuffer_;
    ErrorState errors_;
    bool ext_blend_minmax_ = false;
    bool ext_standard_derivatives_ = false, ext_frag_depth_ = false, ext_shader_texture_lod_ = false;
    bool ext_vertex_array_object_ = false;
    bool ext_instanced_arrays_ = false;
    bool ext_element_index_uint_ = false;
    bool ext_fog_ = false;
    bool ext_smooth_ = false;
    std::shared_ptr<BlendLab> blendlab_;   // shared_ptr: deletable where BlendLab is incomplete
    MemoryReservation blendlab_memory_{memory_account_};   // blendlab_'s records (charge_blend_lab)

    // Object bindings
    InUse<Buffer> array_buffer_, copy_read_buffer_, copy_write_buffer_,
        pixel_pack_buffer_, pixel_unpack_buffer_, uniform_buffer_, transform_feedback_buffer_;
    std::shared_ptr<VertexArray> default_vertex_array_, vertex_array_;
    std::array<CurrentAttrib, kMaxVertexAttribs> current_attribs_;

    std::shared_ptr<Program> current_program_;
    bool check_program(const char* call, const Program* program);
    bool check_shader(const char* call, const Shader* shader);
    bool check_name_length(const char* call, const std::string& name);
    void release_shader(const std::shared_ptr<Shader>& shader);
    bool validate_draw_state(const char* call);
    void run_draw(const DrawCall& call, const char* call_name);
    // A call stopped by its work budget or Ctrl-C: records OUT_OF_MEMORY naming the call
    // (docs/reliability.md, "Work budget and Ctrl-C"); `what` says what was left unchanged.
    void report_stopped(const char* call, StopReason reason, uint64_t limit, const char* what);

    // ---- Textures and framebuffers (textures.cpp, framebuffers.cpp) --------------------------
    struct TextureUnit {
        std::shared_ptr<Texture> tex_2d, cube, tex_3d, array_2d;
        std::shared_ptr<Sampler> sampler;
    };
    std::array<TextureUnit, limits::kMaxCombinedTextureImageUnits> texture_units_;
    std::vector<std::string> texture_extensions_;     // enabled by getExtension
    TextureUnitSampler draw_sampler_;
    uint32_t draw_sampler_filled_[4] = {0, 0, 0, 0};   // units[unit][dim] set by the last draw, bit per unit
    std::shared_ptr<Texture>* texture_binding(GLenum target);
    Texture* bound_texture(const char* call, GLenum target, int* face);
    bool check_tex_format(const char* call, GLenum target, int32_t level, GLenum internal_format,
                          GLenum format, GLenum type, const FormatInfo** info);
    bool check_tex_source(const char* call, const TexSource& source, GLenum format, GLenum type,
                          int32_t width, int32_t height, int32_t depth, PixelUnpack& unpack);
    CompletenessRules completeness_rules() const;
    std::shared_ptr<Framebuffer> draw_framebuffer_, read_framebuffer_;
    std::shared_ptr<Renderbuffer> renderbuffer_;
    GLenum default_read_buffer_ = gl::BACK;
    GLenum default_draw_buffer_ = gl::BACK;
    bool reading_to_pack_buffer_ = false;   // read_pixels called by read_pixels_to_pack_buffer
    std::shared_ptr<Framebuffer>* framebuffer_binding(GLenum target);
    Attachment* attachment_slot(Framebuffer& fb, GLenum attachment, bool* both);
    GLenum framebuffer_status(const Framebuffer& fb, std::string* why) const;
    bool color_renderable(const FormatInfo& f) const;
    bool check_draw_framebuffer(const char* call, const uint32_t used_units[4]);
    std::optional<Value> framebuffer_parameter(GLenum pname);
    void detach_from_framebuffers(const Texture* texture, const Renderbuffer* renderbuffer);
    bool read_source(const char* call, ColorReadSource& out);
    // ---- end textures and framebuffers ------------------------------------------------------

    std::unique_ptr<ThreadPool> pool_;   // created at the first draw
    Tuning tuning_ = Tuning::process_default();
    WorkBudget work_budget_;
    WorkLimits work_limits_;
    DrawStats stats_;
    std::optional<DrawPlan> last_draw_plan_;
};

std::string enum_name(uint32_t value);   // "BLEND" or "0x1234"

}  // namespace softgl
