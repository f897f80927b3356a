// Lowering: checked AST -> scalarised IR (see ir.h). User functions are inlined at each call;
// uniforms are read from the flat uniform buffer at the offsets `uniform_offset` assigned.
#pragma once
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "softgl/glsl/ast.h"
#include "softgl/glsl/checker.h"
#include "softgl/glsl/diagnostics.h"
#include "softgl/glsl/ir.h"

namespace softgl::glsl {

// What the lowering learnt about the shader's behaviour (for reflection and the pipeline).
struct ShaderUsage {
    bool may_discard = false;
    bool writes_frag_depth = false;
    bool uses_derivatives = false;   // dFdx/dFdy/fwidth or implicit-LOD texture lookups
    bool reads_frag_coord = false;
    bool reads_front_facing = false;
    bool reads_point_coord = false;
    bool writes_point_size = false;
    bool uses_vertex_id = false;
    bool uses_instance_id = false;
    // ES 1.00 with `#extension GL_EXT_draw_buffers` enabled and gl_FragColor written: the colour
    // goes to every draw buffer (EXT_draw_buffers / WEBGL_draw_buffers). Set by the compiler.
    bool frag_color_broadcast = false;
};

struct LoweredShader {
    IrProgram program;
    ShaderUsage usage;
    std::unordered_map<const Symbol*, int> uniform_offsets;  // symbol -> first word in the uniform buffer
    int uniform_words = 0;
};

// Lowers `shader` (which must have passed the checker). Reports lowering-time errors
// (recursion, missing function bodies, program too large) through `diagnostics`.
LoweredShader lower(const CheckedShader& shader, Diagnostics& diagnostics);

// ---- The builder the lowering and the built-in functions share ----

struct Value {
    Type type;
    std::vector<Reg> regs;  // one register per scalar component
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

// Lowers a call of a built-in function (builtins.cpp). `args` are the evaluated arguments;
// for modf, `out_target` receives the out parameter's value.
struct BuiltinFunction;
Value lower_builtin_call(IrBuilder& b, const BuiltinFunction& f, const std::vector<Value>& args, Stage stage,
                         ShaderUsage& usage, Value* out_value);

}  // namespace softgl::glsl
