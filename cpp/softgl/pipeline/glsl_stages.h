// The GLSL executor behind the pipeline's stage interfaces: a linked program's vertex and
// fragment IR run over the lanes the pipeline provides, reading the program's uniform buffer.
#pragma once
#include <memory>
#include <mutex>
#include <vector>

#include "softgl/glsl/compiler.h"
#include "softgl/glsl/executor.h"
#include "softgl/pipeline/shader_stage.h"

namespace softgl {

// Texture lookups while softgl has no texture objects: every sampler reads an incomplete
// texture, which samples as (0, 0, 0, 1) (ES 3.0 §3.8.14), and textureSize is 0.
class IncompleteTextureSampler : public glsl::TextureSampler {
public:
    void sample(const glsl::TextureQuery& query) override;
};

class GlslVertexShader : public VertexShader {
public:
    // Per vertex input slot: the attribute location and component it reads (-1: built-in).
    GlslVertexShader(std::shared_ptr<const glsl::LinkedProgram> program, const std::vector<int>& input_location,
                     const std::vector<int>& input_component);
    uint32_t used_attributes() const override { return used_; }
    const VaryingLayout& varying_layout() const override { return layout_; }
    void prepare(const Tuning& tuning) const override;
    void run(const std::array<AttributeStream, kMaxVertexAttribs>& attribs, size_t count,
             const uint32_t* vertex_ids, const uint32_t* instance_ids, const VertexDestination& out) const override;
    void set_uniforms(const glsl::Scalar* uniforms) { uniforms_ = uniforms; }
    // The bound textures for this draw (null: every lookup reads an incomplete texture).
    void set_sampler(glsl::TextureSampler* sampler) { textures_ = sampler; }
    // The lookups the sampler's fast path served since the last call (DrawStats::texture_queries_fast).
    uint64_t take_fast_texture_queries() const;
    // The draw's work budget (core/work_budget.h), charged by the executors' loops.
    void set_budget(WorkBudget* budget) { budget_ = budget; }

private:
    WorkBudget* budget_ = nullptr;
    glsl::TextureSampler* textures_ = nullptr;
    mutable SimdLevel simd_ = best_simd_level();             // the draw's (prepare)
    mutable SamplerPath sampler_path_ = SamplerPath::Best;   // the draw's (prepare)
    mutable bool hoist_ = true;                              // the draw's Tuning::hoist_uniform_values
    std::shared_ptr<const glsl::LinkedProgram> program_;
    std::vector<int> input_location_;    // per vertex input slot: attribute location, -1 built-in
    std::vector<int> input_component_;   // per vertex input slot: component of that location
    std::vector<int> output_word_;       // per vertex output slot: varying word, -1 otherwise
    std::vector<uint8_t> unwritten_;     // per vertex output slot: no instruction writes its register
    int position_slot_[4] = {-1, -1, -1, -1};
    int point_size_slot_ = -1;
    uint32_t used_ = 0;
    VaryingLayout layout_;
    enum class Builtin : uint8_t { None, VertexId, InstanceId };
    std::vector<Builtin> input_builtin_;   // per vertex input slot
    const glsl::Scalar* uniforms_ = nullptr;
    // run() may be called from several threads at once: each call borrows an idle executor with
    // its working arrays (kept between calls: a one-vertex draw allocates nothing).
    struct Run {
        std::unique_ptr<glsl::Executor> executor;
        std::vector<glsl::Scalar> ids, instances, results;
        std::vector<const glsl::Scalar*> inputs;
        std::vector<glsl::Scalar*> outputs;
        std::vector<glsl::Scalar> zeros;                 // an unwritten position component or varying word
        std::vector<const glsl::Scalar*> word_source;    // per varying word: its results (or zeros)
        uint64_t fast_texture_queries = 0;
    };
    mutable std::mutex runs_mutex_;
    mutable std::vector<std::unique_ptr<Run>> idle_runs_;
    mutable IncompleteTextureSampler sampler_;
};

class GlslFragmentShader : public FragmentShader {
public:
    GlslFragmentShader(std::shared_ptr<const glsl::LinkedProgram> program, const VaryingLayout& layout);
    bool may_discard() const override { return program_->reflection.fragment_usage.may_discard; }
    bool writes_depth() const override { return program_->reflection.fragment_usage.writes_frag_depth; }
    bool reads_quad_neighbours() const override { return quad_neighbours_; }
    bool reads_quad_neighbours_in_draw() const override;
    uint32_t builtins_read() const override { return builtins_read_; }
    void prepare(unsigned workers, const Tuning& tuning) const override;
    void run(const FragmentBatch& batch, FragmentResults& out, unsigned worker) const override;
    bool run_constant(FragmentResults& out, unsigned worker) const override;
    bool run_flat(const uint32_t* varyings, FragmentResults& out, unsigned worker) const override;
    bool runs_flat() const override { return flat_; }
    const FragmentCopies* copies() const override;
    bool copies_texture() const override { return texture_copy_.texture >= 0; }
    bool gives_texel_words() const override;
    void run_words(const FragmentBatch& batch, uint32_t* words, unsigned worker) const override;
    void set_uniforms(const glsl::Scalar* uniforms) { uniforms_ = uniforms; }
    // The bound textures for this draw (null: every lookup reads an incomplete texture). The
    // sampler must be safe to call from several workers at once (TextureUnitSampler is).
    void set_sampler(glsl::TextureSampler* sampler) { textures_ = sampler; }
    // The lookups the sampler's fast path served since the last call (DrawStats::texture_queries_fast).
    uint64_t take_fast_texture_queries() const;
    uint64_t instructions_bound() const override { return instructions_bound_; }
    // The draw's work budget (core/work_budget.h), charged by the executors' loops.
    void set_budget(WorkBudget* budget) { budget_ = budget; }

private:
    uint64_t instructions_bound_ = ~uint64_t(0);   // glsl::instructions_bound of the program
    WorkBudget* budget_ = nullptr;
    bool find_copies();
    glsl::TextureSampler* textures_ = nullptr;
    mutable SamplerPath sampler_path_ = SamplerPath::Best;   // the draw's (prepare)
    std::shared_ptr<const glsl::LinkedProgram> program_;
    std::vector<int> input_word_;        // per fragment input slot: varying word, or -1
    std::vector<int> input_builtin_;     // per fragment input slot: 0..3 FragCoord, 4 FrontFacing, 5..6 PointCoord, -1
    std::vector<int> color_slot_;        // output slot of component c of colour output o, [4 * o + c] (or -1)
    int outputs_ = 1;                    // colour outputs the results carry (1 + highest location written)
    bool broadcast_ = false;             // gl_FragColor with GL_EXT_draw_buffers: output 0 copied to all
    int depth_slot_ = -1;
    uint32_t builtins_read_ = 0;         // FragmentBuiltin bits
    bool quad_neighbours_ = true;        // glsl::reads_quad_neighbours of the fragment IR
    bool derivatives_ = true;            // glsl::takes_derivatives of the fragment IR
    uint32_t implicit_lod_dims_ = ~0u;   // glsl::implicit_lod_dims of the fragment IR
    bool uniform_only_ = false;          // outputs depend only on uniforms: run one quad, broadcast
    bool flat_ = false;                  // run_flat: no discard, depth, built-ins or quad neighbours
    bool run_one_quad(const uint32_t* varyings, FragmentResults& out, unsigned worker) const;
    bool copies_only_ = false;           // the program only copies varyings or constants to colours
    FragmentCopies copies_;              // ... which ones (when copies_only_)
    // Texture copies (docs/architecture.md, "Fast paths"): the program loads a sampler uniform,
    // makes one implicit-LOD 2D lookup at two varying words and moves its four results, in order,
    // to its one colour output. run() then builds the executor's query itself and asks the sampler.
    struct TextureCopy {
        int texture = -1;                // the lookup (IrProgram::textures), -1: not such a program
        int32_t unit_uniform = 0;        // the sampler uniform's word in the uniform buffer
        int word[2] = {-1, -1};          // the varying words of s and t
    };
    bool find_texture_copy();
    void run_texture_copy(const FragmentBatch& batch, FragmentResults& out, unsigned worker) const;
    // The texture copy's query for the batch's lanes (outputs and derivatives left unset).
    glsl::TextureQuery texture_copy_query(const FragmentBatch& batch, unsigned worker) const;
    TextureCopy texture_copy_;
    mutable bool texture_copies_ = true;                     // the draw's Tuning::texture_copies (prepare)
    mutable bool linear_words_ = true;                       // ... and Tuning::linear_words
    mutable SimdLevel simd_ = best_simd_level();             // the draw's (prepare), as the executor's
    const glsl::Scalar* uniforms_ = nullptr;
    struct Worker {
        std::unique_ptr<glsl::Executor> executor;
        std::vector<glsl::Scalar> builtins;          // front facing as ints
        std::vector<glsl::Scalar> outputs;
        std::vector<const glsl::Scalar*> input_ptrs;
        std::vector<glsl::Scalar*> output_ptrs;
        FragmentBatch quad;                          // run_constant/run_flat: one quad, every lane alike
        FragmentResults quad_results;
        IncompleteTextureSampler sampler;
        uint64_t fast_texture_queries = 0;
        // run_texture_copy: every lane active, the unit in every lane, the implicit derivatives.
        std::vector<uint32_t> active;
        std::vector<glsl::Scalar> units, derivatives;
    };
    mutable std::vector<Worker> workers_;
};

}  // namespace softgl
