// Buffer objects: WebGL 1.0 §5.14.5 and WebGL 2.0 §3.7.3, with WebGL's extra rules (§6.1: an
// element array buffer never holds other data; every access is bounds-checked).
#include <algorithm>
#include <cstring>

#include "softgl/api/context.h"

namespace softgl {

namespace {

bool valid_usage(GLenum usage, int version) {
    switch (usage) {
        case gl::STREAM_DRAW: case gl::STATIC_DRAW: case gl::DYNAMIC_DRAW: return true;
        case gl::STREAM_READ: case gl::STREAM_COPY: case gl::STATIC_READ: case gl::STATIC_COPY:
        case gl::DYNAMIC_READ: case gl::DYNAMIC_COPY: return version >= 2;
        default: return false;
    }
}

}  // namespace

bool Context::check_object(const char* call, const Object* object) const {
    if (object && object->owner != identity()) {
        const_cast<Context*>(this)->error(gl::INVALID_OPERATION, call, "the object belongs to another context");
        return false;
    }
    if (object && object->deleted) {
        const_cast<Context*>(this)->error(gl::INVALID_OPERATION, call, "the object has been deleted");
        return false;
    }
    return true;
}

InUse<Buffer>* Context::buffer_binding(GLenum target) {
    switch (target) {
        case gl::ARRAY_BUFFER: return &array_buffer_;
        case gl::ELEMENT_ARRAY_BUFFER: return &vertex_array_->element_buffer;
        default: break;
    }
    if (version() < 2) return nullptr;
    switch (target) {
        case gl::COPY_READ_BUFFER: return &copy_read_buffer_;
        case gl::COPY_WRITE_BUFFER: return &copy_write_buffer_;
        case gl::PIXEL_PACK_BUFFER: return &pixel_pack_buffer_;
        case gl::PIXEL_UNPACK_BUFFER: return &pixel_unpack_buffer_;
        case gl::UNIFORM_BUFFER: return &uniform_buffer_;
        case gl::TRANSFORM_FEEDBACK_BUFFER: return &transform_feedback_buffer_;
        default: return nullptr;
    }
}

Buffer* Context::bound_buffer(const char* call, GLenum target) {
    InUse<Buffer>* slot = buffer_binding(target);
    if (!slot) {
        error(gl::INVALID_ENUM, call, enum_name(target) + " is not a buffer target here");
        return nullptr;
    }
    if (!*slot) {
        error(gl::INVALID_OPERATION, call, "no buffer is bound to " + enum_name(target));
        return nullptr;
    }
    return slot->get();
}

std::shared_ptr<Buffer> Context::create_buffer() {
    auto buffer = std::make_shared<Buffer>();
    buffer->owner = identity();
    return buffer;
}

void Context::bind_buffer(GLenum target, const std::shared_ptr<Buffer>& buffer) {
    const char* call = "bindBuffer";
    InUse<Buffer>* slot = buffer_binding(target);
    if (!slot) return error(gl::INVALID_ENUM, call, enum_name(target) + " is not a buffer target here");
    if (!check_object(call, buffer.get())) return;
    if (buffer) {
        const bool element = target == gl::ELEMENT_ARRAY_BUFFER;
        const Buffer::Kind kind = element ? Buffer::Kind::ElementArray : Buffer::Kind::Other;
        // WebGL 2.0 §5.1: COPY_READ/COPY_WRITE may hold either kind.
        const bool any_kind = target == gl::COPY_READ_BUFFER || target == gl::COPY_WRITE_BUFFER;
        if (!any_kind && buffer->kind != Buffer::Kind::Unbound && buffer->kind != kind)
            return error(gl::INVALID_OPERATION, call,
                         element ? "a buffer that held vertex data cannot become an element array buffer"
                                 : "an element array buffer cannot be bound to " + enum_name(target));
        if (!any_kind && buffer->kind == Buffer::Kind::Unbound) buffer->kind = kind;
        buffer->ever_bound = true;
    }
    *slot = buffer;
}

void Context::delete_buffer(const std::shared_ptr<Buffer>& buffer) {
    if (!buffer) return;
    if (buffer->owner != identity())
        return error(gl::INVALID_OPERATION, "deleteBuffer", "the object belongs to another context");
    if (buffer->deleted) return;
    // ES 3.0 §5.1.2: deleting unbinds it from this context's bind points and from the attribute
    // pointers of the currently bound vertex array only; its data goes at once unless another
    // vertex array still uses it (then when the last one lets go: Object::mark_deleted).
    buffer->mark_deleted();
    for (auto* slot : {&array_buffer_, &copy_read_buffer_, &copy_write_buffer_, &pixel_pack_buffer_,
                       &pixel_unpack_buffer_, &uniform_buffer_, &transform_feedback_buffer_})
        if (*slot == buffer) slot->reset();
    if (vertex_array_->element_buffer == buffer) vertex_array_->element_buffer.reset();
    for (auto& attrib : vertex_array_->attribs)
        if (attrib.buffer == buffer) attrib.buffer.reset();
}

bool Context::is_buffer(const std::shared_ptr<Buffer>& buffer) const {
    return buffer && buffer->owner == identity() && !buffer->deleted && buffer->ever_bound;
}

void Context::buffer_data_size(GLenum target, int64_t size, GLenum usage) {
    const char* call = "bufferData";
    if (!buffer_binding(target)) return error(gl::INVALID_ENUM, call, enum_name(target) + " is not a buffer target here");
    if (!valid_usage(usage, version())) return error(gl::INVALID_ENUM, call, enum_name(usage) + " is not a buffer usage");
    if (size < 0) return error(gl::INVALID_VALUE, call, "size must not be negative");
    Buffer* buffer = bound_buffer(call, target);
    if (!buffer) return;
    // The limit bounds all objects together (core/memory_ledger.h), not this call alone.
    MemoryReservation reservation(memory_account_);
    if (!reservation.reserve(uint64_t(size)))
        return error(gl::OUT_OF_MEMORY, call, "a buffer of " + std::to_string(size) + " bytes " + reservation.over_limit(uint64_t(size)));
    std::vector<uint8_t> data;
    try {
        data.assign(size_t(size), 0);   // WebGL: a buffer created with a size reads as zeros
    } catch (const std::bad_alloc&) {
        return error(gl::OUT_OF_MEMORY, call, "could not allocate " + std::to_string(size) + " bytes");
    }
    buffer->data = std::move(data);
    buffer->reservation = std::move(reservation);
    buffer->usage = usage;
}

void Context::buffer_data(GLenum target, const uint8_t* data, int64_t size, GLenum usage) {
    const char* call = "bufferData";
    if (!buffer_binding(target)) return error(gl::INVALID_ENUM, call, enum_name(target) + " is not a buffer target here");
    if (!valid_usage(usage, version())) return error(gl::INVALID_ENUM, call, enum_name(usage) + " is not a buffer usage");
    if (!data) return error(gl::INVALID_VALUE, call, "data is null");
    Buffer* buffer = bound_buffer(call, target);
    if (!buffer) return;
    MemoryReservation reservation(memory_account_);
    if (!reservation.reserve(uint64_t(size)))
        return error(gl::OUT_OF_MEMORY, call, "a buffer of " + std::to_string(size) + " bytes " + reservation.over_limit(uint64_t(size)));
    try {
        buffer->data.assign(data, data + size);
    } catch (const std::bad_alloc&) {
        return error(gl::OUT_OF_MEMORY, call, "could not allocate " + std::to_string(size) + " bytes");
    }
    buffer->reservation = std::move(reservation);
    buffer->usage = usage;
}

void Context::buffer_sub_data(GLenum target, int64_t offset, const uint8_t* data, int64_t size) {
    const char* call = "bufferSubData";
    if (!buffer_binding(target)) return error(gl::INVALID_ENUM, call, enum_name(target) + " is not a buffer target here");
    if (offset < 0) return error(gl::INVALID_VALUE, call, "offset must not be negative");
    Buffer* buffer = bound_buffer(call, target);
    if (!buffer) return;
    if (size > int64_t(buffer->data.size()) - offset)
        return error(gl::INVALID_VALUE, call, "offset + data size exceeds the buffer's " +
                     std::to_string(buffer->data.size()) + " bytes");
    std::copy(data, data + size, buffer->data.begin() + offset);
}

void Context::copy_buffer_sub_data(GLenum read_target, GLenum write_target, int64_t read_offset,
                                   int64_t write_offset, int64_t size) {
    const char* call = "copyBufferSubData";
    if (!buffer_binding(read_target) || !buffer_binding(write_target))
        return error(gl::INVALID_ENUM, call, "not a buffer target here");
    if (read_offset < 0 || write_offset < 0 || size < 0)
        return error(gl::INVALID_VALUE, call, "offsets and size must not be negative");
    Buffer* src = bound_buffer(call, read_target);
    if (!src) return;
    Buffer* dst = bound_buffer(call, write_target);
    if (!dst) return;
    // Written as differences: offset + size could overflow int64.
    if (read_offset > int64_t(src->data.size()) || size > int64_t(src->data.size()) - read_offset ||
        write_offset > int64_t(dst->data.size()) || size > int64_t(dst->data.size()) - write_offset)
        return error(gl::INVALID_VALUE, call, "the range exceeds a buffer's size");
    // WebGL 2.0 §5.1: element array data cannot be copied into a non-element buffer or back.
    if (src->kind != dst->kind && src->kind != Buffer::Kind::Unbound && dst->kind != Buffer::Kind::Unbound)
        return error(gl::INVALID_OPERATION, call, "cannot copy between element array and other buffers");
    if (src == dst && read_offset < write_offset + size && write_offset < read_offset + size)
        return error(gl::INVALID_VALUE, call, "source and destination ranges overlap");
    std::memmove(dst->data.data() + write_offset, src->data.data() + read_offset, size_t(size));
}

bool Context::get_buffer_sub_data(GLenum target, int64_t offset, uint8_t* dst, int64_t size) {
    const char* call = "getBufferSubData";
    if (!buffer_binding(target)) {
        error(gl::INVALID_ENUM, call, enum_name(target) + " is not a buffer target here");
        return false;
    }
    if (offset < 0) { error(gl::INVALID_VALUE, call, "offset must not be negative"); return false; }
    Buffer* buffer = bound_buffer(call, target);
    if (!buffer) return false;
    if (size > int64_t(buffer->data.size()) - offset) {
        error(gl::INVALID_VALUE, call, "the range exceeds the buffer's size");
        return false;
    }
    std::copy(buffer->data.begin() + offset, buffer->data.begin() + offset + size, dst);
    return true;
}

Value Context::get_buffer_parameter(GLenum target, GLenum pname) {
    const char* call = "getBufferParameter";
    if (!buffer_binding(target)) {
        error(gl::INVALID_ENUM, call, enum_name(target) + " is not a buffer target here");
        return Value(Null{});
    }
    if (pname != gl::BUFFER_SIZE && pname != gl::BUFFER_USAGE) {
        error(gl::INVALID_ENUM, call, enum_name(pname) + " is not a buffer parameter");
        return Value(Null{});
    }
    Buffer* buffer = bound_buffer(call, target);
    if (!buffer) return Value(Null{});
    return pname == gl::BUFFER_SIZE ? Value(int64_t(buffer->data.size())) : Value(int64_t(buffer->usage));
}

}  // namespace softgl
