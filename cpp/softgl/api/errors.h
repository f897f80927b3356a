// WebGL error semantics: the first error is kept until getError(); every invalid call is also
// reported to a listener (the Python layer turns it into a GLWarning, or a GLError in strict mode).
#pragma once
#include <cstdint>
#include <functional>
#include <string>

#include "softgl/core/enums.h"

namespace softgl {

using GLenum = uint32_t;

class ErrorState {
public:
    using Listener = std::function<void(GLenum code, const char* call, const std::string& why)>;

    // Records `code` (kept only if no error is pending, per ES 2.0 §2.5) and tells the listener.
    // The listener may throw (strict mode); callers record before touching any state.
    void record(GLenum code, const char* call, const std::string& why) {
        if (pending_ == gl::NO_ERROR) pending_ = code;
        if (listener_) listener_(code, call, why);
    }
    GLenum take() {
        GLenum e = pending_;
        pending_ = gl::NO_ERROR;
        return e;
    }
    void set_listener(Listener l) { listener_ = std::move(l); }

private:
    GLenum pending_ = gl::NO_ERROR;
    Listener listener_;
};

const char* error_name(GLenum code);

}  // namespace softgl
