// Shader and program objects (WebGL 1.0 §5.14.9, WebGL 2.0 §3.7.7): sources, compile and link
// results from softgl's GLSL compiler, uniform storage, and the pipeline stages of a linked program.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "softgl/core/objects.h"
#include "softgl/glsl/compiler.h"
#include "softgl/pipeline/glsl_stages.h"

namespace softgl {

class Shader : public Object {
public:
    GLenum type = gl::VERTEX_SHADER;
    std::string source;
    bool compile_status = false;
    std::string info_log;
    std::shared_ptr<const glsl::CompiledShader> compiled;
    int attachments = 0;          // programs it is attached to: deletion waits for detach
    bool delete_requested = false;
};

class Program : public Object {
public:
    std::shared_ptr<Shader> vertex, fragment;
    std::map<std::string, int> attribute_bindings;   // bindAttribLocation, applied at link
    bool link_status = false, validate_status = false;
    std::string info_log;
    uint32_t link_generation = 0;                     // uniform locations of older links are stale
    bool delete_requested = false;

    // From the last successful link:
    std::shared_ptr<const glsl::LinkedProgram> linked;
    std::vector<glsl::Scalar> uniforms;               // the uniform buffer the executor reads
    std::unique_ptr<GlslVertexShader> vertex_stage;
    std::unique_ptr<GlslFragmentShader> fragment_stage;
    std::vector<int> attribute_locations;             // per linked attribute (reflection order)
};

class UniformLocation {
public:
    std::weak_ptr<Program> program;
    uint32_t link_generation = 0;
    int uniform = 0;                                  // index into reflection.uniforms
    int element = 0;                                  // array element
};

struct ActiveInfo {
    int32_t size = 0;
    GLenum type = 0;
    std::string name;
};

struct PrecisionFormat {
    int32_t range_min = 0, range_max = 0, precision = 0;
};

}  // namespace softgl
