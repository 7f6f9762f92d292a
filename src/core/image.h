// Image<T>: a width x height grid of T, row-major, rows top to bottom (image y grows downward,
// as in the scene format). The building block of every per-pixel buffer and of the filters.
#pragma once

#include <cassert>
#include <cstddef>
#include <algorithm>
#include <type_traits>
#include <vector>

#include "core/math.h"
#include "core/memory.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace wedge {

/// The largest image side wedge renders (--resolution, the scene's camera.resolution) or reads.
constexpr int kMaxImageSide = 16384;

/// Tag: allocate an image without writing it (for trivially constructible T that the caller
/// writes entirely, so that the pages are first touched by that write).
struct NoInit {};

template <class T>
class Image {
public:
    Image() = default;
    Image(int width, int height, NoInit) : m_width(width), m_height(height) {
        static_assert(std::is_trivially_default_constructible_v<T>);
        m_data.resize(size_t(width) * height);
    }
    Image(int width, int height, const T& fill = T{}) : m_width(width), m_height(height) {
        // Unwritten storage (UnwrittenAllocator) filled in parallel: the first touch of the pages
        // (and the kernel's zeroing of them) is spread over the worker threads.
        m_data.resize(size_t(width) * height);
        parallelRange([&](size_t a, size_t b) { std::fill(m_data.begin() + a, m_data.begin() + b, fill); });
    }
    // Copies likewise: a vector's copy would first-touch every page on one thread.
    Image(const Image& o) : m_width(o.m_width), m_height(o.m_height) {
        m_data.resize(o.m_data.size());
        parallelRange([&](size_t a, size_t b) { std::copy(o.m_data.begin() + a, o.m_data.begin() + b, m_data.begin() + a); });
    }
    Image& operator=(const Image& o) {
        if (this != &o) *this = Image(o);
        return *this;
    }
    Image(Image&&) noexcept = default;
    Image& operator=(Image&&) noexcept = default;

    int width() const { return m_width; }
    int height() const { return m_height; }
    size_t size() const { return m_data.size(); }
    bool empty() const { return m_data.empty(); }

    T& operator()(int x, int y) {
        assert(x >= 0 && x < m_width && y >= 0 && y < m_height);
        return m_data[size_t(y) * m_width + x];
    }
    const T& operator()(int x, int y) const {
        assert(x >= 0 && x < m_width && y >= 0 && y < m_height);
        return m_data[size_t(y) * m_width + x];
    }
    T& operator[](size_t i) { return m_data[i]; }
    const T& operator[](size_t i) const { return m_data[i]; }

    T* data() { return m_data.data(); }
    const T* data() const { return m_data.data(); }

    void fill(const T& v) { std::fill(m_data.begin(), m_data.end(), v); }
    bool sameSize(int w, int h) const { return m_width == w && m_height == h; }
    template <class U>
    bool sameSize(const Image<U>& o) const { return m_width == o.width() && m_height == o.height(); }

private:
    template <class Fn>
    void parallelRange(Fn&& fn) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, m_data.size(), 1 << 16),
                          [&](const tbb::blocked_range<size_t>& r) { fn(r.begin(), r.end()); });
    }

    int m_width = 0, m_height = 0;
    std::vector<T, UnwrittenAllocator<T>> m_data;
};

using Image1f = Image<float>;
using Image3f = Image<Vec3f>;

}  // namespace wedge
