// Bytes a container holds on the heap (its capacity, not its size), for charging kept scratch to
// the memory ledger (core/memory_ledger.h; docs/reliability.md, "Memory").
#pragma once
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace softgl {

template <class T>
uint64_t capacity_bytes(const std::vector<T>& v) {
    return uint64_t(v.capacity()) * sizeof(T);
}

// A vector of vectors: the outer array and every inner one.
template <class T>
uint64_t capacity_bytes(const std::vector<std::vector<T>>& v) {
    uint64_t n = uint64_t(v.capacity()) * sizeof(std::vector<T>);
    for (const std::vector<T>& inner : v) n += capacity_bytes(inner);
    return n;
}

// A hash map: the bucket array and one node (the value and two pointers) per element, about
// what libstdc++ allocates.
template <class K, class V>
uint64_t capacity_bytes(const std::unordered_map<K, V>& m) {
    return uint64_t(m.bucket_count()) * sizeof(void*) + uint64_t(m.size()) * (sizeof(std::pair<const K, V>) + 2 * sizeof(void*));
}

}  // namespace softgl
