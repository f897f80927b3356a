#include "softgl/glsl/compiler.h"
#include "softgl/core/work_budget.h"

#include <algorithm>
#include <new>
#include <set>

#include "softgl/glsl/checker.h"
#include "softgl/glsl/optimize.h"
#include "softgl/glsl/parser.h"

namespace softgl::glsl {
namespace {

void flatten_uniform(const std::string& name, const Type& type, Precision precision, int& offset, bool builtin,
                     std::vector<UniformInfo>& out) {
    if (type.is_struct()) {
        int n = type.array_size > 0 ? type.array_size : 1;
        for (int i = 0; i < n; ++i) {
            std::string element = type.is_array() ? name + "[" + std::to_string(i) + "]" : name;
            for (const StructField& f : type.struct_type->fields)
                flatten_uniform(element + "." + f.name, f.type, f.precision != Precision::None ? f.precision : precision, offset, builtin, out);
        }
        return;
    }
    UniformInfo u;
    u.base_name = name;
    u.name = type.is_array() ? name + "[0]" : name;
    Type element = type.element_type();
    u.gl_type = element.gl_enum();
    u.type_name = element.name();
    u.size = type.is_array() ? type.array_size : 1;
    u.stride = element.components();
    u.offset = offset;
    u.precision = precision;
    u.is_sampler = type.is_sampler();
    u.is_builtin = builtin;
    offset += u.size * u.stride;
    out.push_back(u);
}

std::vector<bool> uniform_words_read(const IrProgram& p, int words) {
    std::vector<bool> read(static_cast<size_t>(std::max(words, 0)), false);
    for (const Instruction& i : p.code) {
        if (i.op == Op::LoadUniform && i.imm[0] < words) read[i.imm[0]] = true;
        if (i.op == Op::LoadUniformIndexed)
            for (int k = 0; k < i.imm[2] && i.imm[0] + k < words; ++k) read[i.imm[0] + k] = true;
    }
    return read;
}

std::vector<bool> registers_written(const IrProgram& p) {
    std::vector<bool> written(p.register_count, false);
    for (const Instruction& i : p.code) {
        if (i.op == Op::Texture) { for (Reg r : p.textures[i.texture].dst) if (r != kNoReg) written[r] = true; continue; }
        if (i.op == Op::StoreIndexed) { for (int k = 0; k < i.imm[2]; ++k) written[i.imm[0] + k] = true; continue; }
        if (i.dst != kNoReg) written[i.dst] = true;
    }
    return written;
}

VariableInfo variable_info(const Symbol& s) {
    VariableInfo v;
    v.name = s.name;
    Type element = s.type.element_type();
    v.gl_type = element.gl_enum();
    v.type_name = element.name();
    v.array_size = s.type.is_array() ? s.type.array_size : 0;
    v.components = element.components();
    v.location = s.layout_location;
    v.precision = s.precision;
    v.interpolation = s.interpolation == Interpolation::Default ? Interpolation::Smooth : s.interpolation;
    v.invariant = s.invariant;
    return v;
}

int first_slot(const std::vector<Slot>& slots, const std::string& name) {
    for (size_t i = 0; i < slots.size(); ++i) if (slots[i].name == name) return static_cast<int>(i);
    return -1;
}

bool any_slot(const std::vector<Slot>& slots, const std::string& name, const std::vector<bool>& flags) {
    for (const Slot& s : slots) if (s.name == name && flags[s.reg]) return true;
    return false;
}

// Rows a set of varyings occupies (GLSL ES 1.00 Appendix A.7 packing, simplified: vec4s and
// matrix columns take rows; vec3s take a row each leaving a column for floats; vec2s pair up).
int varying_rows(const std::vector<std::pair<int, int>>& shapes /* components per element, elements */) {
    int rows = 0, vec3 = 0, vec2 = 0, floats = 0;
    for (auto [components, elements] : shapes) {
        if (components >= 4) rows += elements * ((components + 3) / 4);
        else if (components == 3) vec3 += elements;
        else if (components == 2) vec2 += elements;
        else floats += elements;
    }
    rows += vec3;
    floats = std::max(0, floats - vec3);
    rows += (vec2 + 1) / 2;
    if (vec2 % 2) floats = std::max(0, floats - 2);
    rows += (floats + 3) / 4;
    return rows;
}

int uniform_vectors(const std::vector<UniformInfo>& uniforms) {
    int n = 0;
    for (const UniformInfo& u : uniforms) {
        if (!u.active || u.is_builtin) continue;
        int per = (u.stride + 3) / 4;
        n += per * u.size;
    }
    return n;
}

}  // namespace

CompileResult compile(const std::string& source, Stage stage, int webgl_version,
                      const std::set<std::string>* enabled_extensions) {
    CompileResult result;
    Diagnostics diagnostics;
    auto shader = std::make_shared<CompiledShader>();
    shader->stage = stage;
    try {
        PreprocessedSource pre = preprocess(source, stage, webgl_version, diagnostics, enabled_extensions);
        shader->version = pre.version;
        CheckedShader checked;
        checked.stage = stage;
        checked.version = pre.version;
        checked.webgl_version = webgl_version;
        checked.extensions = pre.extensions;
        if (diagnostics.ok()) checked.unit = parse(pre.tokens, pre.version, diagnostics);
        if (diagnostics.ok()) check(checked, diagnostics);
        if (diagnostics.ok() && !checked.main) diagnostics.error(0, "Missing main()");
        LoweredShader lowered;
        if (diagnostics.ok()) lowered = lower(checked, diagnostics);
        if (diagnostics.ok()) {
            IrProgram& program = lowered.program;
            program.fragment = stage == Stage::Fragment;
            optimize(program);
            ShaderReflection& r = shader->reflection;
            r.usage = lowered.usage;
            std::vector<bool> read = registers_read(program);
            std::vector<bool> written = registers_written(program);
            // Uniforms: built-ins first in the layout (gl_DepthRange), then user uniforms.
            int words = 0;
            std::vector<const Symbol*> uniform_symbols;
            for (const auto& [name, sym] : checked.builtin_variables) if (sym->storage == StorageQualifier::Uniform) uniform_symbols.push_back(sym);
            for (const Symbol* sym : checked.globals) if (sym->storage == StorageQualifier::Uniform) uniform_symbols.push_back(sym);
            for (const Symbol* sym : uniform_symbols) {
                int offset = lowered.uniform_offsets.at(sym);
                int start = offset;
                flatten_uniform(sym->name, sym->type, sym->precision, offset, sym->is_builtin, r.uniforms);
                std::string signature = sym->type.name() + (sym->type.is_struct() ? "#" + std::to_string(sym->type.struct_type->fields.size()) : "");
                shader->uniform_blocks.push_back({sym->name, start, offset - start, signature + "/" + std::to_string(static_cast<int>(sym->precision))});
                words = std::max(words, offset);
            }
            r.uniform_words = lowered.uniform_words;
            std::vector<bool> uniform_read = uniform_words_read(program, lowered.uniform_words);
            for (UniformInfo& u : r.uniforms)
                for (int k = 0; k < u.size * u.stride; ++k) if (uniform_read[u.offset + k]) u.active = true;
            for (const Symbol* sym : checked.globals) {
                VariableInfo v = variable_info(*sym);
                const bool vertex = stage == Stage::Vertex;
                if (sym->storage == StorageQualifier::Attribute || (vertex && sym->storage == StorageQualifier::In)) {
                    v.active = any_slot(program.inputs, sym->name, read);
                    v.first_slot = first_slot(program.inputs, sym->name);
                    r.attributes.push_back(v);
                } else if (sym->storage == StorageQualifier::Varying || (vertex && sym->storage == StorageQualifier::Out) ||
                           (!vertex && sym->storage == StorageQualifier::In)) {
                    if (vertex) {
                        v.active = any_slot(program.outputs, sym->name, written);
                        v.first_slot = first_slot(program.outputs, sym->name);
                    } else {
                        v.active = any_slot(program.inputs, sym->name, read);
                        v.first_slot = first_slot(program.inputs, sym->name);
                        if (v.active) r.varyings_read.push_back(sym->name);
                    }
                    r.varyings.push_back(v);
                } else if (!vertex && sym->storage == StorageQualifier::Out) {
                    v.active = any_slot(program.outputs, sym->name, written);
                    v.first_slot = first_slot(program.outputs, sym->name);
                    if (v.location < 0) v.location = 0;
                    r.outputs.push_back(v);
                }
            }
            if (stage == Stage::Fragment) {
                for (const char* name : {"gl_FragColor", "gl_FragData"}) {
                    auto it = checked.builtin_variables.find(name);
                    if (it == checked.builtin_variables.end()) continue;
                    VariableInfo v = variable_info(*it->second);
                    v.active = any_slot(program.outputs, name, written);
                    v.first_slot = first_slot(program.outputs, name);
                    v.location = 0;
                    if (v.active) r.outputs.push_back(v);
                }
                r.usage.frag_color_broadcast = checked.version == 100 && checked.extension_enabled("GL_EXT_draw_buffers") &&
                                               any_slot(program.outputs, "gl_FragColor", written);
                r.usage.writes_frag_depth = any_slot(program.outputs, "gl_FragDepth", written) || any_slot(program.outputs, "gl_FragDepthEXT", written);
                r.usage.reads_frag_coord = any_slot(program.inputs, "gl_FragCoord", read);
                r.usage.reads_front_facing = any_slot(program.inputs, "gl_FrontFacing", read);
                r.usage.reads_point_coord = any_slot(program.inputs, "gl_PointCoord", read);
                r.output_depends_only_on_uniforms = outputs_depend_only_on_uniforms(program);
            } else {
                r.usage.writes_point_size = any_slot(program.outputs, "gl_PointSize", written);
                r.output_depends_only_on_uniforms = outputs_depend_only_on_uniforms(program);
            }
            shader->program = std::move(program);
        }
    } catch (const WorkStopped&) {
        throw;   // the call stops (api/ reports it); not a compile error
    } catch (const std::bad_alloc&) {
        throw;   // no memory: OUT_OF_MEMORY for the call, the shader as it was (bindings/arguments.h)
    } catch (const std::exception& e) {
        diagnostics.error(0, std::string("internal compiler error: ") + e.what());
    }
    result.ok = diagnostics.ok();
    result.info_log = diagnostics.log;
    if (result.ok) result.shader = shader;
    return result;
}

LinkResult link(const CompiledShader& vs, const CompiledShader& fs, const LinkLimits& limits,
                const std::map<std::string, int>& bound_attribute_locations) {
    LinkResult result;
    std::string& log = result.info_log;
    auto error = [&](const std::string& m) { log += "ERROR: " + m + "\n"; };
    if (vs.stage != Stage::Vertex || fs.stage != Stage::Fragment) error("a program needs one vertex and one fragment shader");
    if (vs.version != fs.version) error("vertex and fragment shaders must use the same GLSL ES version");
    auto program = std::make_shared<LinkedProgram>();
    program->version = vs.version;
    program->vertex = vs.program;
    program->fragment = fs.program;
    ProgramReflection& r = program->reflection;
    const ShaderReflection& vr = vs.reflection;
    const ShaderReflection& fr = fs.reflection;

    // ---- varyings (ES 1.00 §4.3.5, ES 3.00 §4.3.4): fragment inputs it reads need a matching vertex output.
    std::vector<std::pair<int, int>> shapes;
    std::vector<Slot> vertex_outputs;    // gl_Position, gl_PointSize first, then linked varyings
    std::vector<Slot> fragment_inputs;   // linked varyings, then built-ins
    for (const Slot& s : vs.program.outputs)
        if (s.kind == SlotKind::Builtin) vertex_outputs.push_back(s);
    for (const VariableInfo& in : fr.varyings) {
        const VariableInfo* out = nullptr;
        for (const VariableInfo& v : vr.varyings) if (v.name == in.name) out = &v;
        if (!out) {
            if (in.active) error("Fragment shader input '" + in.name + "' is not declared (written) by the vertex shader");
            continue;
        }
        if (out->gl_type != in.gl_type || out->array_size != in.array_size) {
            error("Types of varying '" + in.name + "' differ between the vertex shader (" + out->type_name +
                  (out->array_size ? "[" + std::to_string(out->array_size) + "]" : "") + ") and the fragment shader (" + in.type_name +
                  (in.array_size ? "[" + std::to_string(in.array_size) + "]" : "") + ")");
            continue;
        }
        if (vs.version == 300 && out->interpolation != in.interpolation)
            error("Interpolation qualifiers of varying '" + in.name + "' differ between the shaders");
        if (vs.version == 100 && out->invariant != in.invariant)
            error("Invariance of varying '" + in.name + "' differs between the shaders");
        if (!in.active) continue;
        shapes.push_back({in.components, std::max(1, in.array_size)});
        LinkedVarying lv;
        lv.name = in.name;
        lv.components = in.components * std::max(1, in.array_size);
        lv.interpolation = in.interpolation;
        lv.vertex_slot = static_cast<int>(vertex_outputs.size());
        lv.fragment_slot = static_cast<int>(fragment_inputs.size());
        for (const Slot& s : vs.program.outputs) if (s.name == in.name) vertex_outputs.push_back(s);
        for (const Slot& s : fs.program.inputs) if (s.name == in.name) fragment_inputs.push_back(s);
        r.varyings.push_back(lv);
    }
    for (const Slot& s : fs.program.inputs)
        if (s.kind == SlotKind::Builtin) fragment_inputs.push_back(s);
    if (varying_rows(shapes) > limits.max_varying_vectors)
        error("Too many varyings (" + std::to_string(varying_rows(shapes)) + " vectors; the limit is " + std::to_string(limits.max_varying_vectors) + ")");
    program->vertex.outputs = vertex_outputs;
    program->fragment.inputs = fragment_inputs;
    // Vertex outputs the fragment shader does not read are dead now.
    optimize(program->vertex);

    // ---- uniforms: one buffer for both stages; a uniform in both must agree (ES 3.00 §4.3.5).
    std::map<std::string, std::pair<int, const CompiledShader::UniformBlock*>> blocks;  // name -> new offset
    int words = 0;
    auto place = [&](const CompiledShader& shader) {
        for (const auto& b : shader.uniform_blocks) {
            auto it = blocks.find(b.name);
            if (it != blocks.end()) {
                const auto* other = it->second.second;
                std::string type_a = other->signature.substr(0, other->signature.find('/'));
                std::string type_b = b.signature.substr(0, b.signature.find('/'));
                if (type_a != type_b || other->words != b.words) error("Types of uniform '" + b.name + "' differ between the shaders");
                else if (other->signature != b.signature) error("Precisions of uniform '" + b.name + "' differ between the shaders");
                continue;
            }
            blocks[b.name] = {words, &b};
            words += b.words;
        }
    };
    place(vs);
    place(fs);
    r.uniform_words = words;
    auto remap = [&](const CompiledShader& shader, IrProgram& p) {
        // old word -> new word, per block
        std::vector<int> map(static_cast<size_t>(shader.reflection.uniform_words), 0);
        for (const auto& b : shader.uniform_blocks) {
            int base = blocks[b.name].first;
            for (int k = 0; k < b.words; ++k) map[b.offset + k] = base + k;
        }
        for (Instruction& i : p.code)
            if ((i.op == Op::LoadUniform || i.op == Op::LoadUniformIndexed) && i.imm[0] < static_cast<int>(map.size())) i.imm[0] = map[i.imm[0]];
        return map;
    };
    std::vector<int> vmap = remap(vs, program->vertex);
    std::vector<int> fmap = remap(fs, program->fragment);
    std::vector<bool> vread = uniform_words_read(program->vertex, words);
    std::vector<bool> fread = uniform_words_read(program->fragment, words);
    std::set<std::string> seen;
    auto add_uniforms = [&](const ShaderReflection& sr, const std::vector<int>& map) {
        for (UniformInfo u : sr.uniforms) {
            if (!seen.insert(u.name).second) continue;
            u.offset = map[u.offset];
            u.active = false;
            for (int k = 0; k < u.size * u.stride; ++k) if (vread[u.offset + k] || fread[u.offset + k]) u.active = true;
            r.uniforms.push_back(u);
        }
    };
    add_uniforms(vr, vmap);
    add_uniforms(fr, fmap);
    if (uniform_vectors(vr.uniforms) > limits.max_vertex_uniform_vectors) error("Too many vertex shader uniforms");
    if (uniform_vectors(fr.uniforms) > limits.max_fragment_uniform_vectors) error("Too many fragment shader uniforms");
    auto sampler_count = [](const std::vector<UniformInfo>& us) {
        int n = 0;
        for (const UniformInfo& u : us) if (u.is_sampler && u.active) n += u.size;
        return n;
    };
    if (sampler_count(vr.uniforms) > limits.max_vertex_texture_image_units) error("Too many vertex shader samplers");
    if (sampler_count(fr.uniforms) > limits.max_texture_image_units) error("Too many fragment shader samplers");

    // ---- attributes: explicit locations, then bindAttribLocation, then the lowest free ones.
    std::vector<bool> used(static_cast<size_t>(std::max(limits.max_vertex_attribs, 1)), false);
    int attribute_slots = 0;
    r.attributes = vr.attributes;
    auto slots_of = [](const VariableInfo& a) { return a.gl_type >= 0x8B5A && a.gl_type <= 0x8B5C ? (a.gl_type - 0x8B5A + 2) : (a.gl_type >= 0x8B65 && a.gl_type <= 0x8B6A ? (a.gl_type <= 0x8B66 ? 2 : a.gl_type <= 0x8B68 ? 3 : 4) : 1); };
    for (VariableInfo& a : r.attributes) {
        if (!a.active) continue;
        attribute_slots += slots_of(a);
        auto bound = bound_attribute_locations.find(a.name);
        if (a.location < 0 && bound != bound_attribute_locations.end()) a.location = bound->second;
        if (a.location >= 0) {
            for (int k = 0; k < slots_of(a); ++k) {
                int loc = a.location + k;
                if (loc >= limits.max_vertex_attribs) { error("Attribute '" + a.name + "' location out of range"); break; }
                if (used[loc]) { error("Attribute '" + a.name + "' location " + std::to_string(loc) + " is already in use"); break; }
                used[loc] = true;
            }
        }
    }
    if (attribute_slots > limits.max_vertex_attribs) error("Too many attributes (" + std::to_string(attribute_slots) + ")");
    for (VariableInfo& a : r.attributes) {
        if (!a.active || a.location >= 0) continue;
        int need = slots_of(a);
        for (int loc = 0; loc + need <= limits.max_vertex_attribs; ++loc) {
            bool free = true;
            for (int k = 0; k < need; ++k) free = free && !used[loc + k];
            if (!free) continue;
            a.location = loc;
            for (int k = 0; k < need; ++k) used[loc + k] = true;
            break;
        }
    }
    r.outputs = fr.outputs;
    r.vertex_usage = vr.usage;
    r.fragment_usage = fr.usage;
    r.fragment_depends_only_on_uniforms = outputs_depend_only_on_uniforms(program->fragment);
    result.ok = log.empty();
    if (result.ok) result.program = program;
    return result;
}

}  // namespace softgl::glsl
