#include "softgl/pipeline/vertex_fetch.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace softgl {

namespace {

uint32_t float_bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

float half_to_float(uint16_t h) {
    const uint32_t sign = uint32_t(h >> 15) << 31;
    const int exponent = (h >> 10) & 0x1F;
    const uint32_t mantissa = h & 0x3FF;
    float magnitude;
    if (exponent == 0) magnitude = std::ldexp(float(mantissa), -24);               // subnormal
    else if (exponent == 31) magnitude = mantissa ? NAN : INFINITY;
    else magnitude = std::ldexp(float(mantissa | 0x400), exponent - 25);
    uint32_t bits = float_bits(magnitude) | sign;
    float out;
    std::memcpy(&out, &bits, 4);
    return out;
}

template <class T>
T load(const uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return v;
}

// ES 3.0 §2.1.6.1 / eq. 2.2: signed normalized c / (2^(b-1) - 1), clamped at -1.
float snorm(int64_t c, int bits) { return std::max(float(c) / float((int64_t(1) << (bits - 1)) - 1), -1.0f); }
float unorm(uint64_t c, int bits) { return float(c) / float((uint64_t(1) << bits) - 1); }

// Reads `size` components of a float-kind attribute at p.
void read_float_components(const VertexAttribPointer& a, const uint8_t* p, float out[4]) {
    if (a.type == gl::INT_2_10_10_10_REV || a.type == gl::UNSIGNED_INT_2_10_10_10_REV) {
        const uint32_t word = load<uint32_t>(p);
        const int widths[4] = {10, 10, 10, 2};
        int shift = 0;
        for (int c = 0; c < 4; ++c) {
            const uint32_t raw = (word >> shift) & ((1u << widths[c]) - 1);
            shift += widths[c];
            if (a.type == gl::UNSIGNED_INT_2_10_10_10_REV) {
                out[c] = a.normalized ? unorm(raw, widths[c]) : float(raw);
            } else {
                const int32_t v = int32_t(raw << (32 - widths[c])) >> (32 - widths[c]);  // sign-extend
                out[c] = a.normalized ? snorm(v, widths[c]) : float(v);
            }
        }
        return;
    }
    for (int c = 0; c < a.size; ++c) {
        switch (a.type) {
            case gl::FLOAT: out[c] = load<float>(p + 4 * c); break;
            case gl::HALF_FLOAT: out[c] = half_to_float(load<uint16_t>(p + 2 * c)); break;
            case gl::BYTE: { int8_t v = load<int8_t>(p + c); out[c] = a.normalized ? snorm(v, 8) : float(v); break; }
            case gl::UNSIGNED_BYTE: { uint8_t v = p[c]; out[c] = a.normalized ? unorm(v, 8) : float(v); break; }
            case gl::SHORT: { int16_t v = load<int16_t>(p + 2 * c); out[c] = a.normalized ? snorm(v, 16) : float(v); break; }
            case gl::UNSIGNED_SHORT: { uint16_t v = load<uint16_t>(p + 2 * c); out[c] = a.normalized ? unorm(v, 16) : float(v); break; }
            case gl::INT: { int32_t v = load<int32_t>(p + 4 * c); out[c] = a.normalized ? snorm(v, 32) : float(v); break; }
            case gl::UNSIGNED_INT: { uint32_t v = load<uint32_t>(p + 4 * c); out[c] = a.normalized ? unorm(v, 32) : float(v); break; }
            default: out[c] = 0; break;
        }
    }
}

void read_integer_components(const VertexAttribPointer& a, const uint8_t* p, uint32_t out[4]) {
    for (int c = 0; c < a.size; ++c) {
        switch (a.type) {
            case gl::BYTE: out[c] = uint32_t(int32_t(load<int8_t>(p + c))); break;
            case gl::UNSIGNED_BYTE: out[c] = p[c]; break;
            case gl::SHORT: out[c] = uint32_t(int32_t(load<int16_t>(p + 2 * c))); break;
            case gl::UNSIGNED_SHORT: out[c] = load<uint16_t>(p + 2 * c); break;
            default: out[c] = load<uint32_t>(p + 4 * c); break;
        }
    }
}

uint64_t effective_stride(const VertexAttribPointer& a) {
    if (a.stride) return uint64_t(a.stride);
    if (a.type == gl::INT_2_10_10_10_REV || a.type == gl::UNSIGNED_INT_2_10_10_10_REV) return 4;
    return uint64_t(a.size) * uint64_t(attribute_type_size(a.type));
}

// Components 0..kSize-1 of each vertex's float attribute, as they are (a fixed count per vertex: the
// per-vertex copy is unrolled); element(v) is the array element vertex v reads.
template <int kSize, class Element>
void copy_floats(const uint8_t* base, uint64_t stride, size_t count, uint32_t* const comp[4], Element element) {
    for (size_t v = 0; v < count; ++v) {
        const uint8_t* p = base + uint64_t(element(v)) * stride;
        for (int c = 0; c < kSize; ++c) std::memcpy(&comp[c][v], p + 4 * c, 4);
    }
}

template <class Element>
void copy_floats(int size, const uint8_t* base, uint64_t stride, size_t count, uint32_t* const comp[4], Element element) {
    switch (size) {
        case 1: copy_floats<1>(base, stride, count, comp, element); break;
        case 2: copy_floats<2>(base, stride, count, comp, element); break;
        case 3: copy_floats<3>(base, stride, count, comp, element); break;
        default: copy_floats<4>(base, stride, count, comp, element); break;
    }
}

}  // namespace

int attribute_type_size(GLenum type) {
    switch (type) {
        case gl::BYTE: case gl::UNSIGNED_BYTE: return 1;
        case gl::SHORT: case gl::UNSIGNED_SHORT: case gl::HALF_FLOAT: return 2;
        default: return 4;
    }
}

uint64_t attribute_bytes_needed(const VertexAttribPointer& a, uint64_t last_element) {
    const bool packed = a.type == gl::INT_2_10_10_10_REV || a.type == gl::UNSIGNED_INT_2_10_10_10_REV;
    const uint64_t element = packed ? 4 : uint64_t(a.size) * uint64_t(attribute_type_size(a.type));
    return uint64_t(a.offset) + effective_stride(a) * last_element + element;
}

std::string check_attribute_ranges(const VertexArray& vao, uint32_t used, uint64_t max_vertex,
                                   uint64_t instance_count) {
    for (int loc = 0; loc < kMaxVertexAttribs; ++loc) {
        const VertexAttribPointer& a = vao.attribs[size_t(loc)];
        if (!(used & (1u << loc)) || !a.enabled) continue;
        if (!a.buffer) return "attribute " + std::to_string(loc) + " is enabled but has no buffer";
        if (a.buffer->deleted) return "attribute " + std::to_string(loc) + " uses a deleted buffer";
        if (a.divisor == 0 || instance_count > 0) {
            const uint64_t last = a.divisor ? (instance_count - 1) / a.divisor : max_vertex;
            if (attribute_bytes_needed(a, last) > a.buffer->data.size())
                return "attribute " + std::to_string(loc) + " would read past the end of its buffer (" +
                       std::to_string(a.buffer->data.size()) + " bytes)";
        }
    }
    return {};
}

void fetch_attribute(const VertexArray& vao, const CurrentAttrib& current, int location,
                     const uint32_t* vertex_ids, uint32_t first, size_t count, const uint32_t* instance_ids,
                     AttributeStream& out) {
    const VertexAttribPointer& a = vao.attribs[size_t(location)];
    for (auto& c : out.comp) c.resize(count);
    if (!a.enabled) {
        // A disabled array reads the constant value (ES 3.0 §2.8), the same for every vertex.
        out.kind = current.kind;
        for (int c = 0; c < 4; ++c) {
            uint32_t bits = current.kind == CurrentAttrib::Kind::Float ? float_bits(current.f[size_t(c)])
                          : current.kind == CurrentAttrib::Kind::Int ? uint32_t(current.i[size_t(c)])
                                                                      : current.u[size_t(c)];
            std::fill(out.comp[size_t(c)].begin(), out.comp[size_t(c)].end(), bits);
        }
        return;
    }
    out.kind = !a.integer ? CurrentAttrib::Kind::Float
             : (a.type == gl::BYTE || a.type == gl::SHORT || a.type == gl::INT) ? CurrentAttrib::Kind::Int
                                                                                 : CurrentAttrib::Kind::Uint;
    const uint8_t* base = a.buffer->data.data() + a.offset;
    const uint64_t stride = effective_stride(a);
    if (a.type == gl::FLOAT && !a.integer) {
        // The common case: float components copied as they are, missing ones (0, 0, 0, 1); per
        // vertex, or per instance (ES 3.0 §2.9.3: element instance / divisor).
        const int size = a.size;
        uint32_t* comp[4] = {out.comp[0].data(), out.comp[1].data(), out.comp[2].data(), out.comp[3].data()};
        for (int c = size; c < 4; ++c) std::fill_n(comp[c], count, c == 3 ? float_bits(1.0f) : 0u);
        if (a.divisor) {
            // The lanes of one instance are consecutive (a vertex job packs whole instances): the
            // element is read once per run of equal instances and broadcast over its lanes.
            for (size_t v = 0; v < count;) {
                const uint32_t instance = instance_ids ? instance_ids[v] : 0u;
                size_t end = v + 1;
                if (!instance_ids) end = count;
                while (end < count && instance_ids[end] == instance) ++end;
                const uint8_t* const p = base + uint64_t(instance / a.divisor) * stride;
                for (int c = 0; c < size; ++c) {
                    uint32_t bits;
                    std::memcpy(&bits, p + 4 * c, 4);
                    std::fill(comp[c] + v, comp[c] + end, bits);
                }
                v = end;
            }
        } else if (vertex_ids) {
            copy_floats(size, base, stride, count, comp, [&](size_t v) { return vertex_ids[v]; });
        } else {
            copy_floats(size, base, stride, count, comp, [&](size_t v) { return uint64_t(first) + v; });
        }
        return;
    }
    for (size_t v = 0; v < count; ++v) {
        const uint64_t element = a.divisor ? (instance_ids ? instance_ids[v] : 0u) / a.divisor
                                           : (vertex_ids ? vertex_ids[v] : first + v);
        const uint8_t* p = base + element * stride;
        if (a.integer) {
            uint32_t comps[4] = {0, 0, 0, 1};
            read_integer_components(a, p, comps);
            for (int c = 0; c < 4; ++c) out.comp[size_t(c)][v] = comps[c];
        } else {
            float comps[4] = {0, 0, 0, 1};   // missing components are (0, 0, 1) (ES 3.0 §2.8)
            read_float_components(a, p, comps);
            for (int c = 0; c < 4; ++c) out.comp[size_t(c)][v] = float_bits(comps[c]);
        }
    }
}

}  // namespace softgl
