// The account of the bytes that GL objects hold (docs/reliability.md, "Memory"): one total for
// the process and one per context, each with its limit. Each storage is paired with a
// MemoryReservation charged to both before the allocation and released when the storage goes
// (free, resize, deletion, destruction), so a limit bounds the sum of all objects rather than
// each call alone.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

namespace softgl {

// The process-wide limit: half of the machine's physical memory unless set_memory_limit() chose
// another (0 restores the default).
uint64_t memory_limit();
void set_memory_limit(uint64_t bytes);
uint64_t memory_in_use();
// Half of the machine's physical memory (4 GiB if unknown).
uint64_t default_memory_limit();

// One context's bytes and its own limit (default: default_memory_limit(), so one context may
// take all the process may). Shared by the context and every reservation made for it, so an
// object that outlives its context still releases its bytes into a live account.
class MemoryAccount {
public:
    uint64_t in_use() const { return in_use_.load(std::memory_order_relaxed); }
    uint64_t limit() const;
    void set_limit(uint64_t bytes) { limit_.store(bytes, std::memory_order_relaxed); }   // 0: the default

private:
    friend class MemoryReservation;
    std::atomic<uint64_t> in_use_{0};
    std::atomic<uint64_t> limit_{0};
};

// The end of an OUT_OF_MEMORY message for `bytes` more refused by the context's limit (when
// `account` is given and its limit is what refuses) or the process's.
std::string over_memory_limit(const MemoryAccount* account, uint64_t bytes);
// Whether `bytes` more fit under both limits (nothing is charged).
bool memory_fits(const MemoryAccount* account, uint64_t bytes);

class MemoryReservation {
public:
    MemoryReservation() = default;
    explicit MemoryReservation(std::shared_ptr<MemoryAccount> account) : account_(std::move(account)) {}
    ~MemoryReservation() { release(); }
    MemoryReservation(MemoryReservation&& other) noexcept
        : account_(std::move(other.account_)), bytes_(other.bytes_) { other.bytes_ = 0; }
    MemoryReservation& operator=(MemoryReservation&& other) noexcept;
    MemoryReservation(const MemoryReservation&) = delete;
    MemoryReservation& operator=(const MemoryReservation&) = delete;

    // Charges `bytes` (replacing what was held); false (and nothing changed) if that would
    // pass the process's or the account's limit.
    bool reserve(uint64_t bytes);
    // Changes the charge to `bytes`, charging only the growth: false (and nothing changed) if
    // the growth would pass a limit. Shrinking always succeeds.
    bool resize(uint64_t bytes);
    // Charges `bytes` whatever the limits (storage already checked against them, e.g. by
    // DefaultFramebuffer::check, so that the ledger stays the sum of what is held).
    void force(uint64_t bytes);
    void release();
    uint64_t bytes() const { return bytes_; }
    const MemoryAccount* account() const { return account_.get(); }
    // over_memory_limit for this reservation's account.
    std::string over_limit(uint64_t bytes) const { return over_memory_limit(account_.get(), bytes); }

private:
    bool grow(uint64_t bytes);   // charges `bytes` more to the total and the account
    void shrink(uint64_t bytes);
    std::shared_ptr<MemoryAccount> account_;   // null: the process total only
    uint64_t bytes_ = 0;
};

}  // namespace softgl
