// One work budget per call (a draw, a compile, a link): every stage charges the work it does to the
// call's budget, and the call stops when the budget runs out or when someone (Ctrl-C, through the
// bindings) asks it to. docs/reliability.md, "Work budget and Ctrl-C", states the rules.
//
// Units: one unit is roughly one GLSL instruction on one lane (executor: lanes x instructions per
// run, lanes x loop body per loop iteration); the other stages charge a fixed cost per vertex,
// primitive and (primitive, tile) pair, and the compiler per token and per IR instruction. The
// charges of a call do not depend on the thread count or on scheduling, so whether a call fits
// in its budget does not either: it stops exactly when its total exceeds the limit.
//
// Threads charge a shared atomic counter; the executor adds up its charges locally and passes
// them on every kFlushUnits (so the abort flag is seen within a fraction of a millisecond).
#pragma once
#include <atomic>
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
    }
    void clear_interrupt() { stop_.store(uint8_t(StopReason::None), std::memory_order_relaxed); }
    // Adds `units`; throws WorkStopped when the total passes the limit or a stop was requested.
    void charge(uint64_t units) {
        const uint64_t total = used_.fetch_add(units, std::memory_order_relaxed) + units;
        if (total > limit_) request_stop(StopReason::BudgetExhausted);
        const uint8_t s = stop_.load(std::memory_order_relaxed);
        if (s != uint8_t(StopReason::None)) throw WorkStopped(StopReason(s));
    }
    // Throws WorkStopped if the call must stop (a check without work to charge).
    void check() const {
        const uint8_t s = stop_.load(std::memory_order_relaxed);
        if (s != uint8_t(StopReason::None)) throw WorkStopped(StopReason(s));
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
    uint64_t limit_ = ~uint64_t(0);
    std::atomic<uint64_t> used_{0};
    std::atomic<uint8_t> stop_{uint8_t(StopReason::None)};
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
// (primitive, tile) pair rasterized. Calibrated to cost about as much time as that many
// executor units (docs/reliability.md, "Work budget and Ctrl-C").
inline constexpr uint64_t kVertexWorkUnits = 32;
inline constexpr uint64_t kPrimitiveWorkUnits = 64;
inline constexpr uint64_t kTilePrimitiveWorkUnits = 64;

// Default limits (docs/reliability.md, "Work budget and Ctrl-C"); a context's are settable.
inline constexpr uint64_t kDrawWorkBudgetDefault = uint64_t(1) << 36;     // ~6.9e10 lane-instructions
inline constexpr uint64_t kCompileWorkBudgetDefault = uint64_t(1) << 30;  // compile and link each
// An executor run given no budget (the GLSL test harness, constant folding in the optimizer).
inline constexpr uint64_t kExecutorRunBudgetDefault = uint64_t(1) << 30;

}  // namespace softgl
