// Primitive assembly: which vertices form each point, line or triangle of a draw (ES 3.0 §2.6.1).
// The provoking vertex (the source of `flat` varyings, ES 3.0 table 2.12) is always the last
// vertex of each primitive in the output.
#pragma once
#include <cstdint>
#include <vector>

#include "softgl/api/enums.h"

namespace softgl {

using GLenum = uint32_t;

int vertices_per_primitive(GLenum mode);   // 1 (points), 2 (lines) or 3 (triangles)
bool valid_draw_mode(GLenum mode);

// Appends, for `count` vertices numbered 0..count-1 in draw order, the vertex numbers of each
// primitive (vertices_per_primitive(mode) numbers per primitive). Incomplete primitives at the
// end are dropped; triangle strips keep a consistent winding by swapping the first two vertices
// of every odd triangle.
void assemble(GLenum mode, uint32_t count, std::vector<uint32_t>& out);

}  // namespace softgl
