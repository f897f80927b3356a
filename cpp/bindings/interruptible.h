// Calls that can run long (draws, compiles, links) stop on Ctrl-C (docs/reliability.md, "Work
// budget and Ctrl-C"). Python's SIGINT handler only sets a flag that the main thread acts on
// when it runs Python code, and the main thread would be inside the call. So on the main thread
// the call runs on a helper thread (one per process, kept between calls) while the main thread
// waits with the GIL released and, every kPollSeconds, takes the GIL and calls
// PyErr_CheckSignals. When that raises (KeyboardInterrupt, or whatever the SIGINT handler
// raises), the call's work budget is asked to stop: the call puts back what it changed, records
// OUT_OF_MEMORY with a warning naming the call, and the main thread raises the handler's
// exception (KeyboardInterrupt wins over a strict context's GLError).
//
// Other threads run the call themselves (signals go to the main thread only); a call re-entered
// from an error handler runs on the thread of the call it re-enters.
#pragma once
#include <pybind11/pybind11.h>

#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

#include "exclusive.h"

namespace softgl::bindings {

inline constexpr double kPollSeconds = 0.02;

class CallRunner {
public:
    // The process's runner; its thread lives until the process ends (never joined: it may be
    // waiting when the interpreter shuts down).
    static CallRunner& instance() {
        static CallRunner* runner = new CallRunner();
        return *runner;
    }

    // Runs `job` on the runner thread as thread `acting` (exclusive.h) and returns its exception,
    // if any. Meanwhile calls poll() every kPollSeconds until it returns true (then no more).
    std::exception_ptr run(const std::function<void()>& job, uint64_t acting, const std::function<bool()>& poll) {
        std::unique_lock<std::mutex> lock(mutex_);
        job_ = &job;
        acting_ = acting;
        done_ = false;
        error_ = nullptr;
        wake_.notify_one();
        bool polling = true;
        const auto period = std::chrono::duration<double>(kPollSeconds);
        while (!done_) {
            if (!finished_.wait_for(lock, period, [&] { return done_; }) && polling) {
                lock.unlock();
                polling = !poll();
                lock.lock();
            }
        }
        job_ = nullptr;
        return error_;
    }

private:
    CallRunner() { std::thread([this] { loop(); }).detach(); }

    void loop() {
        std::unique_lock<std::mutex> lock(mutex_);
        for (;;) {
            wake_.wait(lock, [&] { return job_ != nullptr && !done_; });
            const std::function<void()>* job = job_;
            acting_thread_tag() = acting_;
            lock.unlock();
            std::exception_ptr error;
            try {
                (*job)();
            } catch (...) {
                error = std::current_exception();
            }
            lock.lock();
            acting_thread_tag() = 0;
            error_ = error;
            done_ = true;
            finished_.notify_one();
        }
    }

    std::mutex mutex_;
    std::condition_variable wake_, finished_;
    const std::function<void()>* job_ = nullptr;
    uint64_t acting_ = 0;
    bool done_ = false;
    std::exception_ptr error_;
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
    PyObject *type = nullptr, *value = nullptr, *traceback = nullptr;   // the interrupt's exception
    std::exception_ptr error;
    {
        ExclusiveWithoutGil release(context);
        if (release.nested() || !main) {
            if (!release.nested()) context.work_budget().clear_interrupt();
            call();
            return;
        }
        context.work_budget().clear_interrupt();
        const std::function<void()> job = [&] { call(); };
        error = CallRunner::instance().run(job, current_thread_tag(), [&] {
            pybind11::gil_scoped_acquire gil;
            if (PyErr_CheckSignals() == 0) return false;
            PyErr_Fetch(&type, &value, &traceback);
            context.work_budget().request_stop(StopReason::Interrupted);
            return true;
        });
    }
    if (type) {
        PyErr_Restore(type, value, traceback);
        error = nullptr;   // a strict context's GLError for the stop: the interrupt wins
        throw pybind11::error_already_set();
    }
    if (error) std::rethrow_exception(error);
}

}  // namespace softgl::bindings
