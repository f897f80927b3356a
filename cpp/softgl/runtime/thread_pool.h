// A fixed pool of worker threads with a parallel-for, used to rasterise screen tiles (docs/architecture.md, "Threads").
//
// Determinism: parallel_for hands every index to exactly one thread, and the work for one index
// (one tile) runs start to finish on that thread, so as long as items touch disjoint data (each tile
// owns its pixels) the result does not depend on the thread count or on scheduling.
#pragma once
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace softgl {

class ThreadPool {
public:
    using Job = std::function<void(size_t index, unsigned worker)>;

    // threads == 0: one thread per hardware thread. The calling thread works too, so a pool of
    // size n starts n - 1 worker threads (threads == 1: everything runs on the caller).
    explicit ThreadPool(unsigned threads = 0);
    ~ThreadPool();
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    unsigned size() const { return size_; }
    static unsigned default_threads();

    // Calls job(index, worker) once for every index in [0, count), worker in [0, size()), and
    // returns when all calls have returned. Indices are handed out in increasing order. If calls
    // throw, the remaining indices still run and the first exception is rethrown here.
    // Calls from several threads are serialised.
    void parallel_for(size_t count, const Job& job);

    // After a call, a worker spins this long for the next one before it sleeps, and the caller
    // spins this long for the workers' last items before it sleeps: a draw's stages and a
    // frame's consecutive draws follow each other within microseconds, and a sleeping thread
    // takes tens of microseconds to wake (docs/architecture.md, "Threads"). 0: no spinning.
    void set_spin_nanoseconds(int64_t nanoseconds) { spin_nanoseconds_.store(nanoseconds, std::memory_order_relaxed); }
    static constexpr int64_t kDefaultSpinNanoseconds = 100'000;

private:
    void worker_main(unsigned worker);
    void run_items(unsigned worker);

    unsigned size_;
    std::vector<std::thread> workers_;
    std::mutex call_mutex_;   // one parallel_for at a time
    std::mutex mutex_;        // guards everything below except next_
    std::condition_variable wake_, done_;
    // Written under mutex_; atomic so that a spinning thread may read them without it.
    std::atomic<uint64_t> generation_{0};
    std::atomic<bool> stop_{false};
    const Job* job_ = nullptr;
    size_t count_ = 0;
    std::atomic<unsigned> active_{0};   // workers inside run_items for the current call
    std::atomic<int64_t> spin_nanoseconds_{kDefaultSpinNanoseconds};
    std::exception_ptr error_;
    std::atomic<size_t> next_{0};
};

}  // namespace softgl
