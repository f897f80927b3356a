// Calls that release the GIL (draws, compiles, blits, resolves) take their context exclusively:
// a second thread entering any call on the same context meanwhile gets a RuntimeError instead of
// racing. A context, like a browser's, is meant to be used from one thread at a time.
#pragma once
#include <pybind11/pybind11.h>

#include <functional>
#include <optional>
#include <thread>

#include "softgl/api/context.h"

namespace softgl::bindings {

inline uint64_t current_thread_tag() {   // never 0 (0 = not busy)
    return uint64_t(std::hash<std::thread::id>{}(std::this_thread::get_id())) | 1u;
}

[[noreturn]] inline void throw_busy() {
    throw std::runtime_error("softgl: this context is busy in another thread; use a context "
                             "from one thread at a time (or one context per thread)");
}

class ExclusiveWithoutGil {
public:
    explicit ExclusiveWithoutGil(Context& context) : context_(context) {
        // The same thread may re-enter (an error handler called from inside a draw draws again).
        const uint64_t me = current_thread_tag();
        uint64_t expected = 0;
        if (!context_.busy().compare_exchange_strong(expected, me)) {
            if (expected != me) throw_busy();
            nested_ = true;
        }
        release_.emplace();
    }
    ~ExclusiveWithoutGil() {
        release_.reset();              // take the GIL back first
        if (!nested_) context_.busy() = 0;
    }
    bool nested() const { return nested_; }   // re-entered from an error handler inside a call
    ExclusiveWithoutGil(const ExclusiveWithoutGil&) = delete;
    ExclusiveWithoutGil& operator=(const ExclusiveWithoutGil&) = delete;

private:
    Context& context_;
    bool nested_ = false;
    std::optional<pybind11::gil_scoped_release> release_;
};

}  // namespace softgl::bindings

namespace pybind11::detail {
// Every binding that takes a Context — all of its methods, whose `self` is loaded here — first
// checks that no other thread is inside a GIL-free call on it; a GIL-holding call (a state
// setter, bufferData, readPixels...) would otherwise change state under a running draw.
// One atomic load per call. Every binding file includes this header, so all agree on the caster.
template <>
class type_caster<softgl::Context> : public type_caster_base<softgl::Context> {
public:
    bool load(handle src, bool convert) {
        if (!type_caster_base<softgl::Context>::load(src, convert)) return false;
        const uint64_t user = value ? static_cast<softgl::Context*>(value)->busy().load() : 0;
        if (user != 0 && user != softgl::bindings::current_thread_tag()) softgl::bindings::throw_busy();
        return true;
    }
};
}  // namespace pybind11::detail
