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
        log += "ERROR: 0:" + std::to_string(line) + ": " + message + "\n";
    }
    void warning(int line, const std::string& message) {
        if (warning_count >= kMaxReported) return;
        ++warning_count;
        log += "WARNING: 0:" + std::to_string(line) + ": " + message + "\n";
    }
    bool ok() const { return error_count == 0; }

    // A hostile source could produce millions of errors; a log that long helps nobody.
    static constexpr int kMaxReported = 100;
};

}  // namespace softgl::glsl
