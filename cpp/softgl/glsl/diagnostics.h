// Compiler diagnostics in the format real GLSL compilers (ANGLE, Mesa) use in their info logs:
// "ERROR: 0:LINE: message", one line per problem. The "0" is the source string number; WebGL
// always passes exactly one source string.
#pragma once
#include <string>
#include <vector>

namespace softgl::glsl {

struct Diagnostics {
    int error_count = 0;
    int warning_count = 0;
    std::string log;

    void error(int line, const std::string& message) {
        if (error_count >= kMaxReported) { ++error_count; return; }
        ++error_count;
        log += "ERROR: 0:" + std::to_string(line) + ": " + printable(message) + "\n";
    }
    void warning(int line, const std::string& message) {
        if (warning_count >= kMaxReported) return;
        ++warning_count;
        log += "WARNING: 0:" + std::to_string(line) + ": " + printable(message) + "\n";
    }
    bool ok() const { return error_count == 0; }

    // The log is ASCII: other bytes of the source (which need not be valid UTF-8) are escaped.
    static std::string printable(const std::string& message) {
        static const char* hex = "0123456789abcdef";
        std::string out;
        for (unsigned char c : message) {
            if (c >= 0x20 && c < 0x7f) out += static_cast<char>(c);
            else { out += "\\x"; out += hex[c >> 4]; out += hex[c & 15]; }
        }
        return out;
    }

    // A hostile source could produce millions of errors; a log that long helps nobody.
    static constexpr int kMaxReported = 100;
};

}  // namespace softgl::glsl
