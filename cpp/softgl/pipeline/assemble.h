// Primitive assembly: which vertices form each point, line or triangle of a draw (ES 3.0 §2.6.1).
// The provoking vertex (the source of `flat` varyings, ES 3.0 table 2.12) is always the last
// vertex of each primitive in the output.
#pragma once
#include <cstdint>
#include <vector>

#include "softgl/core/enums.h"

namespace softgl {

using GLenum = uint32_t;

int vertices_per_primitive(GLenum mode);   // 1 (points), 2 (lines) or 3 (triangles)
bool valid_draw_mode(GLenum mode);

// How many complete primitives `count` vertices in draw order form (incomplete ones at the end
// are dropped).
uint32_t primitive_count(GLenum mode, uint32_t count);

// The vertex numbers (0..count-1, draw order) of primitive `p` < primitive_count(mode, count):
// vertices_per_primitive(mode) numbers. Triangle strips keep a consistent winding by swapping the
// first two vertices of every odd triangle.
inline void primitive_vertices(GLenum mode, uint32_t count, uint32_t p, uint32_t out[3]) {
    switch (mode) {
        case gl::POINTS: out[0] = p; break;
        case gl::LINES: out[0] = 2 * p; out[1] = 2 * p + 1; break;
        case gl::LINE_STRIP: out[0] = p; out[1] = p + 1; break;
        // The closing segment's provoking vertex is v0 (ES 3.0 table 2.12).
        case gl::LINE_LOOP: out[0] = p; out[1] = p + 1 == count ? 0 : p + 1; break;
        case gl::TRIANGLES: out[0] = 3 * p; out[1] = 3 * p + 1; out[2] = 3 * p + 2; break;
        case gl::TRIANGLE_STRIP:
            out[0] = p % 2 ? p + 1 : p; out[1] = p % 2 ? p : p + 1; out[2] = p + 2;
            break;
        default: out[0] = 0; out[1] = p + 1; out[2] = p + 2; break;   // TRIANGLE_FAN
    }
}

// The vertex numbers primitives [p0, p1) use (p0 < p1 <= primitive_count(mode, count)): every
// number in [begin, end), and vertex 0 too when `and_zero` (a fan's centre, a loop's closing line,
// when vertex 0 is not in the range). A draw in batches of primitives shades only these.
struct VertexRange {
    uint32_t begin = 0, end = 0;
    bool and_zero = false;
};
VertexRange primitive_vertex_range(GLenum mode, uint32_t count, uint32_t p0, uint32_t p1);

// Appends the vertex numbers of every primitive, in order (primitive_vertices for each).
void assemble(GLenum mode, uint32_t count, std::vector<uint32_t>& out);

}  // namespace softgl
