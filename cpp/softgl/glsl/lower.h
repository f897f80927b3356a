// Lowering: checked AST -> scalarised IR (see ir.h). User functions are inlined at each call;
// uniforms are read from the flat uniform buffer at the offsets `uniform_offset` assigned.
#pragma once
#include <string>
#include <unordered_map>
#include <vector>

#include "softgl/glsl/ast.h"
#include "softgl/glsl/checker.h"
#include "softgl/glsl/diagnostics.h"
#include "softgl/glsl/ir.h"

namespace softgl::glsl {

struct LoweredShader {
    IrProgram program;
    ShaderUsage usage;
    std::unordered_map<const Symbol*, int> uniform_offsets;  // symbol -> first word in the uniform buffer
    int uniform_words = 0;
};

// Lowers `shader` (which must have passed the checker). Reports lowering-time errors
// (recursion, missing function bodies, program too large) through `diagnostics`.
LoweredShader lower(const CheckedShader& shader, Diagnostics& diagnostics);

}  // namespace softgl::glsl
