#include "04_bvh/advanced/memory.hpp"

#include <cstdint>
#include <new>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace boxes {

void* allocateLarge(size_t bytes) {
    if (bytes < kHugePage / 2) return ::operator new(bytes, std::align_val_t(64));
    size_t rounded = (bytes + kHugePage - 1) & ~(kHugePage - 1);
    void* p = ::operator new(rounded, std::align_val_t(kHugePage));
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, rounded, MADV_HUGEPAGE);  // advice only: a failure changes nothing
#endif
    return p;
}

void freeLarge(void* p, size_t bytes) {
    ::operator delete(p, std::align_val_t(bytes < kHugePage / 2 ? 64 : kHugePage));
}

void adviseHugePages(const void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    uintptr_t begin = reinterpret_cast<uintptr_t>(data), end = begin + bytes;
    begin = (begin + kHugePage - 1) & ~uintptr_t(kHugePage - 1);
    end &= ~uintptr_t(kHugePage - 1);
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
    (void)data, (void)bytes;
#endif
}

namespace {

class LargeArrayMemory final : public std::pmr::memory_resource {
    static constexpr size_t kOffset = 32;  // the second half of a 64-byte line

    void* do_allocate(size_t bytes, size_t alignment) override {
        if (alignment > kOffset) throw std::bad_alloc();
        return static_cast<std::byte*>(allocateLarge(bytes + kOffset)) + kOffset;
    }
    void do_deallocate(void* p, size_t bytes, size_t) override {
        freeLarge(static_cast<std::byte*>(p) - kOffset, bytes + kOffset);
    }
    bool do_is_equal(const std::pmr::memory_resource& other) const noexcept override {
        return this == &other;
    }
};

}  // namespace

std::pmr::memory_resource* largeArrayMemory() {
    static LargeArrayMemory memory;
    return &memory;
}

}  // namespace boxes
