// Parallel loops over image tiles with oneTBB. The thread count is set once per process by
// ThreadLimit (tbb::global_control); results never depend on it because every reduction that
// reaches an image is either per pixel or done in a fixed order. Each block of rows or tiles
// first checks for cancellation (core/cancel.h), which oneTBB carries to the loop's caller.
#pragma once

#include <functional>
#include <memory>

#include <tbb/blocked_range2d.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "core/cancel.h"

namespace wedge {

/// Limits oneTBB to `threads` worker threads while alive; 0 means all hardware threads.
class ThreadLimit {
public:
    explicit ThreadLimit(int threads);
    static int current();

private:
    std::unique_ptr<tbb::global_control> m_control;
};

/// body(x0, x1, y0, y1) over tiles of an image; tiles are processed in any order. The tiles
/// are the same on every run and any number of threads (simple_partitioner: the range is split
/// down to the grain, whatever the stealing), so a body that batches its tile's work (the
/// sampler traces several pixels' rays as one Embree stream) batches it the same way. With
/// TBB's auto_partitioner the ranges varied with the scheduling, and with them the streams; and
/// a few samples' occluder spans depended, in their last bit, on the stream they were traced in
/// (docs/posts.json with AAF: the slope AOV of 2 of 36864 pixels differed by one ulp in 1 run
/// in 6 on two threads; between two tilings on one thread, 3 pixels; which rays, and whether in
/// Embree's stream traversal or in wedge's arithmetic around it, was not isolated; the spans'
/// second, reversed query is gone since 2026-12-01).
template <class Body>
void parallelTiles(int width, int height, int tile, Body&& body) {
    tbb::parallel_for(tbb::blocked_range2d<int>(0, height, tile, 0, width, tile),
                      [&](const tbb::blocked_range2d<int>& r) {
                          throwIfCancelled();
                          body(r.cols().begin(), r.cols().end(), r.rows().begin(), r.rows().end());
                      },
                      tbb::simple_partitioner());
}

/// body(y) for every row, in parallel.
template <class Body>
void parallelRows(int height, Body&& body) {
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 4), [&](const tbb::blocked_range<int>& r) {
        throwIfCancelled();
        for (int y = r.begin(); y < r.end(); ++y) body(y);
    });
}

}  // namespace wedge
