#include "softgl/glsl/checker.h"
#include "softgl/core/work_budget.h"

#include <cmath>
#include <cstring>
#include <functional>
#include <set>
#include <unordered_map>

#include "softgl/glsl/builtin_math.h"
#include "softgl/glsl/builtins.h"
#include "softgl/glsl/parser.h"

namespace softgl::glsl {
namespace {

std::string precision_name(Precision p) {
    return p == Precision::Low ? "lowp" : p == Precision::Medium ? "mediump" : p == Precision::High ? "highp" : "";
}

Scalar make_float(float f) { Scalar s; s.f = f; return s; }
Scalar make_int(int32_t i) { Scalar s; s.i = i; return s; }
Scalar make_uint(uint32_t u) { Scalar s; s.u = u; return s; }

// Converts one constant scalar between base types (constructor semantics, ES 3.00 §5.4.1).
Scalar convert_scalar(Scalar v, BaseType from, BaseType to) {
    if (from == to) return v;
    double x = 0;
    switch (from) {
    case BaseType::Float: x = v.f; break;
    case BaseType::Int: x = v.i; break;
    case BaseType::Uint: x = v.u; break;
    case BaseType::Bool: x = v.i != 0; break;
    default: break;
    }
    switch (to) {
    case BaseType::Float: return make_float(from == BaseType::Float ? v.f : static_cast<float>(x));
    case BaseType::Bool: return make_int(x != 0);
    case BaseType::Int:
        if (from == BaseType::Uint) return make_int(static_cast<int32_t>(v.u));
        if (from == BaseType::Float) return make_int(f_to_i(v.f));
        return make_int(static_cast<int32_t>(x));
    case BaseType::Uint:
        if (from == BaseType::Int) return make_uint(static_cast<uint32_t>(v.i));
        if (from == BaseType::Float) return make_uint(f_to_u(v.f));  // negative float -> uint is undefined; clamp
        return make_uint(static_cast<uint32_t>(x));
    default: return v;
    }
}

constexpr int64_t kMaxArraySize = 65536;  // elements; larger arrays are rejected
// WebGL 1.0, "Maximum Nesting of Structures in GLSL Shaders": 4 levels must work, more may be
// rejected, and browsers (ANGLE) do. Types are walked recursively through their fields.
constexpr int kMaxStructNesting = 4;
// Scalars in one value of a type (a struct, or an array of them): lowering gives each its own
// register, and there are at most 2^22 of those.
constexpr int64_t kMaxTypeComponents = int64_t(1) << 22;

// Scalars of large (over 16 scalars) const variables' values copied into their uses, per shader.
constexpr size_t kMaxCopiedConstants = size_t(1) << 22;

// Scalars in one value of t, in 64 bits (an array of a large struct overflows int).
int64_t components64(const Type& t) { return int64_t(t.element_components()) * std::max(1, t.array_size); }

struct Scope {
    std::unordered_map<std::string, Symbol*> variables;
    std::unordered_map<std::string, std::shared_ptr<const StructType>> structs;
    std::unordered_map<std::string, Precision> default_precision;  // "float", "int", "sampler2D", ...
    bool is_function_scope = false;
};

class Checker {
public:
    Checker(CheckedShader& shader, Diagnostics& diagnostics) : s_(shader), d_(diagnostics), version_(shader.version) {}

    void run() {
        scopes_.emplace_back();  // built-in scope
        declare_builtins();
        scopes_.emplace_back();  // global scope
        for (ExternalDecl& ext : s_.unit.decls) external(ext);
        // ES 3.00 §4.3.4 / link: functions called but never defined are link errors; main too.
        for (auto& [name, list] : functions_) {
            for (FunctionDef* f : list) {
                if (!f->definition && f->body == nullptr) {
                    // A prototype without a body is only an error if it is called (reported at link).
                }
            }
        }
        check_fragment_outputs();
        check_recursion();
    }

private:
    CheckedShader& s_;
    Diagnostics& d_;
    int version_;
    std::vector<Scope> scopes_;
    std::unordered_map<std::string, std::vector<FunctionDef*>> functions_;
    FunctionDef* current_function_ = nullptr;
    // The static call graph: the user functions each definition calls (prototypes included).
    std::unordered_map<const FunctionDef*, std::vector<FunctionDef*>> calls_;
    int loop_depth_ = 0;
    size_t copied_constants_ = 0;  // scalars of large const values copied into their uses
    int switch_depth_ = 0;
    int next_struct_id_ = 1;
    bool wrote_frag_color_ = false;
    bool wrote_frag_data_ = false;
    int frag_color_line_ = 0;
    // Loop indices of ES 1.00 Appendix A for-loops (WebGL 1): may not be assigned in the body.
    std::vector<Symbol*> loop_indices_;

    bool is_vertex() const { return s_.stage == Stage::Vertex; }
    bool is_fragment() const { return s_.stage == Stage::Fragment; }
    bool es3() const { return version_ == 300; }

    void error(int line, const std::string& m) { d_.error(line, m); }

    // ---------------------------------------------------------------- symbols
    Symbol* new_symbol(const std::string& name, const Type& type) {
        s_.symbols.emplace_back();
        Symbol* sym = &s_.symbols.back();
        sym->name = name;
        sym->type = type;
        sym->id = static_cast<int>(s_.symbols.size());
        return sym;
    }

    Symbol* lookup_variable(const std::string& name) {
        for (auto it = scopes_.rbegin(); it != scopes_.rend(); ++it) {
            auto f = it->variables.find(name);
            if (f != it->variables.end()) return f->second;
        }
        return nullptr;
    }
    std::shared_ptr<const StructType> lookup_struct(const std::string& name) {
        for (auto it = scopes_.rbegin(); it != scopes_.rend(); ++it) {
            auto f = it->structs.find(name);
            if (f != it->structs.end()) return f->second;
        }
        return nullptr;
    }
    bool name_in_current_scope(const std::string& name) {
        Scope& sc = scopes_.back();
        if (sc.variables.count(name) || sc.structs.count(name)) return true;
        if (scopes_.size() == 2 && functions_.count(name)) return true;  // global scope: functions too
        // ES 3.00 §4.2.2: a function's parameters and its body's top level share one scope.
        if (scopes_.size() >= 2 && !sc.is_function_scope && scopes_[scopes_.size() - 2].is_function_scope &&
            body_shares_parameter_scope_ && scopes_[scopes_.size() - 2].variables.count(name))
            return true;
        return false;
    }
    bool body_shares_parameter_scope_ = false;

    void check_identifier_name(const std::string& name, int line) {
        if (name.compare(0, 3, "gl_") == 0) error(line, "'" + name + "' : identifiers starting with \"gl_\" are reserved");
        else if (name.compare(0, 6, "webgl_") == 0 || name.compare(0, 7, "_webgl_") == 0)
            error(line, "'" + name + "' : identifiers starting with \"webgl_\" are reserved");
        else if (es3() && name.find("__") != std::string::npos)
            error(line, "'" + name + "' : identifiers containing two consecutive underscores are reserved");
        else if (name.size() > 1024) error(line, "'" + name.substr(0, 32) + "...' : identifier too long");
        else if (s_.webgl_version == 1 && name.size() > 256) error(line, "identifier too long (WebGL 1 allows 256 characters)");
    }

    void declare_variable(Symbol* sym, int line) {
        if (name_in_current_scope(sym->name)) {
            error(line, "'" + sym->name + "' : redefinition");
            return;
        }
        scopes_.back().variables[sym->name] = sym;
    }

    Precision default_precision(const std::string& type_name) {
        for (auto it = scopes_.rbegin(); it != scopes_.rend(); ++it) {
            auto f = it->default_precision.find(type_name);
            if (f != it->default_precision.end()) return f->second;
        }
        return Precision::None;
    }

    // The precision-relevant type name of t ("float" for float vectors/matrices, "int" for int/uint).
    static std::string precision_type_name(const Type& t) {
        if (t.base == BaseType::Float) return "float";
        if (t.base == BaseType::Int || t.base == BaseType::Uint) return "int";
        if (t.base == BaseType::Sampler) return t.element_type().name();
        return "";
    }

    // ES 3.00 §4.5.4: a declaration without a precision qualifier takes the default in scope;
    // the fragment language has no default for float, so omitting one is an error.
    Precision resolve_precision(const Type& t, Precision written, int line, const std::string& what) {
        if (t.base == BaseType::Struct || t.base == BaseType::Bool || t.base == BaseType::Void || t.is_error()) return Precision::None;
        if (written != Precision::None) return written;
        std::string n = precision_type_name(t);
        Precision p = default_precision(n);
        if (p == Precision::None) {
            error(line, "'" + what + "' : No precision specified for (" + n + ")");
            return Precision::High;
        }
        return p;
    }

    void declare_builtins() {
        Scope& sc = scopes_.back();
        // ES 3.00 §4.5.4 predeclared default precisions.
        if (is_vertex()) {
            sc.default_precision["float"] = Precision::High;
            sc.default_precision["int"] = Precision::High;
        } else {
            sc.default_precision["int"] = Precision::Medium;
        }
        sc.default_precision["sampler2D"] = Precision::Low;
        sc.default_precision["samplerCube"] = Precision::Low;

        auto var = [&](const char* name, Type type, StorageQualifier storage, Precision p) {
            Symbol* sym = new_symbol(name, type);
            sym->storage = storage;
            sym->precision = p;
            sym->is_builtin = true;
            sym->is_global = true;
            sc.variables[name] = sym;
            s_.builtin_variables[name] = sym;
            return sym;
        };
        const Type vec4 = Type::vector(BaseType::Float, 4), vec2 = Type::vector(BaseType::Float, 2);
        const Type flt = Type::scalar(BaseType::Float), integer = Type::scalar(BaseType::Int);
        BuiltinConstants limits;
        auto constant = [&](const char* name, int value) {
            Symbol* sym = var(name, integer, StorageQualifier::Const, Precision::Medium);
            sym->has_constant_value = true;
            sym->constant_value = {make_int(value)};
        };
        if (is_vertex()) {
            var("gl_Position", vec4, StorageQualifier::Out, Precision::High);
            var("gl_PointSize", flt, StorageQualifier::Out, Precision::Medium);
            if (es3()) {
                var("gl_VertexID", integer, StorageQualifier::In, Precision::High);
                var("gl_InstanceID", integer, StorageQualifier::In, Precision::High);
            }
        } else {
            var("gl_FragCoord", vec4, StorageQualifier::In, Precision::Medium);
            var("gl_FrontFacing", Type::scalar(BaseType::Bool), StorageQualifier::In, Precision::None);
            var("gl_PointCoord", vec2, StorageQualifier::In, Precision::Medium);
            if (!es3()) {
                var("gl_FragColor", vec4, StorageQualifier::Out, Precision::Medium);
                Type data = vec4;
                data.array_size = s_.extension_enabled("GL_EXT_draw_buffers") ? limits.max_draw_buffers : 1;
                var("gl_FragData", data, StorageQualifier::Out, Precision::Medium);
                if (s_.extension_enabled("GL_EXT_frag_depth")) var("gl_FragDepthEXT", flt, StorageQualifier::Out, Precision::High);
            } else {
                var("gl_FragDepth", flt, StorageQualifier::Out, Precision::High);
            }
        }
        // gl_DepthRange (ES 3.00 §7.5), a built-in uniform struct.
        {
            s_.struct_types.emplace_back();
            StructType& st = s_.struct_types.back();
            st.name = "gl_DepthRangeParameters";
            st.id = next_struct_id_++;
            for (const char* f : {"near", "far", "diff"}) st.fields.push_back({f, flt, Precision::High});
            std::shared_ptr<const StructType> ptr(&st, [](const StructType*) {});
            Type t = Type::scalar(BaseType::Struct);
            t.struct_type = ptr;
            var("gl_DepthRange", t, StorageQualifier::Uniform, Precision::None);
        }
        constant("gl_MaxVertexAttribs", limits.max_vertex_attribs);
        constant("gl_MaxVertexUniformVectors", limits.max_vertex_uniform_vectors);
        constant("gl_MaxVertexTextureImageUnits", limits.max_vertex_texture_image_units);
        constant("gl_MaxCombinedTextureImageUnits", limits.max_combined_texture_image_units);
        constant("gl_MaxTextureImageUnits", limits.max_texture_image_units);
        constant("gl_MaxFragmentUniformVectors", limits.max_fragment_uniform_vectors);
        if (es3()) {
            constant("gl_MaxVertexOutputVectors", limits.max_vertex_output_vectors);
            constant("gl_MaxFragmentInputVectors", limits.max_fragment_input_vectors);
            constant("gl_MaxDrawBuffers", limits.max_draw_buffers);
            constant("gl_MinProgramTexelOffset", limits.min_program_texel_offset);
            constant("gl_MaxProgramTexelOffset", limits.max_program_texel_offset);
        } else {
            constant("gl_MaxVaryingVectors", 8);
            constant("gl_MaxDrawBuffers", s_.extension_enabled("GL_EXT_draw_buffers") ? limits.max_draw_buffers : 1);
        }
    }

    // ---------------------------------------------------------------- types
    Type resolve_type(TypeSpec& spec) {
        Type t;
        if (spec.struct_decl) {
            t = Type::scalar(BaseType::Struct);
            t.struct_type = declare_struct(*spec.struct_decl);
            if (!t.struct_type) return Type::error();
        } else if (builtin_type_from_name(spec.type_name, version_, t)) {
        } else if (auto st = lookup_struct(spec.type_name)) {
            t = Type::scalar(BaseType::Struct);
            t.struct_type = st;
        } else {
            error(spec.line, "'" + spec.type_name + "' : unknown type");
            return Type::error();
        }
        if (spec.is_array) {
            if (!es3()) {
                error(spec.line, "'" + t.name() + "' : array type syntax requires GLSL ES 3.00");
                return Type::error();
            }
            t.array_size = spec.array_size ? array_size(*spec.array_size) : -1;
            if (!fits(t, spec.line, t.name())) return Type::error();
        }
        return t;
    }

    // Reports a type whose values have more than kMaxTypeComponents scalars (arrays of structs).
    bool fits(const Type& t, int line, const std::string& what) {
        if (components64(t) <= kMaxTypeComponents) return true;
        error(line, "'" + what + "' : type too large (" + std::to_string(components64(t)) + " scalars; the limit is " +
                        std::to_string(kMaxTypeComponents) + ")");
        return false;
    }

    int array_size(Expr& e) {
        expression(e);
        if (e.type.is_error()) return 1;
        if (!e.is_constant || e.constant.empty() || !(e.type == Type::scalar(BaseType::Int) || e.type == Type::scalar(BaseType::Uint))) {
            error(e.line, "array size must be a constant integer expression");
            return 1;
        }
        // A decimal literal 2147483648 has the bit pattern of -2^31 as an int (ES 3.00 §4.1.3).
        if (e.kind == ExprKind::IntLiteral && e.literal.u > 0x7fffffffu) {
            error(e.line, "'" + std::to_string(e.literal.u) + "' : array size too large (out of the range of int)");
            return 1;
        }
        int64_t v = e.type.base == BaseType::Int ? e.constant[0].i : static_cast<int64_t>(e.constant[0].u);
        if (v <= 0) {
            error(e.line, "array size must be greater than zero (it is " + std::to_string(v) + ")");
            return 1;
        }
        if (v > kMaxArraySize) {
            error(e.line, "array size too large (" + std::to_string(v) + "; the limit is " + std::to_string(kMaxArraySize) + ")");
            return 1;
        }
        return static_cast<int>(v);
    }

    std::shared_ptr<const StructType> declare_struct(StructDecl& decl) {
        if (decl.resolved) return decl.resolved;
        s_.struct_types.emplace_back();
        StructType& st = s_.struct_types.back();
        st.name = decl.name;
        st.id = next_struct_id_++;
        std::set<std::string> names;
        for (StructDecl::Member& m : decl.members) {
            if (m.type.storage != StorageQualifier::None || m.type.invariant || m.type.interpolation != Interpolation::Default || m.type.layout_location >= 0)
                error(m.line, "'" + (m.names.empty() ? std::string() : m.names[0].name) + "' : struct members cannot have qualifiers other than precision");
            if (m.type.struct_decl && !es3() && false) {}
            if (m.type.struct_decl && m.type.struct_decl->name.empty() == false && false) {}
            if (m.type.struct_decl) {
                // ES 3.00 §4.1.8: embedded struct definitions are not allowed.
                error(m.line, "embedded struct definitions are not allowed");
            }
            Type base = resolve_type(m.type);
            if (base.is_error()) continue;
            if (base.is_void()) { error(m.line, "struct members cannot be void"); continue; }
            for (VarDecl& v : m.names) {
                Type ft = base;
                if (v.is_array) {
                    if (ft.is_array()) { error(v.line, "'" + v.name + "' : arrays of arrays are not allowed"); continue; }
                    if (!v.array_size) { error(v.line, "'" + v.name + "' : struct member arrays must have a size"); continue; }
                    ft.array_size = array_size(*v.array_size);
                    if (!fits(ft, v.line, v.name)) continue;
                }
                if (ft.array_size < 0) { error(v.line, "'" + v.name + "' : struct member arrays must have a size"); continue; }
                check_identifier_name(v.name, v.line);
                if (!names.insert(v.name).second) { error(v.line, "'" + v.name + "' : duplicate field name in structure"); continue; }
                if (ft.is_sampler() && !false) {}
                st.fields.push_back({v.name, ft, m.type.precision});
            }
        }
        if (st.fields.empty()) error(decl.line, "'" + decl.name + "' : a structure must have at least one member");
        int64_t components = 0;
        for (const StructField& f : st.fields) {
            if (f.type.is_struct()) st.nesting = std::max(st.nesting, f.type.struct_type->nesting + 1);
            components = std::min(components + components64(f.type), kMaxTypeComponents + 1);
        }
        const std::string what = decl.name.empty() ? std::string("struct") : decl.name;
        if (st.nesting > kMaxStructNesting) {
            error(decl.line, "'" + what + "' : structures nested " + std::to_string(st.nesting) + " levels deep (the limit is " +
                                 std::to_string(kMaxStructNesting) + ")");
            return nullptr;
        }
        if (components > kMaxTypeComponents) {
            error(decl.line, "'" + what + "' : structure too large (the limit is " + std::to_string(kMaxTypeComponents) + " scalars)");
            return nullptr;
        }
        std::shared_ptr<const StructType> ptr(&st, [](const StructType*) {});
        decl.resolved = ptr;
        if (!decl.name.empty()) {
            check_identifier_name(decl.name, decl.line);
            if (name_in_current_scope(decl.name)) error(decl.line, "'" + decl.name + "' : redefinition");
            else scopes_.back().structs[decl.name] = ptr;
        }
        return ptr;
    }

    // ---------------------------------------------------------------- declarations
    void external(ExternalDecl& ext) {
        switch (ext.kind) {
        case ExternalDecl::Precision: precision_statement(ext.precision, ext.precision_type, ext.line); break;
        case ExternalDecl::Invariant:
            for (const std::string& name : ext.invariant_names) {
                Symbol* sym = lookup_variable(name);
                bool ok = sym && ((is_vertex() && (sym->storage == StorageQualifier::Out || sym->storage == StorageQualifier::Varying)) ||
                                  (is_fragment() && !es3() && sym->storage == StorageQualifier::Varying));
                if (!ok) error(ext.line, "'" + name + "' : only output variables can be declared invariant");
                else sym->invariant = true;
            }
            break;
        case ExternalDecl::Variables: declaration(*ext.declaration, true); break;
        case ExternalDecl::Function: function(*ext.function); break;
        case ExternalDecl::EmptyStruct: break;
        }
    }

    void precision_statement(Precision p, const std::string& type_name, int line) {
        Type t;
        if (!builtin_type_from_name(type_name, version_, t) || !(t.base == BaseType::Float || t.base == BaseType::Int || t.base == BaseType::Sampler) || !t.is_basic() && !t.is_sampler() ||
            t.is_vector() || t.is_matrix()) {
            error(line, "'" + type_name + "' : precision can only be set for float, int and sampler types");
            return;
        }
        scopes_.back().default_precision[type_name] = p;
    }

    void declaration(Stmt& stmt, bool global) {
        TypeSpec& spec = *stmt.decl_type;
        if (!stmt.new_scope && stmt.decls.empty() && !spec.struct_decl && spec.storage == StorageQualifier::None &&
            spec.precision != Precision::None && !spec.type_name.empty() && !global) {
            precision_statement(spec.precision, spec.type_name, stmt.line);
            return;
        }
        Type base = resolve_type(spec);
        if (base.is_error()) return;
        check_qualifiers(spec, base, global, stmt.line);
        if (stmt.decls.empty()) {
            if (!spec.struct_decl) error(stmt.line, "declaration does not declare anything");
            return;
        }
        for (VarDecl& v : stmt.decls) declare_one(spec, base, v, global);
    }

    void check_qualifiers(const TypeSpec& spec, const Type& type, bool global, int line) {
        const StorageQualifier q = spec.storage;
        const std::string tn = type.name();
        if (!global && q != StorageQualifier::None && q != StorageQualifier::Const)
            error(line, "'" + qualifier_name(q) + "' : only allowed at global scope");
        if (q == StorageQualifier::Attribute) {
            if (!is_vertex()) error(line, "'attribute' : only allowed in vertex shaders");
            if (!(type.base == BaseType::Float) || type.is_array()) error(line, "'attribute' : cannot be " + tn);
        }
        if (q == StorageQualifier::Varying) {
            if (type.base != BaseType::Float) error(line, "'varying' : cannot be " + tn);
        }
        if (q == StorageQualifier::In || q == StorageQualifier::Out) {
            bool vertex_input = is_vertex() && q == StorageQualifier::In;
            bool fragment_output = is_fragment() && q == StorageQualifier::Out;
            if (type.base == BaseType::Bool || type.base == BaseType::Sampler || type.contains_sampler())
                error(line, "'" + qualifier_name(q) + "' : cannot be " + tn);
            else if (type.is_struct() && (vertex_input || fragment_output))
                error(line, "'" + qualifier_name(q) + "' : cannot be a structure");
            else if (vertex_input && type.is_array())
                error(line, "'in' : vertex shader inputs cannot be arrays");
            else if (fragment_output && type.is_matrix())
                error(line, "'out' : fragment shader outputs cannot be matrices");
            else if (type.is_struct())
                error(line, "'" + qualifier_name(q) + "' : structure varyings are not supported");
            // ES 3.00 §4.3.6: integer outputs of the vertex shader / inputs of the fragment shader must be flat.
            if (!vertex_input && !fragment_output && type.is_integer() && spec.interpolation != Interpolation::Flat)
                error(line, "'" + qualifier_name(q) + "' : integer varyings must be qualified as flat");
        }
        if (spec.interpolation != Interpolation::Default || spec.centroid) {
            bool ok = (q == StorageQualifier::Out && is_vertex()) || (q == StorageQualifier::In && is_fragment());
            if (!ok) error(line, "interpolation qualifiers are only allowed on vertex outputs and fragment inputs");
        }
        if (spec.invariant) {
            bool ok = (is_vertex() && (q == StorageQualifier::Out || q == StorageQualifier::Varying)) ||
                      (is_fragment() && q == StorageQualifier::Varying);
            if (!ok) error(line, "'invariant' : only allowed on output variables");
        }
        if (spec.layout_location >= 0) {
            bool ok = (is_vertex() && q == StorageQualifier::In) || (is_fragment() && q == StorageQualifier::Out);
            if (!ok) error(line, "'location' : layout location is only allowed on vertex inputs and fragment outputs");
        }
        if (type.contains_sampler() && q != StorageQualifier::Uniform)
            error(line, "'" + tn + "' : samplers must be uniform");
    }

    static std::string qualifier_name(StorageQualifier q) {
        switch (q) {
        case StorageQualifier::Const: return "const";
        case StorageQualifier::Attribute: return "attribute";
        case StorageQualifier::Uniform: return "uniform";
        case StorageQualifier::Varying: return "varying";
        case StorageQualifier::In: return "in";
        case StorageQualifier::Out: return "out";
        case StorageQualifier::InOut: return "inout";
        default: return "";
        }
    }

    void declare_one(const TypeSpec& spec, const Type& base, VarDecl& v, bool global) {
        Type type = base;
        check_identifier_name(v.name, v.line);
        if (v.is_array) {
            if (type.is_array()) { error(v.line, "'" + v.name + "' : arrays of arrays are not allowed"); return; }
            type.array_size = v.array_size ? array_size(*v.array_size) : -1;
            if (!v.array_size && !es3()) { error(v.line, "'" + v.name + "' : array size must be specified"); type.array_size = 1; }
            if (!fits(type, v.line, v.name)) return;
        }
        if (type.is_void()) { error(v.line, "'" + v.name + "' : illegal use of type 'void'"); return; }
        const StorageQualifier q = spec.storage;
        // GLSL ES 1.00 §4.3.3 and ES 3.00 §4.3.4: vertex shader inputs cannot be arrays (the
        // declarator form `attribute vec4 a[2]` is caught here, the type form in check_qualifiers).
        if (v.is_array && (q == StorageQualifier::Attribute || (q == StorageQualifier::In && is_vertex())))
            error(v.line, "'" + v.name + "' : vertex shader inputs cannot be arrays");
        if (v.initializer) {
            if (q == StorageQualifier::Uniform || q == StorageQualifier::Attribute || q == StorageQualifier::Varying ||
                q == StorageQualifier::In || q == StorageQualifier::Out) {
                error(v.line, "'" + v.name + "' : cannot initialize this type of qualifier");
            }
            if (!es3() && type.is_array()) error(v.line, "'" + v.name + "' : arrays cannot be initialized in GLSL ES 1.00");
            expression(*v.initializer);
            const Type& it = v.initializer->type;
            if (type.array_size < 0 && it.is_array()) type.array_size = it.array_size;
            if (!it.is_error() && it != type) {
                error(v.line, "'=' : cannot convert from '" + it.name() + "' to '" + type.name() + "'");
            }
        } else if (q == StorageQualifier::Const) {
            error(v.line, "'" + v.name + "' : variables with qualifier 'const' must be initialized");
        }
        if (type.array_size < 0) {
            error(v.line, "'" + v.name + "' : implicitly sized arrays need an initializer");
            type.array_size = 1;
        }
        if (type.contains_sampler() && q != StorageQualifier::Uniform) {
            // already reported by check_qualifiers for the declaration
        }
        Symbol* sym = new_symbol(v.name, type);
        sym->storage = q;
        sym->interpolation = spec.interpolation;
        sym->invariant = spec.invariant;
        sym->layout_location = spec.layout_location;
        sym->line = v.line;
        sym->is_global = global;
        sym->precision = resolve_precision(type, spec.precision, v.line, v.name);
        if (q == StorageQualifier::Const && v.initializer && !v.initializer->type.is_error()) {
            if (!v.initializer->is_constant) {
                error(v.line, "'" + v.name + "' : initializer of a const variable must be a constant expression");
            } else if (!v.initializer->constant.empty()) {
                sym->has_constant_value = true;
                sym->constant_value = v.initializer->constant;
            }
        }
        // ES 1.00 §4.3 (WebGL): global initializers must be constant expressions.
        if (global && v.initializer && !es3() && !v.initializer->is_constant && !v.initializer->type.is_error())
            error(v.line, "'" + v.name + "' : global variable initializers must be constant expressions");
        v.symbol = sym;
        declare_variable(sym, v.line);
        if (global) s_.globals.push_back(sym);
    }

    // ---------------------------------------------------------------- functions
    static std::string mangle(const std::string& name, const std::vector<Type>& params) {
        std::string m = name + "(";
        for (const Type& t : params) {
            m += t.name();
            if (t.is_struct()) m += "#" + std::to_string(t.struct_type->id);
            m += ",";
        }
        return m + ")";
    }

    void function(FunctionDef& fn) {
        if (!(scopes_.size() == 2)) {}
        Type ret = resolve_type(fn.return_type);
        if (fn.return_type.storage != StorageQualifier::None && fn.return_type.storage != StorageQualifier::Const)
            error(fn.line, "'" + fn.name + "' : function return types cannot have storage qualifiers");
        if (fn.return_type.storage == StorageQualifier::Const) error(fn.line, "'" + fn.name + "' : function return types cannot be const");
        if (ret.contains_sampler()) error(fn.line, "'" + fn.name + "' : functions cannot return samplers");
        if (ret.is_array() && !es3()) error(fn.line, "'" + fn.name + "' : functions cannot return arrays in GLSL ES 1.00");
        if (ret.array_size < 0) { error(fn.line, "'" + fn.name + "' : return array type must be sized"); ret.array_size = 1; }
        fn.resolved_return = ret;
        fn.return_precision = (ret.is_void() || ret.is_error()) ? Precision::None : resolve_precision(ret, fn.return_type.precision, fn.line, fn.name);
        check_identifier_name(fn.name, fn.line);
        Type dummy;
        if (builtin_type_from_name(fn.name, version_, dummy) || lookup_struct(fn.name))
            error(fn.line, "'" + fn.name + "' : a function cannot have the name of a type");
        if (!builtin_overloads(fn.name).empty()) {
            // ES 3.00 §6.1: built-in functions cannot be redefined or overloaded (ES 1.00 allowed
            // overloading; WebGL implementations reject redefinition).
            error(fn.line, "'" + fn.name + "' : cannot redefine or overload a built-in function");
        }
        if (scopes_.back().variables.count(fn.name)) error(fn.line, "'" + fn.name + "' : redefinition (a variable has this name)");
        for (Parameter& p : fn.parameters) {
            Type pt = resolve_type(p.type);
            if (p.is_array) {
                if (pt.is_array()) error(p.line, "arrays of arrays are not allowed");
                else pt.array_size = p.array_size ? array_size(*p.array_size) : -1;
                if (!fits(pt, p.line, p.name)) pt = Type::error();
            }
            if (pt.array_size < 0) { error(p.line, "'" + p.name + "' : array parameters must be sized"); pt.array_size = 1; }
            if (pt.is_void()) error(p.line, "'" + p.name + "' : illegal use of type 'void'");
            if (pt.contains_sampler() && p.direction != StorageQualifier::In)
                error(p.line, "'" + p.name + "' : samplers can only be 'in' parameters");
            if (p.type.storage != StorageQualifier::None) error(p.line, "'" + p.name + "' : invalid parameter qualifier");
            if (p.is_const && p.direction != StorageQualifier::In) error(p.line, "'const' : can only be used with 'in' parameters");
            fn.resolved_parameters.push_back(pt);
        }
        fn.mangled = mangle(fn.name, fn.resolved_parameters);
        // Overloads: same parameters must agree on return type and qualifiers; one definition.
        FunctionDef* previous = nullptr;
        for (FunctionDef* other : functions_[fn.name]) if (other->mangled == fn.mangled) previous = other;
        if (previous) {
            if (previous->resolved_return != fn.resolved_return)
                error(fn.line, "'" + fn.name + "' : overloaded functions must have the same return type");
            for (size_t i = 0; i < fn.parameters.size() && i < previous->parameters.size(); ++i)
                if (fn.parameters[i].direction != previous->parameters[i].direction)
                    error(fn.line, "'" + fn.name + "' : parameter qualifiers do not match the previous declaration");
            FunctionDef* def = previous->definition ? previous->definition : (previous->body ? previous : nullptr);
            if (fn.body && def) { error(fn.line, "'" + fn.name + "' : function already has a body"); return; }
            if (fn.body) {
                // Point every earlier prototype at this definition.
                for (FunctionDef* other : functions_[fn.name]) if (other->mangled == fn.mangled) other->definition = &fn;
            } else {
                fn.definition = def;
            }
        }
        functions_[fn.name].push_back(&fn);
        if (fn.name == "main") {
            if (!fn.resolved_parameters.empty() || !fn.resolved_return.is_void())
                error(fn.line, "'main' : function must have no parameters and return void");
            if (fn.body) s_.main = &fn;
        }
        if (!fn.body) return;
        fn.definition = &fn;
        s_.functions.push_back(&fn);
        // Parameters and the body share a scope (ES 3.00 §4.2.2).
        scopes_.emplace_back();
        scopes_.back().is_function_scope = true;
        for (size_t i = 0; i < fn.parameters.size(); ++i) {
            Parameter& p = fn.parameters[i];
            Symbol* sym = new_symbol(p.name, fn.resolved_parameters[i]);
            sym->is_parameter = true;
            sym->storage = p.is_const ? StorageQualifier::Const : p.direction;
            sym->line = p.line;
            sym->precision = resolve_precision(sym->type, p.type.precision, p.line, p.name.empty() ? fn.name : p.name);
            p.symbol = sym;
            if (!p.name.empty()) {
                check_identifier_name(p.name, p.line);
                declare_variable(sym, p.line);
            }
        }
        current_function_ = &fn;
        body_shares_parameter_scope_ = true;
        block(*fn.body, /*shares_parameter_scope=*/true);
        current_function_ = nullptr;
        scopes_.pop_back();
    }

    // ---------------------------------------------------------------- statements
    void block(Stmt& b, bool shares_parameter_scope = false) {
        scopes_.emplace_back();
        bool saved = body_shares_parameter_scope_;
        body_shares_parameter_scope_ = shares_parameter_scope;
        for (StmtPtr& s : b.body) {
            body_shares_parameter_scope_ = shares_parameter_scope;
            statement(*s);
        }
        body_shares_parameter_scope_ = saved;
        scopes_.pop_back();
    }

    void condition(Expr& e, const char* what) {
        expression(e);
        if (!e.type.is_error() && e.type != Type::scalar(BaseType::Bool))
            error(e.line, std::string("'") + what + "' : boolean expression expected");
    }

    void statement(Stmt& s) {
        WorkBudget::charge_current(1);   // the compile's work budget (core/work_budget.h)
        switch (s.kind) {
        case StmtKind::Block: block(s); break;
        case StmtKind::Declaration: {
            if (s.decl_type && !s.decl_type->struct_decl && s.decls.empty() && !s.new_scope) {
                precision_statement(s.decl_type->precision, s.decl_type->type_name, s.line);
                break;
            }
            declaration(s, false);
            break;
        }
        case StmtKind::Expression: expression(*s.expression); break;
        case StmtKind::If:
            condition(*s.condition, "if");
            for (StmtPtr& b : s.body) sub_statement(*b);
            break;
        case StmtKind::While:
        case StmtKind::DoWhile:
            if (s_.webgl_version == 1 || !es3()) {
                // ES 1.00 Appendix A as enforced by WebGL 1: only restricted for loops.
                error(s.line, std::string("'") + (s.kind == StmtKind::While ? "while" : "do") + "' : This type of loop is not allowed");
            }
            if (s.kind == StmtKind::While) condition(*s.condition, "while");
            ++loop_depth_;
            sub_statement(*s.body[0]);
            --loop_depth_;
            if (s.kind == StmtKind::DoWhile) condition(*s.condition, "do-while");
            break;
        case StmtKind::For: {
            scopes_.emplace_back();
            statement(*s.body[0]);
            if (s.condition) condition(*s.condition, "for");
            if (s.expression) expression(*s.expression);
            if (!es3()) check_appendix_a_loop(s);
            Symbol* index = nullptr;
            const int64_t trips = counted_loop_trips(s, index);
            const uint32_t index_writes = index ? index->writes : 0;
            ++loop_depth_;
            sub_statement(*s.body[1]);
            --loop_depth_;
            if (trips >= 0 && index->writes == index_writes) {
                s.max_trips = trips;
                if (index->type == Type::scalar(BaseType::Int)) record_int_index(s, index);
            }
            if (!es3() && !loop_indices_.empty()) loop_indices_.pop_back();
            scopes_.pop_back();
            break;
        }
        case StmtKind::Switch: switch_statement(s); break;
        case StmtKind::Case:
        case StmtKind::Default:
            error(s.line, std::string("'") + (s.kind == StmtKind::Case ? "case" : "default") + "' : label outside a switch statement");
            break;
        case StmtKind::Break:
            if (loop_depth_ == 0 && switch_depth_ == 0) error(s.line, "'break' : break statement only allowed in loops and switch statements");
            break;
        case StmtKind::Continue:
            if (loop_depth_ == 0) error(s.line, "'continue' : continue statement only allowed in loops");
            break;
        case StmtKind::Discard:
            if (!is_fragment()) error(s.line, "'discard' : only allowed in fragment shaders");
            break;
        case StmtKind::Return: {
            if (!current_function_) break;
            const Type& want = current_function_->resolved_return;
            if (s.expression) {
                expression(*s.expression);
                if (want.is_void()) error(s.line, "'return' : void function cannot return a value");
                else if (!s.expression->type.is_error() && s.expression->type != want)
                    error(s.line, "'return' : function return is not matching type");
            } else if (!want.is_void() && !want.is_error()) {
                error(s.line, "'return' : non-void function must return a value");
            }
            break;
        }
        case StmtKind::Empty: break;
        }
    }

    // A statement that is the body of if/while/for: declarations in it are scoped to it.
    void sub_statement(Stmt& s) {
        if (s.kind == StmtKind::Block) { block(s); return; }
        scopes_.emplace_back();
        statement(s);
        scopes_.pop_back();
    }

    void switch_statement(Stmt& s) {
        expression(*s.condition);
        const Type& t = s.condition->type;
        if (!t.is_error() && !(t == Type::scalar(BaseType::Int) || t == Type::scalar(BaseType::Uint)))
            error(s.line, "'switch' : init-expression in a switch statement must be a scalar integer");
        Stmt& body = *s.body[0];
        std::set<uint32_t> labels;
        bool seen_default = false;
        if (!body.body.empty() && body.body[0]->kind != StmtKind::Case && body.body[0]->kind != StmtKind::Default)
            error(body.body[0]->line, "'switch' : statement before the first label");
        ++switch_depth_;
        scopes_.emplace_back();
        for (StmtPtr& st : body.body) {
            if (st->kind == StmtKind::Case) {
                expression(*st->condition);
                Expr& label = *st->condition;
                if (!label.type.is_error()) {
                    if (!label.is_constant || label.constant.empty() || label.type != t) {
                        error(st->line, "'case' : case label must be a constant integer expression of the switch's type");
                    } else if (!labels.insert(label.constant[0].u).second) {
                        error(st->line, "'case' : duplicate case label");
                    }
                }
            } else if (st->kind == StmtKind::Default) {
                if (seen_default) error(st->line, "'default' : duplicate default label");
                seen_default = true;
            } else {
                statement(*st);
            }
        }
        if (!body.body.empty() && (body.body.back()->kind == StmtKind::Case || body.body.back()->kind == StmtKind::Default))
            error(body.body.back()->line, "'switch' : a label must be followed by a statement");
        scopes_.pop_back();
        --switch_depth_;
    }

    // The iterations of a counted for loop, `for (int|float i = c0; i relop c1; i++ | i-- | ++i |
    // --i | i += c | i -= c)` with constants, counted by running its index in the index's own
    // arithmetic; -1 for any other loop or beyond kMaxCountedTrips. `index` is set for a counted
    // loop: the caller checks that the body does not write it. The pipeline uses the count to bound
    // a fragment shader's work (docs/reliability.md, "Work budget and Ctrl-C").
    static constexpr int64_t kMaxCountedTrips = 1 << 16;
    // For a counted loop with an int index (counted_loop_trips accepted it): its start and step.
    static void record_int_index(Stmt& s, const Symbol* index) {
        const Expr* e = s.expression.get();
        int64_t step = e->op == "++" || e->op == "+=" ? 1 : -1;
        if (e->kind == ExprKind::Assign) step *= int64_t(e->kids[1]->constant[0].i);
        s.counted_int_index = index;
        s.counted_start = s.body[0]->decls[0].initializer->constant[0].i;
        s.counted_step = step;
    }

    static int64_t counted_loop_trips(const Stmt& s, Symbol*& index) {
        index = nullptr;
        const Stmt& init = *s.body[0];
        if (init.kind != StmtKind::Declaration || init.decls.size() != 1 || !init.decls[0].symbol) return -1;
        const VarDecl& d = init.decls[0];
        if (!d.initializer || !d.initializer->is_constant || d.initializer->constant.size() != 1) return -1;
        Symbol* sym = d.symbol;
        const bool is_int = sym->type == Type::scalar(BaseType::Int);
        if (!is_int && !(sym->type == Type::scalar(BaseType::Float))) return -1;
        const Expr* c = s.condition.get();
        if (!c || c->kind != ExprKind::Binary || c->kids[0]->kind != ExprKind::Identifier || c->kids[0]->symbol != sym ||
            !c->kids[1]->is_constant || c->kids[1]->constant.size() != 1 || !(c->kids[1]->type == sym->type))
            return -1;
        const std::string& op = c->op;
        if (op != "<" && op != "<=" && op != ">" && op != ">=" && op != "!=") return -1;
        const Expr* e = s.expression.get();
        if (!e || e->kids.empty() || e->kids[0]->kind != ExprKind::Identifier || e->kids[0]->symbol != sym) return -1;
        double step;
        if ((e->kind == ExprKind::Postfix || e->kind == ExprKind::Unary) && (e->op == "++" || e->op == "--")) {
            step = e->op == "++" ? 1 : -1;
        } else if (e->kind == ExprKind::Assign && (e->op == "+=" || e->op == "-=") && e->kids[1]->is_constant &&
                   e->kids[1]->constant.size() == 1 && e->kids[1]->type == sym->type) {
            const Scalar k = e->kids[1]->constant[0];
            step = (is_int ? double(k.i) : double(k.f)) * (e->op == "+=" ? 1 : -1);
        } else {
            return -1;
        }
        const Scalar start = d.initializer->constant[0], bound = c->kids[1]->constant[0];
        auto holds = [&](auto i, auto b) {
            return op == "<" ? i < b : op == "<=" ? i <= b : op == ">" ? i > b : op == ">=" ? i >= b : i != b;
        };
        int64_t trips = 0;
        if (is_int) {   // int64: no wrap-around within kMaxCountedTrips steps of an int32 step
            for (int64_t i = start.i; holds(i, int64_t(bound.i)); i += int64_t(step))
                if (++trips > kMaxCountedTrips || i < INT32_MIN || i > INT32_MAX) return -1;
        } else {
            for (float i = start.f; holds(i, bound.f); i += float(step))
                if (++trips > kMaxCountedTrips) return -1;
        }
        index = sym;
        return trips;
    }

    // ES 1.00 Appendix A §4: for (type-specifier identifier = constant-expression;
    //   identifier relop constant-expression; identifier++ / -- / += c / -= c) with int/float index.
    void check_appendix_a_loop(Stmt& s) {
        Stmt& init = *s.body[0];
        Symbol* index = nullptr;
        if (init.kind != StmtKind::Declaration || init.decls.size() != 1 || !init.decls[0].initializer || !init.decls[0].symbol) {
            error(s.line, "'for' : Missing init declaration of loop index");
            return;
        }
        index = init.decls[0].symbol;
        const Type& it = index->type;
        if (!(it == Type::scalar(BaseType::Int) || it == Type::scalar(BaseType::Float))) {
            error(s.line, "'" + index->name + "' : Invalid type for loop index");
            return;
        }
        if (!init.decls[0].initializer->is_constant) {
            error(s.line, "'" + index->name + "' : Loop index cannot be initialized with non-constant expression");
            return;
        }
        Expr* c = s.condition.get();
        if (!c || c->kind != ExprKind::Binary || c->kids[0]->kind != ExprKind::Identifier || c->kids[0]->symbol != index ||
            !(c->op == "<" || c->op == ">" || c->op == "<=" || c->op == ">=" || c->op == "==" || c->op == "!=")) {
            error(s.line, "'for' : Invalid loop condition");
            return;
        }
        if (!c->kids[1]->is_constant) {
            error(s.line, "'" + index->name + "' : Loop index cannot be compared with non-constant expression");
            return;
        }
        Expr* e = s.expression.get();
        bool ok = e && ((e->kind == ExprKind::Postfix || e->kind == ExprKind::Unary) && (e->op == "++" || e->op == "--") &&
                        e->kids[0]->kind == ExprKind::Identifier && e->kids[0]->symbol == index);
        ok = ok || (e && e->kind == ExprKind::Assign && (e->op == "+=" || e->op == "-=") && e->kids[0]->kind == ExprKind::Identifier &&
                    e->kids[0]->symbol == index && e->kids[1]->is_constant);
        if (!ok) {
            error(s.line, "'for' : Invalid loop expression");
            return;
        }
        loop_indices_.push_back(index);
    }

    // ---------------------------------------------------------------- expressions
    void expression(Expr& e) {
        switch (e.kind) {
        case ExprKind::IntLiteral:
            e.type = Type::scalar(BaseType::Int);
            e.is_constant = true;
            e.constant = {e.literal};
            break;
        case ExprKind::UintLiteral:
            e.type = Type::scalar(BaseType::Uint);
            e.is_constant = true;
            e.constant = {e.literal};
            break;
        case ExprKind::FloatLiteral:
            e.type = Type::scalar(BaseType::Float);
            e.is_constant = true;
            e.constant = {e.literal};
            break;
        case ExprKind::BoolLiteral:
            e.type = Type::scalar(BaseType::Bool);
            e.is_constant = true;
            e.constant = {e.literal};
            break;
        case ExprKind::Identifier: identifier(e); break;
        case ExprKind::Unary: unary(e); break;
        case ExprKind::Postfix: increment(e); break;
        case ExprKind::Binary: binary(e); break;
        case ExprKind::Assign: assign(e); break;
        case ExprKind::Ternary: ternary(e); break;
        case ExprKind::Call: call(e); break;
        case ExprKind::Index: index(e); break;
        case ExprKind::Field: field(e); break;
        }
    }

    void identifier(Expr& e) {
        Symbol* sym = lookup_variable(e.name);
        if (!sym) {
            if (functions_.count(e.name) || !builtin_overloads(e.name).empty()) error(e.line, "'" + e.name + "' : function name used as a variable");
            else error(e.line, "'" + e.name + "' : undeclared identifier");
            return;
        }
        e.symbol = sym;
        e.type = sym->type;
        e.precision = sym->precision;
        if (sym->storage == StorageQualifier::Const && sym->has_constant_value && !sym->is_parameter) {
            e.is_constant = true;
            // Each use of a const variable gets a copy of its value, within a budget: 20,000
            // uses of a 65536-element const array would copy 5 GB. Past it, a large value is
            // left to run time, and constant indices and fields still fold (constant_value_of).
            const size_t n = sym->constant_value.size();
            if (n <= 16 || copied_constants_ + n <= kMaxCopiedConstants) {
                if (n > 16) copied_constants_ += n;
                e.constant = sym->constant_value;
            }
        }
        if (sym->name == "gl_FragColor") { wrote_frag_color_ = true; frag_color_line_ = e.line; }
        if (sym->name == "gl_FragData") { wrote_frag_data_ = true; frag_color_line_ = e.line; }
    }

    // The value of a constant expression if known: its own, or for a const variable whose value
    // was not copied into the use (see identifier), the variable's.
    static const ConstantValue* constant_value_of(const Expr& e) {
        if (!e.is_constant) return nullptr;
        if (!e.constant.empty()) return &e.constant;
        if (e.kind == ExprKind::Identifier && e.symbol && e.symbol->has_constant_value) return &e.symbol->constant_value;
        return nullptr;
    }

    // Is e something that can be assigned to? Reports the reason if not.
    // `element`: e is indexed by the assignment (a[i] = ...), which ES 1.00 allows for arrays.
    bool check_lvalue(Expr& e, const std::string& op, bool element = false) {
        switch (e.kind) {
        case ExprKind::Identifier: {
            Symbol* sym = e.symbol;
            if (!sym) return false;
            const char* reason = nullptr;
            switch (sym->storage) {
            case StorageQualifier::Const: reason = "can't modify a const"; break;
            case StorageQualifier::Uniform: reason = "can't modify a uniform"; break;
            case StorageQualifier::Attribute: reason = "can't modify an attribute"; break;
            case StorageQualifier::In:
                if (!sym->is_parameter) reason = "can't modify an input";
                break;
            case StorageQualifier::Varying:
                if (is_fragment()) reason = "can't modify a varying in a fragment shader";
                break;
            default: break;
            }
            if (!reason && sym->type.contains_sampler()) reason = "can't modify a sampler";
            if (!reason && !es3() && !element && sym->type.is_array()) reason = "arrays cannot be assigned in GLSL ES 1.00";
            if (!reason) {
                for (Symbol* index : loop_indices_)
                    if (index == sym) reason = "loop index cannot be modified in the loop body";
            }
            if (reason) {
                error(e.line, "'" + op + "' : l-value required (" + reason + " \"" + sym->name + "\")");
                return false;
            }
            sym->written = true;
            ++sym->writes;
            return true;
        }
        case ExprKind::Index: return check_lvalue(*e.kids[0], op, true);
        case ExprKind::Field:
            if (e.is_swizzle) {
                std::set<int> seen;
                for (uint8_t c : e.swizzle)
                    if (!seen.insert(c).second) {
                        error(e.line, "'" + op + "' : l-value of swizzle cannot have duplicate components");
                        return false;
                    }
            }
            return check_lvalue(*e.kids[0], op);
        default:
            error(e.line, "'" + op + "' : l-value required");
            return false;
        }
    }

    void unary(Expr& e) {
        Expr& a = *e.kids[0];
        expression(a);
        if (a.type.is_error()) return;
        const Type& t = a.type;
        if (e.op == "++" || e.op == "--") {
            if (!(t.is_basic() && t.base != BaseType::Bool)) { error(e.line, "'" + e.op + "' : wrong operand type - no operation '" + e.op + "' exists that takes an operand of type " + t.name()); return; }
            check_lvalue(a, e.op);
            e.type = t;
            e.precision = a.precision;
            return;
        }
        bool ok = false;
        if (e.op == "-" || e.op == "+") ok = t.is_basic() && t.base != BaseType::Bool;
        else if (e.op == "!") ok = t == Type::scalar(BaseType::Bool);
        else if (e.op == "~") ok = es3() && t.is_basic() && t.is_integer();
        if (!ok) {
            error(e.line, "'" + e.op + "' : wrong operand type - no operation '" + e.op + "' exists that takes an operand of type " + t.name() + " (or there is no acceptable conversion)");
            return;
        }
        e.type = t;
        e.precision = a.precision;
        if (a.is_constant) {
            e.is_constant = true;
            if (!a.constant.empty()) {
                e.constant = a.constant;
                for (Scalar& v : e.constant) {
                    if (e.op == "-") {
                        if (t.base == BaseType::Float) v.f = -v.f;
                        else v.u = 0u - v.u;
                    } else if (e.op == "!") v.i = !v.i;
                    else if (e.op == "~") v.u = ~v.u;
                }
            }
        }
    }

    void increment(Expr& e) {
        Expr& a = *e.kids[0];
        expression(a);
        if (a.type.is_error()) return;
        if (!(a.type.is_basic() && a.type.base != BaseType::Bool)) {
            error(e.line, "'" + e.op + "' : wrong operand type - no operation '" + e.op + "' exists that takes an operand of type " + a.type.name());
            return;
        }
        check_lvalue(a, e.op);
        e.type = a.type;
        e.precision = a.precision;
    }

    static Precision higher(Precision a, Precision b) { return a > b ? a : b; }

    // Result type of an arithmetic operator (+ - * / %, and & | ^ in ES 3.00), or error.
    Type arithmetic_result(const std::string& op, const Type& a, const Type& b) {
        if (!a.is_basic() || !b.is_basic() || a.base != b.base || a.base == BaseType::Bool) return Type::error();
        bool integer_only = op == "%" || op == "&" || op == "|" || op == "^";
        if (integer_only && (!es3() || !a.is_integer())) return Type::error();
        if (op == "*" && (a.is_matrix() || b.is_matrix())) {
            if (a.is_matrix() && b.is_matrix()) {
                if (a.cols != b.rows) return Type::error();
                return Type::matrix(b.cols, a.rows);
            }
            if (a.is_matrix() && b.is_vector()) return a.cols == b.rows ? Type::vector(BaseType::Float, a.rows) : Type::error();
            if (a.is_vector() && b.is_matrix()) return a.rows == b.rows ? Type::vector(BaseType::Float, b.cols) : Type::error();
        }
        if (a.is_scalar()) return b;
        if (b.is_scalar()) return a;
        if (a == b) return a;
        return Type::error();
    }

    // A left-associative chain (u + u + ... + u) is a left spine as long as the source: its
    // nodes are checked bottom-up in a loop rather than by recursion. Every other way down the
    // tree (right operands, parentheses, calls) costs the parser a nesting level, so recursion
    // stays within the parser's nesting limit.
    void binary(Expr& top) {
        std::vector<Expr*> spine{&top};
        while (spine.back()->kids[0]->kind == ExprKind::Binary) spine.push_back(spine.back()->kids[0].get());
        expression(*spine.back()->kids[0]);
        for (auto it = spine.rbegin(); it != spine.rend(); ++it) {
            expression(*(*it)->kids[1]);
            binary_node(**it);
        }
    }

    // One binary operator whose operands are checked.
    void binary_node(Expr& e) {
        Expr& a = *e.kids[0];
        Expr& b = *e.kids[1];
        if (a.type.is_error() || b.type.is_error()) return;
        const Type& ta = a.type;
        const Type& tb = b.type;
        const std::string& op = e.op;
        auto fail = [&] {
            error(e.line, "'" + op + "' : wrong operand types - no operation '" + op + "' exists that takes a left-hand operand of type '" +
                              ta.name() + "' and a right operand of type '" + tb.name() + "' (or there is no acceptable conversion)");
        };
        e.precision = higher(a.precision, b.precision);
        if (op == ",") {
            e.type = tb;
            e.precision = b.precision;
            return;  // never a constant expression (ES 3.00 §4.3.3)
        }
        if (op == "&&" || op == "||" || op == "^^") {
            if (ta != Type::scalar(BaseType::Bool) || tb != Type::scalar(BaseType::Bool)) return fail();
            e.type = ta;
        } else if (op == "<" || op == ">" || op == "<=" || op == ">=") {
            if (!ta.is_scalar() || ta != tb || ta.base == BaseType::Bool) return fail();
            e.type = Type::scalar(BaseType::Bool);
        } else if (op == "==" || op == "!=") {
            if (ta != tb || ta.contains_sampler() || ta.is_void()) return fail();
            if (!es3() && (ta.contains_array())) return fail();
            e.type = Type::scalar(BaseType::Bool);
        } else if (op == "<<" || op == ">>") {
            if (!es3() || !ta.is_basic() || !tb.is_basic() || !ta.is_integer() || !tb.is_integer() || ta.is_matrix()) return fail();
            if (ta.is_scalar() && !tb.is_scalar()) return fail();
            if (tb.is_vector() && tb.rows != ta.rows) return fail();
            e.type = ta;
            e.precision = a.precision;
        } else {
            Type r = arithmetic_result(op, ta, tb);
            if (r.is_error()) return fail();
            e.type = r;
        }
        if (a.is_constant && b.is_constant) {
            e.is_constant = true;
            if (!a.constant.empty() && !b.constant.empty()) fold_binary(e, a, b);
        }
    }

    void fold_binary(Expr& e, Expr& a, Expr& b) {
        const std::string& op = e.op;
        const Type& ta = a.type;
        const Type& tb = b.type;
        const BaseType base = ta.base;
        if (op == "&&") { e.constant = {make_int(a.constant[0].i && b.constant[0].i)}; return; }
        if (op == "||") { e.constant = {make_int(a.constant[0].i || b.constant[0].i)}; return; }
        if (op == "^^") { e.constant = {make_int((a.constant[0].i != 0) != (b.constant[0].i != 0))}; return; }
        if (op == "==" || op == "!=") {
            bool equal = a.constant.size() == b.constant.size();
            // Compare per component by value type (floats: -0 == 0, NaN != NaN).
            std::vector<BaseType> kinds;
            flatten_bases(ta, kinds);
            for (size_t i = 0; equal && i < a.constant.size(); ++i) {
                if (i < kinds.size() && kinds[i] == BaseType::Float) equal = a.constant[i].f == b.constant[i].f;
                else equal = a.constant[i].u == b.constant[i].u;
            }
            e.constant = {make_int(op == "==" ? equal : !equal)};
            return;
        }
        if (op == "<" || op == ">" || op == "<=" || op == ">=") {
            Scalar x = a.constant[0], y = b.constant[0];
            bool r;
            auto cmp = [&](auto p, auto q) { return op == "<" ? p < q : op == ">" ? p > q : op == "<=" ? p <= q : p >= q; };
            if (base == BaseType::Float) r = cmp(x.f, y.f);
            else if (base == BaseType::Int) r = cmp(x.i, y.i);
            else r = cmp(x.u, y.u);
            e.constant = {make_int(r)};
            return;
        }
        if (op == "*" && (ta.is_matrix() || tb.is_matrix())) {
            // Linear-algebraic product, column-major (ES 3.00 §5.10).
            int a_cols = ta.is_matrix() ? ta.cols : 1, a_rows = ta.is_matrix() ? ta.rows : (ta.is_vector() ? 1 : 0);
            if (ta.is_matrix() && tb.is_matrix()) {
                e.constant.assign(size_t(tb.cols) * ta.rows, make_float(0));
                for (int c = 0; c < tb.cols; ++c)
                    for (int r = 0; r < ta.rows; ++r) {
                        float sum = a.constant[r].f * b.constant[c * tb.rows].f;
                        for (int k = 1; k < ta.cols; ++k) sum += a.constant[k * ta.rows + r].f * b.constant[c * tb.rows + k].f;
                        e.constant[c * ta.rows + r].f = sum;
                    }
                return;
            }
            if (ta.is_matrix() && tb.is_vector()) {
                e.constant.assign(ta.rows, make_float(0));
                for (int r = 0; r < ta.rows; ++r) {
                    float sum = a.constant[r].f * b.constant[0].f;
                    for (int k = 1; k < ta.cols; ++k) sum += a.constant[k * ta.rows + r].f * b.constant[k].f;
                    e.constant[r].f = sum;
                }
                return;
            }
            if (ta.is_vector() && tb.is_matrix()) {
                e.constant.assign(tb.cols, make_float(0));
                for (int c = 0; c < tb.cols; ++c) {
                    float sum = a.constant[0].f * b.constant[c * tb.rows].f;
                    for (int k = 1; k < tb.rows; ++k) sum += a.constant[k].f * b.constant[c * tb.rows + k].f;
                    e.constant[c].f = sum;
                }
                return;
            }
            (void)a_cols; (void)a_rows;
            // scalar * matrix falls through to component-wise
        }
        size_t n = std::max(a.constant.size(), b.constant.size());
        e.constant.resize(n);
        for (size_t i = 0; i < n; ++i) {
            Scalar x = a.constant[a.constant.size() == 1 ? 0 : i];
            Scalar y = b.constant[b.constant.size() == 1 ? 0 : i];
            Scalar r{};
            if (base == BaseType::Float) {
                if (op == "+") r.f = x.f + y.f;
                else if (op == "-") r.f = x.f - y.f;
                else if (op == "*") r.f = x.f * y.f;
                else if (op == "/") r.f = x.f / y.f;
            } else {
                bool is_signed = base == BaseType::Int;
                if (op == "+") r.u = x.u + y.u;
                else if (op == "-") r.u = x.u - y.u;
                else if (op == "*") r.u = x.u * y.u;
                else if (op == "/" || op == "%") {
                    if (y.u == 0) {
                        error(e.line, "'" + op + "' : division by zero in constant expression");
                        r.u = 0;
                    } else if (is_signed) {
                        r.i = op == "/" ? i_div(x.i, y.i) : i_mod(x.i, y.i);
                    } else {
                        r.u = op == "/" ? u_div(x.u, y.u) : u_mod(x.u, y.u);
                    }
                } else if (op == "&") r.u = x.u & y.u;
                else if (op == "|") r.u = x.u | y.u;
                else if (op == "^") r.u = x.u ^ y.u;
                else if (op == "<<") r.u = shift_left(x.u, y.u);
                else if (op == ">>") r.u = is_signed ? static_cast<uint32_t>(shift_right_arithmetic(x.i, y.u)) : shift_right_logical(x.u, y.u);
            }
            e.constant[i] = r;
        }
    }

    static void flatten_bases(const Type& t, std::vector<BaseType>& out) {
        int n = t.array_size > 0 ? t.array_size : 1;
        for (int i = 0; i < n; ++i) {
            if (t.base == BaseType::Struct) {
                for (const StructField& f : t.struct_type->fields) flatten_bases(f.type, out);
            } else {
                for (int c = 0; c < t.element_components(); ++c) out.push_back(t.base);
            }
        }
    }

    void assign(Expr& e) {
        Expr& a = *e.kids[0];
        Expr& b = *e.kids[1];
        expression(a);
        expression(b);
        if (a.type.is_error() || b.type.is_error()) return;
        check_lvalue(a, e.op);
        e.type = a.type;
        e.precision = a.precision;
        if (e.op == "=") {
            if (a.type != b.type || a.type.contains_sampler())
                error(e.line, "'=' : cannot convert from '" + b.type.name() + "' to '" + a.type.name() + "'");
            return;
        }
        std::string op = e.op.substr(0, e.op.size() - 1);
        Type r;
        if (op == "<<" || op == ">>") {
            bool ok = es3() && a.type.is_basic() && b.type.is_basic() && a.type.is_integer() && b.type.is_integer() &&
                      !(a.type.is_scalar() && !b.type.is_scalar()) && !(b.type.is_vector() && b.type.rows != a.type.rows);
            r = ok ? a.type : Type::error();
        } else {
            r = arithmetic_result(op, a.type, b.type);
        }
        if (r.is_error() || r != a.type)
            error(e.line, "'" + e.op + "' : wrong operand types - no operation '" + e.op + "' exists that takes a left-hand operand of type '" +
                              a.type.name() + "' and a right operand of type '" + b.type.name() + "' (or there is no acceptable conversion)");
    }

    void ternary(Expr& e) {
        for (ExprPtr& k : e.kids) expression(*k);
        Expr& c = *e.kids[0];
        Expr& a = *e.kids[1];
        Expr& b = *e.kids[2];
        if (c.type.is_error() || a.type.is_error() || b.type.is_error()) return;
        if (c.type != Type::scalar(BaseType::Bool)) { error(e.line, "'?:' : boolean expression expected"); return; }
        if (a.type != b.type) {
            error(e.line, "'?:' : wrong operand types - no operation '?:' exists that takes a left-hand operand of type '" + a.type.name() +
                              "' and a right operand of type '" + b.type.name() + "' (or there is no acceptable conversion)");
            return;
        }
        if (!es3() && a.type.is_array()) { error(e.line, "'?:' : ternary operator is not allowed for arrays in GLSL ES 1.00"); return; }
        e.type = a.type;
        e.precision = higher(a.precision, b.precision);
        if (c.is_constant && a.is_constant && b.is_constant) {
            e.is_constant = true;
            if (!c.constant.empty() && !a.constant.empty() && !b.constant.empty()) e.constant = c.constant[0].i ? a.constant : b.constant;
        }
    }

    void index(Expr& e) {
        Expr& a = *e.kids[0];
        Expr& i = *e.kids[1];
        expression(a);
        expression(i);
        if (a.type.is_error() || i.type.is_error()) return;
        if (!(i.type == Type::scalar(BaseType::Int) || (es3() && i.type == Type::scalar(BaseType::Uint)))) {
            error(e.line, "'[]' : integer expression required for the index");
            return;
        }
        int size = 0;
        if (a.type.is_array()) {
            e.type = a.type.element_type();
            size = a.type.array_size;
        } else if (a.type.is_matrix()) {
            e.type = a.type.column_type();
            size = a.type.cols;
        } else if (a.type.is_vector()) {
            e.type = a.type.component_type();
            size = a.type.rows;
        } else {
            error(e.line, "'[]' : left of '[' is not of type array, matrix, or vector");
            return;
        }
        e.precision = a.precision;
        if (i.is_constant && !i.constant.empty()) {
            int64_t v = i.type.base == BaseType::Int ? i.constant[0].i : static_cast<int64_t>(i.constant[0].u);
            if (v < 0 || v >= size) {
                error(e.line, "'[]' : index out of range '" + std::to_string(v) + "'");
                e.type = Type::error();
                return;
            }
            if (const ConstantValue* value = constant_value_of(a); value && !value->empty()) {
                int n = e.type.components();
                e.is_constant = true;
                e.constant.assign(value->begin() + v * n, value->begin() + (v + 1) * n);
            }
        } else if (!es3() && a.symbol && a.type.is_array() && a.symbol->storage != StorageQualifier::Uniform &&
                   s_.webgl_version == 1 && !a.symbol->is_builtin) {
            // ES 1.00 Appendix A §5: only constant-index-expressions (loop indices and constants)
            // may index non-uniform arrays; loop indices are constant-index-expressions.
            if (!is_constant_index_expression(i))
                error(e.line, "'[]' : Index expression must be constant");
        } else if (a.type.is_sampler()) {
        }
        if (a.type.is_array() && a.type.contains_sampler() && !(i.is_constant)) {
            if (!es3() || true) {
                if (!is_constant_index_expression(i)) error(e.line, "'[]' : sampler arrays can only be indexed by constant expressions");
            }
        }
    }

    // Constants, loop indices, and operators and built-in calls of those (no recursion: the
    // expression may be a long chain).
    bool is_constant_index_expression(const Expr& root) const {
        std::vector<const Expr*> pending{&root};
        while (!pending.empty()) {
            const Expr& i = *pending.back();
            pending.pop_back();
            if (i.is_constant) continue;
            if (i.kind == ExprKind::Identifier) {
                bool index = false;
                for (Symbol* s : loop_indices_) if (s == i.symbol) index = true;
                if (!index) return false;
                continue;
            }
            bool operation = (i.kind == ExprKind::Binary || i.kind == ExprKind::Unary) && i.op != "++" && i.op != "--" && i.op != ",";
            if (!operation && !(i.kind == ExprKind::Call && i.builtin_id >= 0)) return false;
            for (const ExprPtr& k : i.kids) pending.push_back(k.get());
        }
        return true;
    }

    void field(Expr& e) {
        Expr& a = *e.kids[0];
        expression(a);
        if (a.type.is_error()) return;
        if (a.type.is_struct()) {
            const auto& fields = a.type.struct_type->fields;
            int offset = 0;
            for (size_t k = 0; k < fields.size(); ++k) {
                if (fields[k].name == e.name) {
                    e.field_index = static_cast<int>(k);
                    e.type = fields[k].type;
                    e.precision = fields[k].precision != Precision::None ? fields[k].precision
                                                                          : (fields[k].type.base == BaseType::Float ? Precision::High : Precision::None);
                    if (a.is_constant) {
                        e.is_constant = true;
                        if (const ConstantValue* value = constant_value_of(a); value && !value->empty()) {
                            int n = fields[k].type.components();
                            e.constant.assign(value->begin() + offset, value->begin() + offset + n);
                        }
                    }
                    return;
                }
                offset += fields[k].type.components();
            }
            error(e.line, "'" + e.name + "' : no such field in structure '" + a.type.struct_type->name + "'");
            return;
        }
        if (a.type.is_array()) {
            error(e.line, "'" + e.name + "' : field selection requires structure or vector on left hand side (use .length() for the array size)");
            return;
        }
        if (!(a.type.is_vector() || a.type.is_scalar())) {
            error(e.line, "'" + e.name + "' : field selection requires structure or vector on left hand side");
            return;
        }
        if (a.type.is_scalar() && !es3()) {
            error(e.line, "'" + e.name + "' : field selection requires structure or vector on left hand side");
            return;
        }
        // Swizzle (ES 3.00 §5.5): one naming set, at most four components, each within size.
        static const char* sets[] = {"xyzw", "rgba", "stpq"};
        int set = -1;
        if (e.name.size() > 4) { error(e.line, "'" + e.name + "' : illegal vector field selection"); return; }
        for (char ch : e.name) {
            int found = -1, idx = -1;
            for (int s = 0; s < 3; ++s) {
                const char* p = std::strchr(sets[s], ch);
                if (p && ch) { found = s; idx = static_cast<int>(p - sets[s]); break; }
            }
            if (found < 0 || (set >= 0 && found != set)) { error(e.line, "'" + e.name + "' : illegal vector field selection"); return; }
            set = found;
            if (idx >= a.type.rows) { error(e.line, "'" + e.name + "' : vector field selection out of range"); return; }
            e.swizzle.push_back(static_cast<uint8_t>(idx));
        }
        e.is_swizzle = true;
        e.type = e.swizzle.size() == 1 ? a.type.component_type() : Type::vector(a.type.base, static_cast<int>(e.swizzle.size()));
        e.precision = a.precision;
        if (a.is_constant) {
            e.is_constant = true;
            if (!a.constant.empty()) for (uint8_t c : e.swizzle) e.constant.push_back(a.constant[c]);
        }
    }

    // ---------------------------------------------------------------- calls
    void call(Expr& e) {
        if (e.is_length_method) {
            Expr& a = *e.kids[0];
            expression(a);
            if (a.type.is_error()) return;
            if (!es3() || !a.type.is_array()) { error(e.line, "'length' : method supported only on arrays"); return; }
            e.type = Type::scalar(BaseType::Int);
            e.is_constant = true;
            e.constant = {make_int(a.type.array_size)};
            e.precision = Precision::High;
            return;
        }
        for (ExprPtr& k : e.kids) expression(*k);
        for (ExprPtr& k : e.kids) if (k->type.is_error()) return;
        for (ExprPtr& k : e.kids) {
            if (k->type.is_void()) { error(k->line, "'" + e.name + "' : cannot use a void value as an argument"); return; }
        }
        if (e.constructor_type) { constructor(e); return; }
        // A variable (or struct) name hides functions of that name (ES 3.00 §4.2.2).
        if (Symbol* v = lookup_variable(e.name); v && !v->is_builtin) {
            if (!functions_.count(e.name) || v->is_global == false) {
                error(e.line, "'" + e.name + "' : no matching overloaded function found (the name is a variable)");
                return;
            }
        }
        std::vector<Type> args;
        for (ExprPtr& k : e.kids) args.push_back(k->type);
        // User functions first (they cannot overload built-ins; the definition check reports that).
        auto it = functions_.find(e.name);
        if (it != functions_.end()) {
            std::string m = mangle(e.name, args);
            for (FunctionDef* f : it->second) {
                if (f->mangled != m) continue;
                e.callee = f;
                if (current_function_) calls_[current_function_].push_back(f);
                e.type = f->resolved_return;
                e.precision = f->return_precision;
                for (size_t i = 0; i < f->parameters.size(); ++i) {
                    StorageQualifier dir = f->parameters[i].direction;
                    if (dir == StorageQualifier::Out || dir == StorageQualifier::InOut) check_lvalue(*e.kids[i], dir == StorageQualifier::Out ? "out" : "inout");
                }
                return;
            }
            error(e.line, "'" + e.name + "' : no matching overloaded function found");
            return;
        }
        const std::vector<int>& candidates = builtin_overloads(e.name);
        if (candidates.empty()) {
            error(e.line, "'" + e.name + "' : no matching overloaded function found");
            return;
        }
        const auto& table = builtin_functions();
        bool name_exists_in_version = false;
        for (int id : candidates) {
            const BuiltinFunction& f = table[id];
            if (f.min_version > version_ || f.max_version < version_) continue;
            name_exists_in_version = true;
            if (f.parameters.size() != args.size()) continue;
            bool match = true;
            for (size_t i = 0; i < args.size() && match; ++i) match = f.parameters[i] == args[i];
            if (!match) continue;
            if (f.fragment_only && !is_fragment()) { error(e.line, "'" + e.name + "' : only available in fragment shaders"); return; }
            if (f.vertex_only && !is_vertex()) { error(e.line, "'" + e.name + "' : only available in vertex shaders"); return; }
            if (!f.extension.empty() && version_ == 100 && !s_.extension_enabled(f.extension)) {
                error(e.line, "'" + e.name + "' : requires extension " + f.extension + " to be enabled");
                return;
            }
            e.builtin_id = id;
            e.type = f.result;
            Precision p = Precision::None;
            for (ExprPtr& k : e.kids) p = higher(p, k->precision);
            e.precision = f.result.base == BaseType::Bool ? Precision::None : (p == Precision::None ? Precision::High : p);
            if (f.out_parameter >= 0) check_lvalue(*e.kids[f.out_parameter], "out");
            if (f.has_offset) {
                Expr& off = *e.kids.back();
                if (!off.is_constant) { error(e.line, "'" + e.name + "' : texel offset must be a constant expression"); return; }
                for (const Scalar& c : off.constant)
                    if (c.i < BuiltinConstants{}.min_program_texel_offset || c.i > BuiltinConstants{}.max_program_texel_offset) {
                        error(e.line, "'" + e.name + "' : texel offset out of range");
                        return;
                    }
            }
            // ES 3.00 §4.3.3: built-in calls with constant arguments are constant expressions.
            bool all_constant = f.op != Builtin::TextureLookup && f.op != Builtin::TextureSize && f.op != Builtin::TexelFetch &&
                                f.op != Builtin::DFdx && f.op != Builtin::DFdy && f.op != Builtin::Fwidth && f.out_parameter < 0;
            for (ExprPtr& k : e.kids) all_constant = all_constant && k->is_constant;
            if (all_constant) {
                e.is_constant = true;
                fold_builtin(e, f);
            }
            return;
        }
        if (!name_exists_in_version) error(e.line, "'" + e.name + "' : no matching overloaded function found (not available in this GLSL ES version)");
        else error(e.line, "'" + e.name + "' : no matching overloaded function found");
    }

    // Folds the component-wise built-ins whose value the checker may need (array sizes, case
    // labels); everything else is folded later on the IR by the optimizer.
    void fold_builtin(Expr& e, const BuiltinFunction& f) {
        for (ExprPtr& k : e.kids) if (k->constant.empty()) return;
        const Type& t = e.type;
        if (!t.is_basic() || t.is_matrix()) return;
        int n = t.rows;
        auto arg = [&](int a, int i) { const ConstantValue& c = e.kids[a]->constant; return c[c.size() == 1 ? 0 : i]; };
        BaseType base = e.kids[0]->type.base;
        ConstantValue out(n);
        for (int i = 0; i < n; ++i) {
            Scalar x = arg(0, i);
            switch (f.op) {
            case Builtin::Abs:
                if (base == BaseType::Float) out[i].f = std::fabs(x.f); else out[i].i = i_abs(x.i);
                break;
            case Builtin::Min: {
                Scalar y = arg(1, i);
                if (base == BaseType::Float) out[i].f = f_min(x.f, y.f);
                else if (base == BaseType::Int) out[i].i = i_min(x.i, y.i);
                else out[i].u = u_min(x.u, y.u);
                break;
            }
            case Builtin::Max: {
                Scalar y = arg(1, i);
                if (base == BaseType::Float) out[i].f = f_max(x.f, y.f);
                else if (base == BaseType::Int) out[i].i = i_max(x.i, y.i);
                else out[i].u = u_max(x.u, y.u);
                break;
            }
            case Builtin::Clamp: {
                Scalar lo = arg(1, i), hi = arg(2, i);
                if (base == BaseType::Float) out[i].f = f_clamp(x.f, lo.f, hi.f);
                else if (base == BaseType::Int) out[i].i = i_clamp(x.i, lo.i, hi.i);
                else out[i].u = u_clamp(x.u, lo.u, hi.u);
                break;
            }
            case Builtin::Floor: out[i].f = std::floor(x.f); break;
            case Builtin::Ceil: out[i].f = std::ceil(x.f); break;
            case Builtin::Sqrt: out[i].f = std::sqrt(x.f); break;
            default: e.constant.clear(); return;
            }
        }
        e.constant = out;
    }

    void constructor(Expr& e) {
        Type t = resolve_type(*e.constructor_type);
        if (t.is_error()) return;
        if (t.is_void() || t.is_sampler()) { error(e.line, "'" + t.name() + "' : cannot construct this type"); return; }
        if (e.kids.empty()) { error(e.line, "'" + t.name() + "' : constructor does not have any arguments"); return; }
        bool all_constant = true;
        for (ExprPtr& k : e.kids) all_constant = all_constant && k->is_constant;
        e.is_constructor = true;
        if (t.is_array()) {
            if (t.array_size < 0) t.array_size = static_cast<int>(e.kids.size());
            if (static_cast<int>(e.kids.size()) != t.array_size) { error(e.line, "'" + t.name() + "' : wrong number of arguments in array constructor"); return; }
            for (ExprPtr& k : e.kids)
                if (k->type != t.element_type()) { error(e.line, "'" + t.name() + "' : array constructor argument type mismatch"); return; }
            e.type = t;
            if (all_constant) {
                e.is_constant = true;
                for (ExprPtr& k : e.kids) {
                    if (k->constant.empty()) { e.constant.clear(); break; }
                    e.constant.insert(e.constant.end(), k->constant.begin(), k->constant.end());
                }
            }
            return;
        }
        if (t.is_struct()) {
            const auto& fields = t.struct_type->fields;
            if (e.kids.size() != fields.size()) { error(e.line, "'" + t.name() + "' : wrong number of arguments in structure constructor"); return; }
            for (size_t i = 0; i < fields.size(); ++i)
                if (e.kids[i]->type != fields[i].type) { error(e.line, "'" + t.name() + "' : structure constructor argument type mismatch"); return; }
            e.type = t;
            if (all_constant) {
                e.is_constant = true;
                for (ExprPtr& k : e.kids) {
                    if (k->constant.empty()) { e.constant.clear(); break; }
                    e.constant.insert(e.constant.end(), k->constant.begin(), k->constant.end());
                }
            }
            return;
        }
        // Scalars, vectors, matrices (ES 3.00 §5.4).
        int needed = t.components();
        int provided = 0;
        bool has_matrix = false;
        for (size_t i = 0; i < e.kids.size(); ++i) {
            const Type& a = e.kids[i]->type;
            if (!a.is_basic()) { error(e.line, "'" + t.name() + "' : cannot convert a " + a.name() + " in a constructor"); return; }
            if (provided >= needed && !(t.is_scalar())) { error(e.line, "'" + t.name() + "' : too many arguments"); return; }
            if (t.is_scalar() && i > 0) { error(e.line, "'" + t.name() + "' : too many arguments"); return; }
            has_matrix = has_matrix || a.is_matrix();
            provided += a.components();
        }
        bool single_scalar = e.kids.size() == 1 && e.kids[0]->type.is_scalar();
        bool single_matrix = e.kids.size() == 1 && e.kids[0]->type.is_matrix();
        if (t.is_matrix() && has_matrix && !single_matrix) { error(e.line, "'" + t.name() + "' : constructing matrix from matrix can only take one argument"); return; }
        if (!single_scalar && !single_matrix && provided < needed && !t.is_scalar()) {
            error(e.line, "'" + t.name() + "' : not enough data provided for construction");
            return;
        }
        e.type = t;
        e.precision = Precision::None;
        for (ExprPtr& k : e.kids) e.precision = higher(e.precision, k->precision);
        if (all_constant) {
            e.is_constant = true;
            for (ExprPtr& k : e.kids) if (k->constant.empty()) return;
            e.constant = construct_constant(t, e);
        }
    }

    ConstantValue construct_constant(const Type& t, Expr& e) {
        ConstantValue out(t.components());
        auto conv = [&](Scalar v, BaseType from) { return convert_scalar(v, from, t.base); };
        const Expr& first = *e.kids[0];
        if (e.kids.size() == 1 && first.type.is_scalar() && !t.is_scalar()) {
            Scalar v = conv(first.constant[0], first.type.base);
            if (t.is_matrix()) {
                for (int c = 0; c < t.cols; ++c)
                    for (int r = 0; r < t.rows; ++r) out[c * t.rows + r] = c == r ? v : make_float(0);
            } else {
                for (Scalar& o : out) o = v;
            }
            return out;
        }
        if (e.kids.size() == 1 && first.type.is_matrix() && t.is_matrix()) {
            for (int c = 0; c < t.cols; ++c)
                for (int r = 0; r < t.rows; ++r)
                    out[c * t.rows + r] = (c < first.type.cols && r < first.type.rows) ? first.constant[c * first.type.rows + r]
                                                                                       : make_float(c == r ? 1.0f : 0.0f);
            return out;
        }
        size_t k = 0;
        for (ExprPtr& a : e.kids)
            for (const Scalar& v : a->constant) {
                if (k < out.size()) out[k++] = conv(v, a->type.base);
            }
        return out;
    }

    // ES 1.00 §6.1 and ES 3.00 §6.1: recursion is not allowed, not even statically: a cycle in
    // the static call graph is an error whether or not main reaches it. Depth-first search
    // with an explicit stack (a call chain can be as long as the source).
    void check_recursion() {
        enum State : uint8_t { Unvisited, Open, Done };
        std::unordered_map<const FunctionDef*, State> state;
        auto definition = [](FunctionDef* f) -> FunctionDef* { return f->definition ? f->definition : (f->body ? f : nullptr); };
        static const std::vector<FunctionDef*> none;
        auto callees = [&](const FunctionDef* f) -> const std::vector<FunctionDef*>& {
            auto it = calls_.find(f);
            return it == calls_.end() ? none : it->second;
        };
        struct Frame { FunctionDef* function; size_t next; };
        for (FunctionDef* root : s_.functions) {
            if (state[root] != Unvisited) continue;
            std::vector<Frame> stack{{root, 0}};
            state[root] = Open;
            while (!stack.empty()) {
                Frame& top = stack.back();
                const std::vector<FunctionDef*>& out = callees(top.function);
                if (top.next == out.size()) {
                    state[top.function] = Done;
                    stack.pop_back();
                    continue;
                }
                FunctionDef* callee = definition(out[top.next++]);
                if (!callee || state[callee] == Done) continue;
                if (state[callee] == Open) {
                    size_t first = 0;
                    while (stack[first].function != callee) ++first;
                    std::vector<std::string> chain;
                    for (size_t k = first; k < stack.size(); ++k) chain.push_back(stack[k].function->name);
                    if (chain.size() > 8) chain.erase(chain.begin() + 4, chain.end() - 3), chain.insert(chain.begin() + 4, "...");
                    std::string text;
                    for (const std::string& name : chain) text += name + " -> ";
                    error(callee->line, "'" + callee->name + "' : recursive function calls are not allowed (" + text + callee->name + ")");
                    continue;
                }
                state[callee] = Open;
                stack.push_back({callee, 0});
            }
        }
    }

    void check_fragment_outputs() {
        if (!is_fragment()) return;
        if (wrote_frag_color_ && wrote_frag_data_)
            error(frag_color_line_, "cannot use both gl_FragData and gl_FragColor");
        if (!es3()) return;
        int outputs = 0, without_location = 0;
        std::set<int> locations;
        for (Symbol* g : s_.globals) {
            if (g->storage != StorageQualifier::Out) continue;
            ++outputs;
            if (g->layout_location < 0) ++without_location;
            else {
                int n = g->type.array_size > 0 ? g->type.array_size : 1;
                for (int i = 0; i < n; ++i) {
                    if (g->layout_location + i >= BuiltinConstants{}.max_draw_buffers) error(g->line, "'" + g->name + "' : output location out of range");
                    else if (!locations.insert(g->layout_location + i).second) error(g->line, "'" + g->name + "' : conflicting output locations");
                }
            }
        }
        if (outputs > 1 && without_location > 0) {
            for (Symbol* g : s_.globals)
                if (g->storage == StorageQualifier::Out && g->layout_location < 0) {
                    error(g->line, "'" + g->name + "' : must explicitly specify all locations when using multiple fragment outputs");
                    break;
                }
        }
    }
};

}  // namespace

void check(CheckedShader& shader, Diagnostics& diagnostics) {
    Checker(shader, diagnostics).run();
}

}  // namespace softgl::glsl
