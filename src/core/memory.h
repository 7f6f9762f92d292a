// An allocator for the large per-pixel buffers (planes, pixel statistics, sample records, MAAF
// accumulations): blocks of 2 MiB or more are 2 MiB-aligned and marked for transparent huge
// pages, so that first touching hundreds of megabytes costs hundreds of page faults instead of
// tens of thousands (measured: a third of a 1-spp 512x512 render went to page faults).
//
// Freed large blocks are kept for the next large allocations (best fit, split, merged again when
// freed) until trimLargeBlocks() returns them to the system: first touching fresh memory is
// what costs, not writing it. Measured on the 2-core development machine: first touch of a
// fresh 512 MiB block 0.2-1.3 s (0.4-3 GB/s, page faults, huge-page compaction and the
// hypervisor backing new pages), writing it again 0.013 s. A MAAF render frees its 300 MB of
// sample records just before its filter needs 200 MB of intermediate bands.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace wedge {

namespace detail {
constexpr size_t kHugeBlock = size_t(2) << 20;
/// A 2 MiB-aligned block of at least `bytes` (>= kHugeBlock): part of a kept block if one is
/// large enough, freshly mapped otherwise. Throws std::bad_alloc.
void* acquireLargeBlock(size_t bytes);
/// Keeps the block for reuse (or unmaps it if 4 GiB are kept already).
void releaseLargeBlock(void* p);
}  // namespace detail

/// Returns every kept block to the system. The renderer calls it when a render ends, so that
/// each render pays for its own first touches, as it would in a fresh process, and timings do
/// not depend on what ran before in the same process.
void trimLargeBlocks();
/// Bytes currently kept for reuse.
size_t keptLargeBlockBytes();

template <class T>
struct LargeAllocator {
    using value_type = T;
    LargeAllocator() = default;
    template <class U>
    LargeAllocator(const LargeAllocator<U>&) {}

    T* allocate(size_t n) {
        size_t bytes = n * sizeof(T);
        if (bytes >= detail::kHugeBlock) return static_cast<T*>(detail::acquireLargeBlock(bytes));
        void* p = std::malloc(bytes ? bytes : 1);
        if (!p) throw std::bad_alloc();
        return static_cast<T*>(p);
    }
    void deallocate(T* p, size_t n) {
        if (n * sizeof(T) >= detail::kHugeBlock) detail::releaseLargeBlock(p);
        else std::free(p);
    }

    /// Default-initialise (no zeroing) so that Image can first-touch its pages in parallel.
    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }

    template <class U>
    bool operator==(const LargeAllocator<U>&) const { return true; }
};

template <class T>
using LargeVector = std::vector<T, LargeAllocator<T>>;

}  // namespace wedge
