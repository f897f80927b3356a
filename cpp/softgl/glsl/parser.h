// The parser: tokens -> AST (ES 3.00 §9 grammar, also accepting ES 1.00). Syntax only; the
// checker does the semantics. Stops at the first syntax error, as real compilers do.
#pragma once
#include "softgl/glsl/ast.h"
#include "softgl/glsl/diagnostics.h"
#include "softgl/glsl/token.h"

namespace softgl::glsl {

TranslationUnit parse(const TokenList& tokens, int version, Diagnostics& diagnostics);

bool is_keyword(const std::string& word, int version);
bool is_reserved_word(const std::string& word, int version);

}  // namespace softgl::glsl
