// The executor: runs an IrProgram over many lanes at once (SIMD over vertices or fragments).
// Registers are arrays of `batch` lanes (structure of arrays); each instruction is one tight
// loop over the lanes of a batch. Control flow is masked: lanes leave a branch, loop, function
// or the whole program (discard) by clearing their bit in the execution mask.
//
// Fragment lanes arrive as 2x2 quads: lanes 4q+0, 4q+1, 4q+2, 4q+3 are the pixels (x, y),
// (x+1, y), (x, y+1), (x+1, y+1). dFdx/dFdy (and the implicit LOD of texture lookups) are the
// differences inside a quad: dFdx = row's right - left, dFdy = column's top - bottom (fine
// derivatives). Lanes of a quad that are not covered (helpers) must still be supplied.
//
// Results never depend on the batch size or lane count: lanes are independent (except inside a
// quad, and quads are never split as long as batch sizes are multiples of 4).
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "softgl/core/simd.h"
#include "softgl/core/tuning.h"
#include "softgl/core/work_budget.h"
#include "softgl/glsl/ir.h"

namespace softgl::glsl {

// ---- The texture interface the pipeline implements -------------------------------------
struct TextureQuery {
    TextureKind kind = TextureKind::Sample;
    SamplerDim dim = SamplerDim::Tex2D;
    bool shadow = false;
    BaseType result = BaseType::Float;   // float, int or uint texels
    TextureLod lod_mode = TextureLod::Implicit;
    int lane_count = 0;
    const uint32_t* active = nullptr;    // per lane: all ones if the lane's result is needed
    const Scalar* unit = nullptr;        // per lane: texture unit (.i) from the sampler uniform
    bool uniform_unit = false;           // every lane's unit is the same (a sampler uniform loaded once per run)
    const Scalar* coord[3] = {nullptr, nullptr, nullptr};  // s, t, r/layer (.f; .i for Fetch)
    const Scalar* compare = nullptr;     // shadow reference (.f)
    const Scalar* lod = nullptr;         // bias (Bias), level (Explicit, Fetch, Size)
    // Coordinate derivatives per lane: from the quad for Implicit/Bias in fragment shaders, the
    // shader's for Gradient, zero in vertex shaders.
    const Scalar* ddx[3] = {nullptr, nullptr, nullptr};
    const Scalar* ddy[3] = {nullptr, nullptr, nullptr};
    int offset[3] = {0, 0, 0};
    Scalar* out[4] = {nullptr, nullptr, nullptr, nullptr};  // results (.f, .i or .u); Size: width, height, depth
    // How the pipeline's sampler may serve the query: the draw's path (core/tuning.h) and at most
    // the executor's SIMD level.
    SamplerPath path = SamplerPath::Best;
    SimdLevel simd = SimdLevel::Scalar;
    // The sampler adds 1 here when its fast path serves the query: the worker's own counter, so
    // no two threads write it (null: not counted).
    uint64_t* fast_queries = nullptr;
};

class TextureSampler {
public:
    virtual ~TextureSampler() = default;
    virtual void sample(const TextureQuery& query) = 0;
    // False when the level of detail cannot change what `query` (all but its derivatives filled
    // in) returns: implicit derivatives are then left out.
    virtual bool lod_matters(const TextureQuery&) const { return true; }
    // Texel words (docs/architecture.md, "Fast paths"): true when every result of `query` (all but
    // its coordinates, derivatives and outputs filled in) is the four channels k / 255 of one
    // 8-bit unorm texel whatever the coordinates (NEAREST of byte storage, no LOD choice), or,
    // where `linear` allows, the fixed-point LINEAR rule of one 8-bit unorm level; sample_words
    // then gives the RGBA8 words (channel c in byte c) a plain write makes of them, words[lane].
    virtual bool gives_words(const TextureQuery&, bool linear) const { (void)linear; return false; }
    virtual void sample_words(const TextureQuery& query, uint32_t* words) { (void)query, (void)words; }
    // False when the level of detail can change no lookup of dimension `dim` during the current
    // draw (whichever unit it reads): such lookups then need no quad neighbours.
    virtual bool lod_matters_in(SamplerDim) const { return true; }
};

struct ExecutionError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// One run of a stage over `lane_count` lanes.
struct StageRun {
    int lane_count = 0;
    // program.inputs[i] reads inputs[i][lane] (nullptr: zero). Built-in fragment inputs:
    // gl_FragCoord (4 slots), gl_FrontFacing (.i 0/1), gl_PointCoord (2 slots).
    const Scalar* const* inputs = nullptr;
    // program.outputs[i] is written to outputs[i][lane] (nullptr: not needed): every lane of the run
    // when some instruction writes the output's register (glsl_stages relies on it), else perhaps none.
    Scalar* const* outputs = nullptr;
    const Scalar* uniforms = nullptr;  // the flat uniform buffer (reflection offsets)
    TextureSampler* sampler = nullptr;
    uint8_t* discarded = nullptr;      // fragment: set to 1 for lanes that executed discard
    SamplerPath sampler_path = SamplerPath::Best;   // TextureQuery::path of every lookup
    uint64_t* fast_texture_queries = nullptr;       // TextureQuery::fast_queries of every lookup
    // The call's work budget (core/work_budget.h), charged lanes x loop body per loop iteration
    // (straight-line code is not charged); WorkStopped ends the run. Null: the executor's own
    // budget of kExecutorRunBudgetDefault per run (tests, constant folding).
    WorkBudget* budget = nullptr;
};

struct ExecutorFrame;

// The lane loops are compiled three times: the portable baseline build (SSE2 on x86-64; it serves
// SimdLevel::Scalar and SSE2), and again for 8- and 16-float vectors (AVX2, AVX512; no FMA),
// chosen at run time (core/simd.h). Every level gives the same bits: the loops use only IEEE
// operations that round identically at any width, and the same libm functions (called per lane).
using softgl::SimdLevel;
using softgl::best_simd_level;
using softgl::SamplerPath;

class Executor {
public:
    // batch_lanes: lanes per register (rounded up to a multiple of 4). hoist: values that depend
    // only on uniforms and constants are computed once, before the batches (order_prologue);
    // off: only the leading uniform loads are (the reference, Tuning::hoist_uniform_values).
    explicit Executor(const IrProgram& program, int batch_lanes = 128, bool hoist = true);
    ~Executor();
    Executor(const Executor&) = delete;
    Executor& operator=(const Executor&) = delete;
    void run(const StageRun& run);

    // The level the lane loops (and the sampler's, TextureQuery::simd) run at: best_simd_level()
    // unless lowered, e.g. to a draw's Tuning::simd; capped at best_simd_level().
    void set_simd_level(SimdLevel level) { simd_ = std::min(level, best_simd_level()); }
    SimdLevel simd_level() const { return simd_; }
    // The code that runs, fused instructions included (tests: which fusions applied).
    const std::vector<Instruction>& code() const { return code_; }
    // The first prologue_size() instructions of code() run once per run at most (tests).
    size_t prologue_size() const { return prologue_end_; }
    bool hoists() const { return hoist_; }

private:
    void run_batch(const StageRun& run, int first_lane, int lanes);
    void run_prologue(const StageRun& run);
    // code_[begin, end) over `lanes` lanes; the body, inlined into:
    void execute(int lanes, const StageRun& run, size_t begin, size_t end);
    void execute_portable(int lanes, const StageRun& run, size_t begin, size_t end);
    void execute_avx2(int lanes, const StageRun& run, size_t begin, size_t end);
    void execute_avx512(int lanes, const StageRun& run, size_t begin, size_t end);
    std::vector<Instruction> order_prologue(const IrProgram& program, const std::vector<uint8_t>& is_slot, bool hoist);
    // The longer value operations of execute(), inlined into it.
    void fused_dot(const Instruction& i, int lanes);
    void fused_normalize(const Instruction& i, int lanes);
    void fused_pair(const Instruction& i, int lanes);
    void load_indexed(const Instruction& i, int lanes);
    void store_indexed(const Instruction& i, const uint32_t* mask, bool all, int lanes);
    // Register r's lanes for the current batch: its own storage, or (inputs the program never
    // writes, outputs) the caller's arrays directly, so inputs and outputs are not copied.
    Scalar* reg(Reg r) { return reg_ptr_[r]; }
    Scalar* own(Reg r) { return registers_.data() + static_cast<size_t>(r) * batch_; }
    void texture(const Instruction& ins, int lanes, const StageRun& run);
    void fuse_products(const IrProgram& program, const std::vector<uint8_t>& is_slot);
    void fuse_normalize_and_pairs(const IrProgram& program, const std::vector<uint8_t>& is_slot);
    void fuse_texture_moves(const IrProgram& program, const std::vector<uint8_t>& is_slot);

    const IrProgram& program_;
    // The code that runs: the program's, with each chain `fmul, fmul, fadd (, fmul, fadd)...`
    // of single-use temporaries fused into one FDot (imm[0]: index into products_, imm[1]: the
    // number of products, 2..4): one pass over the lanes with the same operations in the same
    // order instead of one pass per instruction.
    // Then (fuse_normalize_and_pairs) each `FDot v.v, FSqrt, FDiv v_k` of normalize() into one
    // FNormalize (imm[0]: index into products_ holding v_0..v_3 then the results, imm[1]: the
    // components, 2..4), and each float operation whose single-use temporary the next one reads
    // into one FPair (a op1 b, then op2 with c; imm: op1, op2, which operand of op2 the temporary
    // is). The same operations in the same order, one pass instead of several: the same bits.
    std::vector<Instruction> code_;
    std::vector<std::array<Reg, 8>> products_;   // a0, b0, a1, b1, ...: sum of a_k * b_k
    // The texture operands the code uses: the program's, except that fuse_texture_moves points a
    // lookup's results straight at the registers the Movs after it copied them to.
    std::vector<TextureOperands> textures_;
    // What run_batch does per batch for each interface slot, resolved once: the inputs some
    // instruction reads (or an output holds; the others are never pointed at nor filled), and the
    // outputs. alias: the register may be the caller's array; variable: zeroed when not supplied.
    struct BatchSlot {
        uint32_t slot;
        Reg reg;
        bool alias, variable;
    };
    std::vector<BatchSlot> batch_inputs_, batch_outputs_;
    int batch_;
    std::vector<Scalar> registers_;
    std::vector<uint32_t> mask_storage_;
    std::vector<Scalar*> reg_ptr_;
    // Variables that some path may read before writing them in every lane: zeroed per batch.
    // Variables whose first use is a whole-batch write before any control flow are not.
    std::vector<Reg> variable_registers_;
    std::vector<int> input_alias_;    // per program input: 1 if its register may alias the caller's array
    std::vector<int> output_alias_;   // per program output: 1 if its register may alias the caller's array
    std::vector<ExecutorFrame> frames_;
    // code_[0, prologue_end_): uniform loads and (hoist_) values of uniforms and constants only,
    // run once on one quad and copied to the lanes runs use (prologue_lanes_ of them: a run
    // of 36 lanes copies to 48, not to the whole batch); again only when the uniform words
    // [prologue_words_[0], prologue_words_[1]) it loads differ from prologue_uniforms_.
    size_t prologue_end_ = 0;
    int prologue_lanes_ = 0;
    int32_t prologue_words_[2] = {std::numeric_limits<int32_t>::max(), 0};
    std::vector<Scalar> prologue_uniforms_;
    bool prologue_had_uniforms_ = false;
    bool prologue_ready_ = false;
    SimdLevel simd_ = SimdLevel::SSE2;
    bool hoist_ = true;
    bool skip_inactive_lanes_ = false;   // libm calls only in active lanes (see the constructor)
    int max_depth_ = 0;
    std::vector<Scalar> scratch_;  // derivatives for texture lookups
    // The run's budget and the units not yet passed on to it (every WorkBudget::kFlushUnits, and
    // at the end of the run): one shared atomic add per 65,536 units, not per loop iteration.
    WorkBudget* budget_ = nullptr;
    WorkBudget own_budget_;
    uint64_t unflushed_ = 0;
    void charge(uint64_t units) {
        unflushed_ += units;
        if (unflushed_ >= WorkBudget::kFlushUnits) flush_charges();
    }
    void flush_charges() {
        const uint64_t u = unflushed_;
        unflushed_ = 0;
        budget_->charge(u);
    }
    // Registers only the prologue's uniform loads write: the same value in every lane
    // (TextureQuery::uniform_unit).
    std::vector<uint8_t> uniform_register_;
};

}  // namespace softgl::glsl
