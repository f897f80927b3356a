#include "softgl/core/memory_ledger.h"

#include <string>
#include <unistd.h>

namespace softgl {

namespace {
std::atomic<uint64_t> g_in_use{0};
std::atomic<uint64_t> g_limit{0};   // 0: the default

// Adds `bytes` to `used` unless that passes `limit`.
bool charge(std::atomic<uint64_t>& used, uint64_t limit, uint64_t bytes) {
    uint64_t now = used.load(std::memory_order_relaxed);
    do {
        if (bytes > limit || now > limit - bytes) return false;
    } while (!used.compare_exchange_weak(now, now + bytes, std::memory_order_relaxed));
    return true;
}

std::string over(const char* whose, uint64_t used, uint64_t bytes, uint64_t limit, const char* how) {
    return "would bring " + std::string(whose) + " memory to " + std::to_string(used + bytes) +
           " bytes, over its limit of " + std::to_string(limit) + " (" + how + ")";
}

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

uint64_t MemoryAccount::limit() const {
    const uint64_t set = limit_.load(std::memory_order_relaxed);
    return set ? set : default_memory_limit();
}

bool memory_fits(const MemoryAccount* account, uint64_t bytes) {
    auto fits = [&](uint64_t used, uint64_t limit) { return bytes <= limit && used <= limit - bytes; };
    return fits(memory_in_use(), memory_limit()) && (!account || fits(account->in_use(), account->limit()));
}

std::string over_memory_limit(const MemoryAccount* account, uint64_t bytes) {
    if (account) {
        const uint64_t used = account->in_use(), limit = account->limit();
        if (bytes > limit || used > limit - bytes)
            return over("this context's", used, bytes, limit, "gl.set_memory_budget");
    }
    return over("softgl's (all contexts')", memory_in_use(), bytes, memory_limit(), "softgl._core.set_memory_limit");
}

MemoryReservation& MemoryReservation::operator=(MemoryReservation&& other) noexcept {
    if (this != &other) {
        release();
        account_ = std::move(other.account_);
        bytes_ = other.bytes_;
        other.bytes_ = 0;
    }
    return *this;
}

bool MemoryReservation::grow(uint64_t bytes) {
    if (!charge(g_in_use, memory_limit(), bytes)) return false;
    if (account_ && !charge(account_->in_use_, account_->limit(), bytes)) {
        g_in_use.fetch_sub(bytes, std::memory_order_relaxed);
        return false;
    }
    return true;
}

void MemoryReservation::shrink(uint64_t bytes) {
    g_in_use.fetch_sub(bytes, std::memory_order_relaxed);
    if (account_) account_->in_use_.fetch_sub(bytes, std::memory_order_relaxed);
}

bool MemoryReservation::reserve(uint64_t bytes) {
    if (!grow(bytes)) return false;
    release();
    bytes_ = bytes;
    return true;
}

bool MemoryReservation::resize(uint64_t bytes) {
    if (bytes <= bytes_) {
        shrink(bytes_ - bytes);
        bytes_ = bytes;
        return true;
    }
    if (!grow(bytes - bytes_)) return false;
    bytes_ = bytes;
    return true;
}

void MemoryReservation::force(uint64_t bytes) {
    release();
    g_in_use.fetch_add(bytes, std::memory_order_relaxed);
    if (account_) account_->in_use_.fetch_add(bytes, std::memory_order_relaxed);
    bytes_ = bytes;
}

void MemoryReservation::release() {
    if (bytes_) shrink(bytes_);
    bytes_ = 0;
}

}  // namespace softgl
