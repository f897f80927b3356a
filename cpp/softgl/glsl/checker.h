// The checker: semantic analysis of a parsed shader (ES 1.00 and ES 3.00 chapters 4-7): scopes,
// types of every expression, qualifiers, precision defaults, constant expressions, overload
// resolution, and the language version's and WebGL's restrictions.
#pragma once
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "softgl/glsl/ast.h"
#include "softgl/glsl/diagnostics.h"
#include "softgl/glsl/preprocessor.h"

namespace softgl::glsl {

struct CheckedShader {
    Stage stage = Stage::Vertex;
    int version = 100;
    int webgl_version = 2;
    std::map<std::string, ExtensionBehavior> extensions;
    TranslationUnit unit;
    std::deque<Symbol> symbols;                  // owns every variable symbol (stable addresses)
    std::deque<StructType> struct_types;
    std::vector<Symbol*> globals;                // user globals in declaration order
    std::map<std::string, Symbol*> builtin_variables;  // gl_Position, gl_FragCoord, ...
    FunctionDef* main = nullptr;
    std::vector<FunctionDef*> functions;         // every definition, in source order

    bool extension_enabled(const std::string& name) const {
        auto it = extensions.find(name);
        return it != extensions.end() && it->second != ExtensionBehavior::Disable;
    }
};

void check(CheckedShader& shader, Diagnostics& diagnostics);

// Limits that built-in constants report (ES 3.00 §7.4; values WebGL 2 in Chromium reports).
struct BuiltinConstants {
    int max_vertex_attribs = 16;
    int max_vertex_uniform_vectors = 256;
    int max_varying_vectors = 15;
    int max_vertex_output_vectors = 16;
    int max_fragment_input_vectors = 15;
    int max_vertex_texture_image_units = 16;
    int max_combined_texture_image_units = 32;
    int max_texture_image_units = 16;
    int max_fragment_uniform_vectors = 224;
    int max_draw_buffers = 8;
    int min_program_texel_offset = -8;
    int max_program_texel_offset = 7;
};

}  // namespace softgl::glsl
