// Calls that can run long (draws, compiles, links) stop on Ctrl-C (docs/reliability.md, "Work
// budget and Ctrl-C"). Python's SIGINT handler only sets a flag that the main thread acts on when
// it runs Python code, and the main thread is inside the call with the GIL released. So the call
// runs on the calling thread as any other (no hand-off), and on the main thread a SignalPoller is
// installed for its duration: at the call's natural points (core/work_budget.h: charges, tiles,
// the thread pool's wait) it takes the GIL at most every 10 ms and calls PyErr_CheckSignals. When
// that raises (KeyboardInterrupt, or whatever the SIGINT handler raises), the exception is kept
// and the call's budget is asked to stop; after the call the exception is raised (it wins over a
// strict context's GLError for the stop).
//
// Other threads get no poller (signals are acted on by the main thread only); a call re-entered
// from an error handler uses the poller of the call it re-enters.
#pragma once
#include <pybind11/pybind11.h>

#include <exception>

#include "exclusive.h"

namespace softgl::bindings {

class SignalPoller final : public InterruptPoller {
public:
    explicit SignalPoller(WorkBudget& budget) : budget_(budget), saved_(InterruptPoller::current()) {
        InterruptPoller::current() = this;
    }
    ~SignalPoller() override { InterruptPoller::current() = saved_; }
    SignalPoller(const SignalPoller&) = delete;
    SignalPoller& operator=(const SignalPoller&) = delete;

    // With the GIL held, after the call: raises the kept exception, if any.
    bool interrupted() const { return type_ != nullptr; }
    [[noreturn]] void raise() {
        PyErr_Restore(type_, value_, traceback_);
        type_ = value_ = traceback_ = nullptr;
        throw pybind11::error_already_set();
    }

protected:
    void poll() override {
        if (type_) return;   // already asked to stop
        pybind11::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() == 0) return;
        PyErr_Fetch(&type_, &value_, &traceback_);
        budget_.request_stop(StopReason::Interrupted);
    }

private:
    WorkBudget& budget_;
    InterruptPoller* saved_;
    PyObject *type_ = nullptr, *value_ = nullptr, *traceback_ = nullptr;
};

inline bool on_main_thread() {   // with the GIL held
    static const unsigned long main_ident =
        pybind11::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
    return PyThread_get_thread_ident() == main_ident;
}

// Runs `call` with `context` taken exclusively and the GIL released (exclusive.h), stopping it on
// Ctrl-C as described above. Called with the GIL held.
template <class Call>
void run_interruptible(Context& context, Call&& call) {
    const bool main = on_main_thread();
    std::exception_ptr error;
    std::optional<SignalPoller> poller;
    {
        ExclusiveWithoutGil release(context);
        if (release.nested()) {   // inside a call on this thread: its budget and poller
            call();
            return;
        }
        context.work_budget().clear_interrupt();
        if (main) poller.emplace(context.work_budget());
        try {
            call();
        } catch (...) {
            error = std::current_exception();
        }
    }   // the GIL is held again
    if (poller && poller->interrupted()) {
        error = nullptr;   // a strict context's GLError for the stop: the interrupt wins
        poller->raise();
    }
    if (error) std::rethrow_exception(error);
}

}  // namespace softgl::bindings
