#include "softgl/pipeline/assemble.h"

#include <algorithm>

namespace softgl {

bool valid_draw_mode(GLenum mode) { return mode <= gl::TRIANGLE_FAN; }

int vertices_per_primitive(GLenum mode) {
    switch (mode) {
        case gl::POINTS: return 1;
        case gl::LINES: case gl::LINE_STRIP: case gl::LINE_LOOP: return 2;
        default: return 3;
    }
}

uint32_t primitive_count(GLenum mode, uint32_t n) {
    switch (mode) {
        case gl::POINTS: return n;
        case gl::LINES: return n / 2;
        case gl::LINE_STRIP: return n < 2 ? 0 : n - 1;
        case gl::LINE_LOOP: return n < 2 ? 0 : n;   // n - 1 segments and the closing one
        case gl::TRIANGLES: return n / 3;
        case gl::TRIANGLE_STRIP: case gl::TRIANGLE_FAN: return n < 3 ? 0 : n - 2;
        default: return 0;
    }
}

VertexRange primitive_vertex_range(GLenum mode, uint32_t count, uint32_t p0, uint32_t p1) {
    switch (mode) {
        case gl::POINTS: return {p0, p1, false};
        case gl::LINES: return {2 * p0, 2 * p1, false};
        case gl::LINE_STRIP: return {p0, p1 + 1, false};
        case gl::LINE_LOOP: return {p0, std::min(p1 + 1, count), p1 == count && p0 > 0};
        case gl::TRIANGLES: return {3 * p0, 3 * p1, false};
        case gl::TRIANGLE_STRIP: return {p0, p1 + 2, false};
        default: return {p0 == 0 ? 0 : p0 + 1, p1 + 2, p0 > 0};   // TRIANGLE_FAN
    }
}

void assemble(GLenum mode, uint32_t n, std::vector<uint32_t>& out) {
    if (!valid_draw_mode(mode)) return;
    const int per = vertices_per_primitive(mode);
    const uint32_t count = primitive_count(mode, n);
    for (uint32_t p = 0; p < count; ++p) {
        uint32_t v[3];
        primitive_vertices(mode, n, p, v);
        out.insert(out.end(), v, v + per);
    }
}

}  // namespace softgl
