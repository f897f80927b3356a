// softgl's GLSL ES compiler: the API the WebGL layer calls.
//
//   CompileResult r = glsl::compile(source, glsl::Stage::Fragment, /*webgl_version=*/2);
//   r.ok, r.info_log ("ERROR: 0:LINE: message" lines), r.shader->reflection
//   LinkResult l = glsl::link(*vs.shader, *fs.shader, limits, bound_attribute_locations);
//   l.program->vertex / ->fragment: IrPrograms for glsl::Executor; l.program->reflection.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "softgl/glsl/ir.h"
#include "softgl/glsl/lower.h"
#include "softgl/glsl/preprocessor.h"

namespace softgl::glsl {

struct VariableInfo {
    std::string name;
    uint32_t gl_type = 0;     // GL_FLOAT_VEC3 etc.
    std::string type_name;    // "vec3"
    int array_size = 0;       // 0: not an array
    int components = 0;       // per element
    int location = -1;        // layout(location) or assigned at link
    Precision precision = Precision::None;
    Interpolation interpolation = Interpolation::Default;
    bool invariant = false;
    bool active = false;      // read (inputs) or written (outputs) by the optimised program
    int first_slot = -1;      // index of its first component in IrProgram::inputs/outputs
};

struct UniformInfo {
    std::string name;         // WebGL active-uniform name: "u", "u[0]" (arrays), "s.f", "s[1].f"
    std::string base_name;    // without a trailing "[0]"
    uint32_t gl_type = 0;
    std::string type_name;
    int size = 1;             // array elements (1 if not an array)
    int offset = 0;           // first 32-bit word in the uniform buffer
    int stride = 0;           // words per array element
    Precision precision = Precision::None;
    bool is_sampler = false;
    bool is_builtin = false;  // gl_DepthRange.*
    bool active = false;
};

struct ShaderReflection {
    std::vector<VariableInfo> attributes;  // vertex inputs
    std::vector<UniformInfo> uniforms;
    std::vector<VariableInfo> varyings;    // vertex outputs / fragment inputs (user-declared)
    std::vector<VariableInfo> outputs;     // fragment outputs (gl_FragColor, gl_FragData, or `out`s)
    std::vector<std::string> varyings_read;  // fragment: varyings the shader actually reads
    ShaderUsage usage;
    bool output_depends_only_on_uniforms = false;
    int uniform_words = 0;
};

struct CompiledShader {
    Stage stage = Stage::Vertex;
    int version = 100;
    IrProgram program;
    ShaderReflection reflection;
    // Per top-level uniform variable: name -> (first word, words, type string with precision)
    struct UniformBlock { std::string name; int offset; int words; std::string signature; };
    std::vector<UniformBlock> uniform_blocks;
};

struct CompileResult {
    bool ok = false;
    std::string info_log;
    std::shared_ptr<const CompiledShader> shader;  // null unless ok
};

// `enabled_extensions`: as preprocess() takes them (null: every extension softgl implements).
CompileResult compile(const std::string& source, Stage stage, int webgl_version,
                      const std::set<std::string>* enabled_extensions = nullptr);

struct LinkLimits {
    int max_vertex_attribs = 16;
    int max_varying_vectors = 15;
    int max_vertex_uniform_vectors = 256;
    int max_fragment_uniform_vectors = 224;
    int max_vertex_texture_image_units = 16;
    int max_texture_image_units = 16;
    int max_combined_texture_image_units = 32;
};

// A varying the pipeline interpolates: vertex output slots [vertex_slot, +components) feed
// fragment input slots [fragment_slot, +components).
struct LinkedVarying {
    std::string name;
    int components = 0;
    Interpolation interpolation = Interpolation::Smooth;
    int vertex_slot = -1;
    int fragment_slot = -1;
};

struct ProgramReflection {
    std::vector<VariableInfo> attributes;     // with assigned locations
    std::vector<UniformInfo> uniforms;        // combined, offsets into the program's buffer
    std::vector<LinkedVarying> varyings;
    std::vector<VariableInfo> outputs;        // fragment outputs
    ShaderUsage vertex_usage;
    ShaderUsage fragment_usage;
    bool fragment_depends_only_on_uniforms = false;
    int uniform_words = 0;
};

struct LinkedProgram {
    int version = 100;
    IrProgram vertex;
    IrProgram fragment;
    ProgramReflection reflection;
};

struct LinkResult {
    bool ok = false;
    std::string info_log;
    std::shared_ptr<const LinkedProgram> program;
};

LinkResult link(const CompiledShader& vertex, const CompiledShader& fragment, const LinkLimits& limits = {},
                const std::map<std::string, int>& bound_attribute_locations = {});

}  // namespace softgl::glsl
