#include "softgl/glsl/lexer.h"
#include "softgl/core/work_budget.h"

#include <cctype>
#include <cstring>

namespace softgl::glsl {
namespace {

bool is_identifier_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_identifier_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Longest match first (ES 3.00 §3.8 lists the operators).
const char* const kPunctuators[] = {
    "<<=", ">>=", "++", "--", "<<", ">>", "<=", ">=", "==", "!=", "&&", "||", "^^", "+=", "-=", "*=",
    "/=",  "%=",  "&=", "|=", "^=", "##", "(",  ")",  "[",  "]",  "{",  "}",  ".",  ",",  ";",  ":",
    "?",   "+",   "-",  "*",  "/",  "%",  "<",  ">",  "=",  "!",  "~",  "&",  "|",  "^",  "#",
};

class Lexer {
public:
    Lexer(const std::string& source, Diagnostics& diagnostics) : diagnostics_(diagnostics) {
        // Join line continuations ("\\\n") first, remembering where the newlines were so that
        // line numbers stay those of the original source (ES 3.00 §3.2).
        text_.reserve(source.size());
        for (size_t i = 0; i < source.size(); ++i) {
            if (source[i] == '\\' && i + 1 < source.size() &&
                (source[i + 1] == '\n' || source[i + 1] == '\r')) {
                size_t skip = (source[i + 1] == '\r' && i + 2 < source.size() && source[i + 2] == '\n') ? 2 : 1;
                i += skip;
                hidden_newlines_.push_back(text_.size());
                continue;
            }
            text_.push_back(source[i]);
        }
    }

    TokenList run() {
        TokenList tokens;
        bool space = false;
        while (pos_ < text_.size()) {
            advance_hidden_newlines();
            char c = text_[pos_];
            if (c == '\n' || c == '\r') {
                if (c == '\r' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '\n') ++pos_;
                ++pos_;
                push(tokens, TokenKind::Newline, "\n", space);
                ++line_;
                space = false;
                continue;
            }
            if (c == ' ' || c == '\t' || c == '\v' || c == '\f') { ++pos_; space = true; continue; }
            if (c == '/' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '/') {
                while (pos_ < text_.size() && text_[pos_] != '\n' && text_[pos_] != '\r') { ++pos_; advance_hidden_newlines(); }
                space = true;
                continue;
            }
            if (c == '/' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '*') {
                int start_line = line_;
                pos_ += 2;
                bool closed = false;
                while (pos_ < text_.size()) {
                    advance_hidden_newlines();
                    if (text_[pos_] == '*' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '/') { pos_ += 2; closed = true; break; }
                    if (text_[pos_] == '\n') {
                        // A newline inside a comment still ends a preprocessor line.
                        push(tokens, TokenKind::Newline, "\n", space);
                        ++line_;
                    }
                    ++pos_;
                }
                if (!closed) diagnostics_.error(start_line, "unterminated comment");
                space = true;
                continue;
            }
            size_t start = pos_;
            if (is_identifier_start(c)) {
                while (pos_ < text_.size() && is_identifier_char(text_[pos_])) ++pos_;
                push(tokens, TokenKind::Identifier, text_.substr(start, pos_ - start), space);
            } else if (is_digit(c) || (c == '.' && pos_ + 1 < text_.size() && is_digit(text_[pos_ + 1]))) {
                // A preprocessing number: digits, letters, '.', and a sign after an exponent 'e'.
                while (pos_ < text_.size()) {
                    char d = text_[pos_];
                    if (is_identifier_char(d) || d == '.') { ++pos_; continue; }
                    if ((d == '+' || d == '-') && (text_[pos_ - 1] == 'e' || text_[pos_ - 1] == 'E') &&
                        !is_hex(start)) { ++pos_; continue; }
                    break;
                }
                push(tokens, TokenKind::Number, text_.substr(start, pos_ - start), space);
            } else {
                const char* match = nullptr;
                for (const char* p : kPunctuators) {
                    size_t n = std::strlen(p);
                    if (text_.compare(pos_, n, p) == 0) { match = p; break; }
                }
                if (match) {
                    pos_ += std::strlen(match);
                    push(tokens, TokenKind::Punctuator, match, space);
                } else {
                    ++pos_;
                    push(tokens, TokenKind::Invalid, std::string(1, c), space);
                }
            }
            space = false;
        }
        advance_hidden_newlines();
        push(tokens, TokenKind::Newline, "\n", false);
        push(tokens, TokenKind::EndOfInput, "", false);
        return tokens;
    }

private:
    bool is_hex(size_t start) const {
        return text_.size() > start + 1 && text_[start] == '0' && (text_[start + 1] == 'x' || text_[start + 1] == 'X');
    }
    void advance_hidden_newlines() {
        while (next_hidden_ < hidden_newlines_.size() && hidden_newlines_[next_hidden_] <= pos_) {
            ++next_hidden_;
            ++line_;
        }
    }
    void push(TokenList& tokens, TokenKind kind, std::string text, bool space) {
        Token t;
        t.kind = kind;
        t.text = std::move(text);
        t.line = line_;
        t.leading_space = space;
        tokens.push_back(std::move(t));
        // The compile's work budget and Ctrl-C (core/work_budget.h): lexing a huge source takes
        // seconds, so it charges every 4,096 tokens.
        if ((tokens.size() & 4095) == 0) WorkBudget::charge_current(4096);
    }

    Diagnostics& diagnostics_;
    std::string text_;
    std::vector<size_t> hidden_newlines_;
    size_t next_hidden_ = 0;
    size_t pos_ = 0;
    int line_ = 1;
};

}  // namespace

TokenList tokenize(const std::string& source, Diagnostics& diagnostics) {
    return Lexer(source, diagnostics).run();
}

}  // namespace softgl::glsl
