// The memoization cache of decoupled sampling (Ragan-Kelley et al. 2011): a fixed number of
// entries, one shaded shading-grid cell (primitive, cell) each, replaced least recently used
// first. A lookup that hits makes its entry the most recently used. The pipeline's policy on a
// miss (see raster_renderer.h): shade the 2x2 quad of cells containing the missed cell and insert
// all four results, the other three first (in quad order) and the missed one last, so that the
// missed cell is the most recently used even when the cache holds fewer than four entries.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "raster/shading_space.h"

namespace wedge::raster {

class LruShadingCache {
public:
    explicit LruShadingCache(size_t capacity);

    /// The payload cached for `key`, made most recently used; nullptr on a miss.
    const uint32_t* lookup(const CellKey& key);
    /// Inserts or refreshes `key` as the most recently used entry, evicting the least recently used
    /// entry when the cache is full.
    void insert(const CellKey& key, uint32_t payload);

    size_t size() const { return m_map.size(); }
    size_t capacity() const { return m_nodes.size(); }
    uint64_t evictions() const { return m_evictions; }

private:
    struct Node {
        CellKey key;
        uint32_t payload = 0;
        int32_t prev = -1, next = -1;  // towards the most / least recently used end
    };
    void unlink(int32_t i);
    void pushFront(int32_t i);

    std::vector<Node> m_nodes;
    std::unordered_map<CellKey, int32_t, CellKeyHash> m_map;
    int32_t m_head = -1, m_tail = -1;  // most / least recently used
    int32_t m_used = 0;
    uint64_t m_evictions = 0;
};

}  // namespace wedge::raster
