#include "softgl/glsl/preprocessor.h"
#include "softgl/core/work_budget.h"

#include <cstdint>
#include <cstdlib>
#include <set>
#include <unordered_map>

#include "softgl/glsl/lexer.h"

namespace softgl::glsl {
namespace {

// Limits that keep hostile sources from exhausting time or memory.
constexpr size_t kMaxExpansionTokens = size_t(1) << 21;  // tokens of macro-expansion work per shader
constexpr int kMaxExpansionDepth = 64;
constexpr int kMaxConditionalDepth = 64;
constexpr size_t kMaxMacroArguments = 256;

struct Macro {
    bool function_like = false;
    bool predefined = false;
    std::vector<std::string> parameters;
    TokenList body;
};

bool same_body(const Macro& a, const Macro& b) {
    if (a.function_like != b.function_like || a.parameters != b.parameters || a.body.size() != b.body.size()) return false;
    for (size_t i = 0; i < a.body.size(); ++i) {
        if (a.body[i].text != b.body[i].text) return false;
        if (i > 0 && a.body[i].leading_space != b.body[i].leading_space) return false;
    }
    return true;
}

class Preprocessor {
public:
    Preprocessor(Stage stage, int webgl_version, Diagnostics& diagnostics, const std::set<std::string>* enabled)
        : stage_(stage), webgl_version_(webgl_version), enabled_(enabled), diagnostics_(diagnostics) {}

    PreprocessedSource run(const std::string& source) {
        input_ = tokenize(source, diagnostics_);
        define_predefined("GL_ES", "1");
        define_predefined("__VERSION__", "100");
        if (stage_ == Stage::Fragment) define_predefined("GL_FRAGMENT_PRECISION_HIGH", "1");
        macros_["__LINE__"] = Macro{false, true, {}, {}};
        macros_["__FILE__"] = Macro{false, true, {}, {}};

        while (pos_ < input_.size() && input_[pos_].kind != TokenKind::EndOfInput && !aborted_) {
            // Each iteration handles one logical line.
            const Token& first = input_[pos_];
            if (first.kind == TokenKind::Newline) { ++pos_; continue; }
            if (first.is("#")) {
                ++pos_;
                directive(first);
            } else {
                text_line();
            }
            seen_first_line_ = true;
        }
        if (!conditionals_.empty() && !aborted_)
            diagnostics_.error(line_of_end(), "unexpected end of file: missing #endif");
        Token end;
        end.kind = TokenKind::EndOfInput;
        end.line = line_of_end();
        out_.tokens.push_back(end);
        return std::move(out_);
    }

private:
    // ---- helpers over the raw token stream ----
    int line_offset_ = 0;  // #line adjusts reported lines by this much
    int line(const Token& t) const { return t.line + line_offset_; }
    int line_of_end() const { return input_.empty() ? 1 : line(input_.back()); }

    TokenList rest_of_line() {
        TokenList line_tokens;
        while (pos_ < input_.size() && input_[pos_].kind != TokenKind::Newline && input_[pos_].kind != TokenKind::EndOfInput)
            line_tokens.push_back(input_[pos_++]);
        if (pos_ < input_.size() && input_[pos_].kind == TokenKind::Newline) ++pos_;
        for (Token& t : line_tokens) t.line = line(t);
        WorkBudget::charge_current(line_tokens.size() + 1);   // the compile's work budget
        return line_tokens;
    }

    bool skipping() const {
        return !conditionals_.empty() && !conditionals_.back().active;
    }

    void define_predefined(const std::string& name, const std::string& value) {
        Macro m;
        m.predefined = true;
        Token t;
        t.kind = TokenKind::Number;
        t.text = value;
        m.body.push_back(t);
        macros_[name] = m;
    }

    // ---- ordinary lines ----
    void text_line() {
        TokenList line_tokens = rest_of_line();
        if (skipping()) return;
        if (!line_tokens.empty()) seen_non_preprocessor_token_ = true;
        allow_pull_ = true;
        expand(line_tokens, out_.tokens, 0);
        allow_pull_ = false;
    }

    // Counts `n` tokens of macro-expansion work (tokens a macro produces, argument and
    // continuation copies). Past kMaxExpansionTokens the expansion stops with an error: a few
    // hundred bytes of nested macros can ask for 2^256 tokens (ES 3.00 §3.4 sets no limit).
    bool spend(size_t n, int line) {
        expansion_tokens_ += n;
        if (expansion_tokens_ <= kMaxExpansionTokens) return true;
        if (!aborted_)
            diagnostics_.error(line, "'" + outer_macro_ + "' : macro expansion exceeds the limit of " +
                                         std::to_string(kMaxExpansionTokens) + " tokens");
        expansion_error_ = true;
        aborted_ = true;
        return false;
    }

    // Macro expansion (C-like, without # and ##, which GLSL ES does not have).
    // Tokens produced by a macro are rescanned with that macro's name disabled. Only the work
    // of macro invocations counts against the expansion limit: other source passes through.
    void expand(const TokenList& input, TokenList& out, int depth) {
        if (depth > kMaxExpansionDepth) {
            if (!expansion_error_)
                diagnostics_.error(input.empty() ? 0 : input[0].line,
                                   "macro expansion nested more than " + std::to_string(kMaxExpansionDepth) + " levels deep");
            expansion_error_ = true;
            return;
        }
        // An invocation whose arguments continue on following lines continues this loop on
        // the rest of the joined lines (a loop, not recursion: lines are unbounded).
        TokenList continued;
        const TokenList* current = &input;
        for (size_t i = 0; i < current->size(); ++i) {
            if (aborted_) return;
            const TokenList& in = *current;
            const Token& t = in[i];
            if (depth > 0 && !spend(1, t.line)) return;
            if (t.kind == TokenKind::Invalid) {
                diagnostics_.error(t.line, "'" + t.text + "' : invalid character");
                continue;
            }
            if (t.is("#") || t.is("##")) {
                diagnostics_.error(t.line, "'" + t.text + "' : unexpected token");
                continue;
            }
            if (t.kind != TokenKind::Identifier || disabled_.count(t.text) || !macros_.count(t.text)) {
                out.push_back(t);
                continue;
            }
            if (t.text == "__LINE__" || t.text == "__FILE__") {
                Token n = t;
                n.kind = TokenKind::Number;
                n.text = t.text == "__LINE__" ? std::to_string(t.line) : "0";
                out.push_back(n);
                continue;
            }
            if (depth == 0) outer_macro_ = t.text;
            const Macro& macro = macros_[t.text];
            if (!macro.function_like) {
                if (!spend(macro.body.size(), t.line)) return;
                TokenList body = macro.body;
                for (Token& b : body) b.line = t.line;
                if (!body.empty()) body[0].leading_space = t.leading_space;
                disabled_.insert(t.text);
                expand(body, out, depth + 1);
                disabled_.erase(t.text);
                continue;
            }
            // Function-like: needs '(' next; arguments may continue on following lines.
            size_t j = i + 1;
            bool from_input = false;
            if (j >= in.size() && depth == 0 && allow_pull_) {
                // Look ahead into following lines of the raw input (skipping newlines).
                size_t k = pos_;
                while (k < input_.size() && input_[k].kind == TokenKind::Newline) ++k;
                if (k < input_.size() && input_[k].is("(") ) from_input = true;
            }
            if (!from_input && (j >= in.size() || !in[j].is("("))) {
                out.push_back(t);
                continue;
            }
            TokenList pulled;
            if (from_input) {
                // Append the continuation lines to the current line so that argument collection sees them.
                pulled.assign(in.begin(), in.end());
                int parens = 0;
                bool started = false;
                while (pos_ < input_.size() && input_[pos_].kind != TokenKind::EndOfInput) {
                    Token n = input_[pos_++];
                    if (n.kind == TokenKind::Newline) continue;
                    if (n.is("#") && !started) break;
                    n.line = line(n);
                    pulled.push_back(n);
                    if (n.is("(")) { ++parens; started = true; }
                    if (n.is(")")) { if (--parens == 0) break; }
                }
                if (!spend(pulled.size(), t.line)) return;
            }
            const TokenList& src = from_input ? pulled : in;
            std::vector<TokenList> args;
            size_t k = j + 1;
            int parens = 0;
            TokenList current_arg;
            bool closed = false;
            for (; k < src.size(); ++k) {
                const Token& a = src[k];
                if (a.is("(")) ++parens;
                if (a.is(")")) {
                    if (parens == 0) { closed = true; break; }
                    --parens;
                }
                if (a.is(",") && parens == 0) {
                    args.push_back(current_arg);
                    current_arg.clear();
                    if (args.size() > kMaxMacroArguments) break;
                    continue;
                }
                if (!spend(1, t.line)) return;
                current_arg.push_back(a);
            }
            if (!closed) {
                diagnostics_.error(t.line, "'" + t.text + "' : unterminated macro invocation");
                return;
            }
            if (!args.empty() || !current_arg.empty() || !macro.parameters.empty()) args.push_back(current_arg);
            if (args.size() != macro.parameters.size()) {
                diagnostics_.error(t.line, "'" + t.text + "' : wrong number of arguments to macro");
                if (from_input) return;
                i = k;
                continue;
            }
            // Arguments are fully expanded before substitution (C semantics).
            std::vector<TokenList> expanded_args(args.size());
            for (size_t a = 0; a < args.size(); ++a) expand(args[a], expanded_args[a], depth + 1);
            if (aborted_) return;
            TokenList body;
            for (const Token& b : macro.body) {
                size_t p = 0;
                for (; p < macro.parameters.size(); ++p)
                    if (b.kind == TokenKind::Identifier && b.text == macro.parameters[p]) break;
                if (p < macro.parameters.size()) {
                    if (!spend(expanded_args[p].size(), t.line)) return;
                    for (Token e : expanded_args[p]) { e.line = t.line; body.push_back(e); }
                } else {
                    if (!spend(1, t.line)) return;
                    Token c = b;
                    c.line = t.line;
                    body.push_back(c);
                }
            }
            disabled_.insert(t.text);
            expand(body, out, depth + 1);
            disabled_.erase(t.text);
            if (from_input) {
                // Whatever followed the ')' on the pulled line, and the rest of the current
                // physical line, are expanded next, at this depth.
                TokenList tail(src.begin() + static_cast<long>(k) + 1, src.end());
                TokenList line_rest = rest_of_line();
                tail.insert(tail.end(), line_rest.begin(), line_rest.end());
                if (!spend(tail.size(), t.line)) return;
                continued = std::move(tail);
                current = &continued;
                i = static_cast<size_t>(-1);  // the loop's ++i makes it 0
                continue;
            }
            i = k;
        }
    }

    // ---- directives ----
    void directive(const Token& hash) {
        TokenList tokens = rest_of_line();
        int line_number = line(hash);
        if (tokens.empty()) return;  // the null directive
        const std::string name = tokens[0].text;
        if (tokens[0].kind != TokenKind::Identifier) {
            if (!skipping()) diagnostics_.error(line_number, "'" + name + "' : invalid directive");
            return;
        }
        // Conditionals are processed even while skipping, to track nesting.
        if (name == "if" || name == "ifdef" || name == "ifndef") {
            if (conditionals_.size() >= kMaxConditionalDepth) {
                diagnostics_.error(line_number, "conditional nesting too deep");
                aborted_ = true;
                return;
            }
            Conditional c;
            c.parent_active = !skipping();
            bool value = false;
            if (c.parent_active) {
                if (name == "if") value = evaluate_condition(tokens, line_number);
                else {
                    if (tokens.size() < 2 || tokens[1].kind != TokenKind::Identifier) {
                        diagnostics_.error(line_number, "'#" + name + "' : expected a macro name");
                    } else {
                        if (tokens.size() > 2) diagnostics_.error(line_number, "'#" + name + "' : unexpected tokens following the macro name");
                        value = macros_.count(tokens[1].text) > 0;
                        if (name == "ifndef") value = !value;
                    }
                }
            }
            c.active = c.parent_active && value;
            c.taken = c.active;
            conditionals_.push_back(c);
            return;
        }
        if (name == "elif" || name == "else" || name == "endif") {
            if (conditionals_.empty()) {
                diagnostics_.error(line_number, "'#" + name + "' : unexpected without #if");
                return;
            }
            Conditional& c = conditionals_.back();
            if (name == "endif") {
                if (tokens.size() > 1 && c.parent_active) diagnostics_.error(line_number, "'#endif' : unexpected tokens following directive");
                conditionals_.pop_back();
                return;
            }
            if (c.seen_else) {
                diagnostics_.error(line_number, "'#" + name + "' : after #else");
                c.active = false;
                return;
            }
            if (name == "else") {
                if (tokens.size() > 1 && c.parent_active) diagnostics_.error(line_number, "'#else' : unexpected tokens following directive");
                c.seen_else = true;
                c.active = c.parent_active && !c.taken;
                c.taken = c.taken || c.active;
                return;
            }
            // #elif: its expression is evaluated only when no earlier group was taken.
            if (c.parent_active && !c.taken) {
                c.active = evaluate_condition(tokens, line_number);
                c.taken = c.active;
            } else {
                c.active = false;
            }
            return;
        }
        if (skipping()) return;

        if (name == "version") {
            if (seen_first_line_ || seen_version_) {
                diagnostics_.error(line_number, "'#version' : must occur first in a shader");
                return;
            }
            seen_version_ = true;
            if (tokens.size() < 2 || tokens[1].kind != TokenKind::Number) {
                diagnostics_.error(line_number, "'#version' : expected a version number");
                return;
            }
            // "#version 100" or "#version 300 es" (ES 3.00 §3.4), and nothing after it.
            const std::string& number = tokens[1].text;
            if (number != "100" && number != "300") {
                diagnostics_.error(line_number, "'#version' : version number " + number + " not supported");
                return;
            }
            if (number == "300" && (tokens.size() < 3 || tokens[2].text != "es")) {
                diagnostics_.error(line_number, "'#version' : version 300 requires 'es'" +
                                                    (tokens.size() < 3 ? std::string() : " (found '" + tokens[2].text + "')"));
                return;
            }
            const size_t length = number == "300" ? 3 : 2;
            if (tokens.size() > length) {
                diagnostics_.error(line_number, "'#version' : unexpected token '" + tokens[length].text + "' after the version");
                return;
            }
            if (number == "300") {
                if (webgl_version_ < 2) {
                    diagnostics_.error(line_number, "'#version' : version number not supported (WebGL 1 accepts GLSL ES 1.00 only)");
                    return;
                }
                out_.version = 300;
                define_predefined("__VERSION__", "300");
            }
            return;
        }
        if (name == "define") { define(tokens, line_number); return; }
        if (name == "undef") {
            if (tokens.size() < 2 || tokens[1].kind != TokenKind::Identifier) {
                diagnostics_.error(line_number, "'#undef' : expected a macro name");
                return;
            }
            auto it = macros_.find(tokens[1].text);
            if (it != macros_.end() && it->second.predefined) {
                diagnostics_.error(line_number, "'" + tokens[1].text + "' : cannot undefine a predefined macro");
                return;
            }
            if (tokens.size() > 2) diagnostics_.error(line_number, "'#undef' : unexpected tokens following the macro name");
            if (it != macros_.end()) macros_.erase(it);
            return;
        }
        if (name == "error") {
            std::string message;
            for (size_t i = 1; i < tokens.size(); ++i) message += (i > 1 && tokens[i].leading_space ? " " : "") + tokens[i].text;
            diagnostics_.error(line_number, "'#error' : " + message);
            return;
        }
        if (name == "pragma") return;  // ES 3.00 §3.4: unrecognised pragmas are ignored
        if (name == "extension") { extension(tokens, line_number); return; }
        if (name == "line") {
            TokenList expanded;
            TokenList args(tokens.begin() + 1, tokens.end());
            expand(args, expanded, 0);
            if (expanded.empty() || expanded.size() > 2 || expanded[0].kind != TokenKind::Number) {
                diagnostics_.error(line_number, "'#line' : expected a line number");
                return;
            }
            char* end = nullptr;
            long value = std::strtol(expanded[0].text.c_str(), &end, 10);
            if (*end != '\0' || value < 0 || value > 0x7fffffff / 2) {
                diagnostics_.error(line_number, "'#line' : invalid line number");
                return;
            }
            if (expanded.size() == 2 && expanded[1].kind != TokenKind::Number) {
                diagnostics_.error(line_number, "'#line' : invalid source string number");
                return;
            }
            // "#line N": the line after this directive has number N (ES 3.00 §3.4).
            line_offset_ = static_cast<int>(value) - (hash.line + 1);
            return;
        }
        diagnostics_.error(line_number, "'" + name + "' : invalid directive");
    }

    void define(const TokenList& tokens, int line_number) {
        if (tokens.size() < 2 || tokens[1].kind != TokenKind::Identifier) {
            diagnostics_.error(line_number, "'#define' : expected a macro name");
            return;
        }
        const std::string& name = tokens[1].text;
        // ES 3.00 §3.4: names beginning with GL_ are reserved; redefining predefined macros is an error.
        if (name.compare(0, 3, "GL_") == 0) {
            diagnostics_.error(line_number, "'" + name + "' : macro names beginning with \"GL_\" are reserved");
            return;
        }
        if (name.find("__") != std::string::npos) {
            if (name == "__LINE__" || name == "__FILE__" || name == "__VERSION__") {
                diagnostics_.error(line_number, "'" + name + "' : cannot redefine a predefined macro");
                return;
            }
            diagnostics_.warning(line_number, "'" + name + "' : macro names containing \"__\" are reserved");
        }
        if (name == "defined") {
            diagnostics_.error(line_number, "'defined' : cannot be used as a macro name");
            return;
        }
        Macro macro;
        size_t i = 2;
        if (i < tokens.size() && tokens[i].is("(") && !tokens[i].leading_space) {
            macro.function_like = true;
            ++i;
            bool expect_name = true;
            bool closed = false;
            for (; i < tokens.size(); ++i) {
                const Token& p = tokens[i];
                if (p.is(")") && (!expect_name || macro.parameters.empty())) { closed = true; ++i; break; }
                if (expect_name && p.kind == TokenKind::Identifier) {
                    for (const std::string& q : macro.parameters)
                        if (q == p.text) { diagnostics_.error(line_number, "'" + p.text + "' : duplicate macro parameter name"); return; }
                    macro.parameters.push_back(p.text);
                    expect_name = false;
                } else if (!expect_name && p.is(",")) {
                    expect_name = true;
                } else {
                    break;
                }
            }
            if (!closed) {
                diagnostics_.error(line_number, "'" + name + "' : invalid macro parameter list");
                return;
            }
        }
        macro.body.assign(tokens.begin() + static_cast<long>(i), tokens.end());
        for (const Token& b : macro.body) {
            if (b.is("##")) { diagnostics_.error(line_number, "'##' : token pasting is not supported in GLSL ES"); return; }
        }
        auto it = macros_.find(name);
        if (it != macros_.end()) {
            if (it->second.predefined) {
                diagnostics_.error(line_number, "'" + name + "' : cannot redefine a predefined macro");
                return;
            }
            if (!same_body(it->second, macro)) {
                diagnostics_.error(line_number, "'" + name + "' : macro redefined with a different body");
                return;
            }
        }
        macros_[name] = std::move(macro);
    }

    void extension(const TokenList& tokens, int line_number) {
        if (tokens.size() != 4 || tokens[1].kind != TokenKind::Identifier || !tokens[2].is(":") ||
            tokens[3].kind != TokenKind::Identifier) {
            diagnostics_.error(line_number, "'#extension' : expected \"#extension name : behavior\"");
            return;
        }
        if (seen_non_preprocessor_token_ && out_.version == 300) {
            // ES 3.00 §3.5: #extension must come before any non-preprocessor token.
            diagnostics_.error(line_number, "'#extension' : must occur before any non-preprocessor tokens");
            return;
        }
        const std::string& ext = tokens[1].text;
        const std::string& behavior = tokens[3].text;
        ExtensionBehavior b;
        if (behavior == "require") b = ExtensionBehavior::Require;
        else if (behavior == "enable") b = ExtensionBehavior::Enable;
        else if (behavior == "warn") b = ExtensionBehavior::Warn;
        else if (behavior == "disable") b = ExtensionBehavior::Disable;
        else {
            diagnostics_.error(line_number, "'" + behavior + "' : invalid extension behavior");
            return;
        }
        if (ext == "all") {
            if (b == ExtensionBehavior::Require || b == ExtensionBehavior::Enable)
                diagnostics_.error(line_number, "'all' : extension behavior must be 'warn' or 'disable'");
            return;
        }
        // WebGL 1.0 extension registry (OES_standard_derivatives, EXT_frag_depth, ...): a
        // shader's directive takes effect only once getExtension has enabled the extension.
        if (!extension_supported(ext, out_.version, webgl_version_) || (enabled_ && !enabled_->count(ext))) {
            if (b == ExtensionBehavior::Require) diagnostics_.error(line_number, "'" + ext + "' : extension is not supported");
            else if (b != ExtensionBehavior::Disable) diagnostics_.warning(line_number, "'" + ext + "' : extension is not supported");
            return;
        }
        out_.extensions[ext] = b;
        if (b != ExtensionBehavior::Disable) define_predefined(ext, "1");
    }

    // ---- #if expressions: C integer arithmetic (ES 3.00 §3.4) ----
    bool evaluate_condition(const TokenList& tokens, int line_number) {
        // Replace "defined X" and "defined(X)" before macro expansion.
        TokenList replaced;
        for (size_t i = 1; i < tokens.size(); ++i) {
            if (tokens[i].kind == TokenKind::Identifier && tokens[i].text == "defined") {
                size_t j = i + 1;
                bool paren = j < tokens.size() && tokens[j].is("(");
                if (paren) ++j;
                if (j >= tokens.size() || tokens[j].kind != TokenKind::Identifier) {
                    diagnostics_.error(line_number, "'defined' : expected a macro name");
                    return false;
                }
                Token value = tokens[j];
                value.kind = TokenKind::Number;
                value.text = macros_.count(tokens[j].text) ? "1" : "0";
                if (paren) {
                    ++j;
                    if (j >= tokens.size() || !tokens[j].is(")")) {
                        diagnostics_.error(line_number, "'defined' : missing ')'");
                        return false;
                    }
                }
                replaced.push_back(value);
                i = j;
                continue;
            }
            replaced.push_back(tokens[i]);
        }
        TokenList expanded;
        expand(replaced, expanded, 0);
        if (expanded.empty()) {
            diagnostics_.error(line_number, "'#if' : expected an expression");
            return false;
        }
        expr_tokens_ = &expanded;
        expr_pos_ = 0;
        expr_error_ = false;
        expr_line_ = line_number;
        int64_t value = expr_conditional(0);
        if (!expr_error_ && expr_pos_ != expanded.size()) expr_fail("'" + expanded[expr_pos_].text + "' : unexpected token in preprocessor expression");
        return !expr_error_ && value != 0;
    }

    void expr_fail(const std::string& message) {
        if (!expr_error_) diagnostics_.error(expr_line_, message);
        expr_error_ = true;
    }
    const Token* expr_peek() const { return expr_pos_ < expr_tokens_->size() ? &(*expr_tokens_)[expr_pos_] : nullptr; }
    bool expr_accept(const char* p) {
        const Token* t = expr_peek();
        if (t && t->kind == TokenKind::Punctuator && t->text == p) { ++expr_pos_; return true; }
        return false;
    }

    int64_t expr_primary(int depth) {
        if (depth > 200) { expr_fail("preprocessor expression too complex"); return 0; }
        const Token* t = expr_peek();
        if (!t) { expr_fail("unexpected end of preprocessor expression"); return 0; }
        ++expr_pos_;
        if (t->is("(")) {
            int64_t v = expr_conditional(depth + 1);
            if (!expr_accept(")")) expr_fail("missing ')' in preprocessor expression");
            return v;
        }
        if (t->is("-")) return static_cast<int64_t>(0u - static_cast<uint32_t>(expr_primary(depth + 1))) ;
        if (t->is("+")) return expr_primary(depth + 1);
        if (t->is("!")) return !expr_primary(depth + 1);
        if (t->is("~")) return ~expr_primary(depth + 1);
        if (t->kind == TokenKind::Number) {
            const std::string& s = t->text;
            char* end = nullptr;
            int base = 10;
            if (s.size() > 1 && s[0] == '0') base = (s[1] == 'x' || s[1] == 'X') ? 16 : 8;
            unsigned long long v = std::strtoull(s.c_str(), &end, base);
            if (end && (*end == 'u' || *end == 'U') && out_.version == 300) ++end;
            if (!end || *end != '\0') { expr_fail("'" + s + "' : invalid integer constant in preprocessor expression"); return 0; }
            return static_cast<int64_t>(static_cast<int32_t>(static_cast<uint32_t>(v)));
        }
        if (t->kind == TokenKind::Identifier) {
            expr_fail("'" + t->text + "' : undefined identifier in preprocessor expression");
            return 0;
        }
        expr_fail("'" + t->text + "' : unexpected token in preprocessor expression");
        return 0;
    }

    static int precedence(const std::string& op) {
        static const std::unordered_map<std::string, int> table = {
            {"||", 1}, {"&&", 2}, {"|", 3}, {"^", 4}, {"&", 5}, {"==", 6}, {"!=", 6}, {"<", 7}, {">", 7},
            {"<=", 7}, {">=", 7}, {"<<", 8}, {">>", 8}, {"+", 9}, {"-", 9}, {"*", 10}, {"/", 10}, {"%", 10}};
        auto it = table.find(op);
        return it == table.end() ? 0 : it->second;
    }

    int64_t expr_binary(int min_precedence, int depth) {
        int64_t lhs = expr_primary(depth + 1);
        while (!expr_error_) {
            const Token* t = expr_peek();
            if (!t || t->kind != TokenKind::Punctuator) break;
            int p = precedence(t->text);
            if (p == 0 || p < min_precedence) break;
            std::string op = t->text;
            ++expr_pos_;
            int64_t rhs = expr_binary(p + 1, depth + 1);
            // 32-bit two's complement arithmetic, wrapping.
            int32_t a = static_cast<int32_t>(lhs), b = static_cast<int32_t>(rhs);
            uint32_t ua = static_cast<uint32_t>(a), ub = static_cast<uint32_t>(b);
            int32_t r = 0;
            if (op == "||") r = a || b;
            else if (op == "&&") r = a && b;
            else if (op == "|") r = a | b;
            else if (op == "^") r = a ^ b;
            else if (op == "&") r = a & b;
            else if (op == "==") r = a == b;
            else if (op == "!=") r = a != b;
            else if (op == "<") r = a < b;
            else if (op == ">") r = a > b;
            else if (op == "<=") r = a <= b;
            else if (op == ">=") r = a >= b;
            else if (op == "<<") r = static_cast<int32_t>(ua << (ub & 31));
            else if (op == ">>") r = a >> (ub & 31);
            else if (op == "+") r = static_cast<int32_t>(ua + ub);
            else if (op == "-") r = static_cast<int32_t>(ua - ub);
            else if (op == "*") r = static_cast<int32_t>(ua * ub);
            else if (op == "/" || op == "%") {
                if (b == 0) { expr_fail("division by zero in preprocessor expression"); return 0; }
                if (a == INT32_MIN && b == -1) r = op == "/" ? INT32_MIN : 0;
                else r = op == "/" ? a / b : a % b;
            }
            lhs = r;
        }
        return lhs;
    }

    int64_t expr_conditional(int depth) {
        if (depth > 200) { expr_fail("preprocessor expression too complex"); return 0; }
        int64_t c = expr_binary(1, depth);
        if (expr_accept("?")) {
            int64_t a = expr_conditional(depth + 1);
            if (!expr_accept(":")) { expr_fail("missing ':' in preprocessor expression"); return 0; }
            int64_t b = expr_conditional(depth + 1);
            return c ? a : b;
        }
        return c;
    }

    struct Conditional {
        bool parent_active = true;
        bool active = true;
        bool taken = false;
        bool seen_else = false;
    };

    Stage stage_;
    int webgl_version_;
    const std::set<std::string>* enabled_;
    Diagnostics& diagnostics_;
    TokenList input_;
    size_t pos_ = 0;
    PreprocessedSource out_;
    std::unordered_map<std::string, Macro> macros_;
    std::set<std::string> disabled_;
    std::vector<Conditional> conditionals_;
    bool seen_first_line_ = false;
    bool seen_version_ = false;
    bool seen_non_preprocessor_token_ = false;
    bool expansion_error_ = false;
    size_t expansion_tokens_ = 0;
    std::string outer_macro_;  // the macro whose expansion is in progress at depth 0
    bool aborted_ = false;
    bool allow_pull_ = false;  // only ordinary lines may take macro arguments from following lines
    const TokenList* expr_tokens_ = nullptr;
    size_t expr_pos_ = 0;
    bool expr_error_ = false;
    int expr_line_ = 0;
};

}  // namespace

bool extension_supported(const std::string& name, int version, int webgl_version) {
    if (version == 100) {
        return name == "GL_OES_standard_derivatives" || name == "GL_EXT_frag_depth" ||
               name == "GL_EXT_shader_texture_lod" || name == "GL_EXT_draw_buffers";
    }
    return false;
}

PreprocessedSource preprocess(const std::string& source, Stage stage, int webgl_version, Diagnostics& diagnostics,
                              const std::set<std::string>* enabled) {
    return Preprocessor(stage, webgl_version, diagnostics, enabled).run(source);
}

}  // namespace softgl::glsl
