// The LRU memoization cache of decoupled sampling: a hash map into a fixed pool of nodes on an
// intrusive recency list (see shading_cache.h).
#include "raster/shading_cache.h"

#include "core/error.h"

namespace wedge::raster {

LruShadingCache::LruShadingCache(size_t capacity) : m_nodes(capacity) {
    if (capacity == 0 || capacity > (size_t(1) << 30)) throw Error("shading cache", "capacity must be in [1, 2^30]");
    m_map.reserve(capacity);
}

void LruShadingCache::unlink(int32_t i) {
    Node& n = m_nodes[i];
    if (n.prev >= 0) m_nodes[n.prev].next = n.next; else m_head = n.next;
    if (n.next >= 0) m_nodes[n.next].prev = n.prev; else m_tail = n.prev;
    n.prev = n.next = -1;
}

void LruShadingCache::pushFront(int32_t i) {
    Node& n = m_nodes[i];
    n.prev = -1;
    n.next = m_head;
    if (m_head >= 0) m_nodes[m_head].prev = i;
    m_head = i;
    if (m_tail < 0) m_tail = i;
}

const uint32_t* LruShadingCache::lookup(const CellKey& key) {
    auto it = m_map.find(key);
    if (it == m_map.end()) return nullptr;
    int32_t i = it->second;
    if (i != m_head) {
        unlink(i);
        pushFront(i);
    }
    return &m_nodes[i].payload;
}

void LruShadingCache::insert(const CellKey& key, uint32_t payload) {
    auto it = m_map.find(key);
    int32_t i;
    if (it != m_map.end()) {
        i = it->second;
        unlink(i);
    } else if (m_used < int32_t(m_nodes.size())) {
        i = m_used++;
        m_map.emplace(key, i);
    } else {
        i = m_tail;
        unlink(i);
        m_map.erase(m_nodes[i].key);
        m_map.emplace(key, i);
        ++m_evictions;
    }
    m_nodes[i].key = key;
    m_nodes[i].payload = payload;
    pushFront(i);
}

}  // namespace wedge::raster
