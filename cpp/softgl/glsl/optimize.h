// IR optimisation: constant folding (by running the executor itself on one lane, so folded
// values are bit-identical to executed ones), copy propagation and dead code elimination. Also the analyses the
// pipeline uses to skip work: which inputs are read, whether outputs depend only on uniforms.
#pragma once
#include "softgl/glsl/ir.h"

namespace softgl::glsl {

struct OptimizeReport {
    int folded = 0;
    int removed = 0;
    int propagated = 0;   // Movs replaced by their source
};

OptimizeReport optimize(IrProgram& program);

// Registers read by some instruction (after optimisation).
std::vector<bool> registers_read(const IrProgram& program);

// True if every output is a function of uniforms and constants only (no inputs, no
// input-dependent control flow), so the stage could run once per draw.
bool outputs_depend_only_on_uniforms(const IrProgram& program);

}  // namespace softgl::glsl
