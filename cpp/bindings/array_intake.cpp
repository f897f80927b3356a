// Array intake (array_intake.h): the checks and conversions, and the words of their TypeErrors.
#include "array_intake.h"

#include <Python.h>

#include <type_traits>

namespace softgl::bindings {

namespace {

namespace gl = softgl::gl;

// "list", "a NumPy array of dtype object", "a read-only NumPy array of dtype float32", ...
std::string describe(py::handle obj) {
    if (py::isinstance<py::array>(obj)) {
        auto arr = py::reinterpret_borrow<py::array>(obj);
        return std::string(arr.writeable() ? "a" : "a read-only") + " NumPy array of dtype " +
               py::str(arr.dtype()).cast<std::string>();
    }
    return Py_TYPE(obj.ptr())->tp_name;
}

// Read from the descriptor, not through Python attributes: this runs on every call.
bool has_object(const py::dtype& dt) { return (dt.flags() & 0x01) != 0; }   // NPY_ITEM_HASOBJECT

bool is_native(const py::dtype& dt) {
    if (dt.kind() == 'V') return dt.attr("isnative").cast<bool>();   // records: field by field
    const uint16_t probe = 1;
    const char native = *reinterpret_cast<const uint8_t*>(&probe) == 1 ? '<' : '>';
    const char order = dt.byteorder();
    return order == '=' || order == '|' || order == native;
}

// Why a dtype cannot be client memory ("" if it can). JS's typed arrays hold integers of 1, 2, 4
// or 8 bytes and floats of 2, 4 or 8 bytes; records (structured dtypes) and raw bytes (void)
// are bytes, as a DataView's. `suggestion` is the conversion to offer, e.g. np.asarray(x, np.float32).
bool is_client_memory(const py::dtype& dt) {
    if (has_object(dt)) return false;
    const char kind = dt.kind();
    const auto size = dt.itemsize();
    if (kind == 'i' || kind == 'u') return size == 1 || size == 2 || size == 4 || size == 8;
    if (kind == 'f') return size == 2 || size == 4 || size == 8;
    return kind == 'V';
}

std::string dtype_refusal(const py::dtype& dt, const char* param, const std::string& suggestion) {
    if (is_client_memory(dt)) return "";
    if (has_object(dt)) return "convert its items to numbers first: " + suggestion;
    const char kind = dt.kind();
    if (kind == 'b') return std::string("WebGL has no boolean arrays: use ") + param + ".astype(np.uint8)";
    return "WebGL data are integers of 1, 2, 4 or 8 bytes or floats of 2, 4 or 8 bytes: use " + suggestion;
}

bool aligned(const py::array& arr) {
    return (py::detail::array_proxy(arr.ptr())->flags & py::detail::npy_api::NPY_ARRAY_ALIGNED_) != 0;
}

// The array itself when it is native-endian, aligned and C-contiguous; else a converted copy.
py::array native_c_order(const py::array& arr) {
    const py::dtype dt = arr.dtype();
    const bool native = is_native(dt);
    if (native && (arr.flags() & py::array::c_style) && aligned(arr)) return arr;
    py::object numpy = py::module_::import("numpy");
    py::object want = native ? py::object(dt) : dt.attr("newbyteorder")("=");
    return numpy.attr("ascontiguousarray")(arr, want);
}

ClientArray client_array(py::array arr) {
    ClientArray out;
    const py::array native = native_c_order(arr);
    out.array = native;
    out.data = static_cast<uint8_t*>(const_cast<void*>(native.data()));
    out.count = int64_t(native.size());
    out.itemsize = int64_t(native.itemsize());
    out.type = array_type_of(native.dtype());
    return out;
}

const char* kBufferSource = "an ArrayBuffer-like (a NumPy array of numbers, or bytes)";

}  // namespace

[[noreturn]] void refuse(const char* method, const char* param, const std::string& accepts, py::handle got,
                         const std::string& hint) {
    throw py::type_error(std::string(method) + ": " + param + " must be " + accepts + "; got " + describe(got) +
                         (hint.empty() ? "" : " - " + hint));
}


GLenum array_type_of(const py::dtype& dt) {
    const char kind = dt.kind();
    const auto size = dt.itemsize();
    if (kind == 'u' && size == 1) return gl::UNSIGNED_BYTE;
    if (kind == 'i' && size == 1) return gl::BYTE;
    if (kind == 'u' && size == 2) return gl::UNSIGNED_SHORT;
    if (kind == 'i' && size == 2) return gl::SHORT;
    if (kind == 'u' && size == 4) return gl::UNSIGNED_INT;
    if (kind == 'i' && size == 4) return gl::INT;
    if (kind == 'f' && size == 4) return gl::FLOAT;
    return 0;
}

py::dtype dtype_for_pixel_type(GLenum type) {
    switch (type) {
        case gl::FLOAT: return py::dtype::of<float>();
        case gl::BYTE: return py::dtype::of<int8_t>();
        case gl::SHORT: return py::dtype::of<int16_t>();
        case gl::INT: return py::dtype::of<int32_t>();
        case gl::UNSIGNED_INT: case gl::UNSIGNED_INT_2_10_10_10_REV: case gl::UNSIGNED_INT_24_8:
        case gl::UNSIGNED_INT_10F_11F_11F_REV: case gl::UNSIGNED_INT_5_9_9_9_REV:
            return py::dtype::of<uint32_t>();
        case gl::UNSIGNED_SHORT: case gl::UNSIGNED_SHORT_5_6_5: case gl::UNSIGNED_SHORT_4_4_4_4:
        case gl::UNSIGNED_SHORT_5_5_5_1: case gl::HALF_FLOAT: case 0x8D61:   // HALF_FLOAT_OES
            return py::dtype::of<uint16_t>();
        default: return py::dtype::of<uint8_t>();
    }
}

ClientArray buffer_source(const char* method, const char* param, py::handle obj, const char* accepts) {
    if (!accepts) accepts = kBufferSource;
    const auto suggestion = [&] { return std::string("np.asarray(") + param + ", np.float32)"; };
    const py::array arr = [&]() -> py::array {
        if (py::isinstance<py::array>(obj)) return py::reinterpret_borrow<py::array>(obj);
        if (!PyObject_CheckBuffer(obj.ptr())) refuse(method, param, accepts, obj, "use " + suggestion());
        // bytes, bytearray, memoryview, array.array: their elements as the buffer describes them.
        try {
            return py::module_::import("numpy").attr("asarray")(py::memoryview(py::reinterpret_borrow<py::object>(obj)));
        } catch (const py::error_already_set&) {
            refuse(method, param, accepts, obj, "its buffer format is not one NumPy reads");
        }
    }();
    if (!is_client_memory(arr.dtype())) refuse(method, param, accepts, obj, dtype_refusal(arr.dtype(), param, suggestion()));
    return client_array(arr);
}

ClientArray pixel_source(const char* method, const char* param, py::handle obj, GLenum type) {
    const char* accepts = "an ArrayBufferView (a NumPy array of numbers) or None";
    const auto np_type = [&] {
        return "np." + py::str(dtype_for_pixel_type(type).attr("name")).cast<std::string>();
    };
    if (!py::isinstance<py::array>(obj)) {
        const bool bytes_like = PyBytes_Check(obj.ptr()) || PyByteArray_Check(obj.ptr()) || PyMemoryView_Check(obj.ptr());
        refuse(method, param, accepts, obj,
               std::string("use np.") + (bytes_like ? "frombuffer(" : "asarray(") + param + ", " + np_type() +
                   ") (the array type of `type`)");
    }
    py::array arr = py::reinterpret_borrow<py::array>(obj);
    if (!is_client_memory(arr.dtype()))
        refuse(method, param, accepts, obj,
               dtype_refusal(arr.dtype(), param, std::string("np.asarray(") + param + ", " + np_type() + ")"));
    return client_array(arr);
}

ClientDestination destination_array(const char* method, const char* param, py::handle obj, const char* accepts,
                                    const std::string& example) {
    if (!accepts) accepts = "a writeable NumPy array of numbers";
    if (!py::isinstance<py::array>(obj))
        refuse(method, param, accepts, obj, "e.g. " + (example.empty() ? std::string("np.empty(n, np.float32)") : example));
    py::array arr = py::reinterpret_borrow<py::array>(obj);
    if (!arr.writeable()) refuse(method, param, accepts, obj, std::string("pass a writeable copy, np.array(") + param + ")");
    if (!is_client_memory(arr.dtype()))
        refuse(method, param, accepts, obj, dtype_refusal(arr.dtype(), param, "an array of the element type the call writes"));
    ClientDestination out;
    static_cast<ClientArray&>(out) = client_array(arr);
    out.target = arr;
    return out;
}

int64_t byte_offset(const char* method, const char* param, py::handle obj) {
    const int64_t value = PyLong_AsLongLong(py::reinterpret_steal<py::object>(PyNumber_Index(obj.ptr())).ptr());
    if (value == -1 && PyErr_Occurred()) {
        PyErr_Clear();
        const std::string why = std::string(method) + ": " + param +
                                " as a buffer offset must fit a GLintptr (64 bits); got " + py::repr(obj).cast<std::string>();
        PyErr_SetString(PyExc_OverflowError, why.c_str());
        throw py::error_already_set();
    }
    return value;
}

void ClientDestination::commit() const {
    if (array.is(target)) return;
    // The call wrote into a native C-order copy: copy its values back (byte order, strides and
    // all), so a big-endian or strided destination reads as if written directly.
    py::module_::import("numpy").attr("copyto")(target, array.attr("reshape")(target.attr("shape")));
}

template <class T>
py::array_t<T, py::array::c_style | py::array::forcecast> number_sequence(const char* method, const char* param,
                                                                            py::handle obj) {
    const char* accepts = "a sequence of numbers (a list, tuple or NumPy array)";
    if (PyList_Check(obj.ptr()) || PyTuple_Check(obj.ptr())) {
        // The common case, Python floats and ints, without NumPy's list conversion (a few µs).
        py::sequence seq = py::reinterpret_borrow<py::sequence>(obj);
        const py::ssize_t n = PySequence_Fast_GET_SIZE(seq.ptr());
        PyObject** items = PySequence_Fast_ITEMS(seq.ptr());
        py::array_t<T, py::array::c_style | py::array::forcecast> values(n);
        T* out = values.mutable_data();
        py::ssize_t i = 0;
        for (; i < n; ++i) {
            PyObject* item = items[i];
            if (PyLong_CheckExact(item) || PyBool_Check(item)) {
                int overflow = 0;
                const long long v = PyLong_AsLongLongAndOverflow(item, &overflow);
                if (overflow) break;
                // Integers wrap modulo 2^32, as WebIDL's ToInt32/ToUint32 and NumPy's cast do.
                out[i] = std::is_floating_point_v<T> ? T(PyLong_AsDouble(item)) : T(uint32_t(uint64_t(v)));
            } else if (std::is_floating_point_v<T> && PyFloat_CheckExact(item)) {
                out[i] = T(PyFloat_AS_DOUBLE(item));
            } else {
                break;
            }
        }
        if (i == n && n > 0) return values;
    }
    py::object made;   // null when obj is no sequence or NumPy cannot make an array of it (ragged lists, ...)
    if (py::isinstance<py::array>(obj)) {
        made = py::reinterpret_borrow<py::object>(obj);
    } else if (!PyUnicode_Check(obj.ptr()) && !PyBytes_Check(obj.ptr()) && PySequence_Check(obj.ptr())) {
        made = py::array::ensure(obj);
    }
    if (!made || py::reinterpret_borrow<py::array>(made).ndim() == 0) refuse(method, param, accepts, obj, "");
    const auto arr = py::reinterpret_borrow<py::array>(made);
    const py::dtype dt = arr.dtype();
    const char kind = dt.kind();
    if (has_object(dt))
        refuse(method, param, accepts, obj, "its items must all be numbers (NumPy made an object array of them)");
    if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
        refuse(method, param, accepts, obj, "WebGL takes real numbers");
    auto values = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(arr);
    if (!values) refuse(method, param, accepts, obj, "");
    return values;
}

template py::array_t<float, py::array::c_style | py::array::forcecast> number_sequence<float>(const char*, const char*, py::handle);
template py::array_t<int32_t, py::array::c_style | py::array::forcecast> number_sequence<int32_t>(const char*, const char*, py::handle);
template py::array_t<uint32_t, py::array::c_style | py::array::forcecast> number_sequence<uint32_t>(const char*, const char*, py::handle);

}  // namespace softgl::bindings
