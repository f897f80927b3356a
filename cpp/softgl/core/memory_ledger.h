// One process-wide account of the bytes that GL objects hold (docs/reliability.md, "Memory").
// Each storage is paired with a MemoryReservation charged before the allocation and released when
// the storage goes (free, resize, destruction), so the limit bounds the sum of all objects rather
// than each call alone.
#pragma once
#include <cstdint>
#include <string>

namespace softgl {

// The process-wide limit: half of the machine's physical memory unless set_memory_limit() chose
// another (0 restores the default).
uint64_t memory_limit();
void set_memory_limit(uint64_t bytes);
uint64_t memory_in_use();
// Half of the machine's physical memory (4 GiB if unknown).
uint64_t default_memory_limit();
// The end of an OUT_OF_MEMORY message for `bytes` refused by the limit.
std::string over_memory_limit(uint64_t bytes);

class MemoryReservation {
public:
    MemoryReservation() = default;
    ~MemoryReservation() { release(); }
    MemoryReservation(MemoryReservation&& other) noexcept : bytes_(other.bytes_) { other.bytes_ = 0; }
    MemoryReservation& operator=(MemoryReservation&& other) noexcept;
    MemoryReservation(const MemoryReservation&) = delete;
    MemoryReservation& operator=(const MemoryReservation&) = delete;

    // Charges `bytes` to the total; false (and nothing charged) if that would pass the limit.
    bool reserve(uint64_t bytes);
    // Changes the charge to `bytes`, charging only the growth: false (and nothing changed) if
    // the growth would pass the limit. Shrinking always succeeds.
    bool resize(uint64_t bytes);
    // Charges `bytes` whatever the limit (storage already checked against it, e.g. by
    // DefaultFramebuffer::check, so that the ledger stays the sum of what is held).
    void force(uint64_t bytes);
    void release();
    uint64_t bytes() const { return bytes_; }

private:
    uint64_t bytes_ = 0;
};

}  // namespace softgl
