#include "softgl/glsl/types.h"

#include <unordered_map>

namespace softgl::glsl {

bool Type::contains_sampler() const {
    if (base == BaseType::Sampler) return true;
    if (base == BaseType::Struct && struct_type)
        for (const StructField& f : struct_type->fields) if (f.type.contains_sampler()) return true;
    return false;
}

bool Type::contains_array() const {
    if (array_size != 0) return true;
    if (base == BaseType::Struct && struct_type)
        for (const StructField& f : struct_type->fields) if (f.type.contains_array()) return true;
    return false;
}

int Type::element_components() const {
    switch (base) {
    case BaseType::Struct: {
        int n = 0;
        if (struct_type) for (const StructField& f : struct_type->fields) n += f.type.components();
        return n;
    }
    case BaseType::Sampler: return 1;  // the texture unit
    case BaseType::Void:
    case BaseType::Error: return 0;
    default: return cols * rows;
    }
}

bool operator==(const Type& a, const Type& b) {
    if (a.base != b.base || a.cols != b.cols || a.rows != b.rows || a.array_size != b.array_size) return false;
    if (a.base == BaseType::Sampler)
        return a.sampler_dim == b.sampler_dim && a.sampler_shadow == b.sampler_shadow && a.sampler_result == b.sampler_result;
    if (a.base == BaseType::Struct) return a.struct_type == b.struct_type || (a.struct_type && b.struct_type && a.struct_type->id == b.struct_type->id);
    return true;
}

std::string Type::name() const {
    std::string s;
    auto prefix = [](BaseType b) { return b == BaseType::Int ? "i" : b == BaseType::Uint ? "u" : b == BaseType::Bool ? "b" : ""; };
    switch (base) {
    case BaseType::Void: s = "void"; break;
    case BaseType::Error: s = "<error>"; break;
    case BaseType::Struct: s = struct_type ? struct_type->name : "struct"; break;
    case BaseType::Sampler: {
        s = std::string(prefix(sampler_result)) + "sampler";
        s += sampler_dim == SamplerDim::Tex2D ? "2D" : sampler_dim == SamplerDim::Tex3D ? "3D" : sampler_dim == SamplerDim::Cube ? "Cube" : "2DArray";
        if (sampler_shadow) s += "Shadow";
        break;
    }
    default:
        if (cols > 1) {
            s = "mat" + std::to_string(cols);
            if (cols != rows) s += "x" + std::to_string(rows);
        } else if (rows > 1) {
            s = std::string(prefix(base)) + "vec" + std::to_string(rows);
        } else {
            s = base == BaseType::Float ? "float" : base == BaseType::Int ? "int" : base == BaseType::Uint ? "uint" : "bool";
        }
    }
    if (array_size > 0) s += "[" + std::to_string(array_size) + "]";
    if (array_size < 0) s += "[]";
    return s;
}

uint32_t Type::gl_enum() const {
    // Values from the OpenGL ES 3.0 headers (gl2.h / gl3.h).
    switch (base) {
    case BaseType::Float:
        if (cols == 1) return rows == 1 ? 0x1406 : rows == 2 ? 0x8B50 : rows == 3 ? 0x8B51 : 0x8B52;
        if (cols == rows) return cols == 2 ? 0x8B5A : cols == 3 ? 0x8B5B : 0x8B5C;
        if (cols == 2) return rows == 3 ? 0x8B65 : 0x8B66;  // MAT2x3, MAT2x4
        if (cols == 3) return rows == 2 ? 0x8B67 : 0x8B68;  // MAT3x2, MAT3x4
        return rows == 2 ? 0x8B69 : 0x8B6A;                  // MAT4x2, MAT4x3
    case BaseType::Int: return rows == 1 ? 0x1404 : rows == 2 ? 0x8B53 : rows == 3 ? 0x8B54 : 0x8B55;
    case BaseType::Uint: return rows == 1 ? 0x1405 : rows == 2 ? 0x8DC6 : rows == 3 ? 0x8DC7 : 0x8DC8;
    case BaseType::Bool: return rows == 1 ? 0x8B56 : rows == 2 ? 0x8B57 : rows == 3 ? 0x8B58 : 0x8B59;
    case BaseType::Sampler:
        if (sampler_result == BaseType::Int)
            return sampler_dim == SamplerDim::Tex2D ? 0x8DCA : sampler_dim == SamplerDim::Tex3D ? 0x8DCB : sampler_dim == SamplerDim::Cube ? 0x8DCC : 0x8DCF;
        if (sampler_result == BaseType::Uint)
            return sampler_dim == SamplerDim::Tex2D ? 0x8DD2 : sampler_dim == SamplerDim::Tex3D ? 0x8DD3 : sampler_dim == SamplerDim::Cube ? 0x8DD4 : 0x8DD7;
        if (sampler_shadow)
            return sampler_dim == SamplerDim::Tex2D ? 0x8B62 : sampler_dim == SamplerDim::Cube ? 0x8DC5 : 0x8DC4;
        return sampler_dim == SamplerDim::Tex2D ? 0x8B5E : sampler_dim == SamplerDim::Tex3D ? 0x8B5F : sampler_dim == SamplerDim::Cube ? 0x8B60 : 0x8DC1;
    default: return 0;
    }
}

bool builtin_type_from_name(const std::string& name, int version, Type& out) {
    static const std::unordered_map<std::string, std::pair<Type, int>> table = [] {
        std::unordered_map<std::string, std::pair<Type, int>> t;
        t["void"] = {Type::void_type(), 100};
        t["float"] = {Type::scalar(BaseType::Float), 100};
        t["int"] = {Type::scalar(BaseType::Int), 100};
        t["bool"] = {Type::scalar(BaseType::Bool), 100};
        t["uint"] = {Type::scalar(BaseType::Uint), 300};
        for (int n = 2; n <= 4; ++n) {
            std::string d = std::to_string(n);
            t["vec" + d] = {Type::vector(BaseType::Float, n), 100};
            t["ivec" + d] = {Type::vector(BaseType::Int, n), 100};
            t["bvec" + d] = {Type::vector(BaseType::Bool, n), 100};
            t["uvec" + d] = {Type::vector(BaseType::Uint, n), 300};
            t["mat" + d] = {Type::matrix(n, n), 100};
            for (int r = 2; r <= 4; ++r) t["mat" + d + "x" + std::to_string(r)] = {Type::matrix(n, r), 300};
        }
        auto sampler = [&](const char* n, SamplerDim dim, bool shadow, BaseType result, int v) {
            Type s = Type::scalar(BaseType::Sampler);
            s.sampler_dim = dim;
            s.sampler_shadow = shadow;
            s.sampler_result = result;
            t[n] = {s, v};
        };
        sampler("sampler2D", SamplerDim::Tex2D, false, BaseType::Float, 100);
        sampler("samplerCube", SamplerDim::Cube, false, BaseType::Float, 100);
        sampler("sampler3D", SamplerDim::Tex3D, false, BaseType::Float, 300);
        sampler("sampler2DArray", SamplerDim::Tex2DArray, false, BaseType::Float, 300);
        sampler("sampler2DShadow", SamplerDim::Tex2D, true, BaseType::Float, 300);
        sampler("samplerCubeShadow", SamplerDim::Cube, true, BaseType::Float, 300);
        sampler("sampler2DArrayShadow", SamplerDim::Tex2DArray, true, BaseType::Float, 300);
        sampler("isampler2D", SamplerDim::Tex2D, false, BaseType::Int, 300);
        sampler("isampler3D", SamplerDim::Tex3D, false, BaseType::Int, 300);
        sampler("isamplerCube", SamplerDim::Cube, false, BaseType::Int, 300);
        sampler("isampler2DArray", SamplerDim::Tex2DArray, false, BaseType::Int, 300);
        sampler("usampler2D", SamplerDim::Tex2D, false, BaseType::Uint, 300);
        sampler("usampler3D", SamplerDim::Tex3D, false, BaseType::Uint, 300);
        sampler("usamplerCube", SamplerDim::Cube, false, BaseType::Uint, 300);
        sampler("usampler2DArray", SamplerDim::Tex2DArray, false, BaseType::Uint, 300);
        return t;
    }();
    auto it = table.find(name);
    if (it == table.end() || it->second.second > version) return false;
    out = it->second.first;
    return true;
}

}  // namespace softgl::glsl
