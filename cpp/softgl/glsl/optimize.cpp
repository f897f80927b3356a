#include "softgl/glsl/optimize.h"
#include "softgl/core/work_budget.h"

#include <algorithm>
#include <limits>
#include <unordered_map>

#include "softgl/glsl/executor.h"

namespace softgl::glsl {
namespace {

bool foldable(Op op) {
    if (op_is_control(op)) return false;
    switch (op) {
    case Op::Texture: case Op::LoadIndexed: case Op::StoreIndexed: case Op::LoadUniform: case Op::LoadUniformIndexed:
    case Op::DFdx: case Op::DFdy:
        return false;
    default: return true;
    }
}

int fold_constants(IrProgram& p) {
    std::vector<bool> is_constant(p.register_count, false);
    std::vector<Scalar> value(p.register_count, Scalar{});
    for (const ConstantRegister& c : p.constants) { is_constant[c.reg] = true; value[c.reg] = c.value; }
    int folded = 0;
    std::vector<Instruction> kept;
    kept.reserve(p.code.size());
    for (const Instruction& i : p.code) {
        bool can = foldable(i.op) && i.dst != kNoReg && !p.is_variable[i.dst];
        if (can)
            for (Reg r : {i.a, i.b, i.c}) if (r != kNoReg && !is_constant[r]) can = false;
        if (!can) { kept.push_back(i); continue; }
        // Evaluate with the executor on one quad (identical arithmetic to run time).
        IrProgram one;
        one.register_count = 4;
        one.register_types = {p.register_types[i.dst], BaseType::Float, BaseType::Float, BaseType::Float};
        one.is_variable = {false, false, false, false};
        Instruction copy = i;
        copy.dst = 0;
        Reg next = 1;
        for (Reg* r : {&copy.a, &copy.b, &copy.c}) {
            if (*r == kNoReg) continue;
            one.constants.push_back({next, value[*r]});
            *r = next++;
        }
        one.code.push_back(copy);
        one.outputs.push_back(Slot{SlotKind::Builtin, "", 0, 0, BaseType::Float, 0});
        Executor executor(one, 4);   // the executor analyses the program (incl. outputs) here
        Scalar out[4];
        Scalar* outputs[1] = {out};
        StageRun run;
        run.lane_count = 1;
        run.outputs = outputs;
        executor.run(run);
        is_constant[i.dst] = true;
        value[i.dst] = out[0];
        p.constants.push_back({i.dst, out[0]});
        ++folded;
    }
    p.code = std::move(kept);
    return folded;
}

int eliminate_dead_code(IrProgram& p) {
    std::vector<bool> needed_reg(p.register_count, false);
    for (const Slot& s : p.outputs) needed_reg[s.reg] = true;
    std::vector<bool> needed(p.code.size(), false);
    bool changed = true;
    while (changed) {
        changed = false;
        for (size_t k = p.code.size(); k-- > 0;) {
            if (needed[k]) continue;
            const Instruction& i = p.code[k];
            bool need = op_is_control(i.op);
            if (!need) for_each_write(p, i, [&](Reg r) { if (needed_reg[r]) need = true; });
            if (!need) continue;
            needed[k] = true;
            changed = true;
            for_each_read(p, i, [&](Reg r) {
                if (!needed_reg[r]) { needed_reg[r] = true; }
            });
        }
    }
    std::vector<Instruction> kept;
    for (size_t k = 0; k < p.code.size(); ++k) if (needed[k]) kept.push_back(p.code[k]);
    // Drop if/else constructs left empty.
    std::vector<Instruction> compact;
    for (const Instruction& i : kept) {
        if (i.op == Op::IfEnd && !compact.empty() && compact.back().op == Op::Else) compact.pop_back();
        if (i.op == Op::IfEnd && !compact.empty() && compact.back().op == Op::IfBegin) { compact.pop_back(); continue; }
        compact.push_back(i);
    }
    int removed = static_cast<int>(p.code.size() - compact.size());
    p.code = std::move(compact);
    // Constants nobody reads need no register fill.
    std::vector<bool> read = registers_read(p);
    std::vector<ConstantRegister> constants;
    for (const ConstantRegister& c : p.constants) if (read[c.reg]) constants.push_back(c);
    p.constants = std::move(constants);
    return removed;
}

// Copy propagation: `mov v, t` where the variable v has no other write and every read of v
// follows the Mov inside its straight-line region (region_ends) reads t instead, and the Mov
// goes. t must not change in between: it is a temporary (defined once, before the Mov), a
// constant or an input. Inside the region the active lanes are a subset of the lanes the Mov
// wrote, so every active lane reads the same value as before; inactive lanes now see
// t instead of v's older value. Only quad neighbours could observe those, so programs that
// read them keep their Movs.
int propagate_copies(IrProgram& p) {
    const size_t R = p.register_count;
    if (reads_quad_neighbours(p)) return 0;
    std::vector<int> writes(R, 0), defined_at(R, -1);
    std::vector<uint8_t> pinned(R, 0);  // interface, constant or indexed (array) registers
    for (const Slot& s : p.inputs) if (s.reg < R) pinned[s.reg] = 1;
    for (const Slot& s : p.outputs) if (s.reg < R) pinned[s.reg] = 1;
    for (const ConstantRegister& c : p.constants) pinned[c.reg] = 1;
    for (size_t k = 0; k < p.code.size(); ++k) {
        const Instruction& i = p.code[k];
        if (i.op == Op::LoadIndexed || i.op == Op::StoreIndexed)
            for (int32_t e = 0; e < i.imm[2]; ++e) pinned[static_cast<Reg>(i.imm[0] + e)] = 1;
        for_each_write(p, i, [&](Reg r) { ++writes[r]; defined_at[r] = static_cast<int>(k); });
    }
    // First and last reader of each register (a Mov's "read" of its own target aside). The
    // reads of a variable never change below: sources that get propagated are not variables.
    std::vector<int> first_read(R, std::numeric_limits<int>::max()), last_read(R, -1);
    for (size_t k = 0; k < p.code.size(); ++k) {
        const Instruction& i = p.code[k];
        for_each_read(p, i, [&](Reg r) {
            if (i.op == Op::Mov && r == i.dst && r != i.a) return;
            first_read[r] = std::min(first_read[r], static_cast<int>(k));
            last_read[r] = std::max(last_read[r], static_cast<int>(k));
        });
    }
    std::vector<uint8_t> is_input(R, 0), is_constant(R, 0);
    for (const Slot& s : p.inputs) if (s.reg < R) is_input[s.reg] = 1;
    for (const ConstantRegister& c : p.constants) is_constant[c.reg] = 1;

    const std::vector<int32_t> region_end = region_ends(p);
    int removed = 0;
    std::vector<uint8_t> drop(p.code.size(), 0);
    // Every read of a dropped Mov's target lies inside the Mov's region (checked below), so
    // the reads are renamed once at the end rather than by scanning each region (which made
    // 10^5 declarations quadratic). Sources are never renamed: they are not variables.
    std::vector<Reg> renamed(R, kNoReg);
    auto current = [&](Reg r) { return r != kNoReg && renamed[r] != kNoReg ? renamed[r] : r; };
    for (size_t k = 0; k < p.code.size(); ++k) {
        const Instruction& mov = p.code[k];
        if (mov.op != Op::Mov || drop[k]) continue;
        const Reg v = mov.dst, t = current(mov.a);
        if (!p.is_variable[v] || pinned[v] || writes[v] != 1 || v == t) continue;
        const bool stable = (is_constant[t] && writes[t] == 0) || (is_input[t] && writes[t] == 0) ||
                            (!p.is_variable[t] && writes[t] == 1 && defined_at[t] < static_cast<int>(k));
        if (!stable) continue;
        const size_t end = static_cast<size_t>(region_end[k]);
        if (last_read[v] >= 0 && (first_read[v] <= static_cast<int>(k) || last_read[v] >= static_cast<int>(end))) continue;
        renamed[v] = t;
        drop[k] = 1;
        writes[v] = 0;
        p.is_variable[v] = false;   // no longer written at all
        ++removed;
    }
    std::vector<Instruction> kept;
    kept.reserve(p.code.size());
    for (size_t k = 0; k < p.code.size(); ++k) {
        if (drop[k]) continue;
        Instruction i = p.code[k];
        for (Reg* r : {&i.a, &i.b, &i.c}) *r = current(*r);
        kept.push_back(i);
    }
    for (TextureOperands& to : p.textures)
        for (Reg* r : {&to.unit, &to.coord[0], &to.coord[1], &to.coord[2], &to.coord[3], &to.compare, &to.lod,
                       &to.grad_x[0], &to.grad_x[1], &to.grad_x[2], &to.grad_y[0], &to.grad_y[1], &to.grad_y[2]})
            *r = current(*r);
    p.code = std::move(kept);
    return removed;
}

}  // namespace

std::vector<bool> registers_read(const IrProgram& p) {
    std::vector<bool> read(p.register_count, false);
    for (const Instruction& i : p.code) for_each_read(p, i, [&](Reg r) { read[r] = true; });
    for (const Slot& s : p.outputs) read[s.reg] = true;
    return read;
}

bool outputs_depend_only_on_uniforms(const IrProgram& p) {
    std::vector<bool> tainted(p.register_count, false);
    for (const Slot& s : p.inputs) tainted[s.reg] = true;
    bool changed = true;
    while (changed) {
        changed = false;
        for (const Instruction& i : p.code) {
            bool t = false;
            for_each_read(p, i, [&](Reg r) { if (tainted[r]) t = true; });
            if (!t) continue;
            if (i.op == Op::IfBegin || i.op == Op::LoopBreakUnless) return false;  // input-dependent control flow
            for_each_write(p, i, [&](Reg r) {
                if (!tainted[r]) { tainted[r] = true; changed = true; }
            });
        }
    }
    for (const Instruction& i : p.code) if (i.op == Op::Discard) return false;
    for (const Slot& s : p.outputs) if (tainted[s.reg]) return false;
    return true;
}

OptimizeReport optimize(IrProgram& program) {
    OptimizeReport report;
    // The compile's or link's work budget (core/work_budget.h): each pass reads the whole code.
    WorkBudget::charge_current(program.code.size());
    report.folded = fold_constants(program);
    WorkBudget::charge_current(program.code.size());
    report.propagated = propagate_copies(program);
    if (report.propagated) report.folded += fold_constants(program);   // copies of constants fold further
    WorkBudget::charge_current(program.code.size());
    report.removed = eliminate_dead_code(program);
    link_control_flow(program);
    return report;
}

}  // namespace softgl::glsl
