#include "softgl/runtime/thread_pool.h"

#include <chrono>

#include "softgl/core/work_budget.h"

namespace softgl {

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
        stop_ = true;
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
