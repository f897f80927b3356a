// One work budget per call (a draw, a compile, a link): every stage charges the work it does to the
// call's budget, and the call stops when the budget runs out or when Ctrl-C asks it to.
// docs/reliability.md, "Work budget and Ctrl-C", states the rules.
//
// Units: one unit is roughly one GLSL instruction on one lane. The executor charges lanes x loop
// body at every loop back edge (straight-line code is bounded by the geometry and is not charged);
// the other stages charge a fixed cost per vertex, primitive and (primitive, tile) pair, and the
// compiler per token and per IR instruction. The charges of a call do not depend on the thread
// count or on scheduling, so whether a call fits in its budget does not either: it stops exactly
// when its total exceeds the limit.
//
// Threads charge a shared atomic counter; the executor adds up its loop charges locally and passes
// them on every kFlushUnits and at the end of a run.
//
// Ctrl-C: Python's SIGINT handler only sets a flag that the main thread acts on when it runs
// Python code. The bindings install an InterruptPoller on the thread that makes the call (the main
// Python thread only); that thread polls it at natural points (every charge, between tiles and
// chunks, in the thread pool's wait for its workers), at most every kInterruptPollNanoseconds,
// and the poller asks the budget to stop. Workers only read the stop flag.
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>

namespace softgl {

enum class StopReason : uint8_t { None, BudgetExhausted, Interrupted };

// Thrown by a charge when the call must stop; the call's outermost layer (api/) catches it,
// restores what the call changed and reports it.
struct WorkStopped : std::exception {
    StopReason reason;
    explicit WorkStopped(StopReason r) : reason(r) {}
    const char* what() const noexcept override {
        return reason == StopReason::Interrupted ? "interrupted" : "work budget exhausted";
    }
};

// Installed by the bindings on the thread that makes a call (cpp/bindings/interruptible.h).
class InterruptPoller {
public:
    static constexpr int64_t kInterruptPollNanoseconds = 10'000'000;   // 10 ms
    virtual ~InterruptPoller() = default;
    // The poller of this thread; null on workers and outside a call.
    static InterruptPoller*& current() {
        thread_local InterruptPoller* poller = nullptr;
        return poller;
    }
    // Polls when kInterruptPollNanoseconds have passed since the last poll (or the first call).
    void maybe_poll() {
        const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
            std::chrono::steady_clock::now().time_since_epoch()).count();
        if (now < next_) return;
        const bool first = next_ == 0;   // a call's first poll only starts the clock: short calls
        next_ = now + kInterruptPollNanoseconds;   // never take the GIL (Python sees Ctrl-C after them)
        if (!first) poll();
    }

protected:
    // Checks for an interrupt (and, when there is one, asks the call's budget to stop).
    virtual void poll() = 0;

private:
    int64_t next_ = 0;
};

// At a natural point of a call: polls for Ctrl-C if this thread made the call.
inline void poll_interrupt() {
    if (InterruptPoller* p = InterruptPoller::current()) p->maybe_poll();
}

class WorkBudget {
public:
    static constexpr uint64_t kFlushUnits = uint64_t(1) << 16;

    // A fresh budget of `limit` units for one call. A pending interrupt stays: the bindings
    // clear it when a call starts (clear_interrupt), so one that arrives between that and here is
    // not lost.
    void begin(uint64_t limit) {
        limit_ = limit;
        used_.store(0, std::memory_order_relaxed);
        uint8_t exhausted = uint8_t(StopReason::BudgetExhausted);
        stop_.compare_exchange_strong(exhausted, uint8_t(StopReason::None), std::memory_order_relaxed);
        deferred_.store(false, std::memory_order_relaxed);
    }
    void clear_interrupt() { stop_.store(uint8_t(StopReason::None), std::memory_order_relaxed); }
    // Adds `units`; throws WorkStopped when the total passes the limit or a stop was requested
    // (unless stops are deferred).
    void charge(uint64_t units) {
        poll_interrupt();
        const uint64_t total = used_.fetch_add(units, std::memory_order_relaxed) + units;
        if (total > limit_) request_stop(StopReason::BudgetExhausted);
        throw_if_stopped();
    }
    // Throws WorkStopped if the call must stop (a check without work to charge).
    void check() {
        poll_interrupt();
        throw_if_stopped();
    }
    // The flag alone, for the workers' checks between primitives (no poll).
    bool stop_requested() const { return stop_.load(std::memory_order_relaxed) != uint8_t(StopReason::None); }
    // While deferred, a stop request does not throw: a draw that writes pixels it could not put
    // back runs to its end, and the caller acts on the request after it (pipeline/draw.cpp).
    // Set by the calling thread between parallel sections (the pool's lock orders it).
    void defer_stops(bool deferred) { deferred_.store(deferred, std::memory_order_relaxed); }
    // The units left before the budget runs out.
    uint64_t remaining() const {
        const uint64_t u = used();
        return u >= limit_ ? 0 : limit_ - u;
    }
    // Any thread (the bindings' Ctrl-C poll): the call stops at its next charge. The first reason
    // wins, so an interrupt that arrives after the budget ran out does not change the outcome.
    void request_stop(StopReason r) {
        uint8_t none = uint8_t(StopReason::None);
        stop_.compare_exchange_strong(none, uint8_t(r), std::memory_order_relaxed);
    }
    StopReason stop_reason() const { return StopReason(stop_.load(std::memory_order_relaxed)); }
    uint64_t used() const { return used_.load(std::memory_order_relaxed); }
    uint64_t limit() const { return limit_; }

    // The budget of the call running on this thread, for the compiler (one thread per compile);
    // null outside a budgeted call.
    static WorkBudget*& current() {
        thread_local WorkBudget* budget = nullptr;
        return budget;
    }
    // Charges the current call's budget, if any.
    static void charge_current(uint64_t units) {
        if (WorkBudget* b = current()) b->charge(units);
    }

private:
    void throw_if_stopped() const {
        const uint8_t s = stop_.load(std::memory_order_relaxed);
        if (s != uint8_t(StopReason::None) && !deferred_.load(std::memory_order_relaxed)) throw WorkStopped(StopReason(s));
    }

    uint64_t limit_ = ~uint64_t(0);
    std::atomic<uint64_t> used_{0};
    std::atomic<uint8_t> stop_{uint8_t(StopReason::None)};
    std::atomic<bool> deferred_{false};
};

// Sets WorkBudget::current() for a scope (a compile or link on this thread).
class CurrentWorkBudget {
public:
    explicit CurrentWorkBudget(WorkBudget* b) : saved_(WorkBudget::current()) { WorkBudget::current() = b; }
    ~CurrentWorkBudget() { WorkBudget::current() = saved_; }
    CurrentWorkBudget(const CurrentWorkBudget&) = delete;
    CurrentWorkBudget& operator=(const CurrentWorkBudget&) = delete;

private:
    WorkBudget* saved_;
};

// What the pipeline charges besides the executor's lane-instructions (pipeline/draw.cpp,
// pipeline/tile_pass.cpp): per vertex fetched and stored, per primitive assembled and set up, per
// (primitive, tile) pair rasterized and per fragment shaded. Calibrated to cost about as much time as that many
// executor units (docs/reliability.md, "Work budget and Ctrl-C").
inline constexpr uint64_t kVertexWorkUnits = 32;
inline constexpr uint64_t kPrimitiveWorkUnits = 64;
inline constexpr uint64_t kTilePrimitiveWorkUnits = 64;
inline constexpr uint64_t kFragmentWorkUnits = 16;   // per fragment shaded: interpolation, tests, store

// Default limits (docs/reliability.md, "Work budget and Ctrl-C"); a context's are settable.
inline constexpr uint64_t kDrawWorkBudgetDefault = uint64_t(1) << 36;     // ~6.9e10 lane-instructions
inline constexpr uint64_t kCompileWorkBudgetDefault = uint64_t(1) << 30;  // compile and link each
// An executor run given no budget (the GLSL test harness, constant folding in the optimizer).
inline constexpr uint64_t kExecutorRunBudgetDefault = uint64_t(1) << 30;

}  // namespace softgl
