// WebGL objects (WebGLBuffer, WebGLVertexArrayObject, ...). Python holds them through shared
// pointers, so a handle stays valid (and identical) for as long as anyone refers to it.
#pragma once
#include <array>
#include <atomic>
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
    // Containers that use this object (InUse below): framebuffer attachments, vertex arrays'
    // buffers. Bind points of the context do not count: deleting unbinds from them.
    std::atomic<int32_t> uses{0};
    // Frees the object's storage (and its memory ledger charge). Called when the object is
    // deleted and no container uses it, or when the last one stops: ES 3.0 §5.1.3 lets a
    // deleted object live on only while it is attached to a container object.
    virtual void release_storage() {}
    // delete*: marks the object deleted (the caller has unbound it) and frees its storage at
    // once when no container uses it; otherwise the last InUse to let go frees it.
    void mark_deleted() {
        deleted = true;
        if (uses.load(std::memory_order_acquire) == 0) release_storage();
    }
};

// A container's reference to an object it uses (a framebuffer's attachment, a vertex array's
// buffer), counted in Object::uses so that deleting the object frees its storage as soon as no
// container uses it, whatever Python handles still hold it (docs/reliability.md, "Memory").
template <class T>
class InUse {
public:
    InUse() = default;
    InUse(std::shared_ptr<T> p) : p_(std::move(p)) { acquire(); }   // NOLINT: implicit, like shared_ptr
    InUse(const InUse& other) : p_(other.p_) { acquire(); }
    InUse(InUse&& other) noexcept : p_(std::move(other.p_)) {}
    InUse& operator=(InUse other) noexcept {
        p_.swap(other.p_);   // `other` lets go of the old object
        return *this;
    }
    ~InUse() { let_go(); }
    void reset() { let_go(); }
    T* get() const { return p_.get(); }
    T* operator->() const { return p_.get(); }
    T& operator*() const { return *p_; }
    explicit operator bool() const { return bool(p_); }
    const std::shared_ptr<T>& shared() const { return p_; }
    friend bool operator==(const InUse& a, const std::shared_ptr<T>& b) { return a.p_ == b; }
    friend bool operator!=(const InUse& a, const std::shared_ptr<T>& b) { return a.p_ != b; }
    friend bool operator==(const InUse& a, const InUse& b) { return a.p_ == b.p_; }
    friend bool operator!=(const InUse& a, const InUse& b) { return a.p_ != b.p_; }

private:
    void acquire() {
        if (p_) p_->uses.fetch_add(1, std::memory_order_relaxed);
    }
    void let_go() {
        if (!p_) return;
        if (p_->uses.fetch_sub(1, std::memory_order_acq_rel) == 1 && p_->deleted) p_->release_storage();
        p_.reset();
    }
    std::shared_ptr<T> p_;
};

class Buffer : public Object {
public:
    // WebGL 1.0 §6.1 / WebGL 2.0 §5.1: a buffer used for indices can never hold other data.
    enum class Kind { Unbound, ElementArray, Other };
    std::vector<uint8_t> data;
    MemoryReservation reservation;   // data's bytes, charged to the ledger (core/memory_ledger.h)
    GLenum usage = gl::STATIC_DRAW;
    Kind kind = Kind::Unbound;
    void release_storage() override {
        std::vector<uint8_t>().swap(data);
        reservation.release();
    }
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
    InUse<Buffer> buffer;
};

class VertexArray : public Object {
public:
    std::array<VertexAttribPointer, kMaxVertexAttribs> attribs;
    InUse<Buffer> element_buffer;
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
