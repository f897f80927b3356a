#include "softgl/glsl/parser.h"
#include "softgl/core/work_budget.h"

#include <set>
#include <unordered_set>

namespace softgl::glsl {
namespace {

constexpr int kMaxNesting = 200;  // expression/statement nesting; deeper sources are rejected

const std::unordered_set<std::string>& keywords_100() {
    static const std::unordered_set<std::string> k = {
        "attribute", "const", "uniform", "varying", "break", "continue", "do", "for", "while", "if", "else",
        "in", "out", "inout", "float", "int", "void", "bool", "true", "false", "lowp", "mediump", "highp",
        "precision", "invariant", "discard", "return", "mat2", "mat3", "mat4", "vec2", "vec3", "vec4",
        "ivec2", "ivec3", "ivec4", "bvec2", "bvec3", "bvec4", "sampler2D", "samplerCube", "struct"};
    return k;
}
const std::unordered_set<std::string>& keywords_300() {
    static const std::unordered_set<std::string> k = [] {
        std::unordered_set<std::string> s = keywords_100();
        for (const char* w : {"layout", "centroid", "flat", "smooth", "switch", "case", "default", "uint", "uvec2",
                              "uvec3", "uvec4", "mat2x2", "mat2x3", "mat2x4", "mat3x2", "mat3x3", "mat3x4", "mat4x2",
                              "mat4x3", "mat4x4", "sampler3D", "samplerCubeShadow", "sampler2DShadow",
                              "sampler2DArray", "sampler2DArrayShadow", "isampler2D", "isampler3D", "isamplerCube",
                              "isampler2DArray", "usampler2D", "usampler3D", "usamplerCube", "usampler2DArray"})
            s.insert(w);
        return s;
    }();
    return k;
}

}  // namespace

bool is_keyword(const std::string& word, int version) {
    return version == 300 ? keywords_300().count(word) > 0 : keywords_100().count(word) > 0;
}

bool is_reserved_word(const std::string& word, int version) {
    // ES 1.00 §3.7 and ES 3.00 §3.8: reserved for future use; using one is an error.
    static const std::unordered_set<std::string> common = {
        "asm", "class", "union", "enum", "typedef", "template", "this", "packed", "goto", "inline", "noinline",
        "volatile", "public", "static", "extern", "external", "interface", "long", "short", "double", "half",
        "fixed", "unsigned", "superp", "input", "output", "hvec2", "hvec3", "hvec4", "dvec2", "dvec3", "dvec4",
        "fvec2", "fvec3", "fvec4", "sampler1D", "sampler1DShadow", "sampler2DRect", "sampler2DRectShadow",
        "sizeof", "cast", "namespace", "using", "resource", "patch", "sample", "subroutine", "common",
        "partition", "active", "filter", "image1D", "image2D", "image3D", "imageCube", "iimage1D", "iimage2D",
        "iimage3D", "iimageCube", "uimage1D", "uimage2D", "uimage3D", "uimageCube", "image1DArray",
        "image2DArray", "iimage1DArray", "iimage2DArray", "uimage1DArray", "uimage2DArray", "imageBuffer",
        "iimageBuffer", "uimageBuffer", "sampler1DArray", "sampler1DArrayShadow", "isampler1D",
        "isampler1DArray", "usampler1D", "usampler1DArray", "isampler2DRect", "usampler2DRect",
        "samplerBuffer", "isamplerBuffer", "usamplerBuffer", "sampler2DMS", "isampler2DMS", "usampler2DMS",
        "sampler2DMSArray", "isampler2DMSArray", "usampler2DMSArray", "noperspective", "lowp_", "coherent",
        "restrict", "readonly", "writeonly", "atomic_uint", "dmat2", "dmat3", "dmat4", "row_major"};
    static const std::unordered_set<std::string> only_100 = {
        "switch", "default", "flat", "sampler3D", "sampler2DShadow", "sampler3DRect"};
    static const std::unordered_set<std::string> only_300 = {"attribute", "varying"};
    if (common.count(word)) return true;
    if (version == 100) return only_100.count(word) > 0;
    return only_300.count(word) > 0;
}

namespace {

struct SyntaxError {};

class Parser {
public:
    Parser(const TokenList& tokens, int version, Diagnostics& diagnostics)
        : tokens_(tokens), version_(version), diagnostics_(diagnostics) {
        struct_scopes_.emplace_back();
    }

    TranslationUnit run() {
        TranslationUnit unit;
        try {
            while (!peek().kind_is_end()) external_declaration(unit);
        } catch (const SyntaxError&) {
        }
        return unit;
    }

private:
    // ---- token access ----
    struct Peeked {
        const Token& t;
        bool kind_is_end() const { return t.kind == TokenKind::EndOfInput; }
    };
    Peeked peek(size_t ahead = 0) const {
        size_t i = pos_ + ahead;
        return {tokens_[i < tokens_.size() ? i : tokens_.size() - 1]};
    }
    const Token& tok(size_t ahead = 0) const { return peek(ahead).t; }
    bool at(const char* s, size_t ahead = 0) const {
        const Token& t = tok(ahead);
        return t.kind != TokenKind::Number && t.kind != TokenKind::EndOfInput && t.text == s;
    }
    const Token& next() {
        const Token& t = tok();
        if (pos_ < tokens_.size() - 1) ++pos_;
        return t;
    }
    bool accept(const char* s) {
        if (at(s)) { next(); return true; }
        return false;
    }
    [[noreturn]] void fail(const Token& t, const std::string& message) {
        diagnostics_.error(t.line, message);
        throw SyntaxError{};
    }
    [[noreturn]] void syntax_error() {
        const Token& t = tok();
        if (t.kind == TokenKind::EndOfInput) fail(t, "'' : syntax error: unexpected end of file");
        fail(t, "'" + t.text + "' : syntax error");
    }
    void expect(const char* s) {
        if (!accept(s)) syntax_error();
    }
    struct DepthGuard {
        Parser& p;
        explicit DepthGuard(Parser& parser) : p(parser) {
            if (++p.depth_ > kMaxNesting) p.fail(p.tok(), "'" + p.tok().text + "' : nesting too deep");
        }
        ~DepthGuard() { --p.depth_; }
    };

    bool is_identifier_token(const Token& t) const {
        return t.kind == TokenKind::Identifier && !is_keyword(t.text, version_);
    }
    std::string identifier() {
        const Token& t = tok();
        if (t.kind != TokenKind::Identifier) syntax_error();
        if (is_reserved_word(t.text, version_)) fail(t, "'" + t.text + "' : reserved word");
        if (is_keyword(t.text, version_)) syntax_error();
        next();
        return t.text;
    }

    // ---- types ----
    bool is_struct_name(const std::string& name) const {
        for (auto it = struct_scopes_.rbegin(); it != struct_scopes_.rend(); ++it)
            if (it->count(name)) return true;
        return false;
    }
    bool is_type_name(const Token& t) const {
        if (t.kind != TokenKind::Identifier) return false;
        Type dummy;
        if (builtin_type_from_name(t.text, version_, dummy)) return true;
        return is_struct_name(t.text);
    }
    bool is_qualifier(const Token& t) const {
        static const std::set<std::string> q100 = {"const", "attribute", "uniform", "varying", "invariant",
                                                   "lowp", "mediump", "highp"};
        static const std::set<std::string> q300 = {"const", "uniform", "in", "out", "invariant", "lowp",
                                                   "mediump", "highp", "flat", "smooth", "centroid", "layout"};
        if (t.kind != TokenKind::Identifier) return false;
        return version_ == 300 ? q300.count(t.text) > 0 : q100.count(t.text) > 0;
    }
    // Does a declaration start here (as opposed to an expression statement)?
    bool declaration_starts() const {
        const Token& t = tok();
        if (is_qualifier(t) || at("struct")) return true;
        if (!is_type_name(t)) return false;
        if (at("(", 1)) return false;  // constructor
        if (at("[", 1)) {
            // "float[3](...)" is an array constructor; "float[3] a" a declaration.
            size_t i = 2;
            int depth = 1;
            while (depth > 0 && tok(i).kind != TokenKind::EndOfInput) {
                if (at("[", i)) ++depth;
                if (at("]", i)) --depth;
                ++i;
            }
            return !at("(", i);
        }
        return true;
    }

    void type_qualifiers(TypeSpec& spec) {
        for (;;) {
            const Token& t = tok();
            if (t.kind != TokenKind::Identifier || !is_qualifier(t)) return;
            const std::string& w = t.text;
            auto set_storage = [&](StorageQualifier s) {
                if (spec.storage != StorageQualifier::None) fail(t, "'" + w + "' : more than one storage qualifier");
                spec.storage = s;
            };
            if (w == "const") set_storage(StorageQualifier::Const);
            else if (w == "attribute") set_storage(StorageQualifier::Attribute);
            else if (w == "uniform") set_storage(StorageQualifier::Uniform);
            else if (w == "varying") set_storage(StorageQualifier::Varying);
            else if (w == "in") set_storage(StorageQualifier::In);
            else if (w == "out") set_storage(StorageQualifier::Out);
            else if (w == "invariant") spec.invariant = true;
            else if (w == "centroid") spec.centroid = true;
            else if (w == "flat" || w == "smooth") {
                if (spec.interpolation != Interpolation::Default) fail(t, "'" + w + "' : more than one interpolation qualifier");
                spec.interpolation = w == "flat" ? Interpolation::Flat : Interpolation::Smooth;
            } else if (w == "lowp" || w == "mediump" || w == "highp") {
                if (spec.precision != Precision::None) fail(t, "'" + w + "' : more than one precision qualifier");
                spec.precision = w == "lowp" ? Precision::Low : w == "mediump" ? Precision::Medium : Precision::High;
            } else if (w == "layout") {
                next();
                expect("(");
                for (;;) {
                    const Token& id = tok();
                    if (id.kind != TokenKind::Identifier) syntax_error();
                    next();
                    if (id.text == "location") {
                        expect("=");
                        const Token& n = tok();
                        if (n.kind != TokenKind::Number) syntax_error();
                        next();
                        char* end = nullptr;
                        long v = std::strtol(n.text.c_str(), &end, 0);
                        if (*end != '\0' || v < 0 || v > 4096) fail(n, "'" + n.text + "' : invalid location");
                        spec.layout_location = static_cast<int>(v);
                    } else if (id.text == "std140" || id.text == "shared" || id.text == "packed" ||
                               id.text == "row_major" || id.text == "column_major") {
                        fail(id, "'" + id.text + "' : uniform blocks are not supported");
                    } else {
                        fail(id, "'" + id.text + "' : invalid layout qualifier");
                    }
                    if (accept(")")) break;
                    expect(",");
                }
                continue;
            }
            next();
        }
    }

    void type_specifier(TypeSpec& spec) {
        const Token& t = tok();
        spec.line = t.line;
        if (t.kind == TokenKind::Identifier && (t.text == "lowp" || t.text == "mediump" || t.text == "highp")) {
            type_qualifiers(spec);
        }
        if (at("struct")) {
            spec.struct_decl = struct_specifier();
        } else if (is_type_name(tok())) {
            spec.type_name = next().text;
        } else {
            if (tok().kind == TokenKind::Identifier && is_reserved_word(tok().text, version_))
                fail(tok(), "'" + tok().text + "' : reserved word");
            syntax_error();
        }
        if (at("[")) {
            next();
            spec.is_array = true;
            if (!at("]")) spec.array_size = expression();
            expect("]");
        }
    }

    std::shared_ptr<StructDecl> struct_specifier() {
        DepthGuard guard(*this);
        auto decl = std::make_shared<StructDecl>();
        decl->line = next().line;  // "struct"
        if (tok().kind == TokenKind::Identifier && !at("{")) decl->name = identifier();
        expect("{");
        while (!accept("}")) {
            StructDecl::Member member;
            member.line = tok().line;
            type_qualifiers(member.type);
            type_specifier(member.type);
            do {
                VarDecl v;
                v.line = tok().line;
                v.name = identifier();
                if (accept("[")) {
                    v.is_array = true;
                    if (!at("]")) v.array_size = expression();
                    expect("]");
                }
                member.names.push_back(std::move(v));
            } while (accept(","));
            expect(";");
            decl->members.push_back(std::move(member));
        }
        if (!decl->name.empty()) struct_scopes_.back().insert(decl->name);
        return decl;
    }

    // ---- declarations ----
    StmtPtr declaration_after_type(std::unique_ptr<TypeSpec> spec, int line) {
        auto stmt = std::make_unique<Stmt>(StmtKind::Declaration, line);
        if (at(";")) {
            next();
            stmt->decl_type = std::move(spec);
            return stmt;  // e.g. "struct S { ... };" or "precision"-less empty declaration
        }
        do {
            VarDecl v;
            v.line = tok().line;
            v.name = identifier();
            if (accept("[")) {
                v.is_array = true;
                if (!at("]")) v.array_size = expression();
                expect("]");
            }
            if (accept("=")) v.initializer = assignment_expression();
            stmt->decls.push_back(std::move(v));
        } while (accept(","));
        expect(";");
        stmt->decl_type = std::move(spec);
        return stmt;
    }

    void external_declaration(TranslationUnit& unit) {
        const Token& start = tok();
        ExternalDecl ext;
        ext.line = start.line;
        if (accept(";")) return;  // stray semicolons are tolerated at global scope
        if (at("precision")) {
            next();
            ext.kind = ExternalDecl::Precision;
            const Token& p = next();
            if (p.text == "lowp") ext.precision = Precision::Low;
            else if (p.text == "mediump") ext.precision = Precision::Medium;
            else if (p.text == "highp") ext.precision = Precision::High;
            else fail(p, "'" + p.text + "' : syntax error: expected a precision qualifier");
            if (tok().kind != TokenKind::Identifier) syntax_error();
            ext.precision_type = next().text;
            expect(";");
            unit.decls.push_back(std::move(ext));
            return;
        }
        if (at("invariant") && tok(1).kind == TokenKind::Identifier && !is_type_name(tok(1)) && !is_qualifier(tok(1))) {
            // "invariant gl_Position, vColor;" (ES 3.00 §4.6.1)
            next();
            ext.kind = ExternalDecl::Invariant;
            do ext.invariant_names.push_back(next().text);
            while (accept(","));
            expect(";");
            unit.decls.push_back(std::move(ext));
            return;
        }
        auto spec = std::make_unique<TypeSpec>();
        type_qualifiers(*spec);
        type_specifier(*spec);
        // A function definition or prototype: type name '('
        if (tok().kind == TokenKind::Identifier && at("(", 1)) {
            ext.kind = ExternalDecl::Function;
            ext.function = function_after_name(std::move(spec));
            unit.decls.push_back(std::move(ext));
            return;
        }
        ext.kind = ExternalDecl::Variables;
        ext.declaration = declaration_after_type(std::move(spec), start.line);
        unit.decls.push_back(std::move(ext));
    }

    std::unique_ptr<FunctionDef> function_after_name(std::unique_ptr<TypeSpec> return_type) {
        auto fn = std::make_unique<FunctionDef>();
        fn->line = tok().line;
        fn->name = identifier();
        fn->return_type = std::move(*return_type);
        expect("(");
        if (at("void") && at(")", 1)) {
            next();
        } else if (!at(")")) {
            do {
                Parameter p;
                p.line = tok().line;
                for (;;) {
                    if (accept("const")) { p.is_const = true; continue; }
                    if (accept("in")) { p.direction = StorageQualifier::In; continue; }
                    if (accept("out")) { p.direction = StorageQualifier::Out; continue; }
                    if (accept("inout")) { p.direction = StorageQualifier::InOut; continue; }
                    break;
                }
                type_specifier(p.type);
                if (tok().kind == TokenKind::Identifier) {
                    p.name = identifier();
                    if (accept("[")) {
                        p.is_array = true;
                        if (!at("]")) p.array_size = expression();
                        expect("]");
                    }
                }
                fn->parameters.push_back(std::move(p));
            } while (accept(","));
        }
        expect(")");
        if (accept(";")) return fn;
        if (!at("{")) syntax_error();
        struct_scopes_.emplace_back();
        fn->body = compound_statement(false);
        struct_scopes_.pop_back();
        return fn;
    }

    // ---- statements ----
    StmtPtr compound_statement(bool new_scope) {
        DepthGuard guard(*this);
        auto block = std::make_unique<Stmt>(StmtKind::Block, tok().line);
        block->new_scope = new_scope;
        expect("{");
        if (new_scope) struct_scopes_.emplace_back();
        while (!at("}")) {
            if (tok().kind == TokenKind::EndOfInput) syntax_error();
            block->body.push_back(statement());
        }
        next();
        if (new_scope) struct_scopes_.pop_back();
        return block;
    }

    StmtPtr statement() {
        DepthGuard guard(*this);
        WorkBudget::charge_current(1);   // the compile's work budget (core/work_budget.h)
        const Token& t = tok();
        int line = t.line;
        if (at("{")) return compound_statement(true);
        if (accept(";")) return std::make_unique<Stmt>(StmtKind::Empty, line);
        if (at("if")) {
            next();
            auto s = std::make_unique<Stmt>(StmtKind::If, line);
            expect("(");
            s->condition = expression();
            expect(")");
            s->body.push_back(scoped_statement());
            if (accept("else")) s->body.push_back(scoped_statement());
            return s;
        }
        if (at("while")) {
            next();
            auto s = std::make_unique<Stmt>(StmtKind::While, line);
            expect("(");
            s->condition = condition_or_declaration();
            expect(")");
            s->body.push_back(scoped_statement());
            return s;
        }
        if (at("do")) {
            next();
            auto s = std::make_unique<Stmt>(StmtKind::DoWhile, line);
            s->body.push_back(scoped_statement());
            expect("while");
            expect("(");
            s->condition = expression();
            expect(")");
            expect(";");
            return s;
        }
        if (at("for")) {
            next();
            auto s = std::make_unique<Stmt>(StmtKind::For, line);
            expect("(");
            struct_scopes_.emplace_back();
            if (accept(";")) s->body.push_back(std::make_unique<Stmt>(StmtKind::Empty, line));
            else s->body.push_back(simple_statement());
            if (!at(";")) s->condition = condition_or_declaration();
            expect(";");
            if (!at(")")) s->expression = expression();
            expect(")");
            s->body.push_back(scoped_statement());
            struct_scopes_.pop_back();
            return s;
        }
        if (version_ == 300 && at("switch")) {
            next();
            auto s = std::make_unique<Stmt>(StmtKind::Switch, line);
            expect("(");
            s->condition = expression();
            expect(")");
            s->body.push_back(compound_statement(true));
            return s;
        }
        if (version_ == 300 && at("case")) {
            next();
            auto s = std::make_unique<Stmt>(StmtKind::Case, line);
            s->condition = expression();
            expect(":");
            return s;
        }
        if (version_ == 300 && at("default")) {
            next();
            expect(":");
            return std::make_unique<Stmt>(StmtKind::Default, line);
        }
        if (at("break")) { next(); expect(";"); return std::make_unique<Stmt>(StmtKind::Break, line); }
        if (at("continue")) { next(); expect(";"); return std::make_unique<Stmt>(StmtKind::Continue, line); }
        if (at("discard")) { next(); expect(";"); return std::make_unique<Stmt>(StmtKind::Discard, line); }
        if (at("return")) {
            next();
            auto s = std::make_unique<Stmt>(StmtKind::Return, line);
            if (!at(";")) s->expression = expression();
            expect(";");
            return s;
        }
        return simple_statement();
    }

    // A sub-statement of if/while/for: not a new scope unless it is a block (ES 3.00 §6.3),
    // but declarations in it are local to it.
    StmtPtr scoped_statement() {
        struct_scopes_.emplace_back();
        StmtPtr s = statement();
        struct_scopes_.pop_back();
        return s;
    }

    StmtPtr simple_statement() {
        int line = tok().line;
        if (at("precision")) {
            // A precision statement inside a block: recorded as a declaration with no names.
            next();
            auto spec = std::make_unique<TypeSpec>();
            spec->line = line;
            const Token& p = next();
            if (p.text == "lowp") spec->precision = Precision::Low;
            else if (p.text == "mediump") spec->precision = Precision::Medium;
            else if (p.text == "highp") spec->precision = Precision::High;
            else fail(p, "'" + p.text + "' : syntax error: expected a precision qualifier");
            if (tok().kind != TokenKind::Identifier) syntax_error();
            spec->type_name = next().text;
            expect(";");
            auto s = std::make_unique<Stmt>(StmtKind::Declaration, line);
            s->decl_type = std::move(spec);
            s->new_scope = false;  // marks a precision statement
            return s;
        }
        if (declaration_starts()) {
            auto spec = std::make_unique<TypeSpec>();
            type_qualifiers(*spec);
            type_specifier(*spec);
            return declaration_after_type(std::move(spec), line);
        }
        auto s = std::make_unique<Stmt>(StmtKind::Expression, line);
        s->expression = expression();
        expect(";");
        return s;
    }

    // "while (bool b = x)" declares a variable in the condition (ES 3.00 §6.3); rare, but legal.
    ExprPtr condition_or_declaration() {
        if (declaration_starts()) fail(tok(), "'" + tok().text + "' : declarations in loop conditions are not supported");
        return expression();
    }

    // ---- expressions ----
    ExprPtr expression() {
        DepthGuard guard(*this);
        ExprPtr e = assignment_expression();
        while (at(",")) {
            int line = next().line;
            auto c = std::make_unique<Expr>(ExprKind::Binary, line);
            c->op = ",";
            c->kids.push_back(std::move(e));
            c->kids.push_back(assignment_expression());
            e = std::move(c);
        }
        return e;
    }

    ExprPtr assignment_expression() {
        DepthGuard guard(*this);
        ExprPtr lhs = conditional_expression();
        static const char* const ops[] = {"=", "+=", "-=", "*=", "/=", "%=", "<<=", ">>=", "&=", "|=", "^="};
        for (const char* op : ops) {
            if (at(op)) {
                int line = next().line;
                auto a = std::make_unique<Expr>(ExprKind::Assign, line);
                a->op = op;
                a->kids.push_back(std::move(lhs));
                a->kids.push_back(assignment_expression());
                return a;
            }
        }
        return lhs;
    }

    ExprPtr conditional_expression() {
        DepthGuard guard(*this);
        ExprPtr c = binary_expression(0);
        if (at("?")) {
            int line = next().line;
            auto t = std::make_unique<Expr>(ExprKind::Ternary, line);
            t->kids.push_back(std::move(c));
            t->kids.push_back(expression());
            expect(":");
            t->kids.push_back(assignment_expression());
            return t;
        }
        return c;
    }

    static int binary_precedence(const Token& t) {
        if (t.kind != TokenKind::Punctuator) return -1;
        static const std::pair<const char*, int> table[] = {
            {"||", 0}, {"^^", 1}, {"&&", 2}, {"|", 3}, {"^", 4}, {"&", 5}, {"==", 6}, {"!=", 6}, {"<", 7}, {">", 7},
            {"<=", 7}, {">=", 7}, {"<<", 8}, {">>", 8}, {"+", 9}, {"-", 9}, {"*", 10}, {"/", 10}, {"%", 10}};
        for (const auto& [op, p] : table) if (t.text == op) return p;
        return -1;
    }

    ExprPtr binary_expression(int min_precedence) {
        DepthGuard guard(*this);
        ExprPtr lhs = unary_expression();
        for (;;) {
            int p = binary_precedence(tok());
            if (p < 0 || p < min_precedence) return lhs;
            const Token& op = next();
            auto b = std::make_unique<Expr>(ExprKind::Binary, op.line);
            b->op = op.text;
            b->kids.push_back(std::move(lhs));
            b->kids.push_back(binary_expression(p + 1));
            lhs = std::move(b);
        }
    }

    ExprPtr unary_expression() {
        DepthGuard guard(*this);
        if (at("+") || at("-") || at("!") || at("~") || at("++") || at("--")) {
            const Token& op = next();
            auto u = std::make_unique<Expr>(ExprKind::Unary, op.line);
            u->op = op.text;
            u->kids.push_back(unary_expression());
            return u;
        }
        return postfix_expression();
    }

    ExprPtr postfix_expression() {
        ExprPtr e = primary_expression();
        for (int count = 0;; ++count) {
            if (count > kMaxNesting) fail(tok(), "'" + tok().text + "' : expression too complex");
            if (at("[")) {
                int line = next().line;
                auto i = std::make_unique<Expr>(ExprKind::Index, line);
                i->kids.push_back(std::move(e));
                i->kids.push_back(expression());
                expect("]");
                e = std::move(i);
            } else if (at(".")) {
                int line = next().line;
                const Token& f = tok();
                if (f.kind != TokenKind::Identifier) syntax_error();
                next();
                if (f.text == "length" && at("(")) {
                    // array.length() (ES 3.00 §5.9)
                    next();
                    expect(")");
                    auto c = std::make_unique<Expr>(ExprKind::Call, line);
                    c->name = "length";
                    c->is_length_method = true;
                    c->kids.push_back(std::move(e));
                    e = std::move(c);
                    continue;
                }
                auto fe = std::make_unique<Expr>(ExprKind::Field, line);
                fe->name = f.text;
                fe->kids.push_back(std::move(e));
                e = std::move(fe);
            } else if (at("++") || at("--")) {
                const Token& op = next();
                auto p = std::make_unique<Expr>(ExprKind::Postfix, op.line);
                p->op = op.text;
                p->kids.push_back(std::move(e));
                e = std::move(p);
            } else {
                return e;
            }
        }
    }

    ExprPtr primary_expression() {
        DepthGuard guard(*this);
        const Token& t = tok();
        int line = t.line;
        if (t.kind == TokenKind::Number) {
            next();
            return number_literal(t);
        }
        if (at("true") || at("false")) {
            next();
            auto e = std::make_unique<Expr>(ExprKind::BoolLiteral, line);
            e->literal.i = t.text == "true";
            return e;
        }
        if (accept("(")) {
            ExprPtr e = expression();
            expect(")");
            return e;
        }
        if (at("struct")) fail(t, "'struct' : struct declarations are not allowed in expressions");
        if (is_type_name(t)) {
            // Constructor: type "(" args ")" or type "[" size? "]" "(" args ")"
            auto call = std::make_unique<Expr>(ExprKind::Call, line);
            call->constructor_type = std::make_unique<TypeSpec>();
            type_specifier(*call->constructor_type);
            call->name = call->constructor_type->type_name;
            call_arguments(*call);
            return call;
        }
        if (t.kind == TokenKind::Identifier) {
            if (is_reserved_word(t.text, version_)) fail(t, "'" + t.text + "' : reserved word");
            if (is_keyword(t.text, version_)) syntax_error();
            next();
            if (at("(")) {
                auto call = std::make_unique<Expr>(ExprKind::Call, line);
                call->name = t.text;
                call_arguments(*call);
                return call;
            }
            auto id = std::make_unique<Expr>(ExprKind::Identifier, line);
            id->name = t.text;
            return id;
        }
        syntax_error();
    }

    void call_arguments(Expr& call) {
        expect("(");
        if (at("void") && at(")", 1)) { next(); next(); return; }
        if (accept(")")) return;
        do call.kids.push_back(assignment_expression());
        while (accept(","));
        expect(")");
    }

    ExprPtr number_literal(const Token& t) {
        const std::string& s = t.text;
        bool is_float = false;
        bool is_hex = s.size() > 1 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
        if (!is_hex)
            for (char c : s) if (c == '.' || c == 'e' || c == 'E') is_float = true;
        if (is_float || (!is_hex && (s.back() == 'f' || s.back() == 'F'))) {
            std::string body = s;
            if (body.back() == 'f' || body.back() == 'F') {
                if (version_ < 300) fail(t, "'" + s + "' : floating-point suffix is not allowed in GLSL ES 1.00");
                body.pop_back();
            }
            // Validate: digits [. digits] [e [+-] digits]
            size_t i = 0;
            bool digits = false;
            while (i < body.size() && std::isdigit(static_cast<unsigned char>(body[i]))) { ++i; digits = true; }
            if (i < body.size() && body[i] == '.') { ++i; while (i < body.size() && std::isdigit(static_cast<unsigned char>(body[i]))) { ++i; digits = true; } }
            if (!digits) fail(t, "'" + s + "' : invalid floating-point constant");
            if (i < body.size() && (body[i] == 'e' || body[i] == 'E')) {
                ++i;
                if (i < body.size() && (body[i] == '+' || body[i] == '-')) ++i;
                size_t start = i;
                while (i < body.size() && std::isdigit(static_cast<unsigned char>(body[i]))) ++i;
                if (i == start) fail(t, "'" + s + "' : invalid floating-point constant");
            }
            if (i != body.size()) fail(t, "'" + s + "' : invalid floating-point constant");
            auto e = std::make_unique<Expr>(ExprKind::FloatLiteral, t.line);
            // Correctly rounded decimal -> float (strtof rounds to nearest).
            e->literal.f = std::strtof(body.c_str(), nullptr);
            return e;
        }
        std::string body = s;
        bool is_unsigned = false;
        if (body.back() == 'u' || body.back() == 'U') {
            if (version_ < 300) fail(t, "'" + s + "' : unsigned integer suffix is not allowed in GLSL ES 1.00");
            is_unsigned = true;
            body.pop_back();
        }
        int base = 10;
        size_t start = 0;
        if (is_hex) { base = 16; start = 2; }
        else if (body.size() > 1 && body[0] == '0') { base = 8; start = 1; }
        if (start >= body.size() && base == 16) fail(t, "'" + s + "' : invalid integer constant");
        uint64_t value = 0;
        bool overflow = false;
        for (size_t i = start; i < body.size(); ++i) {
            char c = body[i];
            int d = std::isdigit(static_cast<unsigned char>(c)) ? c - '0'
                    : (c >= 'a' && c <= 'f') ? c - 'a' + 10 : (c >= 'A' && c <= 'F') ? c - 'A' + 10 : 99;
            if (d >= base) fail(t, "'" + s + "' : invalid integer constant");
            value = value * base + d;
            if (value > 0xffffffffull) overflow = true;
        }
        // ES 3.00 §4.1.3: an integer literal that does not fit 32 bits is an error. A decimal
        // int literal above 2^31-1 also is, except 2147483648 under unary minus (we accept it).
        if (overflow) fail(t, "'" + s + "' : integer constant overflow");
        if (!is_unsigned && base == 10 && value > 0x80000000ull) fail(t, "'" + s + "' : integer constant overflow");
        auto e = std::make_unique<Expr>(is_unsigned ? ExprKind::UintLiteral : ExprKind::IntLiteral, t.line);
        e->literal.u = static_cast<uint32_t>(value);
        return e;
    }

    const TokenList& tokens_;
    int version_;
    Diagnostics& diagnostics_;
    size_t pos_ = 0;
    int depth_ = 0;
    std::vector<std::set<std::string>> struct_scopes_;
};

}  // namespace

TranslationUnit parse(const TokenList& tokens, int version, Diagnostics& diagnostics) {
    return Parser(tokens, version, diagnostics).run();
}

}  // namespace softgl::glsl
