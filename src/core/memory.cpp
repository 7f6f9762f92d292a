#include "core/memory.h"

#include <cstdint>
#include <map>
#include <mutex>
#include <unordered_map>

#include <sys/mman.h>

namespace wedge {

namespace {

/// Large blocks are mapped directly (2 MiB-aligned), so that a kept block can be split to serve
/// a smaller request and adjacent kept blocks merged again: unmapping works on any page range.
struct BlockPool {
    std::mutex mutex;
    std::unordered_map<char*, size_t> inUse;  // pointer -> bytes
    std::map<char*, size_t> keptByAddress;    // kept blocks, for merging neighbours
    std::multimap<size_t, char*> keptBySize;  // the same blocks, for best fit
    size_t keptBytes = 0;

    void keep(char* p, size_t size) {
        // Merge with the kept blocks just before and just after it.
        auto next = keptByAddress.lower_bound(p);
        if (next != keptByAddress.begin()) {
            auto prev = std::prev(next);
            if (prev->first + prev->second == p) {
                p = prev->first;
                size += prev->second;
                forget(prev);
            }
        }
        if (next != keptByAddress.end() && p + size == next->first) {
            size += next->second;
            forget(next);
        }
        keptByAddress.emplace(p, size);
        keptBySize.emplace(size, p);
        keptBytes += size;
    }
    void forget(std::map<char*, size_t>::iterator it) {
        auto range = keptBySize.equal_range(it->second);
        for (auto s = range.first; s != range.second; ++s)
            if (s->second == it->first) {
                keptBySize.erase(s);
                break;
            }
        keptBytes -= it->second;
        keptByAddress.erase(it);
    }
};

BlockPool& pool() {
    static BlockPool* p = new BlockPool;  // never destroyed: blocks may be freed during exit
    return *p;
}

// Keep at most this much; a block released beyond it is unmapped at once.
constexpr size_t kMaxKept = size_t(4) << 30;

char* mapFresh(size_t bytes) {
    const size_t align = detail::kHugeBlock;
    void* raw = mmap(nullptr, bytes + align, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    char* base = static_cast<char*>(raw);
    char* p = reinterpret_cast<char*>((reinterpret_cast<uintptr_t>(base) + align - 1) / align * align);
    if (p > base) munmap(base, size_t(p - base));
    if (char* end = p + bytes; base + bytes + align > end) munmap(end, size_t(base + bytes + align - end));
    madvise(p, bytes, MADV_HUGEPAGE);  // advisory: ignored where THP is off
    return p;
}

}  // namespace

namespace detail {

void* acquireLargeBlock(size_t bytes) {
    const size_t rounded = (bytes + kHugeBlock - 1) / kHugeBlock * kHugeBlock;
    BlockPool& bp = pool();
    std::lock_guard<std::mutex> lock(bp.mutex);
    auto it = bp.keptBySize.lower_bound(rounded);  // best fit
    char* p;
    if (it != bp.keptBySize.end()) {
        p = it->second;
        const size_t size = it->first;
        bp.forget(bp.keptByAddress.find(p));
        if (size > rounded) bp.keep(p + rounded, size - rounded);  // the rest stays kept
    } else {
        p = mapFresh(rounded);
    }
    bp.inUse.emplace(p, rounded);
    return p;
}

void releaseLargeBlock(void* ptr) {
    char* p = static_cast<char*>(ptr);
    BlockPool& bp = pool();
    std::lock_guard<std::mutex> lock(bp.mutex);
    auto it = bp.inUse.find(p);
    const size_t size = it->second;
    bp.inUse.erase(it);
    if (bp.keptBytes + size <= kMaxKept) bp.keep(p, size);
    else munmap(p, size);
}

}  // namespace detail

void trimLargeBlocks() {
    BlockPool& bp = pool();
    std::lock_guard<std::mutex> lock(bp.mutex);
    for (auto& [p, size] : bp.keptByAddress) munmap(p, size);
    bp.keptByAddress.clear();
    bp.keptBySize.clear();
    bp.keptBytes = 0;
}

size_t keptLargeBlockBytes() {
    BlockPool& bp = pool();
    std::lock_guard<std::mutex> lock(bp.mutex);
    return bp.keptBytes;
}

}  // namespace wedge
