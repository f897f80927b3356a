#include "softgl/api/errors.h"

#include <cstdio>

namespace softgl {

const char* error_name(GLenum code) {
    switch (code) {
        case gl::NO_ERROR: return "NO_ERROR";
        case gl::INVALID_ENUM: return "INVALID_ENUM";
        case gl::INVALID_VALUE: return "INVALID_VALUE";
        case gl::INVALID_OPERATION: return "INVALID_OPERATION";
        case gl::INVALID_FRAMEBUFFER_OPERATION: return "INVALID_FRAMEBUFFER_OPERATION";
        case gl::OUT_OF_MEMORY: return "OUT_OF_MEMORY";
        case gl::CONTEXT_LOST_WEBGL: return "CONTEXT_LOST_WEBGL";
        default: return "UNKNOWN_ERROR";
    }
}

std::string enum_name(uint32_t value) {
    // Several names share a value (e.g. BLEND_EQUATION / BLEND_EQUATION_RGB); the first wins.
    for (const auto& e : gl::kEnumTable)
        if (e.value == int64_t(value) && value > 1) return e.name;
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%X", value);
    return buf;
}

}  // namespace softgl
