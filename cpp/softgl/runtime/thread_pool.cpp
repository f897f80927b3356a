#include "softgl/runtime/thread_pool.h"

#include <chrono>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "softgl/core/work_budget.h"

namespace softgl {

namespace {

// Spins until ready() or `nanoseconds` have passed; returns whether ready() became true. Every
// 64 spins (a PAUSE is tens of cycles) it reads the clock and yields the core: on a machine with
// more runnable threads than cores, the thread it waits for may need this very core.
template <class Ready>
bool spin_until(const Ready& ready, int64_t nanoseconds) {
    if (nanoseconds <= 0) return ready();
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::nanoseconds(nanoseconds);
    for (unsigned i = 1;; ++i) {
        if (ready()) return true;
#if defined(__x86_64__)
        _mm_pause();
#endif
        if ((i & 63) == 0) {
            if (std::chrono::steady_clock::now() >= deadline) return ready();
            std::this_thread::yield();
        }
    }
}

}  // namespace

unsigned ThreadPool::default_threads() {
    unsigned n = std::thread::hardware_concurrency();
    return n == 0 ? 1 : n;
}

ThreadPool::ThreadPool(unsigned threads) : size_(threads == 0 ? default_threads() : threads) {
    workers_.reserve(size_ - 1);
    for (unsigned w = 1; w < size_; ++w) workers_.emplace_back([this, w] { worker_main(w); });
}

ThreadPool::~ThreadPool() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_.store(true, std::memory_order_relaxed);
    }
    wake_.notify_all();
    for (auto& t : workers_) t.join();
}

void ThreadPool::run_items(unsigned worker) {
    for (;;) {
        size_t i = next_.fetch_add(1, std::memory_order_relaxed);
        if (i >= count_) return;
        try {
            (*job_)(i, worker);
        } catch (...) {
            std::lock_guard<std::mutex> lock(mutex_);
            if (!error_) error_ = std::current_exception();
        }
    }
}

void ThreadPool::worker_main(unsigned worker) {
    uint64_t seen = 0;
    for (;;) {
        // A call that follows the last one closely (the next stage of a draw, the next draw of a
        // frame) finds this worker awake; the wait below then returns at once.
        spin_until([&] { return stop_.load(std::memory_order_relaxed) ||
                                generation_.load(std::memory_order_relaxed) != seen; },
                   spin_nanoseconds_.load(std::memory_order_relaxed));
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
            if (stop_) return;
            seen = generation_;
            // A worker that wakes after the caller has finished the call finds no job: the
            // caller never waits for a thread that is still asleep (tiny draws, busy machines).
            if (!job_) continue;
            ++active_;
        }
        run_items(worker);
        {
            std::lock_guard<std::mutex> lock(mutex_);
            if (--active_ == 0) done_.notify_one();
        }
    }
}

void ThreadPool::parallel_for(size_t count, const Job& job) {
    if (count == 0) return;
    if (workers_.empty() || count == 1) {
        for (size_t i = 0; i < count; ++i) job(i, 0);
        return;
    }
    std::lock_guard<std::mutex> call(call_mutex_);
    {
        std::lock_guard<std::mutex> lock(mutex_);
        job_ = &job;
        count_ = count;
        next_.store(0, std::memory_order_relaxed);
        error_ = nullptr;
        ++generation_;
    }
    wake_.notify_all();
    run_items(0);
    // Every index has been taken; a worker still on its last one usually ends within the spin,
    // and the caller is not put to sleep to be woken again (the wait below returns at once).
    spin_until([&] { return active_.load(std::memory_order_relaxed) == 0; },
               spin_nanoseconds_.load(std::memory_order_relaxed));
    std::exception_ptr error;
    {
        std::unique_lock<std::mutex> lock(mutex_);
        // Every index has been taken (run_items returned); wait for the workers still running one.
        // The thread that made a call polls for Ctrl-C meanwhile (core/work_budget.h): a worker
        // may be inside a long tile.
        if (InterruptPoller::current()) {
            const auto period = std::chrono::nanoseconds(InterruptPoller::kInterruptPollNanoseconds);
            while (!done_.wait_for(lock, period, [&] { return active_ == 0; })) {
                lock.unlock();
                poll_interrupt();
                lock.lock();
            }
        } else {
            done_.wait(lock, [&] { return active_ == 0; });
        }
        job_ = nullptr;
        error = error_;
        error_ = nullptr;
    }
    if (error) std::rethrow_exception(error);
}

}  // namespace softgl
