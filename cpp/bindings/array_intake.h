// Array intake: the one conversion between Python data and the client memory a WebGL call reads
// or writes (docs/reliability.md, "Array intake"). Every Context method that takes an array or a
// sequence goes through it, so the rules are the same everywhere:
// - a source in a non-native byte order, or not C-contiguous, is copied to native C order (its
//   values, as NumPy reads them, are what the call sees);
// - a destination that is not native C order is written through a native copy that is copied
//   back only when the call succeeds; a read-only destination is refused;
// - object, bool (where bytes are taken), complex, string, date and long double arrays, and
//   anything that is not an array where WebGL's IDL asks for one, are a TypeError naming the
//   method, the parameter, what it accepts and what to write instead (a JS TypeError: no GL
//   error, no state change).
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>

#include "softgl/api/context.h"

namespace softgl::bindings {

namespace py = pybind11;

// Client memory in native byte order and C order, ready for the core to read or write.
struct ClientArray {
    // Owns the memory: the caller's array or a converted copy. (py::object, not py::array,
    // whose default constructor makes a NumPy array: this runs on every call.)
    py::object array;
    uint8_t* data = nullptr;
    int64_t count = 0;        // elements (records for a structured array, bytes for bytes)
    int64_t itemsize = 1;
    GLenum type = 0;          // the WebGL typed-array kind (UNSIGNED_BYTE, FLOAT, ...), 0 if none
    int64_t bytes() const { return count * itemsize; }
};

// A BufferSource (bufferData, bufferSubData): a NumPy array of numbers or records, or any
// bytes-like object (bytes, bytearray, memoryview, array.array); its bytes are taken.
ClientArray buffer_source(const char* method, const char* param, py::handle obj, const char* accepts = nullptr);

// An ArrayBufferView of pixels (texImage*, texSubImage*): a NumPy array of numbers.
// `type` is the call's pixel type, used to suggest the matching dtype in errors.
ClientArray pixel_source(const char* method, const char* param, py::handle obj, GLenum type);

// A destination ArrayBufferView (readPixels, getBufferSubData): a writeable NumPy array of
// numbers or records. Call commit() after the core wrote into data successfully. `accepts`
// replaces the default description of what the parameter takes.
struct ClientDestination : ClientArray {
    py::object target;        // the caller's array (the same as `array` when no copy was needed)
    void commit() const;
};
ClientDestination destination_array(const char* method, const char* param, py::handle obj,
                                    const char* accepts = nullptr, const std::string& example = "");

// A GLintptr byte offset given where WebGL 2 also takes a buffer offset (pixels of texImage*,
// readPixels): an int of 64 bits, else an OverflowError naming method and parameter.
int64_t byte_offset(const char* method, const char* param, py::handle obj);

// A sequence of numbers converted by value, as WebGL's Float32List / Int32List / Uint32List /
// sequence<GLenum> (uniform*v, vertexAttrib*v, clearBuffer*v, drawBuffers, ...): a list, tuple
// or NumPy array of numbers (bool included), flattened in C order.
template <class T>
py::array_t<T, py::array::c_style | py::array::forcecast> number_sequence(const char* method, const char* param,
                                                                            py::handle obj);

// Raises the intake's TypeError: "<method>: <param> must be <accepts>; got <what obj is> - <hint>".
[[noreturn]] void refuse(const char* method, const char* param, const std::string& accepts, py::handle got,
                         const std::string& hint);

// The WebGL typed-array kind of a NumPy dtype (Uint8Array <-> uint8, ...); 0 if none.
GLenum array_type_of(const py::dtype& dt);

// The NumPy dtype that matches a pixel type (np.uint8 for UNSIGNED_BYTE, np.float32 for FLOAT, ...).
py::dtype dtype_for_pixel_type(GLenum type);

// An argument taken as it is, for the intake to convert, shown in the stubs (_core.pyi) as
// Kind::name says: Arg<Floats> is "collections.abc.Sequence[float] | numpy.ndarray", ...
template <class Kind> struct Arg {
    py::object obj;
    operator py::handle() const { return obj; }
};
#define SOFTGL_ARG_KIND(kind, text) \
    struct kind { static constexpr auto name = py::detail::const_name(text); };
SOFTGL_ARG_KIND(Floats, "collections.abc.Sequence[float] | numpy.ndarray")
SOFTGL_ARG_KIND(Ints, "collections.abc.Sequence[int] | numpy.ndarray")
SOFTGL_ARG_KIND(BufferSource, "typing_extensions.Buffer")
SOFTGL_ARG_KIND(BufferDataSource, "int | typing_extensions.Buffer | None")
SOFTGL_ARG_KIND(PixelsOrOffset, "numpy.ndarray | int | None")
SOFTGL_ARG_KIND(Image, "numpy.ndarray")
SOFTGL_ARG_KIND(Destination, "numpy.ndarray")
#undef SOFTGL_ARG_KIND

}  // namespace softgl::bindings

namespace pybind11::detail {

template <class Kind>
struct type_caster<softgl::bindings::Arg<Kind>> {
    PYBIND11_TYPE_CASTER(softgl::bindings::Arg<Kind>, Kind::name);
    bool load(handle src, bool) {
        value.obj = reinterpret_borrow<object>(src);
        return true;
    }
    static handle cast(const softgl::bindings::Arg<Kind>& v, return_value_policy, handle) {
        return v.obj.inc_ref();
    }
};

}  // namespace pybind11::detail
