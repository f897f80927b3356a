// Names and docstrings for Context's methods from one table (webgl_signatures.h): ContextClass is
// the Context class whose def() adds, to each public method, the parameter names and the
// one-line description of its row, so no call site repeats them, and binds every method through
// the argument conversion (arguments.h), so a wrong argument's TypeError names method and parameter.
#pragma once
#include <pybind11/pybind11.h>

#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include "arguments.h"
#include "softgl/api/context.h"
#include "webgl_signatures.h"

namespace softgl::bindings {

// The names of a method's parameters from its row in kWebGLSignatures with `arity` parameters
// ("a, b, c=0" -> a, b, c); none for softgl's private hooks, which have no row.
inline std::vector<std::string> parameter_names(const char* method, size_t arity);

// Marks a method whose names and doc come from kWebGLSignatures (looked up by its name).
struct from_webgl_signatures {};

class ContextClass : public pybind11::class_<Context> {
public:
    using Base = pybind11::class_<Context>;
    explicit ContextClass(const Base& cls) : Base(cls) {}

    template <class Func, class... Extra>
    ContextClass& def(const char* name, Func&& f, const Extra&... extra) {
        using Shape = arguments::shape<std::decay_t<Func>>;
        const size_t arity = std::tuple_size_v<typename Shape::params>;
        Base::def(name, checked(std::forward<Func>(f), name, parameter_names(name, arity)), extra...,
                  from_webgl_signatures{});
        return *this;
    }
};


// The Context class of module m, once bind_context has made it.
inline ContextClass context_class(pybind11::module_& m) {
    return ContextClass(pybind11::reinterpret_borrow<ContextClass::Base>(m.attr("Context")));
}

// "a, b, c=0" -> "a", "b", "c=0".
inline std::deque<std::string> split_parameters(const char* params) {
    std::deque<std::string> out;
    std::string cur;
    for (const char* c = params;; ++c) {
        if (*c == ',' || *c == 0) {
            if (!cur.empty()) out.push_back(cur);
            cur.clear();
            if (*c == 0) break;
        } else if (*c != ' ') {
            cur += *c;
        }
    }
    return out;
}

inline std::vector<std::string> parameter_names(const char* method, size_t arity) {
    for (const auto& row : kWebGLSignatures) {
        if (std::strcmp(method, row.method) != 0) continue;
        std::deque<std::string> params = split_parameters(row.params);
        if (params.size() != arity) continue;
        std::vector<std::string> names;
        for (const std::string& p : params) names.push_back(p.substr(0, p.find('=')));
        return names;
    }
    return {};
}

}  // namespace softgl::bindings

namespace pybind11::detail {

template <>
struct process_attribute<softgl::bindings::from_webgl_signatures>
    : process_attribute_default<softgl::bindings::from_webgl_signatures> {
    static void init(const softgl::bindings::from_webgl_signatures&, function_record* r) {
        const std::string method = r->name ? r->name : "";
        if (method.empty() || method[0] == '_') return;   // softgl's private hooks
        if (!r->args.empty())
            pybind11_fail("Context." + method + ": give its parameter names in webgl_signatures.h, not py::arg");
        // Positional parameters after self (a py::args tail is not named).
        const size_t wanted = size_t(r->nargs_pos) - 1;
        for (const auto& row : softgl::bindings::kWebGLSignatures) {
            if (method != row.method) continue;
            std::deque<std::string> params = softgl::bindings::split_parameters(row.params);
            if (params.size() != wanted) continue;   // another overload's row
            r->args.emplace_back("self", nullptr, handle(), true, false);
            for (const std::string& p : params) {
                const size_t eq = p.find('=');
                const char* name = keep(p.substr(0, eq));
                if (eq == std::string::npos) {
                    r->args.emplace_back(name, nullptr, handle(), true, true);
                } else {
                    const std::string text = p.substr(eq + 1);
                    r->args.emplace_back(name, keep(text), literal(method, text).release(), true, true);
                }
            }
            r->doc = const_cast<char*>(row.doc);
            return;
        }
        pybind11_fail("Context." + method + " with " + std::to_string(wanted) +
                      " parameters has no row in cpp/bindings/webgl_signatures.h");
    }

private:
    // pybind11 copies names and descriptions when the function is made; the table's strings are
    // split, so they need to live until then (for the life of the module: a handful of bytes).
    static const char* keep(const std::string& s) {
        static std::deque<std::string> store;
        store.push_back(s);
        return store.back().c_str();
    }
    static object literal(const std::string& method, const std::string& text) {
        if (text == "None") return none();
        if (text == "False" || text == "True") return bool_(text == "True");
        if (!text.empty() && text.find_first_not_of("-0123456789") == std::string::npos) return int_(std::stoll(text));
        pybind11_fail("Context." + method + ": default '" + text + "' is not None, True, False or an integer");
    }
};

}  // namespace pybind11::detail
