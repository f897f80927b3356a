// libFuzzer target for the GLSL compiler: any bytes must compile or fail with an info log, never
// crash, hang or trip AddressSanitizer/UndefinedBehaviorSanitizer. Built by tools/run_fuzzers.sh.
//
// Input layout: byte 0 selects the stage (bit 0), the WebGL version (bit 1) and a source generator
// (bits 2-4). Generator 0 takes the rest of the input as the shader source. The others are
// structure-aware: a short input (a few header bytes, then a snippet) expands into the kinds of
// source that plain byte mutation within -max_len cannot reach but that broke the compiler before
// (docs/reliability.md): operator chains of up to 2^15 terms, macro bombs, deep nesting, nested
// loops, and thousands of declarations. The sizes stop where one input still compiles within
// libFuzzer's 10 s timeout under the sanitizers (about 40x slower than a release build);
// tests/glsl/test_hostile_sources.py takes the release build further. Sources that compile are
// also linked against a fixed partner shader.
#include <cstddef>
#include <cstdint>
#include <string>

#include "softgl/glsl/compiler.h"

using namespace softgl::glsl;

namespace {

const char* kPartnerFragment100 = "precision mediump float; void main() { gl_FragColor = vec4(1.0); }";
const char* kPartnerVertex100 = "attribute vec4 p; void main() { gl_Position = p; }";
const char* kPartnerFragment300 = "#version 300 es\nprecision mediump float; out vec4 o; void main() { o = vec4(1.0); }";
const char* kPartnerVertex300 = "#version 300 es\nin vec4 p; void main() { gl_Position = p; }";

// Reads the header bytes of a generated input; missing bytes read as zero.
struct Bytes {
    const uint8_t* data;
    size_t size;
    size_t at = 0;
    unsigned next() { return at < size ? data[at++] : 0u; }
    unsigned next16() { unsigned lo = next(); return lo | (next() << 8); }
    // What is left, kept to printable ASCII: the mutated part of the generated source.
    std::string snippet(size_t max_chars) {
        std::string s;
        for (; at < size && s.size() < max_chars; ++at)
            if (data[at] >= 32 && data[at] < 127) s += char(data[at]);
        return s;
    }
};

std::string header(int webgl_version, Stage stage) {
    std::string h = webgl_version == 2 ? "#version 300 es\nprecision highp float;\n" : "precision highp float;\n";
    h += "uniform vec4 u;\nuniform float f;\n";
    if (stage == Stage::Fragment)
        h += webgl_version == 2 ? "out vec4 o;\n" : "";
    return h;
}

std::string result_statement(int webgl_version, Stage stage, const std::string& value) {
    if (stage == Stage::Vertex) return "gl_Position = " + value + ";\n";
    return (webgl_version == 2 ? "o = " : "gl_FragColor = ") + value + ";\n";
}

// A binary-operator chain `t op t op ... t` of up to 2^15 terms, placed in one of the statement
// kinds that recursed on chain length (expression, return, loop condition, array size, const).
std::string operator_chain(Bytes& in, int version, Stage stage) {
    const unsigned terms = 1 + (in.next16() >> 1);          // 1 .. 32768
    const unsigned place = in.next() % 5;
    const unsigned op_seed = in.next();
    std::string term = in.snippet(8);
    const bool scalar = place >= 2;
    if (term.empty()) term = scalar ? "1.0" : "u";
    static const char* kOps[] = {"+", "-", "*", "/", "+", "*"};
    std::string chain;
    chain.reserve(size_t(terms) * (term.size() + 3));
    for (unsigned i = 0; i < terms; ++i) {
        if (i) { chain += ' '; chain += kOps[(op_seed + i) % 6]; chain += ' '; }
        chain += term;
    }
    std::string s = header(version, stage);
    switch (place) {
        case 0: return s + "void main() {\n" + result_statement(version, stage, "vec4(" + chain + ")") + "}\n";
        case 1: return s + "vec4 g() { return " + chain + "; }\nvoid main() {\n" +
                       result_statement(version, stage, "g()") + "}\n";
        case 2: return s + "void main() { float a = 0.0;\n for (int i = 0; float(i) < " + chain +
                       "; i++) { a += 1.0; if (i > 3) break; }\n" + result_statement(version, stage, "vec4(a)") + "}\n";
        case 3: return s + "void main() { float a[int(" + chain + ")];\n" +
                       result_statement(version, stage, "vec4(a[0])") + "}\n";
        default: return s + "const float c = " + chain + ";\nvoid main() {\n" +
                        result_statement(version, stage, "vec4(c)") + "}\n";
    }
}

// Macros that each expand to several uses of the previous one: object-like or function-like,
// fan-out 2-4, up to 16 levels (4^16 tokens if nothing bounded the expansion).
std::string macro_bomb(Bytes& in, int version, Stage stage) {
    const unsigned levels = 1 + in.next() % 16;
    const unsigned fanout = 2 + in.next() % 3;
    const bool function_like = in.next() & 1;
    std::string base = in.snippet(16);
    if (base.empty()) base = "f";
    std::string s = header(version, stage);
    s += function_like ? "#define M0(x) x\n" : "#define M0 " + base + "\n";
    for (unsigned level = 1; level <= levels; ++level) {
        const std::string prev = "M" + std::to_string(level - 1);
        std::string body;
        for (unsigned k = 0; k < fanout; ++k) {
            if (k) body += " + ";
            body += function_like ? prev + "(" + (k ? prev + "(x)" : "x") + ")" : prev;
        }
        s += "#define M" + std::to_string(level) + (function_like ? "(x) " : " ") + body + "\n";
    }
    const std::string top = "M" + std::to_string(levels) + (function_like ? "(" + base + ")" : "");
    return s + "void main() {\n" + result_statement(version, stage, "vec4(" + top + ")") + "}\n";
}

// Parentheses, unary operators, blocks or if-statements nested to a chosen depth (the parser
// bounds nesting at a few hundred; up to 65535 here).
std::string deep_nesting(Bytes& in, int version, Stage stage) {
    const unsigned depth = 1 + in.next16();
    const unsigned kind = in.next() % 4;
    std::string inner = in.snippet(16);
    if (inner.empty()) inner = "f";
    std::string open, close;
    const char* kOpen[] = {"(", "-", "{", "if (f > 0.0) {"};
    const char* kClose[] = {")", "", "}", "}"};
    for (unsigned i = 0; i < depth; ++i) { open += kOpen[kind]; close += kClose[kind]; }
    std::string s = header(version, stage) + "void main() { float a = 0.0;\n";
    if (kind < 2) s += "a = " + open + inner + close + ";\n";
    else s += open + " a += " + inner + "; " + close + "\n";
    return s + result_statement(version, stage, "vec4(a)") + "}\n";
}

// Loops nested to a chosen depth with chosen bounds (the loop forms of ES 1.00 Appendix A).
std::string nested_loops(Bytes& in, int version, Stage stage) {
    const unsigned depth = 1 + in.next() % 12;
    std::string body = in.snippet(24);
    if (body.empty()) body = "a += f;";
    std::string s = header(version, stage) + "void main() { float a = 0.0;\n";
    for (unsigned d = 0; d < depth; ++d) {
        const unsigned bound = in.next16() * 33;   // up to ~2.2 million iterations per loop
        s += "for (int i" + std::to_string(d) + " = 0; i" + std::to_string(d) + " < " + std::to_string(bound) +
             "; i" + std::to_string(d) + "++) {\n";
    }
    s += body + "\n" + std::string(depth, '}') + "\n";
    return s + result_statement(version, stage, "vec4(a)") + "}\n";
}

// Many declarations: globals, locals or functions (compile time must stay near-linear).
std::string many_declarations(Bytes& in, int version, Stage stage) {
    const unsigned count = 1 + (in.next16() >> 3);  // up to 8192
    const unsigned kind = in.next() % 3;
    std::string s = header(version, stage);
    std::string body;
    for (unsigned i = 0; i < count; ++i) {
        const std::string n = std::to_string(i);
        if (kind == 0) s += "float g" + n + " = " + n + ".0;\n";
        else if (kind == 1) body += "float l" + n + " = f;\n";
        else s += "float h" + n + "(float x) { return x + " + n + ".0; }\n";
    }
    return s + "void main() {\n" + body + result_statement(version, stage, "vec4(f)") + "}\n";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    const Stage stage = (data[0] & 1) ? Stage::Fragment : Stage::Vertex;
    const int webgl_version = (data[0] & 2) ? 2 : 1;
    Bytes rest{data + 1, size - 1};
    std::string source;
    switch ((data[0] >> 2) & 7) {
        case 1: source = operator_chain(rest, webgl_version, stage); break;
        case 2: source = macro_bomb(rest, webgl_version, stage); break;
        case 3: source = deep_nesting(rest, webgl_version, stage); break;
        case 4: source = nested_loops(rest, webgl_version, stage); break;
        case 5: source = many_declarations(rest, webgl_version, stage); break;
        default: source.assign(reinterpret_cast<const char*>(data + 1), size - 1); break;
    }
    CompileResult result = compile(source, stage, webgl_version);
    if (!result.ok) return 0;
    const bool es300 = result.shader->version >= 300;
    const std::string partner = stage == Stage::Vertex ? (es300 ? kPartnerFragment300 : kPartnerFragment100)
                                                       : (es300 ? kPartnerVertex300 : kPartnerVertex100);
    CompileResult other = compile(partner, stage == Stage::Vertex ? Stage::Fragment : Stage::Vertex, webgl_version);
    if (!other.ok) return 0;
    if (stage == Stage::Vertex) link(*result.shader, *other.shader);
    else link(*other.shader, *result.shader);
    return 0;
}
