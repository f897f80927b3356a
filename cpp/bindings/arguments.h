// Argument conversion: the one place where a Context method's non-array arguments become C++
// values (arrays: array_intake.h). ContextClass::def (signatures.h) binds every method through
// checked(), whose parameters accept any Python object, so pybind11's overload resolution always
// reaches the method (WebGL's overloads differ in argument count). The wrapper then converts each
// argument by the C++ type the method declares, with pybind11's own caster, after softgl's rules
// (docs/reliability.md, "Argument conversion"):
// - integers (GLenum, GLint, GLsizei, GLintptr, ...): a Python int, a NumPy integer or a bool;
//   32-bit ones wrap as WebIDL's ToInt32/ToUint32 do (webidl.h). A float is refused even when
//   whole: JS would truncate 1.5 to 1, but in Python it is nearly always n / 2 meant as n // 2.
// - numbers (GLfloat, GLclampf): anything float() takes, except strings.
// - GLboolean: True/False, or a number or None by its truth value (JS's ToBoolean); not a string.
// - objects (WebGLBuffer, ...): that class or None; strings: str.
// A refusal is a TypeError "<method>: <param> must be <what it accepts>; got <type> <value>",
// the array intake's words, before anything is done (no GL error, no state change).
#pragma once
#include <pybind11/pybind11.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "array_intake.h"
#include "webidl.h"

namespace softgl::bindings {

namespace py = pybind11;

// An argument not yet converted: its caster takes any object and shows A's type in the
// signature (help() and _core.pyi see the same text as for A itself).
template <class A> struct Unconverted {
    py::handle obj;
};

namespace arguments {

template <class T> struct is_optional : std::false_type {};
template <class T> struct is_optional<std::optional<T>> : std::true_type {};

template <class T> using bare = std::remove_cv_t<std::remove_reference_t<T>>;

// The class a shared_ptr<T> or T* argument names (WebGLBuffer, WebGLUniformLocation, ...).
template <class T> struct object_class { using type = void; };
template <class T> struct object_class<std::shared_ptr<T>> { using type = T; };
template <class T> struct object_class<T*> { using type = T; };

template <class A>
constexpr bool is_integer = std::is_same_v<A, IdlInt32> || std::is_same_v<A, IdlUint32> ||
                            (std::is_integral_v<A> && !std::is_same_v<A, bool>);

// What a parameter of C++ type A accepts, in the words of the refusal.
template <class A>
std::string accepts() {
    if constexpr (is_optional<A>::value) {
        return accepts<typename A::value_type>() + " or None";
    } else if constexpr (std::is_same_v<A, IdlInt32>) {
        return "an int (GLint, 32 bits)";
    } else if constexpr (std::is_same_v<A, IdlUint32>) {
        return "an int (GLenum/GLuint, 32 bits)";
    } else if constexpr (is_integer<A>) {
        return "an int of " + std::to_string(8 * sizeof(A)) + " bits" + (sizeof(A) == 8 ? " (GLintptr)" : "");
    } else if constexpr (std::is_floating_point_v<A>) {
        return "a number (GLfloat)";
    } else if constexpr (std::is_same_v<A, bool>) {
        return "a bool (GLboolean)";
    } else if constexpr (std::is_same_v<A, std::string>) {
        return "a str";
    } else if constexpr (!std::is_void_v<typename object_class<A>::type>) {
        py::handle cls = py::type::handle_of<typename object_class<A>::type>();
        return "a " + cls.attr("__name__").template cast<std::string>() + " or None";
    } else {
        return "what help() shows";
    }
}

// Refusals before pybind11's caster sees the object: what it would take but softgl does not.
template <class A>
const char* refused(py::handle obj) {
    if constexpr (is_optional<A>::value) {
        return obj.is_none() ? nullptr : refused<typename A::value_type>(obj);
    } else if constexpr (is_integer<A>) {
        // pybind11 also takes NumPy floats and anything int() takes; integers are what __index__ gives.
        if (PyFloat_Check(obj.ptr()) || !PyIndex_Check(obj.ptr()))
            return PyNumber_Check(obj.ptr()) ? "use int(...) (or //): softgl refuses a float where WebGL takes an integer" : "";
    } else if constexpr (std::is_floating_point_v<A>) {
        if (PyUnicode_Check(obj.ptr()) || PyBytes_Check(obj.ptr())) return "";
    } else if constexpr (std::is_same_v<A, bool>) {
        if (!obj.is_none() && !PyBool_Check(obj.ptr()) && !PyNumber_Check(obj.ptr())) return "";
    }
    return nullptr;
}

// "float 1.5", "str 'BLEND'", "None": the object's type and a short repr.
inline std::string shown(py::handle obj) {
    if (obj.is_none()) return "None";
    const std::string type = Py_TYPE(obj.ptr())->tp_name;
    std::string text = py::repr(obj).cast<std::string>();
    if (!text.empty() && text[0] == '<') return type;   // <softgl._core.WebGLProgram object at ...>
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return type + " " + text;
}

[[noreturn]] inline void refuse_argument(const std::string& method, const std::string& param,
                                         const std::string& accepts, py::handle obj, const char* hint) {
    throw py::type_error(method + ": " + param + " must be " + accepts + "; got " + shown(obj) +
                         (hint && *hint ? std::string(" - ") + hint : std::string()));
}

// Converts argument i (of C++ type A) into `caster`, or raises the refusal.
template <class A>
void convert(py::detail::make_caster<A>& caster, const std::string& method, const std::string& param,
             py::handle obj) {
    using T = bare<A>;
    const char* why = refused<T>(obj);
    if (why) refuse_argument(method, param, accepts<T>(), obj, why);
    bool ok;
    try {
        ok = caster.load(obj, true);
    } catch (py::error_already_set&) {
        ok = false;
    }
    if (!ok) {
        PyErr_Clear();
        refuse_argument(method, param, accepts<T>(), obj,
                        is_integer<T> && PyIndex_Check(obj.ptr()) ? "it does not fit" : "");
    }
}

// The one place where running out of memory becomes WebGL's error: a std::bad_alloc from any
// Context method (one its own checks did not foresee) records OUT_OF_MEMORY naming the method
// and returns what WebGL returns after an error (None, or the result type's empty value), instead
// of surfacing as a bare MemoryError (docs/reliability.md, "Memory"). Calls that could be left
// half-done catch it themselves first and restore their object.
template <class R, class Self>
R out_of_memory(Self& self, const std::string& method) {
    auto& context = const_cast<std::remove_const_t<std::remove_reference_t<Self>>&>(self);
    context.errors().record(0x0505 /* OUT_OF_MEMORY */, method.c_str(),
                            "an allocation failed (std::bad_alloc): the machine has no memory left for this call");
    if constexpr (std::is_void_v<R>) return;
    else if constexpr (std::is_base_of_v<py::handle, R>) return py::none();
    else if constexpr (std::is_default_constructible_v<R>) return R{};
    else throw;
}

template <class R, class Self, class... A, class F, size_t... I>
R call_converted(const F& f, Self self, const std::string& method, const std::vector<std::string>& params,
                 const Unconverted<A>&... args, std::index_sequence<I...>) {
    std::tuple<py::detail::make_caster<A>...> casters;
    (convert<A>(std::get<I>(casters), method, params[I], args.obj), ...);
    try {
        return std::invoke(f, std::forward<Self>(self), py::detail::cast_op<A>(std::move(std::get<I>(casters)))...);
    } catch (const std::bad_alloc&) {
        return out_of_memory<R, Self>(self, method);
    }
}

// The shape of a callable bound as a method: its self type, result and other parameters.
// A lambda's operator(): its own first parameter is self.
template <class Call> struct call_shape;
template <class R, class L, class S, class... A> struct call_shape<R (L::*)(S, A...) const> {
    using self = S; using result = R; using params = std::tuple<A...>;
};
template <class R, class L, class S, class... A> struct call_shape<R (L::*)(S, A...)> {
    using self = S; using result = R; using params = std::tuple<A...>;
};
template <class F> struct shape : call_shape<decltype(&F::operator())> {};
template <class R, class S, class... A> struct shape<R (*)(S, A...)> {
    using self = S; using result = R; using params = std::tuple<A...>;
};
template <class R, class C, class... A> struct shape<R (C::*)(A...)> {
    using self = C&; using result = R; using params = std::tuple<A...>;
};
template <class R, class C, class... A> struct shape<R (C::*)(A...) const> {
    using self = const C&; using result = R; using params = std::tuple<A...>;
};

template <class F, class R, class Self, class... A>
auto make_checked(F f, std::string method, std::vector<std::string> params, std::tuple<A...>*) {
    return [f = std::move(f), method = std::move(method), params = std::move(params)](
               Self self, Unconverted<A>... args) -> R {
        return call_converted<R, Self, A...>(f, std::forward<Self>(self), method, params, args...,
                                             std::index_sequence_for<A...>{});
    };
}

}  // namespace arguments

// f (a member function, function pointer or lambda whose first parameter is the context) as a
// callable that converts its arguments by the rules above; `params` names them in refusals.
template <class F>
auto checked(F f, const std::string& method, std::vector<std::string> params) {
    using S = arguments::shape<std::decay_t<F>>;
    constexpr size_t n = std::tuple_size_v<typename S::params>;
    for (size_t i = params.size(); i < n; ++i) params.push_back("argument " + std::to_string(i + 1));
    return arguments::make_checked<std::decay_t<F>, typename S::result, typename S::self>(
        std::move(f), method, std::move(params), static_cast<typename S::params*>(nullptr));
}

}  // namespace softgl::bindings

namespace pybind11::detail {

template <class A>
struct type_caster<softgl::bindings::Unconverted<A>> {
    PYBIND11_TYPE_CASTER(softgl::bindings::Unconverted<A>, make_caster<A>::name);
    bool load(handle src, bool) {
        value.obj = src;   // borrowed: the call's arguments live until it returns
        return true;
    }
};

}  // namespace pybind11::detail
