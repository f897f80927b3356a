// Calls that release the GIL (draws, compiles, blits, resolves) take their context exclusively:
// a second thread entering such a call on the same context gets a RuntimeError instead of racing.
// A context, like a browser's, is meant to be used from one thread at a time.
#pragma once
#include <pybind11/pybind11.h>

#include <functional>
#include <optional>
#include <thread>

#include "softgl/api/context.h"

namespace softgl::bindings {

class ExclusiveWithoutGil {
public:
    explicit ExclusiveWithoutGil(Context& context) : context_(context) {
        // The same thread may re-enter (an error handler called from inside a draw draws again).
        const uint64_t me = uint64_t(std::hash<std::thread::id>{}(std::this_thread::get_id())) | 1u;
        uint64_t expected = 0;
        if (!context_.busy().compare_exchange_strong(expected, me)) {
            if (expected != me)
                throw std::runtime_error("softgl: this context is busy in another thread; use a context "
                                         "from one thread at a time (or one context per thread)");
            nested_ = true;
        }
        release_.emplace();
    }
    ~ExclusiveWithoutGil() {
        release_.reset();              // take the GIL back first
        if (!nested_) context_.busy() = 0;
    }
    ExclusiveWithoutGil(const ExclusiveWithoutGil&) = delete;
    ExclusiveWithoutGil& operator=(const ExclusiveWithoutGil&) = delete;

private:
    Context& context_;
    bool nested_ = false;
    std::optional<pybind11::gil_scoped_release> release_;
};

}  // namespace softgl::bindings
