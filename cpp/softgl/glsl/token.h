// Tokens shared by the lexer, preprocessor and parser.
#pragma once
#include <string>
#include <vector>

namespace softgl::glsl {

enum class TokenKind : unsigned char {
    Identifier,
    Number,       // a preprocessing number; the parser decides whether it is int, uint or float
    Punctuator,   // operators and separators, e.g. "+=", "(", "."
    Newline,      // only inside the preprocessor
    Invalid,      // a character that is not in the GLSL ES character set (ES 3.00 §3.1)
    EndOfInput,
};

struct Token {
    TokenKind kind = TokenKind::EndOfInput;
    std::string text;
    int line = 1;
    bool leading_space = false;

    bool is(const char* s) const { return kind != TokenKind::Number && text == s; }
};

using TokenList = std::vector<Token>;

}  // namespace softgl::glsl
