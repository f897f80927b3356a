// Testing bindings for softgl's GLSL compiler and executor: conversions only.
#include <chrono>
#include <cstring>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "softgl/glsl/compiler.h"
#include "softgl/glsl/executor.h"
#include "testing/test_sampler.h"

namespace py = pybind11;
namespace glsl = softgl::glsl;
using softgl::SimdLevel;
using softgl::best_simd_level;

namespace {

glsl::Stage stage_from(const std::string& s) {
    if (s == "vertex") return glsl::Stage::Vertex;
    if (s == "fragment") return glsl::Stage::Fragment;
    throw py::value_error("stage must be 'vertex' or 'fragment'");
}

const char* precision_name(glsl::Precision p) {
    switch (p) {
    case glsl::Precision::Low: return "lowp";
    case glsl::Precision::Medium: return "mediump";
    case glsl::Precision::High: return "highp";
    default: return "";
    }
}

py::dict variable_dict(const glsl::VariableInfo& v) {
    py::dict d;
    d["name"] = v.name;
    d["type"] = v.gl_type;
    d["type_name"] = v.type_name;
    d["array_size"] = v.array_size;
    d["size"] = v.array_size ? v.array_size : 1;
    d["location"] = v.location;
    d["precision"] = precision_name(v.precision);
    d["interpolation"] = v.interpolation == glsl::Interpolation::Flat ? "flat" : "smooth";
    d["invariant"] = v.invariant;
    d["active"] = v.active;
    return d;
}

py::dict uniform_dict(const glsl::UniformInfo& u) {
    py::dict d;
    d["name"] = u.name;
    d["base_name"] = u.base_name;
    d["type"] = u.gl_type;
    d["type_name"] = u.type_name;
    d["size"] = u.size;
    d["offset"] = u.offset;
    d["stride"] = u.stride;
    d["precision"] = precision_name(u.precision);
    d["is_sampler"] = u.is_sampler;
    d["builtin"] = u.is_builtin;
    d["active"] = u.active;
    return d;
}

py::dict usage_dict(const glsl::ShaderUsage& u) {
    py::dict d;
    d["may_discard"] = u.may_discard;
    d["writes_frag_depth"] = u.writes_frag_depth;
    d["uses_derivatives"] = u.uses_derivatives;
    d["reads_frag_coord"] = u.reads_frag_coord;
    d["reads_front_facing"] = u.reads_front_facing;
    d["reads_point_coord"] = u.reads_point_coord;
    d["writes_point_size"] = u.writes_point_size;
    return d;
}

py::dict reflection_dict(const glsl::CompiledShader& s) {
    const glsl::ShaderReflection& r = s.reflection;
    py::dict d;
    d["version"] = s.version;
    py::list attributes, uniforms, varyings, outputs;
    for (const auto& v : r.attributes) attributes.append(variable_dict(v));
    for (const auto& u : r.uniforms) uniforms.append(uniform_dict(u));
    for (const auto& v : r.varyings) varyings.append(variable_dict(v));
    for (const auto& v : r.outputs) outputs.append(variable_dict(v));
    d["attributes"] = attributes;
    d["uniforms"] = uniforms;
    d["varyings"] = varyings;
    d["outputs"] = outputs;
    d["varyings_read"] = r.varyings_read;
    d.attr("update")(usage_dict(r.usage));
    d["output_depends_only_on_uniforms"] = r.output_depends_only_on_uniforms;
    d["uniform_words"] = r.uniform_words;
    d["instructions"] = s.program.code.size();
    d["ir"] = s.program.dump();
    return d;
}

py::dict program_dict(const glsl::LinkedProgram& p) {
    const glsl::ProgramReflection& r = p.reflection;
    py::dict d;
    py::list attributes, uniforms, varyings, outputs;
    for (const auto& v : r.attributes) attributes.append(variable_dict(v));
    for (const auto& u : r.uniforms) uniforms.append(uniform_dict(u));
    for (const auto& v : r.varyings) {
        py::dict x;
        x["name"] = v.name;
        x["components"] = v.components;
        x["interpolation"] = v.interpolation == glsl::Interpolation::Flat ? "flat" : "smooth";
        x["vertex_slot"] = v.vertex_slot;
        x["fragment_slot"] = v.fragment_slot;
        varyings.append(x);
    }
    for (const auto& v : r.outputs) outputs.append(variable_dict(v));
    d["attributes"] = attributes;
    d["uniforms"] = uniforms;
    d["varyings"] = varyings;
    d["outputs"] = outputs;
    d["vertex"] = usage_dict(r.vertex_usage);
    d["fragment"] = usage_dict(r.fragment_usage);
    d["fragment_depends_only_on_uniforms"] = r.fragment_depends_only_on_uniforms;
    d["uniform_words"] = r.uniform_words;
    d["vertex_instructions"] = p.vertex.code.size();
    d["fragment_instructions"] = p.fragment.code.size();
    return d;
}

py::tuple compile_py(const std::string& source, const std::string& stage, int version) {
    glsl::CompileResult r;
    {
        py::gil_scoped_release release;
        r = glsl::compile(source, stage_from(stage), version);
    }
    return py::make_tuple(r.ok, r.info_log, r.ok ? py::object(reflection_dict(*r.shader)) : py::object(py::none()));
}

py::tuple link_py(const std::string& vertex, const std::string& fragment, int version, py::dict limits,
                  std::map<std::string, int> bound) {
    glsl::CompileResult vs = glsl::compile(vertex, glsl::Stage::Vertex, version);
    glsl::CompileResult fs = glsl::compile(fragment, glsl::Stage::Fragment, version);
    if (!vs.ok || !fs.ok) return py::make_tuple(false, vs.info_log + fs.info_log, py::none());
    glsl::LinkLimits l;
    for (auto [key, value] : limits) {
        std::string k = py::str(key);
        int v = value.cast<int>();
        if (k == "max_vertex_attribs") l.max_vertex_attribs = v;
        else if (k == "max_varying_vectors") l.max_varying_vectors = v;
        else if (k == "max_vertex_uniform_vectors") l.max_vertex_uniform_vectors = v;
        else if (k == "max_fragment_uniform_vectors") l.max_fragment_uniform_vectors = v;
        else if (k == "max_texture_image_units") l.max_texture_image_units = v;
        else if (k == "max_vertex_texture_image_units") l.max_vertex_texture_image_units = v;
        else throw py::key_error(k);
    }
    glsl::LinkResult r = glsl::link(*vs.shader, *fs.shader, l, bound);
    return py::make_tuple(r.ok, r.info_log, r.ok ? py::object(program_dict(*r.program)) : py::object(py::none()));
}

// The executor's builds by name, in order (core/simd.h: "portable" serves Scalar and SSE2); those
// up to best_simd_level() run on this CPU.
const char* const kExecutorLevelNames[] = {"portable", "avx2", "avx512"};
const SimdLevel kExecutorLevels[] = {SimdLevel::SSE2, SimdLevel::AVX2, SimdLevel::AVX512};
int executor_level_count() { return best_simd_level() >= SimdLevel::AVX512 ? 3 : best_simd_level() >= SimdLevel::AVX2 ? 2 : 1; }

SimdLevel simd_level_named(const std::string& name) {
    for (int k = 0; k < executor_level_count(); ++k)
        if (name == kExecutorLevelNames[k]) return kExecutorLevels[k];
    throw py::value_error("simd '" + name + "' is not available (see glsl_simd_levels())");
}

// Runs one stage of `source` over `lanes` lanes. inputs: name -> array (lanes,) or (lanes, n);
// uniforms: WebGL uniform name (or base name) -> values; textures: unit -> (h, w, 4) float array.
py::dict run_py(const std::string& source, const std::string& stage, int version, py::dict inputs, py::dict uniforms,
                int lanes, py::dict textures, int batch, int repeat, std::string simd, bool hoist) {
    const SimdLevel level = simd.empty() ? best_simd_level() : simd_level_named(simd);
    glsl::CompileResult compiled = glsl::compile(source, stage_from(stage), version);
    if (!compiled.ok) throw py::value_error("compile failed:\n" + compiled.info_log);
    const glsl::CompiledShader& shader = *compiled.shader;
    const glsl::IrProgram& program = shader.program;
    using glsl::Scalar;
    // Uniform buffer
    std::vector<Scalar> buffer(static_cast<size_t>(shader.reflection.uniform_words) + 1, Scalar{});
    for (auto [key, value] : uniforms) {
        std::string name = py::str(key);
        const glsl::UniformInfo* info = nullptr;
        for (const auto& u : shader.reflection.uniforms) if (u.name == name || u.base_name == name) info = &u;
        if (!info) continue;  // inactive or unknown: ignored, like WebGL with a null location
        bool is_float = info->type_name.find("vec") == 0 || info->type_name.find("mat") == 0 || info->type_name == "float";
        int count = info->size * info->stride;
        if (is_float) {
            auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
            for (int k = 0; k < count && k < a.size(); ++k) buffer[info->offset + k].f = a.data()[k];
        } else {
            auto a = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(value);
            for (int k = 0; k < count && k < a.size(); ++k) buffer[info->offset + k].u = static_cast<uint32_t>(a.data()[k]);
        }
    }
    // Inputs: one lane array per slot
    std::vector<std::vector<Scalar>> input_data(program.inputs.size());
    std::vector<const Scalar*> input_ptrs(program.inputs.size(), nullptr);
    std::map<std::string, int> per_element;
    for (const auto& s : program.inputs) per_element[s.name] = std::max(per_element[s.name], s.component + 1);
    for (size_t i = 0; i < program.inputs.size(); ++i) {
        const glsl::Slot& s = program.inputs[i];
        if (!inputs.contains(s.name)) continue;
        py::object value = inputs[py::str(s.name)];
        int column = s.element * per_element[s.name] + s.component;
        input_data[i].assign(lanes, Scalar{});
        if (s.base == glsl::BaseType::Float) {
            auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
            py::ssize_t columns = a.ndim() >= 2 ? a.size() / a.shape(0) : 1;
            if (a.shape(0) != lanes) throw py::value_error("input '" + s.name + "' must have one row per lane");
            if (column >= columns) throw py::value_error("input '" + s.name + "' has too few components");
            for (int l = 0; l < lanes; ++l) input_data[i][l].f = a.data()[l * columns + column];
        } else {
            auto a = py::array_t<int32_t, py::array::c_style | py::array::forcecast>::ensure(value);
            py::ssize_t columns = a.ndim() >= 2 ? a.size() / a.shape(0) : 1;
            if (a.shape(0) != lanes) throw py::value_error("input '" + s.name + "' must have one row per lane");
            if (column >= columns) throw py::value_error("input '" + s.name + "' has too few components");
            for (int l = 0; l < lanes; ++l) input_data[i][l].i = a.data()[l * columns + column];
        }
        input_ptrs[i] = input_data[i].data();
    }
    std::vector<std::vector<Scalar>> output_data(program.outputs.size(), std::vector<Scalar>(lanes));
    std::vector<Scalar*> output_ptrs;
    for (auto& o : output_data) output_ptrs.push_back(o.data());
    std::vector<uint8_t> discarded(lanes, 0);
    softgl::testing::TestSampler sampler;
    for (auto [key, value] : textures) {
        auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
        if (a.ndim() != 3 || a.shape(2) != 4) throw py::value_error("textures must be (h, w, 4) arrays");
        softgl::testing::TestImage img;
        img.height = static_cast<int>(a.shape(0));
        img.width = static_cast<int>(a.shape(1));
        img.rgba.assign(a.data(), a.data() + a.size());
        sampler.units[key.cast<int>()] = img;
    }
    glsl::StageRun run;
    run.lane_count = lanes;
    run.inputs = input_ptrs.data();
    run.outputs = output_ptrs.data();
    run.uniforms = buffer.data();
    run.sampler = &sampler;
    run.discarded = discarded.data();
    double seconds = 0;
    {
        py::gil_scoped_release release;
        glsl::Executor executor(program, batch, hoist);
        executor.set_simd_level(level);
        auto start = std::chrono::steady_clock::now();
        for (int k = 0; k < std::max(repeat, 1); ++k) executor.run(run);
        seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    // Outputs: name -> (lanes, components) array
    py::dict result;
    std::map<std::string, std::vector<size_t>> by_name;
    for (size_t i = 0; i < program.outputs.size(); ++i) by_name[program.outputs[i].name].push_back(i);
    for (auto& [name, slots] : by_name) {
        bool is_float = program.outputs[slots[0]].base == glsl::BaseType::Float;
        py::ssize_t n = static_cast<py::ssize_t>(slots.size());
        if (is_float) {
            py::array_t<float> a({static_cast<py::ssize_t>(lanes), n});
            auto m = a.mutable_unchecked<2>();
            for (int l = 0; l < lanes; ++l)
                for (py::ssize_t k = 0; k < n; ++k) m(l, k) = output_data[slots[k]][l].f;
            result[py::str(name)] = a;
        } else {
            py::array_t<int32_t> a({static_cast<py::ssize_t>(lanes), n});
            auto m = a.mutable_unchecked<2>();
            for (int l = 0; l < lanes; ++l)
                for (py::ssize_t k = 0; k < n; ++k) m(l, k) = output_data[slots[k]][l].i;
            result[py::str(name)] = a;
        }
    }
    py::array_t<bool> killed(lanes);
    for (int l = 0; l < lanes; ++l) killed.mutable_data()[l] = discarded[l] != 0;
    result["discarded"] = killed;
    result["seconds"] = seconds / std::max(repeat, 1);
    return result;
}

}  // namespace

void bind_glsl(py::module_& m) {
    m.def("glsl_compile", &compile_py, py::arg("source"), py::arg("stage"), py::arg("version") = 2,
          "Compile GLSL ES source -> (ok, info_log, reflection dict or None)");
    m.def("glsl_ir", [](const std::string& source, const std::string& stage, int version) {
        glsl::CompileResult r = glsl::compile(source, stage_from(stage), version);
        if (!r.ok) throw py::value_error(r.info_log);
        return r.shader->program.dump();
    }, py::arg("source"), py::arg("stage"), py::arg("version") = 2,
          "The optimised IR of a shader as a readable listing (for tests and profiling)");
    m.def("glsl_executor_ops", [](const std::string& source, const std::string& stage, int version) {
        glsl::CompileResult r = glsl::compile(source, stage_from(stage), version);
        if (!r.ok) throw py::value_error(r.info_log);
        glsl::Executor executor(r.shader->program);
        std::vector<std::string> ops;
        for (const glsl::Instruction& i : executor.code()) ops.push_back(glsl::op_name(i.op));
        return ops;
    }, py::arg("source"), py::arg("stage"), py::arg("version") = 2,
          "The op names of the code the executor runs for a shader, its fused instructions included (tests)");
    m.def("glsl_executor_prologue", [](const std::string& source, const std::string& stage, int version) {
        glsl::CompileResult r = glsl::compile(source, stage_from(stage), version);
        if (!r.ok) throw py::value_error(r.info_log);
        glsl::Executor executor(r.shader->program);
        std::vector<std::string> ops;
        for (size_t k = 0; k < executor.prologue_size(); ++k) ops.push_back(glsl::op_name(executor.code()[k].op));
        return ops;
    }, py::arg("source"), py::arg("stage"), py::arg("version") = 2,
          "The op names of the executor's prologue, run once before the lanes: uniform loads and hoisted values (tests)");
    m.def("glsl_link", &link_py, py::arg("vertex"), py::arg("fragment"), py::arg("version") = 2,
          py::arg("limits") = py::dict(), py::arg("bound_attributes") = std::map<std::string, int>(),
          "Compile and link a vertex/fragment pair -> (ok, info_log, program reflection or None)");
    m.def("glsl_run", &run_py, py::arg("source"), py::arg("stage"), py::arg("version") = 2, py::arg("inputs") = py::dict(),
          py::arg("uniforms") = py::dict(), py::arg("lanes") = 4, py::arg("textures") = py::dict(), py::arg("batch") = 128,
          py::arg("repeat") = 1, py::arg("simd") = "", py::arg("hoist") = true,
          "Run one shader stage over `lanes` lanes (fragment lanes are 2x2 quads) -> dict of output arrays; "
          "simd: '' (the best the CPU has) or one of glsl_simd_levels(); hoist: values of uniforms and "
          "constants only computed once before the lanes (Executor)");
    m.def("glsl_simd_levels", [] {
        std::vector<std::string> levels;
        for (int k = 0; k < executor_level_count(); ++k) levels.push_back(kExecutorLevelNames[k]);
        return levels;
    }, "The executor's SIMD levels this CPU can run: 'portable', 'avx2', 'avx512'");
}
