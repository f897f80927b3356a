// The signature table of built-in functions (ES 1.00 §8, ES 3.00 §8). "genType" families are
// expanded here into one entry per concrete signature; the checker matches argument types
// exactly (GLSL ES has no implicit conversions).
#include <unordered_map>

#include "softgl/glsl/builtins.h"

namespace softgl::glsl {
namespace {

Type F(int n = 1) { return n == 1 ? Type::scalar(BaseType::Float) : Type::vector(BaseType::Float, n); }
Type I(int n = 1) { return n == 1 ? Type::scalar(BaseType::Int) : Type::vector(BaseType::Int, n); }
Type U(int n = 1) { return n == 1 ? Type::scalar(BaseType::Uint) : Type::vector(BaseType::Uint, n); }
Type B(int n = 1) { return n == 1 ? Type::scalar(BaseType::Bool) : Type::vector(BaseType::Bool, n); }
Type G(BaseType b, int n) { return n == 1 ? Type::scalar(b) : Type::vector(b, n); }
Type S(SamplerDim dim, BaseType result, bool shadow = false) {
    Type t = Type::scalar(BaseType::Sampler);
    t.sampler_dim = dim;
    t.sampler_result = result;
    t.sampler_shadow = shadow;
    return t;
}

class TableBuilder {
public:
    std::vector<BuiltinFunction> table;

    BuiltinFunction& add(const std::string& name, Builtin op, Type result, std::vector<Type> params, int min_version = 100) {
        BuiltinFunction f;
        f.name = name;
        f.op = op;
        f.result = result;
        f.parameters = std::move(params);
        f.min_version = min_version;
        table.push_back(f);
        return table.back();
    }
    // genType f(genType [, genType [, genType]]) for float, n = 1..4
    void gen_float(const std::string& name, Builtin op, int arity, int min_version = 100) {
        for (int n = 1; n <= 4; ++n) add(name, op, F(n), std::vector<Type>(arity, F(n)), min_version);
    }
};

// §8.1 angle and trigonometry functions
void add_angle_and_trigonometry(TableBuilder& t) {
    t.gen_float("radians", Builtin::Radians, 1);
    t.gen_float("degrees", Builtin::Degrees, 1);
    t.gen_float("sin", Builtin::Sin, 1);
    t.gen_float("cos", Builtin::Cos, 1);
    t.gen_float("tan", Builtin::Tan, 1);
    t.gen_float("asin", Builtin::Asin, 1);
    t.gen_float("acos", Builtin::Acos, 1);
    t.gen_float("atan", Builtin::Atan2, 2);
    t.gen_float("atan", Builtin::Atan, 1);
    t.gen_float("sinh", Builtin::Sinh, 1, 300);
    t.gen_float("cosh", Builtin::Cosh, 1, 300);
    t.gen_float("tanh", Builtin::Tanh, 1, 300);
    t.gen_float("asinh", Builtin::Asinh, 1, 300);
    t.gen_float("acosh", Builtin::Acosh, 1, 300);
    t.gen_float("atanh", Builtin::Atanh, 1, 300);
}

// §8.2 exponential functions
void add_exponential(TableBuilder& t) {
    t.gen_float("pow", Builtin::Pow, 2);
    t.gen_float("exp", Builtin::Exp, 1);
    t.gen_float("log", Builtin::Log, 1);
    t.gen_float("exp2", Builtin::Exp2, 1);
    t.gen_float("log2", Builtin::Log2, 1);
    t.gen_float("sqrt", Builtin::Sqrt, 1);
    t.gen_float("inversesqrt", Builtin::InverseSqrt, 1);
}

// §8.3 common functions (with ES 3.00's integer and bit-cast forms)
void add_common(TableBuilder& t) {
    t.gen_float("abs", Builtin::Abs, 1);
    t.gen_float("sign", Builtin::Sign, 1);
    t.gen_float("floor", Builtin::Floor, 1);
    t.gen_float("trunc", Builtin::Trunc, 1, 300);
    t.gen_float("round", Builtin::Round, 1, 300);
    t.gen_float("roundEven", Builtin::RoundEven, 1, 300);
    t.gen_float("ceil", Builtin::Ceil, 1);
    t.gen_float("fract", Builtin::Fract, 1);
    t.gen_float("mod", Builtin::Mod, 2);
    t.gen_float("min", Builtin::Min, 2);
    t.gen_float("max", Builtin::Max, 2);
    t.gen_float("clamp", Builtin::Clamp, 3);
    t.gen_float("mix", Builtin::Mix, 3);
    t.gen_float("step", Builtin::Step, 2);
    t.gen_float("smoothstep", Builtin::Smoothstep, 3);
    for (int n = 1; n <= 4; ++n) {
        if (n > 1) {
            t.add("mod", Builtin::Mod, F(n), {F(n), F()});
            t.add("min", Builtin::Min, F(n), {F(n), F()});
            t.add("max", Builtin::Max, F(n), {F(n), F()});
            t.add("clamp", Builtin::Clamp, F(n), {F(n), F(), F()});
            t.add("mix", Builtin::Mix, F(n), {F(n), F(n), F()});
            t.add("step", Builtin::Step, F(n), {F(), F(n)});
            t.add("smoothstep", Builtin::Smoothstep, F(n), {F(), F(), F(n)});
        }
        t.add("modf", Builtin::Modf, F(n), {F(n), F(n)}, 300).out_parameter = 1;
        t.add("mix", Builtin::Mix, F(n), {F(n), F(n), B(n)}, 300);
        t.add("isnan", Builtin::IsNan, B(n), {F(n)}, 300);
        t.add("isinf", Builtin::IsInf, B(n), {F(n)}, 300);
        t.add("floatBitsToInt", Builtin::FloatBitsToInt, I(n), {F(n)}, 300);
        t.add("floatBitsToUint", Builtin::FloatBitsToUint, U(n), {F(n)}, 300);
        t.add("intBitsToFloat", Builtin::IntBitsToFloat, F(n), {I(n)}, 300);
        t.add("uintBitsToFloat", Builtin::UintBitsToFloat, F(n), {U(n)}, 300);
        for (BaseType b : {BaseType::Int, BaseType::Uint}) {
            if (b == BaseType::Int) {
                t.add("abs", Builtin::Abs, I(n), {I(n)}, 300);
                t.add("sign", Builtin::Sign, I(n), {I(n)}, 300);
            }
            t.add("min", Builtin::Min, G(b, n), {G(b, n), G(b, n)}, 300);
            t.add("max", Builtin::Max, G(b, n), {G(b, n), G(b, n)}, 300);
            t.add("clamp", Builtin::Clamp, G(b, n), {G(b, n), G(b, n), G(b, n)}, 300);
            if (n > 1) {
                t.add("min", Builtin::Min, G(b, n), {G(b, n), G(b, 1)}, 300);
                t.add("max", Builtin::Max, G(b, n), {G(b, n), G(b, 1)}, 300);
                t.add("clamp", Builtin::Clamp, G(b, n), {G(b, n), G(b, 1), G(b, 1)}, 300);
            }
        }
    }
}

// §8.4 floating-point pack and unpack functions
void add_packing(TableBuilder& t) {
    t.add("packSnorm2x16", Builtin::PackSnorm2x16, U(), {F(2)}, 300);
    t.add("unpackSnorm2x16", Builtin::UnpackSnorm2x16, F(2), {U()}, 300);
    t.add("packUnorm2x16", Builtin::PackUnorm2x16, U(), {F(2)}, 300);
    t.add("unpackUnorm2x16", Builtin::UnpackUnorm2x16, F(2), {U()}, 300);
    t.add("packHalf2x16", Builtin::PackHalf2x16, U(), {F(2)}, 300);
    t.add("unpackHalf2x16", Builtin::UnpackHalf2x16, F(2), {U()}, 300);
}

// §8.5 geometric functions
void add_geometric(TableBuilder& t) {
    for (int n = 1; n <= 4; ++n) {
        t.add("length", Builtin::Length, F(), {F(n)});
        t.add("distance", Builtin::Distance, F(), {F(n), F(n)});
        t.add("dot", Builtin::Dot, F(), {F(n), F(n)});
        t.add("normalize", Builtin::Normalize, F(n), {F(n)});
        t.add("faceforward", Builtin::FaceForward, F(n), {F(n), F(n), F(n)});
        t.add("reflect", Builtin::Reflect, F(n), {F(n), F(n)});
        t.add("refract", Builtin::Refract, F(n), {F(n), F(n), F()});
    }
    t.add("cross", Builtin::Cross, F(3), {F(3), F(3)});
}

// §8.6 matrix functions
void add_matrix(TableBuilder& t) {
    for (int c = 2; c <= 4; ++c) {
        for (int r = 2; r <= 4; ++r) {
            int v = c == r ? 100 : 300;
            t.add("matrixCompMult", Builtin::MatrixCompMult, Type::matrix(c, r), {Type::matrix(c, r), Type::matrix(c, r)}, v);
            t.add("outerProduct", Builtin::OuterProduct, Type::matrix(c, r), {F(r), F(c)}, 300);
            t.add("transpose", Builtin::Transpose, Type::matrix(r, c), {Type::matrix(c, r)}, 300);
        }
        t.add("determinant", Builtin::Determinant, F(), {Type::matrix(c, c)}, 300);
        t.add("inverse", Builtin::Inverse, Type::matrix(c, c), {Type::matrix(c, c)}, 300);
    }
}

// §8.7 vector relational functions
void add_vector_relational(TableBuilder& t) {
    for (int n = 2; n <= 4; ++n) {
        for (BaseType b : {BaseType::Float, BaseType::Int, BaseType::Uint}) {
            int v = b == BaseType::Uint ? 300 : 100;
            t.add("lessThan", Builtin::LessThan, B(n), {G(b, n), G(b, n)}, v);
            t.add("lessThanEqual", Builtin::LessThanEqual, B(n), {G(b, n), G(b, n)}, v);
            t.add("greaterThan", Builtin::GreaterThan, B(n), {G(b, n), G(b, n)}, v);
            t.add("greaterThanEqual", Builtin::GreaterThanEqual, B(n), {G(b, n), G(b, n)}, v);
            t.add("equal", Builtin::Equal, B(n), {G(b, n), G(b, n)}, v);
            t.add("notEqual", Builtin::NotEqual, B(n), {G(b, n), G(b, n)}, v);
        }
        t.add("equal", Builtin::Equal, B(n), {B(n), B(n)});
        t.add("notEqual", Builtin::NotEqual, B(n), {B(n), B(n)});
        t.add("any", Builtin::Any, B(), {B(n)});
        t.add("all", Builtin::All, B(), {B(n)});
        t.add("not", Builtin::Not, B(n), {B(n)});
    }
}

// §8.9 derivatives: ES 3.00 core; ES 1.00 with OES_standard_derivatives.
void add_derivatives(TableBuilder& t) {
    for (int n = 1; n <= 4; ++n) {
        for (auto [name, op] : {std::pair{"dFdx", Builtin::DFdx}, {"dFdy", Builtin::DFdy}, {"fwidth", Builtin::Fwidth}}) {
            BuiltinFunction& f = t.add(name, op, F(n), {F(n)});
            f.fragment_only = true;
            f.extension = "GL_OES_standard_derivatives";
        }
    }
}

// §8.8 texture lookups, ES 1.00 names (and EXT_shader_texture_lod's)
void add_es100_texture_lookups(TableBuilder& t) {
    auto tex = [&](const std::string& name, Type sampler, Type coord, Type result, bool projective, TextureLod lod,
                   int min_v, int max_v, const std::string& extension = "") {
        std::vector<Type> params = {sampler, coord};
        if (lod == TextureLod::Bias || lod == TextureLod::Explicit) params.push_back(F());
        BuiltinFunction& f = t.add(name, Builtin::TextureLookup, result, params, min_v);
        f.max_version = max_v;
        f.projective = projective;
        f.lod_mode = lod;
        f.extension = extension;
        if (lod == TextureLod::Bias) f.fragment_only = true;
        return &f;
    };
    Type s2d = S(SamplerDim::Tex2D, BaseType::Float), scube = S(SamplerDim::Cube, BaseType::Float);
    tex("texture2D", s2d, F(2), F(4), false, TextureLod::Implicit, 100, 100);
    tex("texture2D", s2d, F(2), F(4), false, TextureLod::Bias, 100, 100);
    tex("texture2DProj", s2d, F(3), F(4), true, TextureLod::Implicit, 100, 100);
    tex("texture2DProj", s2d, F(4), F(4), true, TextureLod::Implicit, 100, 100);
    tex("texture2DProj", s2d, F(3), F(4), true, TextureLod::Bias, 100, 100);
    tex("texture2DProj", s2d, F(4), F(4), true, TextureLod::Bias, 100, 100);
    tex("textureCube", scube, F(3), F(4), false, TextureLod::Implicit, 100, 100);
    tex("textureCube", scube, F(3), F(4), false, TextureLod::Bias, 100, 100);
    tex("texture2DLod", s2d, F(2), F(4), false, TextureLod::Explicit, 100, 100)->vertex_only = true;
    tex("texture2DProjLod", s2d, F(3), F(4), true, TextureLod::Explicit, 100, 100)->vertex_only = true;
    tex("texture2DProjLod", s2d, F(4), F(4), true, TextureLod::Explicit, 100, 100)->vertex_only = true;
    tex("textureCubeLod", scube, F(3), F(4), false, TextureLod::Explicit, 100, 100)->vertex_only = true;
    // EXT_shader_texture_lod (fragment shaders of WebGL 1)
    const std::string lod_ext = "GL_EXT_shader_texture_lod";
    tex("texture2DLodEXT", s2d, F(2), F(4), false, TextureLod::Explicit, 100, 100, lod_ext)->fragment_only = true;
    tex("texture2DProjLodEXT", s2d, F(3), F(4), true, TextureLod::Explicit, 100, 100, lod_ext)->fragment_only = true;
    tex("texture2DProjLodEXT", s2d, F(4), F(4), true, TextureLod::Explicit, 100, 100, lod_ext)->fragment_only = true;
    tex("textureCubeLodEXT", scube, F(3), F(4), false, TextureLod::Explicit, 100, 100, lod_ext)->fragment_only = true;
    for (auto [name, sampler, coord, grad, proj] :
         {std::tuple{"texture2DGradEXT", s2d, F(2), F(2), false}, {"texture2DProjGradEXT", s2d, F(3), F(2), true},
          {"texture2DProjGradEXT", s2d, F(4), F(2), true}, {"textureCubeGradEXT", scube, F(3), F(3), false}}) {
        BuiltinFunction& f = t.add(name, Builtin::TextureLookup, F(4), {sampler, coord, grad, grad}, 100);
        f.max_version = 100;
        f.projective = proj;
        f.lod_mode = TextureLod::Gradient;
        f.extension = lod_ext;
    }
}

// ES 3.00 §8.8: the lookups a sampler type has.
struct SamplerInfo {
    Type sampler;
    int coord;      // coordinate components (incl. layer, excl. shadow reference)
    int grad;       // gradient components
    int offset;     // offset components (0: no offset variants)
    bool projective_ok;
    bool fetch_ok;
    int size;       // textureSize result components
};

// texture, textureProj, textureLod, textureOffset, texelFetch, ... of one sampler type.
void add_sampler_lookups(TableBuilder& t, const SamplerInfo& s) {
    const bool shadow = s.sampler.sampler_shadow;
    Type result = shadow ? F() : G(s.sampler.sampler_result, 4);
    int coord = s.coord + (shadow ? 1 : 0);
    Type P = F(coord);
    auto variant = [&](const std::string& name, Type coord_type, bool proj, TextureLod lod, bool offset) {
        std::vector<Type> params = {s.sampler, coord_type};
        if (lod == TextureLod::Explicit) params.push_back(F());
        if (lod == TextureLod::Gradient) { params.push_back(F(s.grad)); params.push_back(F(s.grad)); }
        if (offset) params.push_back(I(s.offset));
        std::vector<TextureLod> lods = {lod};
        if (lod == TextureLod::Implicit) lods.push_back(TextureLod::Bias);
        for (TextureLod l : lods) {
            std::vector<Type> p = params;
            if (l == TextureLod::Bias) p.push_back(F());
            BuiltinFunction& f = t.add(name, Builtin::TextureLookup, result, p, 300);
            f.projective = proj;
            f.lod_mode = l;
            f.has_offset = offset;
            if (l == TextureLod::Bias) f.fragment_only = true;
        }
    };
    // samplerCubeShadow with bias and 2DArrayShadow have restrictions; ES 3.00 lists:
    // texture(sampler2DArrayShadow, vec4) without bias.
    bool is_array_shadow = shadow && s.sampler.sampler_dim == SamplerDim::Tex2DArray;
    if (is_array_shadow) {
        BuiltinFunction& f = t.add("texture", Builtin::TextureLookup, result, {s.sampler, P}, 300);
        f.lod_mode = TextureLod::Implicit;
    } else {
        variant("texture", P, false, TextureLod::Implicit, false);
    }
    if (s.projective_ok) {
        if (!shadow && s.sampler.sampler_dim == SamplerDim::Tex2D) {
            variant("textureProj", F(3), true, TextureLod::Implicit, false);
            variant("textureProjLod", F(3), true, TextureLod::Explicit, false);
            variant("textureProjGrad", F(3), true, TextureLod::Gradient, false);
            variant("textureProjOffset", F(3), true, TextureLod::Implicit, true);
            variant("textureProjLodOffset", F(3), true, TextureLod::Explicit, true);
            variant("textureProjGradOffset", F(3), true, TextureLod::Gradient, true);
        }
        variant("textureProj", F(4), true, TextureLod::Implicit, false);
        variant("textureProjLod", F(4), true, TextureLod::Explicit, false);
        variant("textureProjGrad", F(4), true, TextureLod::Gradient, false);
        variant("textureProjOffset", F(4), true, TextureLod::Implicit, true);
        variant("textureProjLodOffset", F(4), true, TextureLod::Explicit, true);
        variant("textureProjGradOffset", F(4), true, TextureLod::Gradient, true);
    }
    if (!(shadow && s.sampler.sampler_dim != SamplerDim::Tex2D)) variant("textureLod", P, false, TextureLod::Explicit, false);
    variant("textureGrad", P, false, TextureLod::Gradient, false);
    if (s.offset) {
        if (!is_array_shadow) variant("textureOffset", P, false, TextureLod::Implicit, true);
        if (!shadow) variant("textureLodOffset", P, false, TextureLod::Explicit, true);
        if (shadow && s.sampler.sampler_dim == SamplerDim::Tex2D) variant("textureLodOffset", P, false, TextureLod::Explicit, true);
        variant("textureGradOffset", P, false, TextureLod::Gradient, true);
    }
    if (s.fetch_ok) {
        t.add("texelFetch", Builtin::TexelFetch, result, {s.sampler, I(s.coord), I()}, 300);
        BuiltinFunction& f = t.add("texelFetchOffset", Builtin::TexelFetch, result, {s.sampler, I(s.coord), I(), I(s.offset)}, 300);
        f.has_offset = true;
    }
    t.add("textureSize", Builtin::TextureSize, I(s.size), {s.sampler, I()}, 300);
}

// ES 3.00 §8.8: texture, textureProj, textureLod, textureOffset, texelFetch, ... per sampler.
void add_es300_texture_lookups(TableBuilder& t) {
    std::vector<SamplerInfo> samplers;
    for (BaseType r : {BaseType::Float, BaseType::Int, BaseType::Uint}) {
        samplers.push_back({S(SamplerDim::Tex2D, r), 2, 2, 2, true, true, 2});
        samplers.push_back({S(SamplerDim::Tex3D, r), 3, 3, 3, true, true, 3});
        samplers.push_back({S(SamplerDim::Cube, r), 3, 3, 0, false, false, 2});
        samplers.push_back({S(SamplerDim::Tex2DArray, r), 3, 2, 2, false, true, 3});
    }
    samplers.push_back({S(SamplerDim::Tex2D, BaseType::Float, true), 2, 2, 2, true, false, 2});
    samplers.push_back({S(SamplerDim::Cube, BaseType::Float, true), 3, 3, 0, false, false, 2});
    samplers.push_back({S(SamplerDim::Tex2DArray, BaseType::Float, true), 3, 2, 2, false, false, 3});
    for (const SamplerInfo& s : samplers) add_sampler_lookups(t, s);
}

// In this order: a name's overloads are listed (and tried) in table order.
std::vector<BuiltinFunction> build_table() {
    TableBuilder t;
    add_angle_and_trigonometry(t);
    add_exponential(t);
    add_common(t);
    add_packing(t);
    add_geometric(t);
    add_matrix(t);
    add_vector_relational(t);
    add_derivatives(t);
    add_es100_texture_lookups(t);
    add_es300_texture_lookups(t);
    return t.table;
}

}  // namespace

const std::vector<BuiltinFunction>& builtin_functions() {
    static const std::vector<BuiltinFunction> table = build_table();
    return table;
}

const std::vector<int>& builtin_overloads(const std::string& name) {
    static const std::unordered_map<std::string, std::vector<int>> index = [] {
        std::unordered_map<std::string, std::vector<int>> m;
        const auto& table = builtin_functions();
        for (size_t i = 0; i < table.size(); ++i) m[table[i].name].push_back(static_cast<int>(i));
        return m;
    }();
    static const std::vector<int> none;
    auto it = index.find(name);
    return it == index.end() ? none : it->second;
}

}  // namespace softgl::glsl
