#include "softgl/pipeline/assemble.h"

namespace softgl {

bool valid_draw_mode(GLenum mode) { return mode <= gl::TRIANGLE_FAN; }

int vertices_per_primitive(GLenum mode) {
    switch (mode) {
        case gl::POINTS: return 1;
        case gl::LINES: case gl::LINE_STRIP: case gl::LINE_LOOP: return 2;
        default: return 3;
    }
}

void assemble(GLenum mode, uint32_t n, std::vector<uint32_t>& out) {
    auto push = [&out](std::initializer_list<uint32_t> v) { out.insert(out.end(), v); };
    switch (mode) {
        case gl::POINTS:
            for (uint32_t i = 0; i < n; ++i) push({i});
            break;
        case gl::LINES:
            for (uint32_t i = 0; i + 1 < n; i += 2) push({i, i + 1});
            break;
        case gl::LINE_STRIP:
            for (uint32_t i = 0; i + 1 < n; ++i) push({i, i + 1});
            break;
        case gl::LINE_LOOP:
            if (n < 2) break;
            for (uint32_t i = 0; i + 1 < n; ++i) push({i, i + 1});
            push({n - 1, 0});   // the closing segment; its provoking vertex is v0 (ES 3.0 t. 2.12)
            break;
        case gl::TRIANGLES:
            for (uint32_t i = 0; i + 2 < n; i += 3) push({i, i + 1, i + 2});
            break;
        case gl::TRIANGLE_STRIP:
            for (uint32_t i = 0; i + 2 < n; ++i) {
                if (i % 2 == 0) push({i, i + 1, i + 2});
                else push({i + 1, i, i + 2});
            }
            break;
        case gl::TRIANGLE_FAN:
            for (uint32_t i = 0; i + 2 < n; ++i) push({0, i + 1, i + 2});
            break;
        default:
            break;
    }
}

}  // namespace softgl
