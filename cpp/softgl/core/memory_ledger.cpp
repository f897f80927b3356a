#include "softgl/core/memory_ledger.h"

#include <atomic>
#include <string>
#include <unistd.h>

namespace softgl {

namespace {
std::atomic<uint64_t> g_in_use{0};
std::atomic<uint64_t> g_limit{0};   // 0: the default

}  // namespace

uint64_t default_memory_limit() {
    const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page_size <= 0) return uint64_t(1) << 32;   // unknown: a conservative 4 GiB
    return uint64_t(pages) * uint64_t(page_size) / 2;
}

uint64_t memory_limit() {
    const uint64_t set = g_limit.load(std::memory_order_relaxed);
    return set ? set : default_memory_limit();
}

void set_memory_limit(uint64_t bytes) { g_limit.store(bytes, std::memory_order_relaxed); }

uint64_t memory_in_use() { return g_in_use.load(std::memory_order_relaxed); }

std::string over_memory_limit(uint64_t bytes) {
    return "would bring softgl's memory to " + std::to_string(memory_in_use() + bytes) +
           " bytes, over its limit of " + std::to_string(memory_limit());
}

MemoryReservation& MemoryReservation::operator=(MemoryReservation&& other) noexcept {
    if (this != &other) {
        release();
        bytes_ = other.bytes_;
        other.bytes_ = 0;
    }
    return *this;
}

bool MemoryReservation::reserve(uint64_t bytes) {
    const uint64_t limit = memory_limit();
    uint64_t used = g_in_use.load(std::memory_order_relaxed);
    do {
        if (bytes > limit || used > limit - bytes) return false;
    } while (!g_in_use.compare_exchange_weak(used, used + bytes, std::memory_order_relaxed));
    release();
    bytes_ = bytes;
    return true;
}

bool MemoryReservation::resize(uint64_t bytes) {
    if (bytes <= bytes_) {
        g_in_use.fetch_sub(bytes_ - bytes, std::memory_order_relaxed);
        bytes_ = bytes;
        return true;
    }
    const uint64_t grow = bytes - bytes_, limit = memory_limit();
    uint64_t used = g_in_use.load(std::memory_order_relaxed);
    do {
        if (grow > limit || used > limit - grow) return false;
    } while (!g_in_use.compare_exchange_weak(used, used + grow, std::memory_order_relaxed));
    bytes_ = bytes;
    return true;
}

void MemoryReservation::force(uint64_t bytes) {
    release();
    g_in_use.fetch_add(bytes, std::memory_order_relaxed);
    bytes_ = bytes;
}

void MemoryReservation::release() {
    if (bytes_) g_in_use.fetch_sub(bytes_, std::memory_order_relaxed);
    bytes_ = 0;
}

}  // namespace softgl
