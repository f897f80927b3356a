#include "softgl/glsl/optimize.h"

#include <unordered_map>

#include "softgl/glsl/executor.h"

namespace softgl::glsl {
namespace {

// Calls f(reg) for every register instruction i reads.
template <class F>
void for_each_read(const IrProgram& p, const Instruction& i, F&& f) {
    if (i.op == Op::Texture) {
        const TextureOperands& t = p.textures[i.texture];
        for (Reg r : {t.unit, t.coord[0], t.coord[1], t.coord[2], t.coord[3], t.compare, t.lod, t.grad_x[0], t.grad_x[1],
                      t.grad_x[2], t.grad_y[0], t.grad_y[1], t.grad_y[2]})
            if (r != kNoReg) f(r);
        return;
    }
    if (i.op == Op::LoadIndexed) {
        for (int32_t k = 0; k < i.imm[2]; ++k) f(static_cast<Reg>(i.imm[0] + k));
    }
    if (i.op == Op::StoreIndexed || i.op == Op::Mov) {
        // A masked write keeps the old value in inactive lanes: it also "reads" its target.
        if (i.op == Op::Mov && p.is_variable[i.dst]) f(i.dst);
        if (i.op == Op::StoreIndexed)
            for (int32_t k = 0; k < i.imm[2]; ++k) f(static_cast<Reg>(i.imm[0] + k));
    }
    for (Reg r : {i.a, i.b, i.c}) if (r != kNoReg) f(r);
}

// Calls f(reg) for every register instruction i writes.
template <class F>
void for_each_write(const IrProgram& p, const Instruction& i, F&& f) {
    if (i.op == Op::Texture) {
        for (Reg r : p.textures[i.texture].dst) if (r != kNoReg) f(r);
        return;
    }
    if (i.op == Op::StoreIndexed) {
        for (int32_t k = 0; k < i.imm[2]; ++k) f(static_cast<Reg>(i.imm[0] + k));
        return;
    }
    if (i.dst != kNoReg) f(i.dst);
}

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
    report.folded = fold_constants(program);
    report.removed = eliminate_dead_code(program);
    link_control_flow(program);
    return report;
}

}  // namespace softgl::glsl
