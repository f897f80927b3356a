#include "softgl/glsl/ir.h"

#include <sstream>

namespace softgl::glsl {

const char* op_name(Op op) {
    static const char* const names[] = {
        "mov", "fadd", "fsub", "fmul", "fdiv", "fneg", "fabs", "fsign", "ffloor", "fceil", "ffract", "ftrunc", "fround",
        "froundeven", "fmin", "fmax", "fmod", "fstep", "fsqrt", "finversesqrt", "fsin", "fcos", "ftan", "fasin", "facos",
        "fatan", "fatan2", "fsinh", "fcosh", "ftanh", "fasinh", "facosh", "fatanh", "fexp", "flog", "fexp2", "flog2",
        "fpow", "fclamp", "fmix", "fsmoothstep", "fdot", "fnormalize", "fpair", "fisnan", "fisinf", "flt", "fle", "fgt", "fge", "feq", "fne", "iadd",
        "isub", "imul", "idiv", "imod", "ineg", "iabs", "isign", "imin", "imax", "iclamp", "ilt", "ile", "igt", "ige",
        "udiv", "umod", "umin", "umax", "uclamp", "ult", "ule", "ugt", "uge", "and", "or", "xor", "not", "shl", "sar",
        "shr", "eq", "ne", "bnot", "select", "itof", "utof", "ftoi", "ftou", "btof", "ftob", "itob", "packsnorm2x16",
        "packunorm2x16", "packhalf2x16", "unpacksnorm2x16.x", "unpacksnorm2x16.y", "unpackunorm2x16.x",
        "unpackunorm2x16.y", "unpackhalf2x16.x", "unpackhalf2x16.y", "dfdx", "dfdy", "load.indexed", "store.indexed",
        "load.uniform", "load.uniform.indexed", "texture", "if", "else", "endif", "loop", "break.unless",
        "continue.point", "endloop", "switch", "endswitch", "function", "endfunction", "break", "continue", "return",
        "discard"};
    static_assert(sizeof(names) / sizeof(names[0]) == static_cast<size_t>(Op::Count_), "op names");
    return op < Op::Count_ ? names[static_cast<int>(op)] : "?";
}

bool op_is_control(Op op) { return op >= Op::IfBegin && op < Op::Count_; }

std::vector<int32_t> region_ends(const IrProgram& program) {
    const std::vector<Instruction>& code = program.code;
    std::vector<int32_t> end(code.size(), static_cast<int32_t>(code.size()));
    std::vector<std::vector<int32_t>> open(1);   // per nesting level: instructions whose region is open
    for (size_t k = 0; k < code.size(); ++k) {
        const Op op = code[k].op;
        const bool ends = op == Op::Else || op == Op::IfEnd || op == Op::LoopContinuePoint || op == Op::LoopEnd ||
                          op == Op::SwitchEnd || op == Op::FunctionEnd;
        if (ends) {
            for (int32_t i : open.back()) end[static_cast<size_t>(i)] = static_cast<int32_t>(k);
            open.back().clear();
            if (op != Op::Else && op != Op::LoopContinuePoint && open.size() > 1) open.pop_back();
        }
        open.back().push_back(static_cast<int32_t>(k));
        if (op == Op::IfBegin || op == Op::LoopBegin || op == Op::SwitchBegin || op == Op::FunctionBegin) open.emplace_back();
    }
    return end;
}

bool reads_quad_neighbours(const IrProgram& program) {
    if (!program.fragment) return false;
    for (const Instruction& i : program.code) {
        if (i.op == Op::DFdx || i.op == Op::DFdy) return true;
        if (i.op == Op::Texture) {
            const TextureOperands& t = program.textures[static_cast<size_t>(i.texture)];
            if (t.kind == TextureKind::Sample && (t.lod_mode == TextureLod::Implicit || t.lod_mode == TextureLod::Bias)) return true;
        }
    }
    return false;
}

bool takes_derivatives(const IrProgram& program) {
    if (!program.fragment) return false;
    for (const Instruction& i : program.code)
        if (i.op == Op::DFdx || i.op == Op::DFdy) return true;
    return false;
}

uint32_t implicit_lod_dims(const IrProgram& program) {
    uint32_t dims = 0;
    if (!program.fragment) return dims;
    for (const Instruction& i : program.code) {
        if (i.op != Op::Texture) continue;
        const TextureOperands& t = program.textures[static_cast<size_t>(i.texture)];
        if (t.kind == TextureKind::Sample && (t.lod_mode == TextureLod::Implicit || t.lod_mode == TextureLod::Bias))
            dims |= 1u << static_cast<unsigned>(t.dim);
    }
    return dims;
}

bool link_control_flow(IrProgram& program) {
    std::vector<int> stack;
    std::vector<Instruction>& code = program.code;
    for (int pc = 0; pc < static_cast<int>(code.size()); ++pc) {
        Instruction& i = code[pc];
        switch (i.op) {
        case Op::IfBegin: case Op::LoopBegin: case Op::SwitchBegin: case Op::FunctionBegin:
            stack.push_back(pc);
            break;
        case Op::Else:
            if (stack.empty() || code[stack.back()].op != Op::IfBegin) return false;
            code[stack.back()].target = pc;
            stack.back() = pc;  // the IfEnd links to Else; Else links to IfEnd
            break;
        case Op::LoopContinuePoint:
            if (stack.empty() || code[stack.back()].op != Op::LoopBegin) return false;
            code[stack.back()].imm[0] = pc;
            break;
        case Op::IfEnd: case Op::LoopEnd: case Op::SwitchEnd: case Op::FunctionEnd: {
            if (stack.empty()) return false;
            int open = stack.back();
            stack.pop_back();
            code[open].target = pc;
            i.target = open;
            if (code[open].op == Op::Else) {
                // Find the IfBegin whose target is this Else: it keeps pointing at the Else.
            }
            break;
        }
        default: break;
        }
    }
    return stack.empty();
}

std::string IrProgram::dump() const {
    std::ostringstream out;
    for (size_t pc = 0; pc < code.size(); ++pc) {
        const Instruction& i = code[pc];
        out << pc << ": " << op_name(i.op);
        if (i.dst != kNoReg) out << " r" << i.dst;
        for (Reg r : {i.a, i.b, i.c}) if (r != kNoReg) out << ", r" << r;
        if (i.op == Op::LoadUniform || i.op == Op::LoadIndexed || i.op == Op::StoreIndexed || i.op == Op::LoadUniformIndexed)
            out << " [" << i.imm[0] << ", " << i.imm[1] << ", " << i.imm[2] << "]";
        if (i.target >= 0) out << " -> " << i.target;
        out << "\n";
    }
    return out.str();
}

uint64_t instructions_bound(const IrProgram& program) {
    constexpr uint64_t kUnbounded = ~uint64_t(0);
    auto saturating_add = [](uint64_t a, uint64_t b) { return a > kUnbounded - b ? kUnbounded : a + b; };
    std::vector<uint64_t> times{1};   // how often the current instruction can run
    uint64_t total = 0;
    for (const Instruction& i : program.code) {
        if (i.op == Op::LoopBegin) {
            if (i.imm[1] <= 0) return kUnbounded;
            const uint64_t outer = times.back(), n = uint64_t(i.imm[1]);
            times.push_back(outer > kUnbounded / n ? kUnbounded : outer * n);
        }
        total = saturating_add(total, times.back());
        if (i.op == Op::LoopEnd && times.size() > 1) times.pop_back();
    }
    return total;
}

}  // namespace softgl::glsl
