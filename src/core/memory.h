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

/// A LargeAllocator for containers that write every element right after allocating it (Image:
/// in parallel). Its value-less construct() leaves implicit-lifetime types (trivially copyable
/// and destructible: Vec3f, PixelStats) unwritten. Default member initialisers would otherwise
/// make std::vector initialise, and so first-touch, every page on one thread before the
/// parallel fill (measured: the pixel statistics' 155 MB at 512x512 were 6% of a MAAF render's
/// CPU samples in page faults of one serial memset, `perf record`).
template <class T>
struct UnwrittenAllocator : LargeAllocator<T> {
    using value_type = T;
    template <class U>
    struct rebind {
        using other = UnwrittenAllocator<U>;
    };
    UnwrittenAllocator() = default;
    template <class U>
    UnwrittenAllocator(const UnwrittenAllocator<U>&) {}

    using LargeAllocator<T>::construct;  // with arguments: as LargeAllocator
    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        if constexpr (!(std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U>))
            ::new (static_cast<void*>(p)) U;
    }
};

}  // namespace wedge
