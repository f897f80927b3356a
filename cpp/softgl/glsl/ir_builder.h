// The builder the lowering (lower.cpp) and the built-in functions (builtins.cpp) share: appends
// instructions to an IrProgram, hands out registers and keeps one register per constant.
#pragma once
#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "softgl/glsl/ir.h"
#include "softgl/glsl/types.h"

namespace softgl::glsl {

// A GLSL value during lowering: one register per scalar component.
struct Value {
    Type type;
    std::vector<Reg> regs;
};

class IrBuilder {
public:
    explicit IrBuilder(IrProgram& program) : p_(program) {}

    Reg temp(BaseType type);
    Reg variable(BaseType type);
    Reg constant(BaseType type, Scalar value);
    Reg float_constant(float v) { Scalar s; s.f = v; return constant(BaseType::Float, s); }
    Reg int_constant(int32_t v) { Scalar s; s.i = v; return constant(BaseType::Int, s); }
    Reg uint_constant(uint32_t v) { Scalar s; s.u = v; return constant(BaseType::Uint, s); }
    Reg bool_constant(bool v) { Scalar s; s.i = v; return constant(BaseType::Bool, s); }

    Reg op(Op op, BaseType result, Reg a, Reg b = kNoReg, Reg c = kNoReg);
    Instruction& emit(Op op);
    void mov(Reg dst, Reg src);
    BaseType type_of(Reg r) const { return p_.register_types[r]; }
    // The value of a constant register, if `r` is one.
    bool constant_of(Reg r, Scalar& value) const {
        for (const ConstantRegister& c : p_.constants) if (c.reg == r) { value = c.value; return true; }
        return false;
    }
    size_t size() const { return p_.code.size(); }
    IrProgram& program() { return p_; }
    int current_line = 0;

private:
    IrProgram& p_;
    std::map<std::pair<int, uint32_t>, Reg> constants_;
};

}  // namespace softgl::glsl
