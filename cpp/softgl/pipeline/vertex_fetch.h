// Vertex fetch: reads generic attributes from buffers (or their constant values) and converts
// them to the shader's 32-bit components (ES 3.0 §2.9: normalization and integer rules).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "softgl/core/objects.h"

namespace softgl {

// One attribute for a batch of vertices, structure-of-arrays: comp[c][v] is component c of
// vertex v, as the bit pattern of a float (Float kind) or an int32/uint32 (integer kinds).
struct AttributeStream {
    CurrentAttrib::Kind kind = CurrentAttrib::Kind::Float;
    std::array<std::vector<uint32_t>, 4> comp;
};

// Bytes an attribute occupies per vertex and in total up to vertex `last` (for range checks).
int attribute_type_size(GLenum type);
uint64_t attribute_bytes_needed(const VertexAttribPointer& a, uint64_t last_element);

// Checks that every enabled attribute in `used` (bit per location) can be read for vertex
// indices [0, max_vertex] and instances [0, instance_count): the WebGL 1.0 §6.6 rule that a
// draw never reads out of bounds. Returns an empty string or the reason (INVALID_OPERATION).
std::string check_attribute_ranges(const VertexArray& vao, uint32_t used, uint64_t max_vertex,
                                   uint64_t instance_count);

// Fetches attribute `location` for `count` vertices whose indices are `vertex_ids` (or
// first, first+1, ... when null) and whose instances are `instance_ids` (vertex v of instance
// instance_ids[v]; null: instance 0).
void fetch_attribute(const VertexArray& vao, const CurrentAttrib& current, int location,
                     const uint32_t* vertex_ids, uint32_t first, size_t count, const uint32_t* instance_ids,
                     AttributeStream& out);

}  // namespace softgl
