// WebGL objects (WebGLBuffer, WebGLVertexArrayObject, ...). Python holds them through shared
// pointers, so a handle stays valid (and identical) for as long as anyone refers to it.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "softgl/core/enums.h"
#include "softgl/core/memory_ledger.h"

namespace softgl {

using GLenum = uint32_t;

inline constexpr int kMaxVertexAttribs = 16;

class Object {
public:
    virtual ~Object() = default;
    const void* owner = nullptr;   // the context that created it (WebGL 1.0 §5.14: no sharing)
    bool deleted = false;
    bool ever_bound = false;       // is* answers false until the first bind (ES 2.0 §6.1.4)
};

class Buffer : public Object {
public:
    // WebGL 1.0 §6.1 / WebGL 2.0 §5.1: a buffer used for indices can never hold other data.
    enum class Kind { Unbound, ElementArray, Other };
    std::vector<uint8_t> data;
    MemoryReservation reservation;   // data's bytes, charged to the process-wide total
    GLenum usage = gl::STATIC_DRAW;
    Kind kind = Kind::Unbound;
};

struct VertexAttribPointer {
    bool enabled = false;
    int32_t size = 4;
    GLenum type = gl::FLOAT;
    bool normalized = false;
    bool integer = false;          // vertexAttribIPointer
    int32_t stride = 0;            // as specified (0 = tightly packed)
    int64_t offset = 0;
    uint32_t divisor = 0;
    std::shared_ptr<Buffer> buffer;
};

class VertexArray : public Object {
public:
    std::array<VertexAttribPointer, kMaxVertexAttribs> attribs;
    std::shared_ptr<Buffer> element_buffer;
};

// The value of a generic vertex attribute when its array is disabled (ES 3.0 §2.8).
struct CurrentAttrib {
    enum class Kind { Float, Int, Uint };
    Kind kind = Kind::Float;
    std::array<float, 4> f{0, 0, 0, 1};
    std::array<int32_t, 4> i{0, 0, 0, 1};
    std::array<uint32_t, 4> u{0, 0, 0, 1};
};

}  // namespace softgl
