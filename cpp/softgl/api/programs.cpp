// Shader and program entry points: WebGL 1.0 §5.14.9-10 and WebGL 2.0 §3.7.7-8, compiled and
// linked by softgl's GLSL compiler. Error codes follow WebGL (and match Chromium): a deleted
// object is INVALID_VALUE, an object of another context INVALID_OPERATION.
#include <cstring>
#include <set>

#include "softgl/api/context.h"

namespace softgl {

namespace {

// The shape of a uniform type: its component kind ('f', 'i', 'u', 'b', 's' for samplers),
// components per element, and matrix columns x rows (0 when not a matrix).
struct UniformShape {
    char kind = 'f';
    int components = 1;
    int columns = 0, rows = 0;
};

UniformShape uniform_shape(uint32_t t) {
    switch (t) {
        case gl::FLOAT: return {'f', 1};
        case gl::FLOAT_VEC2: return {'f', 2};
        case gl::FLOAT_VEC3: return {'f', 3};
        case gl::FLOAT_VEC4: return {'f', 4};
        case gl::INT: return {'i', 1};
        case gl::INT_VEC2: return {'i', 2};
        case gl::INT_VEC3: return {'i', 3};
        case gl::INT_VEC4: return {'i', 4};
        case gl::UNSIGNED_INT: return {'u', 1};
        case gl::UNSIGNED_INT_VEC2: return {'u', 2};
        case gl::UNSIGNED_INT_VEC3: return {'u', 3};
        case gl::UNSIGNED_INT_VEC4: return {'u', 4};
        case gl::BOOL: return {'b', 1};
        case gl::BOOL_VEC2: return {'b', 2};
        case gl::BOOL_VEC3: return {'b', 3};
        case gl::BOOL_VEC4: return {'b', 4};
        case gl::FLOAT_MAT2: return {'m', 4, 2, 2};
        case gl::FLOAT_MAT3: return {'m', 9, 3, 3};
        case gl::FLOAT_MAT4: return {'m', 16, 4, 4};
        case gl::FLOAT_MAT2x3: return {'m', 6, 2, 3};
        case gl::FLOAT_MAT2x4: return {'m', 8, 2, 4};
        case gl::FLOAT_MAT3x2: return {'m', 6, 3, 2};
        case gl::FLOAT_MAT3x4: return {'m', 12, 3, 4};
        case gl::FLOAT_MAT4x2: return {'m', 8, 4, 2};
        case gl::FLOAT_MAT4x3: return {'m', 12, 4, 3};
        default: return {'s', 1};   // samplers
    }
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

bool Context::check_shader(const char* call, const Shader* shader) {
    if (!shader) { error(gl::INVALID_VALUE, call, "the shader is null"); return false; }
    if (shader->owner != identity()) { error(gl::INVALID_OPERATION, call, "the shader belongs to another context"); return false; }
    if (shader->deleted) { error(gl::INVALID_VALUE, call, "the shader has been deleted"); return false; }
    return true;
}

bool Context::check_name_length(const char* call, const std::string& name) {
    // WebGL 1.0 §6.21 / WebGL 2.0 §5.19: names longer than 256 (WebGL 2: 1024) characters are
    // INVALID_VALUE, checked before anything else.
    const size_t limit = version() >= 2 ? 1024 : 256;
    if (name.size() <= limit) return true;
    error(gl::INVALID_VALUE, call, "names longer than " + std::to_string(limit) + " characters are not allowed");
    return false;
}

bool Context::check_program(const char* call, const Program* program) {
    if (!program) { error(gl::INVALID_VALUE, call, "the program is null"); return false; }
    if (program->owner != identity()) { error(gl::INVALID_OPERATION, call, "the program belongs to another context"); return false; }
    if (program->deleted) { error(gl::INVALID_VALUE, call, "the program has been deleted"); return false; }
    return true;
}

// ------------------------------------------------------------------------------------- shaders

std::shared_ptr<Shader> Context::create_shader(GLenum type) {
    if (type != gl::VERTEX_SHADER && type != gl::FRAGMENT_SHADER) {
        error(gl::INVALID_ENUM, "createShader", enum_name(type) + " is not VERTEX_SHADER or FRAGMENT_SHADER");
        return nullptr;
    }
    auto shader = std::make_shared<Shader>();
    shader->owner = identity();
    shader->type = type;
    return shader;
}

void Context::shader_source(const std::shared_ptr<Shader>& shader, const std::string& source) {
    if (!check_shader("shaderSource", shader.get())) return;
    shader->source = source;
}

std::string Context::get_shader_source(const std::shared_ptr<Shader>& shader) {
    if (!check_shader("getShaderSource", shader.get())) return {};
    return shader->source;
}

void Context::compile_shader(const std::shared_ptr<Shader>& shader) {
    if (!check_shader("compileShader", shader.get())) return;
    const glsl::Stage stage = shader->type == gl::VERTEX_SHADER ? glsl::Stage::Vertex : glsl::Stage::Fragment;
    // WebGL 1's extension registry: a GLSL ES 1.00 #extension directive takes effect only for an
    // extension the page enabled with getExtension. In WebGL 2 what they add is core, and 1.00
    // shaders may still name them.
    std::set<std::string> enabled;
    if (version() == 1) {
        for (auto [webgl, glsl_name] : {std::pair{"OES_standard_derivatives", "GL_OES_standard_derivatives"},
                                        {"EXT_frag_depth", "GL_EXT_frag_depth"},
                                        {"EXT_shader_texture_lod", "GL_EXT_shader_texture_lod"},
                                        {"WEBGL_draw_buffers", "GL_EXT_draw_buffers"}})
            if (extension_enabled(webgl)) enabled.insert(glsl_name);
    }
    glsl::CompileResult result;
    try {
        // The compile's work budget (core/work_budget.h): the compiler charges the current one.
        work_budget_.begin(work_limits_.compile);
        CurrentWorkBudget budget(&work_budget_);
        result = glsl::compile(shader->source, stage, version(), version() == 1 ? &enabled : nullptr);
    } catch (const WorkStopped& stopped) {
        return report_stopped("compileShader", stopped.reason, work_limits_.compile,
                              "the shader is as before the call (its status, info log and compiled code)");
    }
    // Moves only (no allocation): an allocation failure before this line leaves the shader as it
    // was (docs/reliability.md, "Memory").
    shader->info_log = std::move(result.info_log);
    shader->compiled = result.ok ? std::move(result.shader) : nullptr;
    shader->compile_status = result.ok;
}

Value Context::get_shader_parameter(const std::shared_ptr<Shader>& shader, GLenum pname) {
    if (!check_shader("getShaderParameter", shader.get())) return Value(Null{});
    switch (pname) {
        case gl::SHADER_TYPE: return Value(int64_t(shader->type));
        case gl::DELETE_STATUS: return Value(shader->delete_requested);
        case gl::COMPILE_STATUS: return Value(shader->compile_status);
        default:
            error(gl::INVALID_ENUM, "getShaderParameter", enum_name(pname) + " is not a shader parameter");
            return Value(Null{});
    }
}

std::string Context::get_shader_info_log(const std::shared_ptr<Shader>& shader) {
    if (!check_shader("getShaderInfoLog", shader.get())) return {};
    return shader->info_log;
}

void Context::release_shader(const std::shared_ptr<Shader>& shader) {
    // ES 2.0 §2.10.1: a shader flagged for deletion goes away when no program holds it.
    if (shader && --shader->attachments == 0 && shader->delete_requested) shader->deleted = true;
}

void Context::delete_shader(const std::shared_ptr<Shader>& shader) {
    if (!shader || shader->deleted) return;
    if (shader->owner != identity()) return error(gl::INVALID_OPERATION, "deleteShader", "the shader belongs to another context");
    shader->delete_requested = true;
    if (shader->attachments == 0) shader->deleted = true;
}

bool Context::is_shader(const std::shared_ptr<Shader>& shader) const {
    return shader && shader->owner == identity() && !shader->deleted;
}

// ------------------------------------------------------------------------------------ programs

std::shared_ptr<Program> Context::create_program() {
    auto program = std::make_shared<Program>();
    program->owner = identity();
    return program;
}

void Context::attach_shader(const std::shared_ptr<Program>& program, const std::shared_ptr<Shader>& shader) {
    const char* call = "attachShader";
    if (!check_program(call, program.get()) || !check_shader(call, shader.get())) return;
    std::shared_ptr<Shader>& slot = shader->type == gl::VERTEX_SHADER ? program->vertex : program->fragment;
    if (slot) return error(gl::INVALID_OPERATION, call, "a shader of this type is already attached");
    slot = shader;
    shader->attachments++;
}

void Context::detach_shader(const std::shared_ptr<Program>& program, const std::shared_ptr<Shader>& shader) {
    const char* call = "detachShader";
    if (!check_program(call, program.get()) || !check_shader(call, shader.get())) return;
    std::shared_ptr<Shader>& slot = shader->type == gl::VERTEX_SHADER ? program->vertex : program->fragment;
    if (slot != shader) return error(gl::INVALID_OPERATION, call, "the shader is not attached to the program");
    slot.reset();
    release_shader(shader);
}

std::vector<std::shared_ptr<Shader>> Context::get_attached_shaders(const std::shared_ptr<Program>& program, bool* ok) {
    *ok = check_program("getAttachedShaders", program.get());
    std::vector<std::shared_ptr<Shader>> out;
    if (!*ok) return out;
    if (program->vertex) out.push_back(program->vertex);
    if (program->fragment) out.push_back(program->fragment);
    return out;
}

void Context::bind_attrib_location(const std::shared_ptr<Program>& program, uint32_t index, const std::string& name) {
    const char* call = "bindAttribLocation";
    if (!check_name_length(call, name) || !check_program(call, program.get())) return;
    if (index >= uint32_t(kMaxVertexAttribs)) return error(gl::INVALID_VALUE, call, "index is not below MAX_VERTEX_ATTRIBS");
    if (starts_with(name, "gl_") || starts_with(name, "webgl_") || starts_with(name, "_webgl_"))
        return error(gl::INVALID_OPERATION, call, "'" + name + "' uses a reserved prefix");
    program->attribute_bindings[name] = int(index);
}

void Context::link_program(const std::shared_ptr<Program>& program) {
    if (!check_program("linkProgram", program.get())) return;
    Program& p = *program;
    // Everything that allocates happens first, into locals; the program changes only at the end,
    // by moves, so a stop (work budget, Ctrl-C) or an allocation failure (std::bad_alloc, turned
    // into OUT_OF_MEMORY by the bindings) leaves it as it was (docs/reliability.md, "Memory").
    std::string log;
    if (!p.vertex || !p.fragment) log = "ERROR: a vertex and a fragment shader must be attached\n";
    else if (!p.vertex->compile_status) log = "ERROR: the vertex shader is not compiled\n";
    else if (!p.fragment->compile_status) log = "ERROR: the fragment shader is not compiled\n";
    glsl::LinkResult result;
    if (log.empty()) {
        glsl::LinkLimits link_limits;
        link_limits.max_vertex_attribs = kMaxVertexAttribs;
        link_limits.max_varying_vectors = limits::kMaxVaryingVectors;
        link_limits.max_vertex_uniform_vectors = limits::kMaxVertexUniformVectors;
        link_limits.max_fragment_uniform_vectors = limits::kMaxFragmentUniformVectors;
        link_limits.max_vertex_texture_image_units = limits::kMaxVertexTextureImageUnits;
        link_limits.max_texture_image_units = limits::kMaxTextureImageUnits;
        link_limits.max_combined_texture_image_units = limits::kMaxCombinedTextureImageUnits;
        try {
            work_budget_.begin(work_limits_.compile);   // a link's work budget (core/work_budget.h)
            CurrentWorkBudget budget(&work_budget_);
            result = glsl::link(*p.vertex->compiled, *p.fragment->compiled, link_limits, p.attribute_bindings);
        } catch (const WorkStopped& stopped) {
            return report_stopped("linkProgram", stopped.reason, work_limits_.compile,
                                  "the program is as before the call (its status, info log and executable)");
        }
        log = std::move(result.info_log);
    }
    if (!result.ok) {
        p.link_status = false;
        p.validate_status = false;
        p.info_log = std::move(log);
        p.link_generation++;   // every link invalidates earlier uniform locations (WebGL 1.0 §5.14.10)
        // ES 3.0 §2.11.3: a failed relink keeps the current executable of a program in use.
        if (current_program_ != program) {
            p.linked.reset();
            p.vertex_stage.reset();
            p.fragment_stage.reset();
        }
        return;
    }
    const std::shared_ptr<const glsl::LinkedProgram>& linked = result.program;
    const glsl::ProgramReflection& r = linked->reflection;
    std::vector<glsl::Scalar> uniforms(size_t(r.uniform_words) + 1, glsl::Scalar{});
    // Per vertex input slot: the attribute location and component it reads. A matrix takes one
    // location per column (ES 3.0 §2.11.5); its slots are numbered column-major.
    const glsl::IrProgram& vertex_ir = linked->vertex;
    std::vector<int> slot_location(vertex_ir.inputs.size(), -1), slot_component(vertex_ir.inputs.size(), 0);
    for (size_t i = 0; i < vertex_ir.inputs.size(); ++i) {
        const glsl::Slot& slot = vertex_ir.inputs[i];
        if (slot.kind != glsl::SlotKind::Attribute) continue;
        for (const auto& a : r.attributes) {
            if (a.name != slot.name) continue;
            const UniformShape shape = uniform_shape(a.gl_type);
            const int rows = shape.kind == 'm' ? shape.rows : 4;
            slot_location[i] = a.location + slot.component / rows;
            slot_component[i] = slot.component % rows;
        }
    }
    auto vertex_stage = std::make_unique<GlslVertexShader>(linked, slot_location, slot_component);
    auto fragment_stage = std::make_unique<GlslFragmentShader>(linked, vertex_stage->varying_layout());
    vertex_stage->set_uniforms(uniforms.data());   // a moved vector keeps its storage
    fragment_stage->set_uniforms(uniforms.data());
    // The commit: moves and plain stores only.
    p.link_status = true;
    p.validate_status = false;
    p.info_log = std::move(log);
    p.link_generation++;
    p.linked = std::move(result.program);
    p.uniforms = std::move(uniforms);
    p.vertex_stage = std::move(vertex_stage);
    p.fragment_stage = std::move(fragment_stage);
}

void Context::validate_program(const std::shared_ptr<Program>& program) {
    if (!check_program("validateProgram", program.get())) return;
    program->validate_status = program->link_status;
}

void Context::use_program(const std::shared_ptr<Program>& program) {
    const char* call = "useProgram";
    if (program) {
        if (program->owner != identity()) return error(gl::INVALID_OPERATION, call, "the program belongs to another context");
        if (program->deleted) return error(gl::INVALID_OPERATION, call, "the program has been deleted");
        if (!program->link_status) return error(gl::INVALID_OPERATION, call, "the program is not linked");
    }
    if (current_program_ && current_program_->delete_requested && current_program_ != program) {
        // The deferred deletion of the program that was in use happens now.
        current_program_->deleted = true;
        for (auto* s : {&current_program_->vertex, &current_program_->fragment})
            if (*s) release_shader(*s), s->reset();
    }
    current_program_ = program;
}

void Context::delete_program(const std::shared_ptr<Program>& program) {
    if (!program || program->deleted || program->delete_requested) return;
    if (program->owner != identity()) return error(gl::INVALID_OPERATION, "deleteProgram", "the program belongs to another context");
    program->delete_requested = true;
    if (current_program_ == program) return;   // deleted when it stops being used
    program->deleted = true;
    for (auto* s : {&program->vertex, &program->fragment})
        if (*s) release_shader(*s), s->reset();
}

bool Context::is_program(const std::shared_ptr<Program>& program) const {
    return program && program->owner == identity() && !program->deleted && !program->delete_requested;
}

Value Context::get_program_parameter(const std::shared_ptr<Program>& program, GLenum pname) {
    const char* call = "getProgramParameter";
    if (!check_program(call, program.get())) return Value(Null{});
    const Program& p = *program;
    auto active_count = [&](bool uniforms) -> int64_t {
        if (!p.linked) return 0;
        int64_t n = 0;
        if (uniforms) {
            for (const auto& u : p.linked->reflection.uniforms) n += u.active && !u.is_builtin;
        } else {
            for (const auto& a : p.linked->reflection.attributes) n += a.active && !starts_with(a.name, "gl_");
        }
        return n;
    };
    switch (pname) {
        case gl::DELETE_STATUS: return Value(p.delete_requested);
        case gl::LINK_STATUS: return Value(p.link_status);
        case gl::VALIDATE_STATUS: return Value(p.validate_status);
        case gl::ATTACHED_SHADERS: return Value(int64_t((p.vertex ? 1 : 0) + (p.fragment ? 1 : 0)));
        case gl::ACTIVE_ATTRIBUTES: return Value(active_count(false));
        case gl::ACTIVE_UNIFORMS: return Value(active_count(true));
        default: break;
    }
    if (version() >= 2) {
        switch (pname) {
            case gl::TRANSFORM_FEEDBACK_BUFFER_MODE: return Value(int64_t(gl::INTERLEAVED_ATTRIBS));
            case gl::TRANSFORM_FEEDBACK_VARYINGS: return Value(int64_t(0));
            case gl::ACTIVE_UNIFORM_BLOCKS: return Value(int64_t(0));
            default: break;
        }
    }
    error(gl::INVALID_ENUM, call, enum_name(pname) + " is not a program parameter here");
    return Value(Null{});
}

std::string Context::get_program_info_log(const std::shared_ptr<Program>& program) {
    if (!check_program("getProgramInfoLog", program.get())) return {};
    return program->info_log;
}

int32_t Context::get_attrib_location(const std::shared_ptr<Program>& program, const std::string& name) {
    const char* call = "getAttribLocation";
    if (!check_name_length(call, name) || !check_program(call, program.get())) return -1;
    if (!program->link_status) { error(gl::INVALID_OPERATION, call, "the program is not linked"); return -1; }
    for (const auto& a : program->linked->reflection.attributes)
        if (a.name == name && a.active) return a.location;
    return -1;
}

std::shared_ptr<UniformLocation> Context::get_uniform_location(const std::shared_ptr<Program>& program,
                                                               const std::string& name) {
    const char* call = "getUniformLocation";
    if (!check_name_length(call, name) || !check_program(call, program.get())) return nullptr;
    if (!program->link_status) { error(gl::INVALID_OPERATION, call, "the program is not linked"); return nullptr; }
    if (starts_with(name, "gl_") || starts_with(name, "webgl_") || starts_with(name, "_webgl_")) return nullptr;
    const auto& uniforms = program->linked->reflection.uniforms;
    // "u", "u[0]" and "s.f" name element 0; "u[N]" names element N of an array.
    std::string base = name;
    int element = 0;
    if (!name.empty() && name.back() == ']') {
        const size_t open = name.rfind('[');
        if (open == std::string::npos || open + 2 > name.size() - 1 + 1) return nullptr;
        const std::string digits = name.substr(open + 1, name.size() - open - 2);
        if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) return nullptr;
        element = std::stoi(digits);
        base = name.substr(0, open);
    }
    for (size_t i = 0; i < uniforms.size(); ++i) {
        const auto& u = uniforms[i];
        if (!u.active || u.is_builtin) continue;
        const bool match = (element == 0 && (u.name == name || u.base_name == name)) ||
                           (u.base_name == base && u.name != u.base_name && element < u.size);
        if (!match) continue;
        auto location = std::make_shared<UniformLocation>();
        location->program = program;
        location->link_generation = program->link_generation;
        location->uniform = int(i);
        location->element = element;
        return location;
    }
    return nullptr;
}

std::shared_ptr<ActiveInfo> Context::get_active_attrib(const std::shared_ptr<Program>& program, uint32_t index) {
    const char* call = "getActiveAttrib";
    if (!check_program(call, program.get())) return nullptr;
    uint32_t n = 0;
    if (program->linked)
        for (const auto& a : program->linked->reflection.attributes) {
            if (!a.active || starts_with(a.name, "gl_")) continue;
            if (n++ == index) return std::make_shared<ActiveInfo>(ActiveInfo{1, a.gl_type, a.name});
        }
    error(gl::INVALID_VALUE, call, "index is not below ACTIVE_ATTRIBUTES");
    return nullptr;
}

std::shared_ptr<ActiveInfo> Context::get_active_uniform(const std::shared_ptr<Program>& program, uint32_t index) {
    const char* call = "getActiveUniform";
    if (!check_program(call, program.get())) return nullptr;
    uint32_t n = 0;
    if (program->linked)
        for (const auto& u : program->linked->reflection.uniforms) {
            if (!u.active || u.is_builtin) continue;
            if (n++ == index) return std::make_shared<ActiveInfo>(ActiveInfo{u.size, u.gl_type, u.name});
        }
    error(gl::INVALID_VALUE, call, "index is not below ACTIVE_UNIFORMS");
    return nullptr;
}

std::shared_ptr<PrecisionFormat> Context::get_shader_precision_format(GLenum shader_type, GLenum precision_type) {
    const char* call = "getShaderPrecisionFormat";
    if (shader_type != gl::VERTEX_SHADER && shader_type != gl::FRAGMENT_SHADER) {
        error(gl::INVALID_ENUM, call, enum_name(shader_type) + " is not a shader type");
        return nullptr;
    }
    // softgl evaluates every precision in IEEE single precision and 32-bit integers.
    switch (precision_type) {
        case gl::LOW_FLOAT: case gl::MEDIUM_FLOAT: case gl::HIGH_FLOAT:
            return std::make_shared<PrecisionFormat>(PrecisionFormat{127, 127, 23});
        case gl::LOW_INT: case gl::MEDIUM_INT: case gl::HIGH_INT:
            return std::make_shared<PrecisionFormat>(PrecisionFormat{31, 30, 0});
        default:
            error(gl::INVALID_ENUM, call, enum_name(precision_type) + " is not a precision type");
            return nullptr;
    }
}

// ------------------------------------------------------------------------------------ uniforms

void Context::set_uniform(const char* call, const UniformLocation* location, char kind, int columns, int rows,
                          const void* values, size_t count, bool transpose) {
    if (!location) return;   // WebGL: a null location is silently ignored
    const std::shared_ptr<Program> program = location->program.lock();
    if (!current_program_) return error(gl::INVALID_OPERATION, call, "no program is in use");
    if (program != current_program_) return error(gl::INVALID_OPERATION, call, "the location belongs to another program");
    if (location->link_generation != program->link_generation)
        return error(gl::INVALID_OPERATION, call, "the location is from an earlier link of the program");
    const glsl::UniformInfo& u = program->linked->reflection.uniforms[size_t(location->uniform)];
    const UniformShape shape = uniform_shape(u.gl_type);
    const bool matrix_call = kind == 'm';
    bool compatible;
    if (matrix_call) compatible = shape.kind == 'm' && shape.columns == columns && shape.rows == rows;
    else if (shape.kind == 'b') compatible = columns == shape.components;                 // bools take any kind
    else if (shape.kind == 's') compatible = kind == 'i' && columns == 1;                 // samplers: uniform1i(v)
    else compatible = shape.kind == kind && shape.components == columns;
    if (!compatible)
        return error(gl::INVALID_OPERATION, call, "the call does not match the uniform's type (" + u.type_name + ")");
    if (matrix_call && transpose && version() < 2)
        return error(gl::INVALID_VALUE, call, "transpose must be false in WebGL 1");
    if (count == 0) return;
    const int components = shape.components;
    const size_t elements = count;
    if (elements > 1 && u.name == u.base_name)
        return error(gl::INVALID_OPERATION, call, "more than one value for a uniform that is not an array");
    if (shape.kind == 's') {
        const int32_t* v = static_cast<const int32_t*>(values);
        for (size_t e = 0; e < elements; ++e)
            if (v[e] < 0 || v[e] >= limits::kMaxCombinedTextureImageUnits)
                return error(gl::INVALID_VALUE, call, "sampler value is not a texture unit");
    }
    // Elements past the end of the array are ignored (ES 3.0 §2.11.6).
    const size_t writable = std::min(elements, size_t(u.size - location->element));
    for (size_t e = 0; e < writable; ++e) {
        glsl::Scalar* dst = &program->uniforms[size_t(u.offset + (location->element + int(e)) * u.stride)];
        for (int k = 0; k < components; ++k) {
            // Matrices: WebGL gives column-major values; transpose (WebGL 2) gives row-major.
            int source = k;
            if (matrix_call && transpose) source = (k % rows) * columns + (k / rows);
            const size_t index = e * size_t(components) + size_t(source);
            glsl::Scalar value;
            if (kind == 'f' || kind == 'm') {
                const float f = static_cast<const float*>(values)[index];
                if (shape.kind == 'b') value.u = f != 0.0f ? 1u : 0u;
                else value.f = f;
            } else if (kind == 'i') {
                const int32_t i = static_cast<const int32_t*>(values)[index];
                if (shape.kind == 'b') value.u = i != 0 ? 1u : 0u;
                else value.i = i;
            } else {
                const uint32_t ui = static_cast<const uint32_t*>(values)[index];
                if (shape.kind == 'b') value.u = ui != 0 ? 1u : 0u;
                else value.u = ui;
            }
            dst[k] = value;
        }
    }
}

Value Context::get_uniform(const std::shared_ptr<Program>& program, const UniformLocation* location) {
    const char* call = "getUniform";
    if (!check_program(call, program.get())) return Value(Null{});
    if (!location || location->program.lock() != program || location->link_generation != program->link_generation) {
        error(gl::INVALID_OPERATION, call, "the location does not belong to this program's last link");
        return Value(Null{});
    }
    const glsl::UniformInfo& u = program->linked->reflection.uniforms[size_t(location->uniform)];
    const UniformShape shape = uniform_shape(u.gl_type);
    const glsl::Scalar* src = &program->uniforms[size_t(u.offset + location->element * u.stride)];
    const int n = shape.components;
    switch (shape.kind) {
        case 'f': case 'm':
            if (n == 1) return Value(double(src[0].f));
            { Float32Array a; for (int k = 0; k < n; ++k) a.values.push_back(src[k].f); return Value(a); }
        case 'i': case 's':
            if (n == 1) return Value(int64_t(src[0].i));
            { Int32Array a; for (int k = 0; k < n; ++k) a.values.push_back(src[k].i); return Value(a); }
        case 'u':
            if (n == 1) return Value(int64_t(src[0].u));
            { Uint32Array a; for (int k = 0; k < n; ++k) a.values.push_back(src[k].u); return Value(a); }
        default:
            if (n == 1) return Value(src[0].u != 0);
            { BoolList a; for (int k = 0; k < n; ++k) a.values.push_back(src[k].u != 0); return Value(a); }
    }
}

}  // namespace softgl
