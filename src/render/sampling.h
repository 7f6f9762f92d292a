// The parallel sampling loop shared by every method: for each pixel, trace a range of sample
// indices, fold them into PixelStats and hand each to a sink (which may store the record or
// accumulate filter bands). Tiles run in parallel in any order; every per-pixel result is
// independent of that order, so images do not depend on the thread count.
#pragma once

#include <atomic>
#include <cstdint>

#include "core/parallel.h"
#include "core/progress.h"
#include "render/pixel_stats.h"

namespace wedge::render {

struct SampleRange {
    uint32_t first = 0, count = 0;
};

/// range(x, y) -> SampleRange; sink(x, y, const TracedSample&, int slot) with the surface slot
/// PixelStats::add put the sample in. Returns the number of rays traced.
template <class RangeFn, class SinkFn>
uint64_t samplePixels(const PathSampler& sampler, PixelStatsImage& stats, const ViewGeometry& view, RangeFn&& range,
                      bool span, bool slopes, SinkFn&& sink, Progress* progress) {
    std::atomic<uint64_t> rays{0};
    SlotPool& pool = stats.pool();
    parallelTiles(stats.width(), stats.height(), 16, [&](int x0, int x1, int y0, int y1) {
        uint64_t localRays = 0, localSamples = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                SampleRange r = range(x, y);
                PixelStats& ps = stats(x, y);
                TracedSample batch[16];
                for (uint32_t i = 0; i < r.count; i += 16) {
                    uint32_t n = std::min<uint32_t>(16, r.count - i);
                    sampler.traceBatch(x, y, r.first + i, n, span, batch);
                    for (uint32_t k = 0; k < n; ++k) {
                        int slot = ps.add(batch[k], view, slopes, pool);
                        sink(x, y, batch[k], slot);
                        localRays += batch[k].rays;
                    }
                }
                localSamples += r.count;
            }
        rays += localRays;
        if (progress) progress->add(localSamples);
    });
    return rays;
}

}  // namespace wedge::render
