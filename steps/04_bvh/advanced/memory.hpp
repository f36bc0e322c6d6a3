// Step 04's engine: memory for the trees' large arrays. A one-shot build first touches
// tens of megabytes (the primitives, the nodes, the leaf triangles) one 4 KiB page fault at
// a time; on transparent huge pages ("madvise" mode on Linux) it takes 512 times fewer
// faults, and tracing fewer TLB misses.
#pragma once

#include <cstddef>
#include <memory_resource>

namespace boxes {

constexpr size_t kHugePage = size_t(2) << 20;

// At least 64-byte aligned; from half a megabyte on, 2 MiB aligned and on transparent
// huge pages where Linux offers them.
void* allocateLarge(size_t bytes);
void freeLarge(void* p, size_t bytes);

// Asks for transparent huge pages over the whole 2 MiB blocks inside [data, data + bytes).
// Advice only: any failure changes nothing.
void adviseHugePages(const void* data, size_t bytes);

// An array a build fills once (a wide tree's arrays): when it is large, its reserved, not
// yet touched capacity goes on huge pages (without 2 MiB alignment the blocks at its ends
// keep 4 KiB pages).
template <typename Vector>
void reserveOnHugePages(Vector& v, size_t capacity) {
    v.reserve(capacity);
    adviseHugePages(v.data(), v.capacity() * sizeof(*v.data()));
}

// The memory of the engine's binary trees (BvhBuildOptions::memory): every array from
// allocateLarge, starting in the second half of a 64-byte cache line. In a node array that
// is where the root (which has no sibling) lies, so every pair of children (1, 2), (3, 4),
// ... starts a cache line: one fetch brings both children's boxes (an ordinary allocation
// puts every pair across two lines). Alignments up to 32 bytes; one instance per process.
std::pmr::memory_resource* largeArrayMemory();

}  // namespace boxes
