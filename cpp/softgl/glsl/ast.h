// The abstract syntax tree. The parser builds it; the checker fills in types, constant values
// and resolved symbols; lowering turns it into IR.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "softgl/glsl/types.h"

namespace softgl::glsl {

// One 32-bit scalar of a constant value: float, int, uint or bool (0/1) by the owning type.
union Scalar {
    float f;
    int32_t i;
    uint32_t u;
};
using ConstantValue = std::vector<Scalar>;

enum class StorageQualifier : uint8_t { None, Const, Attribute, Uniform, Varying, In, Out, InOut };
enum class Interpolation : uint8_t { Default, Smooth, Flat };

struct Expr;
struct Stmt;
using ExprPtr = std::unique_ptr<Expr>;
using StmtPtr = std::unique_ptr<Stmt>;

struct StructDecl;

// A type as written: qualifiers + type name or struct definition + optional array size.
struct TypeSpec {
    int line = 0;
    StorageQualifier storage = StorageQualifier::None;
    Interpolation interpolation = Interpolation::Default;
    bool invariant = false;
    bool centroid = false;
    Precision precision = Precision::None;
    int layout_location = -1;
    std::string type_name;                 // built-in or struct name; empty if struct_decl
    std::shared_ptr<StructDecl> struct_decl;
    bool is_array = false;
    ExprPtr array_size;                    // null with is_array: unsized "[]"
};

struct VarDecl {
    int line = 0;
    std::string name;
    bool is_array = false;
    ExprPtr array_size;
    ExprPtr initializer;
    struct Symbol* symbol = nullptr;  // set by the checker
};

struct StructDecl {
    int line = 0;
    std::string name;
    struct Member {
        int line;
        TypeSpec type;
        std::vector<VarDecl> names;
    };
    std::vector<Member> members;
    std::shared_ptr<const StructType> resolved;  // set by the checker
};

// Variables, parameters, functions' symbols (owned by the checker's symbol table).
struct Symbol {
    std::string name;
    Type type;
    Precision precision = Precision::None;
    StorageQualifier storage = StorageQualifier::None;
    Interpolation interpolation = Interpolation::Default;
    bool invariant = false;
    int layout_location = -1;
    int line = 0;
    bool is_builtin = false;     // gl_Position, gl_FragCoord, ...
    bool is_parameter = false;
    bool is_global = false;
    bool has_constant_value = false;
    ConstantValue constant_value;  // for const variables with constant initializers
    bool statically_used = false;  // referenced by code reachable from main (set during lowering)
    bool written = false;
    uint32_t writes = 0;         // l-values naming it checked so far (a loop body's writes: checker)
    int id = 0;
};

enum class ExprKind : uint8_t {
    IntLiteral, UintLiteral, FloatLiteral, BoolLiteral,
    Identifier,
    Unary,        // op: "-", "+", "!", "~", "++", "--" (prefix)
    Postfix,      // op: "++", "--"
    Binary,       // op: arithmetic, logical, relational, bitwise, ","
    Assign,       // op: "=", "+=", ...
    Ternary,
    Call,         // function call or constructor; name = function or type name
    Index,
    Field,        // struct field or swizzle; name = field text
};

struct FunctionDef;

struct Expr {
    ExprKind kind;
    int line = 0;
    std::string op;
    std::string name;
    std::vector<ExprPtr> kids;
    Scalar literal{};
    // Constructors written with a type specifier (also array constructors "float[3](...)").
    std::unique_ptr<TypeSpec> constructor_type;

    // Filled in by the checker.
    Type type = Type::error();
    Precision precision = Precision::None;
    bool is_constant = false;     // a constant expression (ES 3.00 §4.3.3)
    ConstantValue constant;       // its value, when is_constant and computable
    Symbol* symbol = nullptr;     // Identifier
    FunctionDef* callee = nullptr;  // user function call
    int builtin_id = -1;          // built-in function call (index into the builtin table)
    bool is_constructor = false;
    bool is_swizzle = false;
    std::vector<uint8_t> swizzle;  // component indices
    int field_index = -1;          // struct field
    bool is_length_method = false; // a.length()

    Expr(ExprKind k, int l) : kind(k), line(l) {}
    Expr(const Expr&) = delete;
    Expr& operator=(const Expr&) = delete;
    // Frees the subtree without recursion: `u + u + ... + u` is a left spine as long as the
    // source, deeper than any stack.
    ~Expr() {
        std::vector<ExprPtr> pending;
        for (ExprPtr& k : kids) pending.push_back(std::move(k));
        while (!pending.empty()) {
            ExprPtr e = std::move(pending.back());
            pending.pop_back();
            if (!e) continue;
            for (ExprPtr& k : e->kids) pending.push_back(std::move(k));
        }
    }
};

enum class StmtKind : uint8_t {
    Block, Declaration, Expression, If, For, While, DoWhile, Switch, Case, Default,
    Break, Continue, Return, Discard, Empty,
};

struct Stmt {
    StmtKind kind;
    int line = 0;
    std::vector<StmtPtr> body;     // Block, Switch body; If: [then, else]; loops: [body]; For: [init, body]
    ExprPtr condition;             // If, While, DoWhile, For (may be null), Switch (selector), Case label
    ExprPtr expression;            // Expression, Return value, For increment
    std::unique_ptr<TypeSpec> decl_type;  // Declaration
    std::vector<VarDecl> decls;
    bool new_scope = true;         // a Block that is a function body shares the parameters' scope
    // For: the most iterations it can run when it is a counted loop (constant start, bound and
    // step; the body never writes the index), else -1. Set by the checker; bounds a shader's work.
    int64_t max_trips = -1;
    // For with an int index among those counted: the index and its first value and step (the
    // lowering unrolls small such loops, lower.cpp).
    const Symbol* counted_int_index = nullptr;
    int64_t counted_start = 0, counted_step = 0;

    Stmt(StmtKind k, int l) : kind(k), line(l) {}
};

struct Parameter {
    int line = 0;
    StorageQualifier direction = StorageQualifier::In;  // In, Out, InOut
    bool is_const = false;
    TypeSpec type;
    std::string name;
    bool is_array = false;
    ExprPtr array_size;
    Symbol* symbol = nullptr;
};

struct FunctionDef {
    int line = 0;
    TypeSpec return_type;
    std::string name;
    std::vector<Parameter> parameters;
    StmtPtr body;  // null for a prototype

    // Filled in by the checker.
    Type resolved_return = Type::void_type();
    Precision return_precision = Precision::None;
    std::vector<Type> resolved_parameters;
    FunctionDef* definition = nullptr;  // a prototype points to the definition, if any
    std::string mangled;                // name + parameter types, for overload resolution
};

// A top-level declaration, in source order.
struct ExternalDecl {
    enum Kind { Variables, Function, Precision, Invariant, EmptyStruct } kind;
    int line = 0;
    StmtPtr declaration;                    // Variables (a Declaration statement)
    std::unique_ptr<FunctionDef> function;  // Function
    ::softgl::glsl::Precision precision = ::softgl::glsl::Precision::None;  // Precision: "precision highp float;"
    std::string precision_type;
    std::vector<std::string> invariant_names;
};

struct TranslationUnit {
    std::vector<ExternalDecl> decls;
};

}  // namespace softgl::glsl
