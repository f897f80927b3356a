#include "softgl/glsl/ir_builder.h"
#include "softgl/core/work_budget.h"

namespace softgl::glsl {

Reg IrBuilder::temp(BaseType type) {
    Reg r = p_.register_count++;
    p_.register_types.push_back(type);
    p_.is_variable.push_back(false);
    return r;
}
Reg IrBuilder::variable(BaseType type) {
    Reg r = temp(type);
    p_.is_variable[r] = true;
    return r;
}
Reg IrBuilder::constant(BaseType type, Scalar value) {
    auto key = std::make_pair(static_cast<int>(type), value.u);
    auto it = constants_.find(key);
    if (it != constants_.end()) return it->second;
    Reg r = temp(type);
    p_.constants.push_back({r, value});
    constants_[key] = r;
    return r;
}
Instruction& IrBuilder::emit(Op op) {
    WorkBudget::charge_current(1);   // the compile's work budget (core/work_budget.h)
    Instruction i;
    i.op = op;
    i.line = current_line;
    p_.code.push_back(i);
    return p_.code.back();
}
Reg IrBuilder::op(Op op, BaseType result, Reg a, Reg b, Reg c) {
    Reg dst = temp(result);
    Instruction& i = emit(op);
    i.dst = dst;
    i.a = a;
    i.b = b;
    i.c = c;
    return dst;
}
void IrBuilder::mov(Reg dst, Reg src) {
    Instruction& i = emit(Op::Mov);
    i.dst = dst;
    i.a = src;
}

}  // namespace softgl::glsl
