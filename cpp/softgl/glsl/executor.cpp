#include "softgl/glsl/executor.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "softgl/core/vector_math.h"
#include "softgl/glsl/builtin_math.h"

namespace softgl::glsl {
namespace {

bool any_set(const uint32_t* m, int n) {
    uint32_t acc = 0;
    for (int l = 0; l < n; ++l) acc |= m[l];
    return acc != 0;
}
bool all_set(const uint32_t* m, int n) {
    uint32_t acc = ~0u;
    for (int l = 0; l < n; ++l) acc &= m[l];
    return acc == ~0u;
}

// d = a in the lanes of `mask`. Through uint32_t pointers: GCC 12 does not vectorise this
// read-modify-write through the Scalar union ("unsupported data-type").
__attribute__((always_inline)) inline void masked_copy(Scalar* d, const Scalar* a, const uint32_t* mask, int n) {
    uint32_t* du = reinterpret_cast<uint32_t*>(d);
    const uint32_t* au = reinterpret_cast<const uint32_t*>(a);
    for (int l = 0; l < n; ++l) du[l] = (au[l] & mask[l]) | (du[l] & ~mask[l]);
}

// A value in every lane (written through .u so the loop vectorises).
void fill(Scalar* d, int n, Scalar v) {
    for (int l = 0; l < n; ++l) d[l].u = v.u;
}

bool same_in_all_lanes(const Scalar* v, int n) {
    uint32_t diff = 0;
    for (int l = 0; l < n; ++l) diff |= v[l].u ^ v[0].u;
    return diff == 0;
}

enum class FrameKind : uint8_t { If, Loop, Switch, Function };

}  // namespace

struct ExecutorFrame {
    FrameKind kind;
    uint32_t* saved;  // mask at entry (minus lanes that left through an enclosing construct)
    uint32_t* other;  // If: lanes for the else branch; Loop: lanes still looping
    int begin;        // index of the opening instruction
    bool in_else = false;
};
using Frame = ExecutorFrame;

Executor::Executor(const IrProgram& program, int batch_lanes, bool hoist)
    : program_(program), simd_(best_simd_level()), hoist_(hoist) {
    batch_ = std::max(4, (batch_lanes + 3) / 4 * 4);
    registers_.assign(static_cast<size_t>(program.register_count) * batch_, Scalar{});
    reg_ptr_.resize(program.register_count);
    for (Reg r = 0; r < program.register_count; ++r) reg_ptr_[r] = own(r);
    for (const ConstantRegister& c : program.constants) std::fill_n(own(c.reg), batch_, c.value);

    // Which variables need zeroing per batch. Before the first control-flow instruction (other
    // than entering a function) every lane is active, so a Mov or any value instruction writes
    // all lanes of its destination; a variable whose first use there is such a write is never
    // observed unwritten. Everything else (read first, written under a mask, written by a
    // texture lookup or StoreIndexed, or first used after control flow) is zeroed as before.
    const size_t R = program.register_count;
    std::vector<uint8_t> seen(R, 0), full_write_first(R, 0), written(R, 0);
    bool prefix = true;
    for (const Instruction& i : program.code) {
        if (op_is_control(i.op) && i.op != Op::FunctionBegin) prefix = false;
        for_each_read(program, i, [&](Reg r) { seen[r] = 1; }, false);
        for_each_write(program, i, [&](Reg r) {
            written[r] = 1;
            if (!seen[r] && prefix && i.op != Op::Texture && i.op != Op::StoreIndexed) full_write_first[r] = 1;
            seen[r] = 1;
        });
    }
    std::vector<uint8_t> is_input(R, 0);
    for (const Slot& s : program.inputs) if (s.reg < R) is_input[s.reg] = 1;
    for (Reg r = 0; r < program.register_count; ++r)   // inputs: copied, aliased or zeroed in run_batch
        if (program.is_variable[r] && !full_write_first[r] && !is_input[r]) variable_registers_.push_back(r);
    // Aliasing: an input register the program never writes can be read straight from the
    // caller's array; an output register (used by one output slot, not an input, not a
    // constant) can live in the caller's output array.
    std::vector<uint8_t> is_constant(R, 0), slot_uses(R, 0);
    for (const ConstantRegister& c : program.constants) is_constant[c.reg] = 1;
    for (const Slot& s : program.inputs) if (s.reg < R) ++slot_uses[s.reg];
    for (const Slot& s : program.outputs) if (s.reg < R) ++slot_uses[s.reg];
    input_alias_.assign(program.inputs.size(), 0);
    for (size_t k = 0; k < program.inputs.size(); ++k) {
        const Reg r = program.inputs[k].reg;
        input_alias_[k] = r < R && !written[r] && !is_constant[r] && slot_uses[r] == 1;
    }
    output_alias_.assign(program.outputs.size(), 0);
    for (size_t k = 0; k < program.outputs.size(); ++k) {
        const Reg r = program.outputs[k].reg;
        output_alias_[k] = r < R && !is_constant[r] && slot_uses[r] == 1;
    }
    // The uniform loads the lowering puts first write temporaries whose value is the same in
    // every batch of a run.
    std::vector<uint8_t> is_slot(R, 0);
    for (const Slot& s : program.inputs) if (s.reg < R) is_slot[s.reg] = 1;
    for (const Slot& s : program.outputs) if (s.reg < R) is_slot[s.reg] = 1;
    code_ = order_prologue(program, is_slot, hoist);
    uniform_register_.assign(R, 0);
    for (size_t pc = 0; pc < prologue_end_; ++pc) uniform_register_[code_[pc].dst] = 1;
    for (size_t pc = prologue_end_; pc < code_.size(); ++pc)
        for_each_write(program, code_[pc], [&](Reg r) { uniform_register_[r] = 0; });
    for (size_t pc = 0; pc < prologue_end_; ++pc)
        if (code_[pc].op == Op::LoadUniform) {
            prologue_words_[0] = std::min(prologue_words_[0], code_[pc].imm[0]);
            prologue_words_[1] = std::max(prologue_words_[1], code_[pc].imm[0] + 1);
        }
    // Lanes that are inactive compute values nobody reads: a libm call (tan, asin, sinh...) or
    // a vector_math op (pow, exp2, sin...) can skip them when provably nothing does. Readers of inactive lanes would be quad neighbours
    // (derivatives, implicit LOD), or a temporary read where more lanes are active than where
    // it was defined: outside its straight-line region (region_ends). Masked Movs and stores
    // never copy inactive lanes into variables, and outputs are variables.
    skip_inactive_lanes_ = !reads_quad_neighbours(program);
    const std::vector<int32_t> region_end = region_ends(program);
    std::vector<int32_t> defined_at(R, -1);
    auto temporary = [&](Reg r) { return !program.is_variable[r] && !is_constant[r] && !is_input[r]; };
    for (const Slot& s : program.outputs) if (s.reg < R && temporary(s.reg)) skip_inactive_lanes_ = false;
    for (size_t k = 0; k < program.code.size() && skip_inactive_lanes_; ++k) {
        const Instruction& i = program.code[k];
        for_each_read(program, i, [&](Reg r) {
            if (!temporary(r)) return;
            const int32_t d = defined_at[r];
            if (d < 0 || static_cast<int32_t>(k) >= region_end[static_cast<size_t>(d)]) skip_inactive_lanes_ = false;
        });
        for_each_write(program, i, [&](Reg r) {
            if (!temporary(r)) return;
            if (defined_at[r] >= 0) skip_inactive_lanes_ = false;   // temporaries are written once
            defined_at[r] = static_cast<int32_t>(k);
        });
    }
    fuse_products(program, is_slot);
    fuse_normalize_and_pairs(program, is_slot);
    textures_ = program.textures;
    fuse_texture_moves(program, is_slot);
    // run_batch's slots. An input register that no instruction reads and no output holds is
    // never looked at: not pointed at, copied or zeroed (gl_FragCoord, gl_PointCoord... unread).
    std::vector<uint8_t> read(R, 0);
    for (const Instruction& i : program.code) for_each_read(program, i, [&](Reg r) { read[r] = 1; });
    for (const Slot& s : program.outputs) if (s.reg < R) read[s.reg] = 1;
    for (size_t k = 0; k < program.inputs.size(); ++k) {
        const Reg r = program.inputs[k].reg;
        if (r < R && read[r]) batch_inputs_.push_back({uint32_t(k), r, input_alias_[k] != 0, bool(program.is_variable[r])});
    }
    for (size_t k = 0; k < program.outputs.size(); ++k)
        batch_outputs_.push_back({uint32_t(k), program.outputs[k].reg, output_alias_[k] != 0, false});
    int depth = 0;
    for (const Instruction& i : program.code) {
        if (i.op == Op::IfBegin || i.op == Op::LoopBegin || i.op == Op::SwitchBegin || i.op == Op::FunctionBegin) max_depth_ = std::max(max_depth_, ++depth);
        if (i.op == Op::IfEnd || i.op == Op::LoopEnd || i.op == Op::SwitchEnd || i.op == Op::FunctionEnd) --depth;
    }
    mask_storage_.assign(static_cast<size_t>(2 * max_depth_ + 2) * batch_, 0);
    scratch_.assign(static_cast<size_t>(6) * batch_, Scalar{});
    frames_.reserve(static_cast<size_t>(max_depth_) + 1);
}

// The prologue, run once per run (or less often, see run()) instead of per batch: the leading
// uniform loads and, when hoisting, every value instruction outside loops whose operands all
// have the same value in every lane (constants, uniforms, results of such instructions), moved
// before the rest in program order. Such a value is the same in every lane, so computing it once
// on one quad gives each lane the bits it computed before: the value operations are lane by lane
// (derivatives, texture lookups, indexed loads and masked writes stay put) and give the same bits
// at every SIMD width and lane count. Moving one out of a branch computes it where no lane needed
// it: value operations do not trap (integer division is defined for every operand,
// builtin_math.h) and straight-line code is not charged to the work budget, so nothing else can
// tell. Loop bodies are left whole: their length is what each iteration charges.
std::vector<Instruction> Executor::order_prologue(const IrProgram& program, const std::vector<uint8_t>& is_slot, bool hoist) {
    const std::vector<Instruction>& code = program.code;
    const size_t R = program.register_count;
    std::vector<int> writes(R, 0);
    for (const Instruction& i : code) for_each_write(program, i, [&](Reg r) { ++writes[r]; });
    std::vector<uint8_t> invariant(R, 0);   // the same value in every lane of the run
    for (const ConstantRegister& c : program.constants)
        if (c.reg < R && writes[c.reg] == 0 && !program.is_variable[c.reg]) invariant[c.reg] = 1;
    std::vector<uint8_t> moved(code.size(), 0);
    bool leading = true;   // still in the lowering's leading uniform loads
    int loops = 0;
    for (size_t k = 0; k < code.size(); ++k) {
        const Instruction& i = code[k];
        if (i.op == Op::LoopBegin) ++loops;
        if (i.op == Op::LoopEnd) --loops;
        const bool temporary = i.dst != kNoReg && i.dst < R && !program.is_variable[i.dst] && !is_slot[i.dst] &&
                               writes[i.dst] == 1 && !invariant[i.dst];
        bool move = false;
        if (leading && i.op == Op::LoadUniform && temporary) move = true;
        else if (hoist && temporary && loops == 0) {
            switch (i.op) {
            case Op::Mov: case Op::Texture: case Op::LoadIndexed: case Op::StoreIndexed: case Op::LoadUniformIndexed:
            case Op::DFdx: case Op::DFdy: case Op::FDot: case Op::FNormalize: case Op::FPair:
                break;
            default:
                move = !op_is_control(i.op);
                for_each_read(program, i, [&](Reg r) { if (r >= R || !invariant[r]) move = false; });
            }
        }
        if (!move || i.op != Op::LoadUniform) leading = false;
        if (move) moved[k] = 1, invariant[i.dst] = 1;
    }
    std::vector<Instruction> ordered;
    ordered.reserve(code.size());
    for (size_t k = 0; k < code.size(); ++k) if (moved[k]) ordered.push_back(code[k]);
    prologue_end_ = ordered.size();
    for (size_t k = 0; k < code.size(); ++k) if (!moved[k]) ordered.push_back(code[k]);
    IrProgram linked;   // control instructions moved: their targets again
    linked.code = std::move(ordered);
    link_control_flow(linked);
    return std::move(linked.code);
}

void Executor::fuse_products(const IrProgram& program, const std::vector<uint8_t>& is_slot) {
    const std::vector<Instruction> code = code_;
    std::vector<int> reads(program.register_count, 0);
    for (const Instruction& i : code) for_each_read(program, i, [&](Reg r) { ++reads[r]; });
    // A temporary only the next link of the chain reads.
    auto single_use = [&](Reg r) { return !program.is_variable[r] && !is_slot[r] && reads[r] == 1; };
    // No fusion joins the prologue to the body: `end` is the end of k's part.
    size_t end = code.size();
    auto is_mul = [&](size_t k) { return k < end && code[k].op == Op::FMul && single_use(code[k].dst); };
    IrProgram fused;
    fused.code.reserve(code.size());
    size_t prologue_end = 0;
    for (size_t k = 0; k < code.size();) {
        end = k < prologue_end_ ? prologue_end_ : code.size();
        if (k == prologue_end_) prologue_end = fused.code.size();
        if (!(is_mul(k) && is_mul(k + 1) && k + 2 < end && code[k + 2].op == Op::FAdd &&
              code[k + 2].a == code[k].dst && code[k + 2].b == code[k + 1].dst)) {
            fused.code.push_back(code[k++]);
            continue;
        }
        std::array<Reg, 8> p{};
        p.fill(kNoReg);
        p[0] = code[k].a; p[1] = code[k].b; p[2] = code[k + 1].a; p[3] = code[k + 1].b;
        int terms = 2;
        size_t last = k + 2;   // the FAdd holding the sum so far
        while (terms < 4 && single_use(code[last].dst) && is_mul(last + 1) && last + 2 < end &&
               code[last + 2].op == Op::FAdd && code[last + 2].a == code[last].dst && code[last + 2].b == code[last + 1].dst) {
            p[2 * terms] = code[last + 1].a;
            p[2 * terms + 1] = code[last + 1].b;
            ++terms;
            last += 2;
        }
        Instruction dot;
        dot.op = Op::FDot;
        dot.dst = code[last].dst;
        dot.imm[0] = static_cast<int32_t>(products_.size());
        dot.imm[1] = terms;
        dot.line = code[last].line;
        products_.push_back(p);
        fused.code.push_back(dot);
        k = last + 1;
    }
    if (prologue_end_ == code.size()) prologue_end = fused.code.size();
    prologue_end_ = prologue_end;
    link_control_flow(fused);
    code_ = std::move(fused.code);
}

// The float operations an FPair combines, by number (imm[0], imm[1]); -1: not one of them.
namespace {
int pair_first_op(Op op) {
    switch (op) {
    case Op::FAdd: return 0;
    case Op::FSub: return 1;
    case Op::FMul: return 2;
    case Op::FDiv: return 3;
    default: return -1;
    }
}
int pair_second_op(Op op) {
    switch (op) {
    case Op::FAdd: return 0;
    case Op::FSub: return 1;
    case Op::FMul: return 2;
    case Op::FMax: return 3;
    case Op::FMin: return 4;
    default: return -1;
    }
}
}  // namespace

void Executor::fuse_normalize_and_pairs(const IrProgram& program, const std::vector<uint8_t>& is_slot) {
    const size_t R = program.register_count;
    auto each_read = [&](const Instruction& i, auto&& f) {
        if (i.op == Op::FDot) {
            const std::array<Reg, 8>& p = products_[static_cast<size_t>(i.imm[0])];
            for (int k = 0; k < 2 * i.imm[1]; ++k) f(p[static_cast<size_t>(k)]);
        } else {
            for_each_read(program, i, f);
        }
    };
    std::vector<int> reads(R, 0);
    for (const Instruction& i : code_) each_read(i, [&](Reg r) { ++reads[r]; });
    // A temporary read `uses` times, all of them by the instructions being fused.
    auto only_read = [&](Reg r, int uses) { return r < R && !program.is_variable[r] && !is_slot[r] && reads[r] == uses; };
    const std::vector<Instruction>& code = code_;
    IrProgram fused;
    fused.code.reserve(code.size());
    size_t prologue_end = 0;
    for (size_t k = 0; k < code.size();) {
        const Instruction& i = code[k];
        const size_t end = k < prologue_end_ ? prologue_end_ : code.size();   // no fusion joins prologue and body
        if (k == prologue_end_) prologue_end = fused.code.size();
        // normalize(v): FDot(v, v) -> FSqrt -> v_j / length for each component, in that order.
        if (i.op == Op::FDot && only_read(i.dst, 1) && k + 1 < end && code[k + 1].op == Op::FSqrt &&
            code[k + 1].a == i.dst) {
            const std::array<Reg, 8>& p = products_[static_cast<size_t>(i.imm[0])];
            const int m = i.imm[1];
            const Reg length = code[k + 1].dst;
            bool match = only_read(length, m) && k + 1 + static_cast<size_t>(m) < end;
            for (int j = 0; match && j < m; ++j) {
                const Instruction& d = code[k + 2 + static_cast<size_t>(j)];
                match = p[2 * j] == p[2 * j + 1] && d.op == Op::FDiv && d.a == p[2 * j] && d.b == length;
                for (int c = 0; match && c < m; ++c) match = d.dst != p[2 * c];   // results distinct from inputs (__restrict)
            }
            if (match) {
                std::array<Reg, 8> q{};
                q.fill(kNoReg);
                for (int j = 0; j < m; ++j) q[j] = p[2 * j], q[4 + j] = code[k + 2 + static_cast<size_t>(j)].dst;
                Instruction n;
                n.op = Op::FNormalize;
                n.dst = q[4];
                n.imm[0] = static_cast<int32_t>(products_.size());
                n.imm[1] = m;
                n.line = i.line;
                products_.push_back(q);
                fused.code.push_back(n);
                k += 2 + static_cast<size_t>(m);
                continue;
            }
        }
        // t = a op1 b; d = t op2 c (or c op2 t), t read by nothing else.
        if (k + 1 < end && pair_first_op(i.op) >= 0 && only_read(i.dst, 1)) {
            const Instruction& next = code[k + 1];
            const int second = pair_second_op(next.op);
            const Reg other = next.a == i.dst ? next.b : next.a;
            if (second >= 0 && (next.a == i.dst) != (next.b == i.dst) && next.dst != i.a && next.dst != i.b &&
                next.dst != other) {
                Instruction n;
                n.op = Op::FPair;
                n.dst = next.dst;
                n.a = i.a;
                n.b = i.b;
                n.c = other;
                n.imm[0] = pair_first_op(i.op);
                n.imm[1] = second;
                n.imm[2] = next.a == i.dst ? 0 : 1;
                n.line = next.line;
                fused.code.push_back(n);
                k += 2;
                continue;
            }
        }
        fused.code.push_back(code[k++]);
    }
    if (prologue_end_ == code.size()) prologue_end = fused.code.size();
    prologue_end_ = prologue_end;
    link_control_flow(fused);
    code_ = std::move(fused.code);
}

// `texture rT..; mov X, rT` where rT is a temporary only that Mov reads: the lookup writes X
// itself. Only before the first control flow (other than entering a function), where every lane
// is active, so the lookup writes every lane of X (inactive lanes too: (0, 0, 0, 1)) and the Mov
// copied every lane; X is neither an operand of the lookup nor read or written between the two.
// The same values in X, one pass over the lanes fewer.
void Executor::fuse_texture_moves(const IrProgram& program, const std::vector<uint8_t>& is_slot) {
    const size_t R = program.register_count;
    std::vector<uint8_t> is_constant(R, 0);
    for (const ConstantRegister& c : program.constants) is_constant[c.reg] = 1;
    auto each_read = [&](const Instruction& i, auto&& f) {
        if (i.op == Op::FDot || i.op == Op::FNormalize) {
            const std::array<Reg, 8>& p = products_[static_cast<size_t>(i.imm[0])];
            for (Reg r : p) if (r != kNoReg) f(r);
        } else if (i.op == Op::FPair) {
            f(i.a), f(i.b), f(i.c);
        } else {
            for_each_read(program, i, f);
        }
    };
    auto each_write = [&](const Instruction& i, auto&& f) {
        if (i.op == Op::FNormalize) {
            const std::array<Reg, 8>& p = products_[static_cast<size_t>(i.imm[0])];
            for (int k = 4; k < 8; ++k) if (p[k] != kNoReg) f(p[k]);
        } else if (i.op == Op::Texture) {
            for (Reg r : textures_[static_cast<size_t>(i.texture)].dst) if (r != kNoReg) f(r);
        } else if (i.op != Op::FDot && i.op != Op::FPair) {
            for_each_write(program, i, f);
        } else {
            f(i.dst);
        }
    };
    std::vector<int> reads(R, 0), lookups(program.textures.size(), 0);
    for (const Instruction& i : code_) {
        each_read(i, [&](Reg r) { ++reads[r]; });
        if (i.op == Op::Texture) ++lookups[static_cast<size_t>(i.texture)];
    }
    std::vector<uint8_t> dropped(code_.size(), 0);
    bool any = false;
    // The Mov copying d, when it is the first instruction after k to read d and no control flow
    // comes before it; code_.size() otherwise.
    auto sole_copy_of = [&](size_t k, Reg d) {
        for (size_t j = k + 1; j < code_.size() && !(op_is_control(code_[j].op) && code_[j].op != Op::FunctionBegin); ++j) {
            bool reads_d = false;
            each_read(code_[j], [&](Reg r) { reads_d = reads_d || r == d; });
            if (reads_d) return !dropped[j] && code_[j].op == Op::Mov && code_[j].a == d ? j : code_.size();
        }
        return code_.size();
    };
    // Whether no instruction strictly between k and j reads or writes x.
    auto untouched_between = [&](size_t k, size_t j, Reg x) {
        bool clear = true;
        for (size_t m = k + 1; m < j && clear; ++m) {
            if (dropped[m]) continue;
            each_read(code_[m], [&](Reg r) { clear = clear && r != x; });
            each_write(code_[m], [&](Reg r) { clear = clear && r != x; });
        }
        return clear;
    };
    for (size_t k = 0; k < code_.size(); ++k) {
        const Instruction& i = code_[k];
        if (op_is_control(i.op) && i.op != Op::FunctionBegin) break;   // the prefix only
        if (i.op != Op::Texture || lookups[static_cast<size_t>(i.texture)] != 1) continue;
        TextureOperands& t = textures_[static_cast<size_t>(i.texture)];
        for (int c = 0; c < 4; ++c) {
            const Reg d = t.dst[c];
            if (d == kNoReg || d >= R || program.is_variable[d] || is_slot[d] || is_constant[d] || reads[d] != 1) continue;
            const size_t j = sole_copy_of(k, d);
            if (j == code_.size()) continue;
            const Reg x = code_[j].dst;
            bool clear = x != d && x < R && !is_constant[x];
            Instruction lookup = i;
            for_each_read(program, lookup, [&](Reg r) { clear = clear && r != x; });
            for (int e = 0; e < 4; ++e) clear = clear && t.dst[e] != x;
            if (!clear || !untouched_between(k, j, x)) continue;
            t.dst[c] = x;
            dropped[j] = 1;
            any = true;
        }
    }
    // `op rT, a, b; mov X, rT` for the plain float operations (F2: lane l reads a[l] and b[l]
    // before it writes d[l], so X may be an operand, as in `c += t`): the operation writes X
    // itself, on the same conditions (in the body, not the prologue, which runs once per run).
    for (size_t k = prologue_end_; k < code_.size(); ++k) {
        const Instruction& i = code_[k];
        if (op_is_control(i.op) && i.op != Op::FunctionBegin) break;   // the prefix only
        if (dropped[k] || !(i.op == Op::FAdd || i.op == Op::FSub || i.op == Op::FMul || i.op == Op::FDiv)) continue;
        const Reg d = i.dst;
        if (d == kNoReg || d >= R || program.is_variable[d] || is_slot[d] || is_constant[d] || reads[d] != 1) continue;
        const size_t j = sole_copy_of(k, d);
        if (j == code_.size()) continue;
        const Reg x = code_[j].dst;
        if (x == d || x >= R || is_constant[x] || !untouched_between(k, j, x)) continue;
        code_[k].dst = x;
        dropped[j] = 1;
        any = true;
    }
    if (!any) return;
    IrProgram fused;
    fused.code.reserve(code_.size());
    for (size_t k = 0; k < code_.size(); ++k)
        if (!dropped[k]) fused.code.push_back(code_[k]);
    link_control_flow(fused);
    code_ = std::move(fused.code);
}

Executor::~Executor() = default;

void Executor::run(const StageRun& run) {
    budget_ = run.budget;
    if (!budget_) {
        own_budget_.begin(kExecutorRunBudgetDefault);
        budget_ = &own_budget_;
    }
    unflushed_ = 0;
    run_prologue(run);
    for (int first = 0; first < run.lane_count; first += batch_) run_batch(run, first, std::min(batch_, run.lane_count - first));
    if (unflushed_) flush_charges();   // loops ran: their last iterations (straight-line code is not charged)
}

// The prologue's registers hold the same value in all batch_ lanes, computed on one quad and
// copied to the rest, and kept while the uniforms it reads keep their values (usually a whole
// draw): the registers are written by nothing else.
void Executor::run_prologue(const StageRun& run) {
    if (prologue_end_ == 0) return;
    const bool loads = prologue_words_[0] < prologue_words_[1];
    const int32_t lo = loads ? prologue_words_[0] : 0, hi = loads ? prologue_words_[1] : 0;
    const size_t words = static_cast<size_t>(hi - lo);
    // The lanes this run's batches execute, rounded up to whole 16-lane vectors: a small run (a
    // draw of 36 vertices, one quad of fragments) copies to those only, not to the whole batch.
    const int lanes = std::min(batch_, (std::max(run.lane_count, 4) + 15) / 16 * 16);
    auto broadcast = [&](int from) {
        auto fill_from = [&](Reg r) { Scalar* d = own(r); fill(d + from, lanes - from, d[0]); };
        for (size_t pc = 0; pc < prologue_end_; ++pc) {
            const Instruction& i = code_[pc];
            if (i.op == Op::FNormalize)   // writes one register per component
                for (int j = 0; j < i.imm[1]; ++j) fill_from(products_[static_cast<size_t>(i.imm[0])][4 + static_cast<size_t>(j)]);
            else
                fill_from(i.dst);
        }
        prologue_lanes_ = lanes;
    };
    if (prologue_ready_ && prologue_had_uniforms_ == (run.uniforms != nullptr) &&
        (!run.uniforms || std::memcmp(prologue_uniforms_.data(), run.uniforms + lo, sizeof(Scalar) * words) == 0)) {
        if (prologue_lanes_ < lanes) broadcast(prologue_lanes_);   // a larger run than the ones before
        return;
    }
    const int quad = std::min(4, batch_);
    switch (simd_) {
    case SimdLevel::AVX512: execute_avx512(quad, run, 0, prologue_end_); break;
    case SimdLevel::AVX2: execute_avx2(quad, run, 0, prologue_end_); break;
    case SimdLevel::SSE2:
    case SimdLevel::Scalar: execute_portable(quad, run, 0, prologue_end_); break;
    }
    broadcast(1);
    prologue_had_uniforms_ = run.uniforms != nullptr;
    if (run.uniforms) prologue_uniforms_.assign(run.uniforms + lo, run.uniforms + hi);
    prologue_ready_ = true;
}

void Executor::run_batch(const StageRun& run, int first, int lanes) {
    // Point the aliased registers at this batch's part of the caller's arrays (an input that
    // the caller does not supply reads its own storage, which stays zero: it is never written).
    for (const BatchSlot& o : batch_outputs_) {
        Scalar* dst = run.outputs ? run.outputs[o.slot] : nullptr;
        reg_ptr_[o.reg] = o.alias && dst ? dst + first : own(o.reg);
    }
    for (const BatchSlot& in : batch_inputs_) {
        const Scalar* src = run.inputs ? run.inputs[in.slot] : nullptr;
        reg_ptr_[in.reg] = in.alias && src ? const_cast<Scalar*>(src + first) : own(in.reg);
    }
    for (Reg r : variable_registers_) std::memset(static_cast<void*>(reg(r)), 0, sizeof(Scalar) * lanes);
    for (const BatchSlot& in : batch_inputs_) {
        const Scalar* src = run.inputs ? run.inputs[in.slot] : nullptr;
        if (src) { if (!in.alias) std::memcpy(reg(in.reg), src + first, sizeof(Scalar) * lanes); }
        else if (in.variable) std::memset(static_cast<void*>(reg(in.reg)), 0, sizeof(Scalar) * lanes);
    }
    switch (simd_) {
    case SimdLevel::AVX512: execute_avx512(lanes, run, prologue_end_, code_.size()); break;
    case SimdLevel::AVX2: execute_avx2(lanes, run, prologue_end_, code_.size()); break;
    case SimdLevel::SSE2:
    case SimdLevel::Scalar: execute_portable(lanes, run, prologue_end_, code_.size()); break;
    }
    for (const BatchSlot& o : batch_outputs_) {
        Scalar* dst = run.outputs ? run.outputs[o.slot] : nullptr;
        if (dst && !o.alias) std::memcpy(dst + first, reg(o.reg), sizeof(Scalar) * lanes);
    }
    if (run.discarded) {
        const uint32_t* killed = mask_storage_.data() + static_cast<size_t>(2 * max_depth_ + 1) * batch_;
        for (int l = 0; l < lanes; ++l) run.discarded[first + l] = killed[l] ? 1 : 0;
    }
}

// ---- the longer value operations of execute(), always inlined into it ----
namespace {

// d = a in the active lanes (all: every lane is).
__attribute__((always_inline)) inline void copy_active(Scalar* d, const Scalar* a, const uint32_t* mask, bool all, int n) {
    if (all) { if (d != a) std::memcpy(d, a, sizeof(Scalar) * n); }
    else masked_copy(d, a, mask, n);
}

// A core/vector_math.h function f(d, a, b, count) of every lane, or, when inactive lanes may be
// skipped (skip_inactive_lanes_), of the active ones packed together in `scratch` (4 lanes per
// lane of the batch): fewer blocks of 8 or 16 to compute when a branch holds few lanes.
template <class F>
__attribute__((always_inline)) inline void vector_math(Scalar* d, const Scalar* a, const Scalar* b, const uint32_t* mask,
                                                       bool only_active, int n, Scalar* scratch, F f) {
    if (!only_active) return f(&d->f, &a->f, b ? &b->f : nullptr, n);
    float* pa = &scratch[0].f;
    float* pb = &scratch[n].f;
    float* pd = &scratch[2 * n].f;
    int32_t* lane = &scratch[3 * n].i;
    int m = 0;
    for (int l = 0; l < n; ++l) {
        pa[m] = a[l].f;
        pb[m] = b ? b[l].f : 0.0f;
        lane[m] = l;
        m += mask[l] ? 1 : 0;
    }
    f(pd, pa, pb, m);
    for (int k = 0; k < m; ++k) d[lane[k]].f = pd[k];
}

// dFdx (dx) or dFdy inside each 2x2 quad: lanes 4q..4q+3 are (x, y), (x+1, y), (x, y+1), (x+1, y+1).
__attribute__((always_inline)) inline void quad_derivative(Scalar* d, const Scalar* a, int n, bool dx) {
    int quads = n / 4;
    for (int q = 0; q < quads; ++q) {
        const Scalar* v = a + 4 * q;
        Scalar* o = d + 4 * q;
        if (dx) {
            float top = v[1].f - v[0].f, bottom = v[3].f - v[2].f;
            o[0].f = top; o[1].f = top; o[2].f = bottom; o[3].f = bottom;
        } else {
            float left = v[2].f - v[0].f, right = v[3].f - v[1].f;
            o[0].f = left; o[1].f = right; o[2].f = left; o[3].f = right;
        }
    }
    for (int l = quads * 4; l < n; ++l) d[l].f = 0.0f;  // an incomplete quad has no derivative
}

// The register or uniform slot an indexed access reaches: start + clamp(offset + index, 0,
// size - 1), with imm = start, offset, size.
__attribute__((always_inline)) inline int32_t indexed(const Instruction& i, int32_t index) {
    return i.imm[0] + std::min(std::max(i.imm[1] + index, 0), i.imm[2] - 1);
}

// Indexed accesses: when every lane uses the same index (constant-bound loops, uniform
// indices) the access is one whole-register copy instead of a per-lane gather.
__attribute__((always_inline)) inline void load_uniform_indexed(Scalar* d, const Scalar* idx, const Instruction& i, int n,
                                                                const Scalar* uniforms) {
    if (!uniforms) return fill(d, n, Scalar{});
    if (same_in_all_lanes(idx, n)) return fill(d, n, uniforms[indexed(i, idx[0].i)]);
    for (int l = 0; l < n; ++l) d[l] = uniforms[indexed(i, idx[l].i)];
}

}  // namespace

__attribute__((always_inline)) inline void Executor::load_indexed(const Instruction& i, const int n) {
    Scalar* d = reg(i.dst);
    const Scalar* idx = reg(i.b);
    if (same_in_all_lanes(idx, n)) std::memcpy(d, reg(static_cast<Reg>(indexed(i, idx[0].i))), sizeof(Scalar) * n);
    else for (int l = 0; l < n; ++l) d[l] = reg(static_cast<Reg>(indexed(i, idx[l].i)))[l];
}

__attribute__((always_inline)) inline void Executor::store_indexed(const Instruction& i, const uint32_t* mask, bool all, int n) {
    const Scalar* src = reg(i.a);
    const Scalar* idx = reg(i.b);
    if (same_in_all_lanes(idx, n)) return copy_active(reg(static_cast<Reg>(indexed(i, idx[0].i))), src, mask, all, n);
    for (int l = 0; l < n; ++l)
        if (mask[l]) reg(static_cast<Reg>(indexed(i, idx[l].i)))[l] = src[l];
}

// FDot: the fused chain's operations in its order, ((a0*b0 + a1*b1) + a2*b2) + a3*b3.
__attribute__((always_inline)) inline void Executor::fused_dot(const Instruction& i, const int n) {
    const std::array<Reg, 8>& p = products_[static_cast<size_t>(i.imm[0])];
    Scalar* d = reg(i.dst);
    const Scalar *a0 = reg(p[0]), *b0 = reg(p[1]), *a1 = reg(p[2]), *b1 = reg(p[3]);
    if (i.imm[1] == 2) { for (int l = 0; l < n; ++l) d[l].f = a0[l].f * b0[l].f + a1[l].f * b1[l].f; return; }
    const Scalar *a2 = reg(p[4]), *b2 = reg(p[5]);
    if (i.imm[1] == 3) { for (int l = 0; l < n; ++l) d[l].f = (a0[l].f * b0[l].f + a1[l].f * b1[l].f) + a2[l].f * b2[l].f; return; }
    const Scalar *a3 = reg(p[6]), *b3 = reg(p[7]);
    for (int l = 0; l < n; ++l) d[l].f = ((a0[l].f * b0[l].f + a1[l].f * b1[l].f) + a2[l].f * b2[l].f) + a3[l].f * b3[l].f;
}

// FNormalize: FDot's order for the squared length, then std::sqrt and one division per component,
// as the unfused FDot, FSqrt and FDiv instructions compute them.
namespace {
// The squared length in FDot's order, then std::sqrt and one division per component. Through
// float pointers, the results __restrict (temporaries written once, distinct from the inputs):
// GCC 12 otherwise does not vectorise (too many alias checks, no vector type for the union).
template <int M>
__attribute__((always_inline)) inline void normalize_lanes(const float* __restrict x, const float* __restrict y,
                                                           const float* __restrict z, const float* __restrict w,
                                                           float* __restrict dx, float* __restrict dy, float* __restrict dz,
                                                           float* __restrict dw, int n) {
    for (int l = 0; l < n; ++l) {
        const float a = x[l], b = y[l];
        float sum = a * a + b * b;
        if constexpr (M >= 3) sum = sum + z[l] * z[l];
        if constexpr (M >= 4) sum = sum + w[l] * w[l];
        const float len = std::sqrt(sum);
        dx[l] = a / len;
        dy[l] = b / len;
        if constexpr (M >= 3) dz[l] = z[l] / len;
        if constexpr (M >= 4) dw[l] = w[l] / len;
    }
}
}  // namespace

__attribute__((always_inline)) inline void Executor::fused_normalize(const Instruction& i, const int n) {
    const std::array<Reg, 8>& p = products_[static_cast<size_t>(i.imm[0])];
    const int m = i.imm[1];
    const float* v[4];
    float* out[4];
    for (int k = 0; k < 4; ++k) {
        v[k] = &reg(p[k < m ? k : 0])->f;
        out[k] = &reg(p[4 + (k < m ? k : 0)])->f;
    }
    if (m == 2) normalize_lanes<2>(v[0], v[1], v[2], v[3], out[0], out[1], out[2], out[3], n);
    else if (m == 3) normalize_lanes<3>(v[0], v[1], v[2], v[3], out[0], out[1], out[2], out[3], n);
    else normalize_lanes<4>(v[0], v[1], v[2], v[3], out[0], out[1], out[2], out[3], n);
}

namespace {
// FPair's operations by number (pair_first_op, pair_second_op): the unfused instructions' expressions.
template <int O>
__attribute__((always_inline)) inline float first_op(float x, float y) {
    if constexpr (O == 0) return x + y;
    else if constexpr (O == 1) return x - y;
    else if constexpr (O == 2) return x * y;
    else return x / y;
}
template <int O>
__attribute__((always_inline)) inline float second_op(float x, float y) {
    if constexpr (O == 0) return x + y;
    else if constexpr (O == 1) return x - y;
    else if constexpr (O == 2) return x * y;
    else if constexpr (O == 3) return f_max(x, y);
    else return f_min(x, y);
}
template <int O1, int O2, bool TempFirst>
__attribute__((always_inline)) inline void pair_lanes(float* __restrict d, const float* __restrict a, const float* __restrict b,
                                                      const float* __restrict c, int n) {
    for (int l = 0; l < n; ++l) {
        const float t = first_op<O1>(a[l], b[l]);
        d[l] = TempFirst ? second_op<O2>(t, c[l]) : second_op<O2>(c[l], t);
    }
}
template <int O1, int O2>
__attribute__((always_inline)) inline void pair_side(Scalar* d, const Scalar* a, const Scalar* b, const Scalar* c, int n, bool temp_first) {
    // d: a temporary written once, distinct from a, b and c (__restrict; see normalize_lanes).
    if (temp_first) pair_lanes<O1, O2, true>(&d->f, &a->f, &b->f, &c->f, n);
    else pair_lanes<O1, O2, false>(&d->f, &a->f, &b->f, &c->f, n);
}
template <int O1>
__attribute__((always_inline)) inline void pair_second(Scalar* d, const Scalar* a, const Scalar* b, const Scalar* c, int n, int o2, bool temp_first) {
    switch (o2) {
    case 0: return pair_side<O1, 0>(d, a, b, c, n, temp_first);
    case 1: return pair_side<O1, 1>(d, a, b, c, n, temp_first);
    case 2: return pair_side<O1, 2>(d, a, b, c, n, temp_first);
    case 3: return pair_side<O1, 3>(d, a, b, c, n, temp_first);
    default: return pair_side<O1, 4>(d, a, b, c, n, temp_first);
    }
}
}  // namespace

__attribute__((always_inline)) inline void Executor::fused_pair(const Instruction& i, const int n) {
    Scalar* d = reg(i.dst);
    const Scalar *a = reg(i.a), *b = reg(i.b), *c = reg(i.c);
    const bool temp_first = i.imm[2] == 0;
    switch (i.imm[0]) {
    case 0: return pair_second<0>(d, a, b, c, n, i.imm[1], temp_first);
    case 1: return pair_second<1>(d, a, b, c, n, i.imm[1], temp_first);
    case 2: return pair_second<2>(d, a, b, c, n, i.imm[1], temp_first);
    default: return pair_second<3>(d, a, b, c, n, i.imm[1], temp_first);
    }
}

// The interpreter. It is inlined into one function per SIMD level (below), so its lane loops
// vectorise to that level's width. The control flow stays written out in this one switch: moving
// it into helpers (a struct of the mask and frames, a second switch, or one step() per
// instruction) gave fewer instructions but cost 4-17% time on control-heavy shaders (measured at
// AVX2, issue 17), while the value operations above inline for free.
__attribute__((always_inline)) inline void Executor::execute(const int n, const StageRun& run, size_t begin, size_t end) {
    const std::vector<Instruction>& code = code_;
    uint32_t* mask = mask_storage_.data();
    uint32_t* killed = mask_storage_.data() + static_cast<size_t>(2 * max_depth_ + 1) * batch_;
    std::fill_n(mask, n, ~0u);
    std::fill_n(killed, n, 0u);
    bool all = true;
    std::vector<Frame>& frames = frames_;
    frames.clear();
    auto push = [&](FrameKind kind, int begin) -> Frame& {
        size_t d = frames.size();
        Frame f{kind, mask_storage_.data() + (2 * d + 1) * batch_, mask_storage_.data() + (2 * d + 2) * batch_, begin};
        std::memcpy(f.saved, mask, sizeof(uint32_t) * n);
        frames.push_back(f);
        return frames.back();
    };
    auto set_mask = [&](const uint32_t* m) {
        std::memcpy(mask, m, sizeof(uint32_t) * n);
        all = all_set(mask, n);
    };
    // Where execution continues when no lane of the innermost construct is active any more.
    auto skip_target = [&]() -> int {
        const Frame& f = frames.back();
        const Instruction& open = code[f.begin];
        switch (f.kind) {
        case FrameKind::If: return f.in_else ? code[open.target].target : open.target;  // IfEnd, or Else/IfEnd
        case FrameKind::Loop: return open.imm[0];  // the continue point
        default: return open.target;
        }
    };
    // Lanes in `mask` leave every construct above frame index `target` (exclusive).
    auto leave = [&](size_t target, bool clear_target_other) {
        for (size_t k = target + 1; k < frames.size(); ++k) {
            Frame& f = frames[k];
            for (int l = 0; l < n; ++l) {
                f.saved[l] &= ~mask[l];
                if (f.kind == FrameKind::If || f.kind == FrameKind::Loop) f.other[l] &= ~mask[l];
            }
        }
        if (clear_target_other)
            for (int l = 0; l < n; ++l) frames[target].other[l] &= ~mask[l];
        std::fill_n(mask, n, 0u);
        all = false;
    };

#define LANES for (int l = 0; l < n; ++l)
#define D reg(i.dst)
#define A reg(i.a)
#define B reg(i.b)
#define C reg(i.c)
#define F1(expr) { Scalar* d = D; const Scalar* a = A; LANES { float x = a[l].f; d[l].f = (expr); } break; }
#define F2(expr) { Scalar* d = D; const Scalar* a = A; const Scalar* b = B; LANES { float x = a[l].f, y = b[l].f; d[l].f = (expr); } break; }
#define F3(expr) { Scalar* d = D; const Scalar* a = A; const Scalar* b = B; const Scalar* c = C; LANES { float x = a[l].f, y = b[l].f, z = c[l].f; d[l].f = (expr); } break; }
// softgl's vectorised functions (core/vector_math.h), on the active lanes packed when only they
// need computing (see vector_math above).
#define VMATH1(call) { vector_math(D, A, nullptr, mask, !all && skip_inactive_lanes_, n, scratch_.data(), \
                                   [](float* d, const float* a, const float*, int m) __attribute__((always_inline)) { call; }); break; }
#define VMATH2(call) { vector_math(D, A, B, mask, !all && skip_inactive_lanes_, n, scratch_.data(), \
                                   [](float* d, const float* a, const float* b, int m) __attribute__((always_inline)) { call; }); break; }
// The rarer functions are libm calls: only the active lanes when that is allowed (skip_inactive_lanes_).
#define CALL1(expr) { if (!all && skip_inactive_lanes_) { Scalar* d = D; const Scalar* a = A; LANES if (mask[l]) { float x = a[l].f; d[l].f = (expr); } break; } F1(expr) }
#define CALL2(expr) { if (!all && skip_inactive_lanes_) { Scalar* d = D; const Scalar* a = A; const Scalar* b = B; LANES if (mask[l]) { float x = a[l].f, y = b[l].f; d[l].f = (expr); } break; } F2(expr) }
#define FB1(expr) { Scalar* d = D; const Scalar* a = A; LANES { float x = a[l].f; d[l].i = (expr) ? 1 : 0; } break; }
#define FB2(expr) { Scalar* d = D; const Scalar* a = A; const Scalar* b = B; LANES { float x = a[l].f, y = b[l].f; d[l].i = (expr) ? 1 : 0; } break; }
#define I1(expr) { Scalar* d = D; const Scalar* a = A; LANES { int32_t x = a[l].i; uint32_t ux = a[l].u; (void)ux; (void)x; d[l].i = (expr); } break; }
#define I2(expr) { Scalar* d = D; const Scalar* a = A; const Scalar* b = B; LANES { int32_t x = a[l].i, y = b[l].i; uint32_t ux = a[l].u, uy = b[l].u; (void)x; (void)y; (void)ux; (void)uy; d[l].i = (expr); } break; }
#define U2(expr) { Scalar* d = D; const Scalar* a = A; const Scalar* b = B; LANES { uint32_t x = a[l].u, y = b[l].u; d[l].u = (expr); } break; }
#define I3(expr) { Scalar* d = D; const Scalar* a = A; const Scalar* b = B; const Scalar* c = C; LANES { int32_t x = a[l].i, y = b[l].i, z = c[l].i; d[l].i = (expr); } break; }
#define U3(expr) { Scalar* d = D; const Scalar* a = A; const Scalar* b = B; const Scalar* c = C; LANES { uint32_t x = a[l].u, y = b[l].u, z = c[l].u; d[l].u = (expr); } break; }
// Conversions and packing: d from a (and b), lane by lane.
#define CONVERT(field, expr) { Scalar* d = D; const Scalar* a = A; LANES d[l].field = (expr); break; }
#define PACK(pack) { Scalar* d = D; const Scalar* a = A; const Scalar* b = B; LANES d[l].u = pack(a[l].f) | (pack(b[l].f) << 16); break; }

    const int count = static_cast<int>(end);
    for (int pc = static_cast<int>(begin); pc < count; ++pc) {
        const Instruction& i = code[pc];
        switch (i.op) {
        case Op::Mov: copy_active(D, A, mask, all, n); break;
        case Op::FAdd: F2(x + y)
        case Op::FSub: F2(x - y)
        case Op::FMul: F2(x * y)
        case Op::FDiv: F2(x / y)
        case Op::FNeg: F1(-x)
        case Op::FAbs: F1(std::fabs(x))
        case Op::FSign: F1(f_sign(x))
        case Op::FFloor: F1(std::floor(x))
        case Op::FCeil: F1(std::ceil(x))
        case Op::FFract: F1(x - std::floor(x))
        case Op::FTrunc: F1(std::trunc(x))
        case Op::FRound: F1(std::round(x))
        case Op::FRoundEven: F1(std::nearbyint(x))
        case Op::FMin: F2(f_min(x, y))
        case Op::FMax: F2(f_max(x, y))
        case Op::FMod: F2(f_mod(x, y))
        case Op::FStep: F2(f_step(x, y))
        case Op::FSqrt: F1(std::sqrt(x))
        case Op::FInverseSqrt: F1(1.0f / std::sqrt(x))
        case Op::FSin: VMATH1(vmath::sin_cos_lanes(d, a, m, false))
        case Op::FCos: VMATH1(vmath::sin_cos_lanes(d, a, m, true))
        case Op::FTan: CALL1(std::tan(x))
        case Op::FAsin: CALL1(std::asin(x))
        case Op::FAcos: CALL1(std::acos(x))
        case Op::FAtan: CALL1(std::atan(x))
        case Op::FAtan2: CALL2(std::atan2(x, y))
        case Op::FSinh: CALL1(std::sinh(x))
        case Op::FCosh: CALL1(std::cosh(x))
        case Op::FTanh: CALL1(std::tanh(x))
        case Op::FAsinh: CALL1(std::asinh(x))
        case Op::FAcosh: CALL1(std::acosh(x))
        case Op::FAtanh: CALL1(std::atanh(x))
        case Op::FExp: VMATH1(vmath::exp_lanes(d, a, m))
        case Op::FLog: VMATH1(vmath::log_lanes(d, a, m))
        case Op::FExp2: VMATH1(vmath::exp2_lanes(d, a, m))
        case Op::FLog2: VMATH1(vmath::log2_lanes(d, a, m))
        case Op::FPow: VMATH2(vmath::pow_lanes(d, a, b, m))
        case Op::FDot: fused_dot(i, n); break;
        case Op::FNormalize: fused_normalize(i, n); break;
        case Op::FPair: fused_pair(i, n); break;
        case Op::FClamp: F3(f_clamp(x, y, z))
        case Op::FMix: F3(f_mix(x, y, z))
        case Op::FSmoothstep: F3(f_smoothstep(x, y, z))
        case Op::FIsNan: FB1(std::isnan(x))
        case Op::FIsInf: FB1(std::isinf(x))
        case Op::FLess: FB2(x < y)
        case Op::FLessEqual: FB2(x <= y)
        case Op::FGreater: FB2(x > y)
        case Op::FGreaterEqual: FB2(x >= y)
        case Op::FEqual: FB2(x == y)
        case Op::FNotEqual: FB2(x != y)
        case Op::IAdd: I2(static_cast<int32_t>(ux + uy))
        case Op::ISub: I2(static_cast<int32_t>(ux - uy))
        case Op::IMul: I2(static_cast<int32_t>(ux * uy))
        case Op::IDiv: I2(i_div(x, y))
        case Op::IMod: I2(i_mod(x, y))
        case Op::INeg: I1(static_cast<int32_t>(0u - ux))
        case Op::IAbs: I1(i_abs(x))
        case Op::ISign: I1(x > 0 ? 1 : (x < 0 ? -1 : 0))
        case Op::IMin: I2(i_min(x, y))
        case Op::IMax: I2(i_max(x, y))
        case Op::IClamp: I3(i_clamp(x, y, z))
        case Op::ILess: I2(x < y)
        case Op::ILessEqual: I2(x <= y)
        case Op::IGreater: I2(x > y)
        case Op::IGreaterEqual: I2(x >= y)
        case Op::UDiv: U2(u_div(x, y))
        case Op::UMod: U2(u_mod(x, y))
        case Op::UMin: U2(u_min(x, y))
        case Op::UMax: U2(u_max(x, y))
        case Op::UClamp: U3(u_clamp(x, y, z))
        case Op::ULess: I2(ux < uy)
        case Op::ULessEqual: I2(ux <= uy)
        case Op::UGreater: I2(ux > uy)
        case Op::UGreaterEqual: I2(ux >= uy)
        case Op::BitAnd: U2(x & y)
        case Op::BitOr: U2(x | y)
        case Op::BitXor: U2(x ^ y)
        case Op::BitNot: I1(static_cast<int32_t>(~ux))
        case Op::ShiftLeft: U2(shift_left(x, y))
        case Op::ShiftRightArithmetic: I2(shift_right_arithmetic(x, uy))
        case Op::ShiftRightLogical: U2(shift_right_logical(x, y))
        case Op::Equal: I2(ux == uy)
        case Op::NotEqual: I2(ux != uy)
        case Op::BoolNot: I1(x == 0)
        case Op::Select: U3(x ? y : z)
        case Op::IntToFloat: CONVERT(f, static_cast<float>(a[l].i))
        case Op::UintToFloat: CONVERT(f, static_cast<float>(a[l].u))
        case Op::BoolToFloat: CONVERT(f, a[l].i ? 1.0f : 0.0f)
        case Op::FloatToInt: CONVERT(i, f_to_i(a[l].f))
        case Op::FloatToUint: CONVERT(u, f_to_u(a[l].f))
        case Op::FloatToBool: FB1(x != 0.0f)
        case Op::IntToBool: I1(x != 0)
        case Op::PackSnorm2x16: PACK(pack_snorm16)
        case Op::PackUnorm2x16: PACK(pack_unorm16)
        case Op::PackHalf2x16: PACK(float_to_half)
        case Op::UnpackSnorm2x16X: CONVERT(f, unpack_snorm16(a[l].u & 0xffffu))
        case Op::UnpackSnorm2x16Y: CONVERT(f, unpack_snorm16(a[l].u >> 16))
        case Op::UnpackUnorm2x16X: CONVERT(f, unpack_unorm16(a[l].u & 0xffffu))
        case Op::UnpackUnorm2x16Y: CONVERT(f, unpack_unorm16(a[l].u >> 16))
        case Op::UnpackHalf2x16X: CONVERT(f, half_to_float(a[l].u & 0xffffu))
        case Op::UnpackHalf2x16Y: CONVERT(f, half_to_float(a[l].u >> 16))
        case Op::DFdx:
        case Op::DFdy: quad_derivative(D, A, n, i.op == Op::DFdx); break;
        case Op::LoadIndexed: load_indexed(i, n); break;
        case Op::StoreIndexed: store_indexed(i, mask, all, n); break;
        case Op::LoadUniform: fill(D, n, run.uniforms ? run.uniforms[i.imm[0]] : Scalar{}); break;
        case Op::LoadUniformIndexed: load_uniform_indexed(D, B, i, n, run.uniforms); break;
        case Op::Texture: texture(i, n, run); break;

        // ---- control flow ----
        case Op::IfBegin: {
            Frame& f = push(FrameKind::If, pc);
            const Scalar* c = A;
            LANES {
                uint32_t take = c[l].i ? ~0u : 0u;
                f.other[l] = mask[l] & ~take;
                mask[l] &= take;
            }
            all = all_set(mask, n);
            if (!all && !any_set(mask, n)) pc = i.target - 1;  // to Else or IfEnd
            break;
        }
        case Op::Else: {
            Frame& f = frames.back();
            f.in_else = true;
            set_mask(f.other);
            if (!all && !any_set(mask, n)) pc = i.target - 1;  // to IfEnd
            break;
        }
        case Op::IfEnd:
        case Op::SwitchEnd:
        case Op::FunctionEnd:
            set_mask(frames.back().saved);
            frames.pop_back();
            break;
        case Op::SwitchBegin:
        case Op::FunctionBegin:
            push(i.op == Op::SwitchBegin ? FrameKind::Switch : FrameKind::Function, pc);
            break;
        case Op::LoopBegin: {
            Frame& f = push(FrameKind::Loop, pc);
            std::memcpy(f.other, mask, sizeof(uint32_t) * n);
            break;
        }
        case Op::LoopBreakUnless: {
            Frame& f = frames.back();
            const Scalar* c = A;
            LANES {
                uint32_t stay = c[l].i ? ~0u : 0u;
                mask[l] &= stay;
                f.other[l] &= stay;
            }
            all = all_set(mask, n);
            if (!any_set(f.other, n)) pc = code[f.begin].target - 1;  // to LoopEnd
            break;
        }
        case Op::LoopContinuePoint: {
            Frame& f = frames.back();
            set_mask(f.other);
            if (!all && !any_set(mask, n)) pc = code[f.begin].target - 1;
            break;
        }
        case Op::LoopEnd: {
            Frame& f = frames.back();
            if (any_set(f.other, n)) {
                charge(uint64_t(n) * uint64_t(pc - f.begin + 1));   // the call's work budget
                set_mask(f.other);
                pc = f.begin;  // continue after LoopBegin
            } else {
                set_mask(f.saved);
                frames.pop_back();
            }
            break;
        }
        case Op::Break:
        case Op::Continue:
        case Op::Return: {
            size_t t = frames.size();
            while (t > 0) {
                FrameKind k = frames[t - 1].kind;
                if (i.op == Op::Break && (k == FrameKind::Loop || k == FrameKind::Switch)) break;
                if (i.op == Op::Continue && k == FrameKind::Loop) break;
                if (i.op == Op::Return && k == FrameKind::Function) break;
                --t;
            }
            if (t == 0) break;  // cannot happen for checked programs
            size_t target = t - 1;
            bool clear_loop = i.op == Op::Break && frames[target].kind == FrameKind::Loop;
            leave(target, clear_loop);
            pc = skip_target() - 1;
            break;
        }
        case Op::Discard: {
            LANES killed[l] |= mask[l];
            for (Frame& f : frames)
                LANES { f.saved[l] &= ~mask[l]; f.other[l] &= ~mask[l]; }
            std::fill_n(mask, n, 0u);
            all = false;
            if (all_set(killed, n)) return;  // every lane discarded
            pc = skip_target() - 1;
            break;
        }
        case Op::Count_: break;
        }
    }
#undef LANES
#undef D
#undef A
#undef B
#undef C
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
__attribute__((target("avx2"))) void Executor::execute_avx2(int n, const StageRun& run, size_t begin, size_t end) { execute(n, run, begin, end); }
// prefer-vector-width=512: GCC otherwise vectorises AVX-512 code with 256-bit vectors.
__attribute__((target("avx512f,avx512bw,avx512dq,avx512vl,prefer-vector-width=512")))
void Executor::execute_avx512(int n, const StageRun& run, size_t begin, size_t end) { execute(n, run, begin, end); }
#else
void Executor::execute_avx2(int n, const StageRun& run, size_t begin, size_t end) { execute(n, run, begin, end); }
void Executor::execute_avx512(int n, const StageRun& run, size_t begin, size_t end) { execute(n, run, begin, end); }
#endif
void Executor::execute_portable(int n, const StageRun& run, size_t begin, size_t end) { execute(n, run, begin, end); }

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
namespace {
// The implicit derivatives of quads [0, quads) two at a time (each 128-bit half one quad, as the
// SSE2 loop in texture()): returns the quads done.
__attribute__((target("avx2"))) int quad_derivatives_avx2(const Scalar* v, Scalar* dx, Scalar* dy, int quads) {
    int qd = 0;
    for (; qd + 2 <= quads; qd += 2) {
        const __m256 p = _mm256_loadu_ps(&v[4 * qd].f);
        _mm256_storeu_ps(&dx[4 * qd].f, _mm256_sub_ps(_mm256_permute_ps(p, _MM_SHUFFLE(3, 3, 1, 1)),
                                                     _mm256_permute_ps(p, _MM_SHUFFLE(2, 2, 0, 0))));
        _mm256_storeu_ps(&dy[4 * qd].f, _mm256_sub_ps(_mm256_permute_ps(p, _MM_SHUFFLE(3, 2, 3, 2)),
                                                     _mm256_permute_ps(p, _MM_SHUFFLE(1, 0, 1, 0))));
    }
    return qd;
}
}  // namespace
#endif

void Executor::texture(const Instruction& ins, int n, const StageRun& run) {
    const TextureOperands& t = textures_[static_cast<size_t>(ins.texture)];
    TextureQuery q;
    q.kind = t.kind;
    q.dim = t.dim;
    q.shadow = t.shadow;
    q.result = t.result;
    q.lod_mode = t.lod_mode;
    q.lane_count = n;
    q.active = mask_storage_.data();
    q.unit = reg(t.unit);
    q.uniform_unit = uniform_register_[t.unit] != 0;
    for (int k = 0; k < 3; ++k) q.coord[k] = t.coord[k] != kNoReg ? reg(t.coord[k]) : nullptr;
    q.compare = t.compare != kNoReg ? reg(t.compare) : nullptr;
    q.lod = t.lod != kNoReg ? reg(t.lod) : nullptr;
    for (int k = 0; k < 3; ++k) q.offset[k] = t.offset[k];
    for (int k = 0; k < 4; ++k) q.out[k] = t.dst[k] != kNoReg ? reg(t.dst[k]) : nullptr;
    q.path = run.sampler_path;
    q.simd = simd_;
    q.fast_queries = run.fast_texture_queries;
    if (t.lod_mode == TextureLod::Gradient) {
        for (int k = 0; k < 3; ++k) {
            q.ddx[k] = t.grad_x[k] != kNoReg ? reg(t.grad_x[k]) : nullptr;
            q.ddy[k] = t.grad_y[k] != kNoReg ? reg(t.grad_y[k]) : nullptr;
        }
    } else if (t.kind == TextureKind::Sample && (t.lod_mode == TextureLod::Implicit || t.lod_mode == TextureLod::Bias) &&
               run.sampler && run.sampler->lod_matters(q)) {
        // Implicit derivatives: differences inside each quad (zero in vertex shaders).
        for (int k = 0; k < 3; ++k) {
            if (!q.coord[k]) continue;
            Scalar* dx = scratch_.data() + static_cast<size_t>(2 * k) * batch_;
            Scalar* dy = dx + batch_;
            const Scalar* v = q.coord[k];
            int quads = program_.fragment ? n / 4 : 0;
            int qd = 0;
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
            if (simd_ >= SimdLevel::AVX2) qd = quad_derivatives_avx2(v, dx, dy, quads);
#endif
#if defined(__SSE2__)
            // A quad at a time: the same subtractions of the same lanes.
            for (; qd < quads; ++qd) {   // (the quads left)
                const __m128 p = _mm_loadu_ps(&v[4 * qd].f);
                _mm_storeu_ps(&dx[4 * qd].f, _mm_sub_ps(_mm_shuffle_ps(p, p, _MM_SHUFFLE(3, 3, 1, 1)),
                                                      _mm_shuffle_ps(p, p, _MM_SHUFFLE(2, 2, 0, 0))));   // top, top, bottom, bottom
                _mm_storeu_ps(&dy[4 * qd].f, _mm_sub_ps(_mm_shuffle_ps(p, p, _MM_SHUFFLE(3, 2, 3, 2)),
                                                      _mm_shuffle_ps(p, p, _MM_SHUFFLE(1, 0, 1, 0))));   // left, right, left, right
            }
#endif
            for (; qd < quads; ++qd) {
                const Scalar* p = v + 4 * qd;
                float top = p[1].f - p[0].f, bottom = p[3].f - p[2].f, left = p[2].f - p[0].f, right = p[3].f - p[1].f;
                dx[4 * qd].f = top; dx[4 * qd + 1].f = top; dx[4 * qd + 2].f = bottom; dx[4 * qd + 3].f = bottom;
                dy[4 * qd].f = left; dy[4 * qd + 1].f = right; dy[4 * qd + 2].f = left; dy[4 * qd + 3].f = right;
            }
            for (int l = quads * 4; l < n; ++l) { dx[l].f = 0.0f; dy[l].f = 0.0f; }
            q.ddx[k] = dx;
            q.ddy[k] = dy;
        }
    }
    if (!run.sampler) {
        // No textures bound: GL returns (0, 0, 0, 1) for incomplete textures.
        for (int k = 0; k < 4; ++k)
            if (q.out[k]) {
                Scalar v{};
                if (k == 3 && t.kind == TextureKind::Sample) { if (t.result == BaseType::Float) v.f = 1.0f; else v.i = 1; }
                std::fill_n(q.out[k], n, v);
            }
        return;
    }
    run.sampler->sample(q);
}

}  // namespace softgl::glsl
