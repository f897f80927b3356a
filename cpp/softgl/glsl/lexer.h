// The lexer: source text -> preprocessing tokens (ES 3.00 §3.1-§3.8). Comments become white
// space, line continuations are joined, and newlines are kept as tokens for the preprocessor.
#pragma once
#include <string>

#include "softgl/glsl/diagnostics.h"
#include "softgl/glsl/token.h"

namespace softgl::glsl {

TokenList tokenize(const std::string& source, Diagnostics& diagnostics);

}  // namespace softgl::glsl
