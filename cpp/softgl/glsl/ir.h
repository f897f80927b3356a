// The IR: a linear list of scalar, typed, register-based instructions with structured control
// flow markers. Every GLSL value is split into 32-bit scalar components ("scalarised"), one
// register each; a register holds one value per lane. The executor runs each instruction as a
// tight loop over lanes (structure of arrays); a JIT could translate the same list 1:1.
//
// Rules the lowering guarantees and the executor relies on:
//  * Only Mov and StoreIndexed write variable registers; they honour the execution mask.
//    Every other instruction writes a fresh temporary and computes all lanes unmasked (lanes
//    that are inactive compute values nobody reads).
//  * Control flow is structured: IfBegin/Else/IfEnd, LoopBegin/LoopEnd, SwitchBegin/SwitchEnd,
//    FunctionBegin/FunctionEnd (user functions are inlined; recursion is illegal in GLSL ES).
//    `target` of a control instruction is the index of its matching instruction.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "softgl/glsl/ast.h"
#include "softgl/glsl/types.h"

namespace softgl::glsl {

using Reg = uint32_t;
constexpr Reg kNoReg = 0xffffffffu;

enum class Op : uint8_t {
    Mov,  // dst = a (masked)
    // Float arithmetic (IEEE single precision, no contraction)
    FAdd, FSub, FMul, FDiv, FNeg, FAbs, FSign, FFloor, FCeil, FFract, FTrunc, FRound, FRoundEven,
    FMin, FMax, FMod, FStep, FSqrt, FInverseSqrt,
    FSin, FCos, FTan, FAsin, FAcos, FAtan, FAtan2, FSinh, FCosh, FTanh, FAsinh, FAcosh, FAtanh,
    FExp, FLog, FExp2, FLog2, FPow,
    FClamp, FMix, FSmoothstep,  // three operands
    FDot,  // executor-internal (never produced by lowering or optimize): fused FMul/FAdd chain, see Executor
    FNormalize,  // executor-internal: FDot of a vector with itself, FSqrt, one FDiv per component, see Executor
    FPair,       // executor-internal: two float operations through a single-use temporary, see Executor
    FIsNan, FIsInf,
    FLess, FLessEqual, FGreater, FGreaterEqual, FEqual, FNotEqual,
    // Signed integers (two's complement, wrapping)
    IAdd, ISub, IMul, IDiv, IMod, INeg, IAbs, ISign, IMin, IMax, IClamp,
    ILess, ILessEqual, IGreater, IGreaterEqual,
    // Unsigned integers
    UDiv, UMod, UMin, UMax, UClamp, ULess, ULessEqual, UGreater, UGreaterEqual,
    // Bitwise (also used on bools, which are 0/1), equality of 32-bit patterns
    BitAnd, BitOr, BitXor, BitNot, ShiftLeft, ShiftRightArithmetic, ShiftRightLogical,
    Equal, NotEqual, BoolNot,
    Select,  // dst = a ? b : c
    // Conversions
    IntToFloat, UintToFloat, FloatToInt, FloatToUint, BoolToFloat, FloatToBool, IntToBool,
    // ES 3.00 §8.4 packing
    PackSnorm2x16, PackUnorm2x16, PackHalf2x16,
    UnpackSnorm2x16X, UnpackSnorm2x16Y, UnpackUnorm2x16X, UnpackUnorm2x16Y, UnpackHalf2x16X, UnpackHalf2x16Y,
    // Derivatives inside 2x2 quads (fragment stage)
    DFdx, DFdy,
    // Dynamic indexing into a run of registers: reg[base + clamp(index, 0, count-1) * stride]
    LoadIndexed,   // dst = regs[a + idx(b)*stride]           (imm: stride, count)
    StoreIndexed,  // regs[dst + idx(b)*stride] = a  (masked) (imm: stride, count)
    LoadUniform,         // dst = uniforms[imm0]
    LoadUniformIndexed,  // dst = uniforms[imm0 + idx(b)*stride]  (imm: offset, stride, count)
    Texture,       // see TextureInstruction (extra operands)
    // Structured control flow
    IfBegin, Else, IfEnd,
    LoopBegin,     // imm[1]: the most times the loop's condition runs (counted for loops), 0: unknown
    LoopBreakUnless, LoopContinuePoint, LoopEnd,
    SwitchBegin, SwitchEnd,
    FunctionBegin, FunctionEnd,
    Break, Continue, Return, Discard,
    Count_
};

const char* op_name(Op op);
bool op_is_control(Op op);

enum class TextureLod : uint8_t { Implicit, Bias, Explicit, Gradient };
enum class TextureKind : uint8_t { Sample, Fetch, Size };

struct TextureOperands {
    TextureKind kind = TextureKind::Sample;
    SamplerDim dim = SamplerDim::Tex2D;
    bool shadow = false;
    BaseType result = BaseType::Float;
    TextureLod lod_mode = TextureLod::Implicit;
    Reg unit = kNoReg;              // texture unit (int)
    Reg coord[4] = {kNoReg, kNoReg, kNoReg, kNoReg};   // s, t, r/layer, (cube shadow: q)
    Reg compare = kNoReg;           // shadow reference
    Reg lod = kNoReg;               // bias or explicit lod (or fetch level / size level)
    Reg grad_x[3] = {kNoReg, kNoReg, kNoReg};
    Reg grad_y[3] = {kNoReg, kNoReg, kNoReg};
    int offset[3] = {0, 0, 0};
    Reg dst[4] = {kNoReg, kNoReg, kNoReg, kNoReg};
};

struct Instruction {
    Op op;
    Reg dst = kNoReg;
    Reg a = kNoReg, b = kNoReg, c = kNoReg;
    int32_t imm[3] = {0, 0, 0};
    int32_t target = -1;   // control flow: index of the matching instruction
    int32_t texture = -1;  // Texture: index into Program::textures
    int line = 0;
};

// Scalar component slots of the program's interface. Inputs are attributes (vertex) or
// varyings + built-ins (fragment); outputs are gl_Position, gl_PointSize, varyings (vertex) or
// colours + gl_FragDepth (fragment).
enum class SlotKind : uint8_t { Attribute, Varying, Builtin, FragmentOutput };

struct Slot {
    SlotKind kind;
    std::string name;      // variable name, e.g. "aPos", "vRay", "gl_Position", "fragColor"
    int element = 0;       // array element
    int component = 0;     // component within the element (column-major for matrices)
    BaseType base = BaseType::Float;
    Reg reg = kNoReg;
};

struct ConstantRegister {
    Reg reg;
    Scalar value;
};

struct IrProgram {
    std::vector<Instruction> code;
    std::vector<TextureOperands> textures;
    std::vector<ConstantRegister> constants;  // registers holding constants, set before running
    std::vector<Slot> inputs;
    std::vector<Slot> outputs;
    std::vector<BaseType> register_types;
    uint32_t register_count = 0;
    std::vector<bool> is_variable;  // written by Mov/StoreIndexed (masked) rather than defined once
    bool fragment = false;          // lanes are 2x2 quads (derivatives)

    std::string dump() const;  // a readable listing, for tests and debugging
};

// What a lowered program does besides its code, for reflection and the pipeline (recorded by the
// lowering, lower.cpp, and the built-in functions', builtins.cpp).
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

// Calls f(reg) for every register instruction i reads. A masked write keeps the old value in
// inactive lanes, so StoreIndexed also reads its targets, and so does a Mov of a variable unless
// `mov_reads_target` is false (for callers that only reason about lanes the Mov writes).
template <class F>
void for_each_read(const IrProgram& p, const Instruction& i, F&& f, bool mov_reads_target = true) {
    if (i.op == Op::Texture) {
        const TextureOperands& t = p.textures[i.texture];
        for (Reg r : {t.unit, t.coord[0], t.coord[1], t.coord[2], t.coord[3], t.compare, t.lod, t.grad_x[0], t.grad_x[1],
                      t.grad_x[2], t.grad_y[0], t.grad_y[1], t.grad_y[2]})
            if (r != kNoReg) f(r);
        return;
    }
    if (i.op == Op::LoadIndexed || i.op == Op::StoreIndexed)
        for (int32_t k = 0; k < i.imm[2]; ++k) f(static_cast<Reg>(i.imm[0] + k));
    if (mov_reads_target && i.op == Op::Mov && p.is_variable[i.dst]) f(i.dst);
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

// For every instruction, the index of the end of its straight-line region: the first Else,
// IfEnd, LoopContinuePoint, LoopEnd, SwitchEnd or FunctionEnd at its own nesting level (or the
// program's size). Between an instruction and its region end (nested constructs included) the
// active lanes are always a subset of the lanes active at the instruction: masks only shrink
// there, and only those instructions restore lanes that left earlier.
std::vector<int32_t> region_ends(const IrProgram& program);

// True if some lane reads values of the other lanes of its quad: derivatives, and the implicit
// LOD of fragment texture lookups. Only then can a lane observe values computed in lanes that
// were inactive.
bool reads_quad_neighbours(const IrProgram& program);
// Whether fragment code takes derivatives (dFdx, dFdy, fwidth), and the sampler dimensions of its
// implicit-LOD lookups (bit int(SamplerDim)): the two ways reads_quad_neighbours can be true.
bool takes_derivatives(const IrProgram& program);
uint32_t implicit_lod_dims(const IrProgram& program);

// The most instructions one invocation can execute (each loop's body counted as often as its
// condition can run); UINT64_MAX when a loop has no known bound. The draw uses it to decide whether
// it must be able to put pixels back when stopped (docs/reliability.md, "Work budget and Ctrl-C").
uint64_t instructions_bound(const IrProgram& program);

// Sets `target` of every control instruction (and LoopBegin.imm[0] = its continue point).
// Returns false if the structure is malformed.
bool link_control_flow(IrProgram& program);

}  // namespace softgl::glsl
