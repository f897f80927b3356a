// Generic vertex attributes and vertex array objects: ES 3.0 §2.8-2.10, WebGL 1.0 §6.4-6.6
// (stride <= 255, offsets aligned to the type size), WebGL 2.0 §5.x.
#include "softgl/api/context.h"

namespace softgl {

namespace {

int type_size(GLenum type) {
    switch (type) {
        case gl::BYTE: case gl::UNSIGNED_BYTE: return 1;
        case gl::SHORT: case gl::UNSIGNED_SHORT: case gl::HALF_FLOAT: return 2;
        case gl::INT: case gl::UNSIGNED_INT: case gl::FLOAT:
        case gl::INT_2_10_10_10_REV: case gl::UNSIGNED_INT_2_10_10_10_REV: return 4;
        default: return 0;
    }
}

bool valid_float_attrib_type(GLenum type, int version) {
    switch (type) {
        case gl::BYTE: case gl::UNSIGNED_BYTE: case gl::SHORT: case gl::UNSIGNED_SHORT: case gl::FLOAT:
            return true;
        case gl::INT: case gl::UNSIGNED_INT: case gl::HALF_FLOAT: case gl::INT_2_10_10_10_REV:
        case gl::UNSIGNED_INT_2_10_10_10_REV:
            return version >= 2;
        default: return false;
    }
}

bool valid_integer_attrib_type(GLenum type) {
    switch (type) {
        case gl::BYTE: case gl::UNSIGNED_BYTE: case gl::SHORT: case gl::UNSIGNED_SHORT:
        case gl::INT: case gl::UNSIGNED_INT: return true;
        default: return false;
    }
}

}  // namespace

static std::string index_message(uint32_t index) {
    return "index " + std::to_string(index) + " is not below MAX_VERTEX_ATTRIBS (" +
           std::to_string(kMaxVertexAttribs) + ")";
}

// The shared rules of vertexAttribPointer and vertexAttribIPointer (type validity differs).
static bool valid_attrib_type(GLenum type, bool integer, int version) {
    return integer ? valid_integer_attrib_type(type) : valid_float_attrib_type(type, version);
}

void Context::vertex_attrib_pointer(uint32_t index, int32_t size, GLenum type, bool normalized,
                                    int32_t stride, int64_t offset) {
    set_attrib_pointer("vertexAttribPointer", index, size, type, normalized, false, stride, offset);
}

void Context::vertex_attrib_i_pointer(uint32_t index, int32_t size, GLenum type, int32_t stride, int64_t offset) {
    set_attrib_pointer("vertexAttribIPointer", index, size, type, false, true, stride, offset);
}

void Context::set_attrib_pointer(const char* call, uint32_t index, int32_t size, GLenum type, bool normalized,
                                 bool integer, int32_t stride, int64_t offset) {
    if (index >= uint32_t(kMaxVertexAttribs)) return error(gl::INVALID_VALUE, call, index_message(index));
    if (size < 1 || size > 4) return error(gl::INVALID_VALUE, call, "size must be 1, 2, 3 or 4");
    if (!valid_attrib_type(type, integer, version()))
        return error(gl::INVALID_ENUM, call, enum_name(type) + " is not a vertex attribute type here");
    if ((type == gl::INT_2_10_10_10_REV || type == gl::UNSIGNED_INT_2_10_10_10_REV) && size != 4)
        return error(gl::INVALID_OPERATION, call, "packed 2_10_10_10 attributes need size 4");
    if (stride < 0 || stride > 255) return error(gl::INVALID_VALUE, call, "stride must be in [0, 255]");
    if (offset < 0) return error(gl::INVALID_VALUE, call, "offset must not be negative");
    const int bytes = type_size(type);
    if (offset % bytes != 0 || stride % bytes != 0)
        return error(gl::INVALID_OPERATION, call, "offset and stride must be multiples of the type's size");
    if (!array_buffer_ && offset != 0)
        return error(gl::INVALID_OPERATION, call, "no ARRAY_BUFFER is bound and offset is not 0");
    VertexAttribPointer& a = vertex_array_->attribs[index];
    a.size = size;
    a.type = type;
    a.normalized = normalized;
    a.integer = integer;
    a.stride = stride;
    a.offset = offset;
    a.buffer = array_buffer_;
}

void Context::enable_vertex_attrib_array(uint32_t index) {
    if (index >= uint32_t(kMaxVertexAttribs))
        return error(gl::INVALID_VALUE, "enableVertexAttribArray", index_message(index));
    vertex_array_->attribs[index].enabled = true;
}

void Context::disable_vertex_attrib_array(uint32_t index) {
    if (index >= uint32_t(kMaxVertexAttribs))
        return error(gl::INVALID_VALUE, "disableVertexAttribArray", index_message(index));
    vertex_array_->attribs[index].enabled = false;
}

void Context::vertex_attrib_f(const char* call, uint32_t index, const float* values, int count) {
    if (index >= uint32_t(kMaxVertexAttribs)) return error(gl::INVALID_VALUE, call, index_message(index));
    CurrentAttrib& c = current_attribs_[index];
    c.kind = CurrentAttrib::Kind::Float;
    c.f = {0, 0, 0, 1};   // ES 2.0 §2.7: missing components are (0, 0, 1)
    for (int k = 0; k < count; ++k) c.f[size_t(k)] = values[k];
}

void Context::vertex_attrib_i4i(uint32_t index, int32_t x, int32_t y, int32_t z, int32_t w) {
    if (index >= uint32_t(kMaxVertexAttribs)) return error(gl::INVALID_VALUE, "vertexAttribI4i", index_message(index));
    current_attribs_[index].kind = CurrentAttrib::Kind::Int;
    current_attribs_[index].i = {x, y, z, w};
}

void Context::vertex_attrib_i4ui(uint32_t index, uint32_t x, uint32_t y, uint32_t z, uint32_t w) {
    if (index >= uint32_t(kMaxVertexAttribs)) return error(gl::INVALID_VALUE, "vertexAttribI4ui", index_message(index));
    current_attribs_[index].kind = CurrentAttrib::Kind::Uint;
    current_attribs_[index].u = {x, y, z, w};
}

void Context::vertex_attrib_divisor(uint32_t index, uint32_t divisor) {
    if (index >= uint32_t(kMaxVertexAttribs)) return error(gl::INVALID_VALUE, "vertexAttribDivisor", index_message(index));
    vertex_array_->attribs[index].divisor = divisor;
}

Value Context::get_vertex_attrib(uint32_t index, GLenum pname) {
    const char* call = "getVertexAttrib";
    if (index >= uint32_t(kMaxVertexAttribs)) {
        error(gl::INVALID_VALUE, call, index_message(index));
        return Value(Null{});
    }
    const VertexAttribPointer& a = vertex_array_->attribs[index];
    switch (pname) {
        case gl::VERTEX_ATTRIB_ARRAY_BUFFER_BINDING:
            if (a.buffer) return Value(std::shared_ptr<Object>(a.buffer.shared()));
            return Value(Null{});
        case gl::VERTEX_ATTRIB_ARRAY_ENABLED: return Value(a.enabled);
        case gl::VERTEX_ATTRIB_ARRAY_SIZE: return Value(int64_t(a.size));
        case gl::VERTEX_ATTRIB_ARRAY_STRIDE: return Value(int64_t(a.stride));
        case gl::VERTEX_ATTRIB_ARRAY_TYPE: return Value(int64_t(a.type));
        case gl::VERTEX_ATTRIB_ARRAY_NORMALIZED: return Value(a.normalized);
        case gl::CURRENT_VERTEX_ATTRIB: {
            const CurrentAttrib& c = current_attribs_[index];
            if (c.kind == CurrentAttrib::Kind::Int) return Value(Int32Array{{c.i.begin(), c.i.end()}});
            if (c.kind == CurrentAttrib::Kind::Uint) return Value(Uint32Array{{c.u.begin(), c.u.end()}});
            return Value(Float32Array{{c.f.begin(), c.f.end()}});
        }
        default: break;
    }
    if (version() >= 2 && pname == gl::VERTEX_ATTRIB_ARRAY_INTEGER) return Value(a.integer);
    if ((version() >= 2 || ext_instanced_arrays_) && pname == gl::VERTEX_ATTRIB_ARRAY_DIVISOR)
        return Value(int64_t(a.divisor));
    error(gl::INVALID_ENUM, call, enum_name(pname) + " is not a vertex attribute parameter here");
    return Value(Null{});
}

int64_t Context::get_vertex_attrib_offset(uint32_t index, GLenum pname) {
    const char* call = "getVertexAttribOffset";
    if (pname != gl::VERTEX_ATTRIB_ARRAY_POINTER) {
        error(gl::INVALID_ENUM, call, enum_name(pname) + " is not VERTEX_ATTRIB_ARRAY_POINTER");
        return 0;
    }
    if (index >= uint32_t(kMaxVertexAttribs)) {
        error(gl::INVALID_VALUE, call, index_message(index));
        return 0;
    }
    return vertex_array_->attribs[index].offset;
}

std::shared_ptr<VertexArray> Context::create_vertex_array() {
    auto vao = std::make_shared<VertexArray>();
    vao->owner = identity();
    return vao;
}

void Context::bind_vertex_array(const std::shared_ptr<VertexArray>& vao) {
    if (!check_object("bindVertexArray", vao.get())) return;
    if (vao) vao->ever_bound = true;
    vertex_array_ = vao ? vao : default_vertex_array_;
}

void Context::delete_vertex_array(const std::shared_ptr<VertexArray>& vao) {
    if (!vao) return;
    if (vao->owner != identity())
        return error(gl::INVALID_OPERATION, "deleteVertexArray", "the object belongs to another context");
    if (vao->deleted) return;
    vao->deleted = true;
    if (vertex_array_ == vao) vertex_array_ = default_vertex_array_;   // ES 3.0 §2.10
    // It can never be bound again: it lets go of its buffers, which frees deleted buffers it
    // alone kept (Object::mark_deleted).
    for (auto& attrib : vao->attribs) attrib.buffer.reset();
    vao->element_buffer.reset();
}

bool Context::is_vertex_array(const std::shared_ptr<VertexArray>& vao) const {
    return vao && vao->owner == identity() && !vao->deleted && vao->ever_bound;
}

}  // namespace softgl
