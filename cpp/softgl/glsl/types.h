// GLSL ES types (ES 3.00 §4.1): scalars, vectors, matrices, samplers, structs, 1-D arrays.
// Values are stored as flat lists of 32-bit scalar components: array elements in order, struct
// fields in declaration order, matrices column by column.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace softgl::glsl {

enum class BaseType : uint8_t { Void, Float, Int, Uint, Bool, Sampler, Struct, Error };

enum class SamplerDim : uint8_t { None, Tex2D, Tex3D, Cube, Tex2DArray };

enum class Precision : uint8_t { None, Low, Medium, High };

struct StructType;

struct Type {
    BaseType base = BaseType::Error;
    uint8_t cols = 1;  // matrices: number of columns; otherwise 1
    uint8_t rows = 1;  // vectors: number of components; matrices: rows
    // Samplers
    SamplerDim sampler_dim = SamplerDim::None;
    bool sampler_shadow = false;
    BaseType sampler_result = BaseType::Float;  // isampler*/usampler* return int/uint
    std::shared_ptr<const StructType> struct_type;
    int array_size = 0;  // 0: not an array; -1: unsized (only before an initializer sizes it)

    static Type scalar(BaseType b) { Type t; t.base = b; return t; }
    static Type vector(BaseType b, int n) { Type t; t.base = b; t.rows = uint8_t(n); return t; }
    static Type matrix(int c, int r) { Type t; t.base = BaseType::Float; t.cols = uint8_t(c); t.rows = uint8_t(r); return t; }
    static Type void_type() { return scalar(BaseType::Void); }
    static Type error() { return scalar(BaseType::Error); }

    bool is_error() const { return base == BaseType::Error; }
    bool is_void() const { return base == BaseType::Void && array_size == 0; }
    bool is_array() const { return array_size != 0; }
    bool is_scalar() const { return !is_array() && cols == 1 && rows == 1 && is_numeric_or_bool(); }
    bool is_vector() const { return !is_array() && cols == 1 && rows > 1; }
    bool is_matrix() const { return !is_array() && cols > 1; }
    bool is_numeric_or_bool() const { return base == BaseType::Float || base == BaseType::Int || base == BaseType::Uint || base == BaseType::Bool; }
    bool is_basic() const { return !is_array() && is_numeric_or_bool(); }  // scalar, vector or matrix
    bool is_sampler() const { return base == BaseType::Sampler; }
    bool is_struct() const { return base == BaseType::Struct; }
    bool is_integer() const { return base == BaseType::Int || base == BaseType::Uint; }
    bool contains_sampler() const;
    bool contains_array() const;

    Type element_type() const { Type t = *this; t.array_size = 0; return t; }
    Type component_type() const { Type t = element_type(); t.cols = 1; t.rows = 1; return t; }  // scalar of same base
    Type column_type() const { Type t = element_type(); t.cols = 1; return t; }

    int element_components() const;  // scalars in one element
    int components() const { return element_components() * (array_size > 0 ? array_size : 1); }
    std::string name() const;  // GLSL spelling, e.g. "vec3", "float[4]"
    uint32_t gl_enum() const;   // GL_FLOAT_VEC3 etc. for reflection (0 for structs)
};

bool operator==(const Type& a, const Type& b);
inline bool operator!=(const Type& a, const Type& b) { return !(a == b); }

struct StructField {
    std::string name;
    Type type;
    Precision precision = Precision::None;
};

struct StructType {
    std::string name;
    std::vector<StructField> fields;
    int id = 0;  // unique per declaration: two structs are equal only if the same declaration
    int nesting = 1;  // 1, or 1 + the nesting of the deepest struct among the fields
};

// Parses a built-in type name ("vec3", "mat2x4", "usampler2D", ...). Returns false if not one.
bool builtin_type_from_name(const std::string& name, int version, Type& out);

}  // namespace softgl::glsl
