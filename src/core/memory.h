// An allocator for the large per-pixel buffers (planes, pixel statistics, sample records, MAAF
// accumulations): blocks of 2 MiB or more are 2 MiB-aligned and marked for transparent huge
// pages, so that first touching hundreds of megabytes costs hundreds of page faults instead of
// tens of thousands (measured: a third of a 1-spp 512x512 render went to page faults).
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include <sys/mman.h>

namespace wedge {

template <class T>
struct LargeAllocator {
    using value_type = T;
    LargeAllocator() = default;
    template <class U>
    LargeAllocator(const LargeAllocator<U>&) {}

    static constexpr size_t kHuge = size_t(2) << 20;

    T* allocate(size_t n) {
        size_t bytes = n * sizeof(T);
        if (bytes < kHuge) {
            void* p = std::malloc(bytes ? bytes : 1);
            if (!p) throw std::bad_alloc();
            return static_cast<T*>(p);
        }
        size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
        void* p = std::aligned_alloc(kHuge, rounded);
        if (!p) throw std::bad_alloc();
        madvise(p, rounded, MADV_HUGEPAGE);  // advisory: ignored where THP is off
        return static_cast<T*>(p);
    }
    void deallocate(T* p, size_t) { std::free(p); }

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
