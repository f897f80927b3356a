// WebIDL integer conversions for bound entry points: GLenum/GLuint/GLbitfield arguments take any
// Python integer modulo 2^32 (ToUint32) and GLint/GLsizei wrap to 32 bits (ToInt32), as in JS,
// so that e.g. gl.stencilMask(~0) works. Non-integers (floats, strings) raise TypeError.
#pragma once
#include <pybind11/pybind11.h>

#include <cstdint>

namespace softgl::bindings {

struct IdlUint32 { uint32_t value; };
struct IdlInt32 { int32_t value; };

template <class T> struct Idl { using type = T; };
template <> struct Idl<uint32_t> { using type = IdlUint32; };
template <> struct Idl<int32_t> { using type = IdlInt32; };

template <class T> T from_idl(const T& v) { return v; }
inline uint32_t from_idl(IdlUint32 v) { return v.value; }
inline int32_t from_idl(IdlInt32 v) { return v.value; }

template <class C, class R, class... A>
auto webidl(R (C::*f)(A...) const) {
    return [f](const C& self, typename Idl<std::decay_t<A>>::type... args) -> R {
        return (self.*f)(static_cast<A>(from_idl(args))...);
    };
}

// Wraps a Context member function so its 32-bit integer parameters convert like WebIDL.
template <class C, class R, class... A>
auto webidl(R (C::*f)(A...)) {
    return [f](C& self, typename Idl<std::decay_t<A>>::type... args) -> R {
        return (self.*f)(static_cast<A>(from_idl(args))...);
    };
}

inline bool load_wrapped_u64(pybind11::handle src, uint64_t& out) {
    PyObject* obj = src.ptr();
    if (PyFloat_Check(obj) || !PyIndex_Check(obj)) return false;
    PyObject* index = PyNumber_Index(obj);
    if (!index) { PyErr_Clear(); return false; }
    out = PyLong_AsUnsignedLongLongMask(index);   // reduction modulo 2^64, never fails on ints
    Py_DECREF(index);
    return true;
}

}  // namespace softgl::bindings

namespace pybind11::detail {

template <> struct type_caster<softgl::bindings::IdlUint32> {
    PYBIND11_TYPE_CASTER(softgl::bindings::IdlUint32, const_name("int"));
    bool load(handle src, bool) {
        uint64_t v;
        if (!softgl::bindings::load_wrapped_u64(src, v)) return false;
        value.value = uint32_t(v);
        return true;
    }
    static handle cast(softgl::bindings::IdlUint32 v, return_value_policy, handle) {
        return PyLong_FromUnsignedLong(v.value);
    }
};

template <> struct type_caster<softgl::bindings::IdlInt32> {
    PYBIND11_TYPE_CASTER(softgl::bindings::IdlInt32, const_name("int"));
    bool load(handle src, bool) {
        uint64_t v;
        if (!softgl::bindings::load_wrapped_u64(src, v)) return false;
        value.value = int32_t(uint32_t(v));
        return true;
    }
    static handle cast(softgl::bindings::IdlInt32 v, return_value_policy, handle) {
        return PyLong_FromLong(v.value);
    }
};

}  // namespace pybind11::detail
