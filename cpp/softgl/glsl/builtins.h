// Built-in functions of GLSL ES 1.00 (§8) and 3.00 (§8): the signature table the checker
// resolves calls against, and their lowering to IR (lower_builtin_call, in builtins.cpp).
#pragma once
#include <string>
#include <vector>

#include "softgl/glsl/ir.h"
#include "softgl/glsl/ir_builder.h"
#include "softgl/glsl/preprocessor.h"
#include "softgl/glsl/types.h"

namespace softgl::glsl {

enum class Builtin : uint8_t {
    // §8.1 angle and trigonometry
    Radians, Degrees, Sin, Cos, Tan, Asin, Acos, Atan, Atan2, Sinh, Cosh, Tanh, Asinh, Acosh, Atanh,
    // §8.2 exponential
    Pow, Exp, Log, Exp2, Log2, Sqrt, InverseSqrt,
    // §8.3 common
    Abs, Sign, Floor, Trunc, Round, RoundEven, Ceil, Fract, Mod, Modf, Min, Max, Clamp, Mix, Step,
    Smoothstep, IsNan, IsInf, FloatBitsToInt, FloatBitsToUint, IntBitsToFloat, UintBitsToFloat,
    // §8.4 packing
    PackSnorm2x16, UnpackSnorm2x16, PackUnorm2x16, UnpackUnorm2x16, PackHalf2x16, UnpackHalf2x16,
    // §8.5 geometric
    Length, Distance, Dot, Cross, Normalize, FaceForward, Reflect, Refract,
    // §8.6 matrix
    MatrixCompMult, OuterProduct, Transpose, Determinant, Inverse,
    // §8.7 vector relational
    LessThan, LessThanEqual, GreaterThan, GreaterThanEqual, Equal, NotEqual, Any, All, Not,
    // §8.8 texture lookup (one entry per variant; see BuiltinFunction::texture)
    TextureLookup, TextureSize, TexelFetch,
    // §8.9 fragment processing
    DFdx, DFdy, Fwidth,
};

struct BuiltinFunction {
    std::string name;
    Builtin op;
    Type result;
    std::vector<Type> parameters;
    int out_parameter = -1;   // modf's second parameter is "out"
    int min_version = 100;
    int max_version = 300;
    bool fragment_only = false;
    bool vertex_only = false;
    std::string extension;    // required extension in ES 1.00 (derivatives, texture LOD)
    // Texture variants
    bool projective = false;
    TextureLod lod_mode = TextureLod::Implicit;
    bool has_offset = false;
};

const std::vector<BuiltinFunction>& builtin_functions();
// Indices of built-ins named `name` (all versions; the caller filters).
const std::vector<int>& builtin_overloads(const std::string& name);

// Lowers a call of `f` (builtins.cpp). `args` are the evaluated arguments; for modf, `out_value`
// receives the out parameter's value. Records derivative use in `usage`.
Value lower_builtin_call(IrBuilder& b, const BuiltinFunction& f, const std::vector<Value>& args, Stage stage,
                         ShaderUsage& usage, Value* out_value);

}  // namespace softgl::glsl
