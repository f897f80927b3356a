// The preprocessor (ES 1.00 §3.4, ES 3.00 §3.4): directives, macro expansion, conditional
// compilation. Produces the token stream the parser reads, plus what the directives declared.
#pragma once
#include <map>
#include <set>
#include <string>

#include "softgl/glsl/diagnostics.h"
#include "softgl/glsl/token.h"

namespace softgl::glsl {

enum class Stage { Vertex, Fragment };

enum class ExtensionBehavior { Disable, Warn, Enable, Require };

struct PreprocessedSource {
    TokenList tokens;        // no newlines; ends with EndOfInput
    int version = 100;       // 100 or 300 (from #version)
    std::map<std::string, ExtensionBehavior> extensions;
};

// webgl_version 1 accepts only GLSL ES 1.00; webgl_version 2 accepts 1.00 and 3.00.
// `enabled`: the GLSL extensions (e.g. "GL_OES_standard_derivatives") the WebGL context has
// enabled with getExtension; a directive naming another is treated as unsupported. Null: every
// extension softgl implements (the compiler on its own, and WebGL 2, where they are core).
PreprocessedSource preprocess(const std::string& source, Stage stage, int webgl_version,
                              Diagnostics& diagnostics, const std::set<std::string>* enabled = nullptr);

// Extensions softgl implements, by language version.
bool extension_supported(const std::string& name, int version, int webgl_version);

}  // namespace softgl::glsl
