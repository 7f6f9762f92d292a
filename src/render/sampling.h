// The parallel sampling loop shared by every method: for each pixel, trace a range of sample
// indices, fold them into PixelStats and hand each to a sink (which may store the record or
// accumulate filter bands). Tiles run in parallel in any order; every per-pixel result is
// independent of that order, so images do not depend on the thread count.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/light_field.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "render/distribution.h"
#include "render/pixel_stats.h"

namespace wedge::render {

struct SampleRange {
    uint32_t first = 0, count = 0;
};

/// One sampling stage's samples into the light field (render/methods.h, MethodContext::lightField):
/// made with the stage's sample count per pixel, record() called from samplePixels' sink. Does
/// nothing without a light field.
class LightFieldStage {
public:
    template <class CountFn>
    LightFieldStage(LightFieldSamples* lf, CountFn&& count) : m_lf(lf) {
        if (!m_lf) return;
        m_stage = m_lf->addStage(count);
        m_fill.assign(size_t(m_lf->width()) * m_lf->height(), 0);
    }
    /// Sample s of pixel (x, y), which PixelStats::add put in surface slot `slot`. Each pixel's
    /// samples come from one thread, in order; the stage keeps the first count(p) of them.
    void record(int x, int y, const TracedSample& s, int slot) {
        if (!m_lf) return;
        const size_t p = size_t(y) * m_lf->width() + x;
        // A sample that sees an emitter through a wide blur carries its emission too, and no
        // albedo: its radiance is then its own everywhere, where the filters' light (albedo x
        // the surface's filtered light) would drop the emission (LightFieldSamples::wideBlur).
        // Its pixel's emission counts it, kept or not, as the pixel's statistics do.
        const float emitted = LightFieldSamples::emissionLevel(s.emission);
        const bool wide = emitted > 0.f && m_lf->wideBlur(s.depth, s.motion, s.object);
        if (emitted > 0.f) m_lf->addEmission(p, emitted, wide);
        if (m_fill[p] == m_lf->runLength(m_stage, p)) return;
        const SampleRecord& r = s.record;
        if (m_lf->curved()) m_lf->sagRun(m_stage, p)[m_fill[p]] = LightFieldSag::pack(s.sag);
        Vec3f radiance = s.albedo * (r.direct + r.indirect);
        if (wide) radiance += s.emission;
        m_lf->run(m_stage, p)[m_fill[p]++] = LightFieldSample::pack(s.film, r.lens, s.time, s.hit ? s.depth : kInf, s.motion,
                                                                    wide ? Vec3f(0.f) : s.albedo, radiance * m_lf->radianceScale(), slot);
        // A bent path on a surface that turns towards or away from the camera (render/renderer.cpp,
        // leavePixelsToTheMethod). The sample lands in its layer's sharp image within |m| / 2 of
        // x, where a ray of a pixel within |m| / 2 of it reads it; the bend and the grid's blur
        // (2 px) on top.
        if (s.bend > LightFieldSamples::kBentPath && s.faceTurn > LightFieldSamples::kFaceTurn)
            m_lf->markBent(p, std::sqrt(s.motion.x * s.motion.x + s.motion.y * s.motion.y) + s.bend + 2.f);
    }

private:
    LightFieldSamples* m_lf;
    int m_stage = 0;
    std::vector<uint32_t> m_fill;
};

/// range(x, y) -> SampleRange; sink(x, y, const TracedSample&, int slot) with the surface slot
/// PixelStats::add put the sample in. Returns the number of rays traced. Over several ranks
/// (render/distribution.h) only this rank's rows are traced, and then every pixel's statistics
/// are copied from its owner, so that every rank holds all of them, as one process would.
template <class RangeFn, class SinkFn>
uint64_t samplePixels(const PathSampler& sampler, PixelStatsImage& stats, const ViewGeometry& view, RangeFn&& range,
                      bool span, bool slopes, SinkFn&& sink, Progress* progress) {
    std::atomic<uint64_t> rays{0};
    SlotPool& pool = stats.pool();
    parallelTiles(stats.width(), stats.height(), 16, [&](int x0, int x1, int y0, int y1) {
        uint64_t localRays = 0, localSamples = 0;
        // Several pixels' samples are traced together (PathSampler::traceMany: their shadow rays
        // as one Embree stream), then added pixel by pixel, each pixel's in order.
        std::vector<PathSampler::SampleRun> runs;
        std::vector<TracedSample> traced;
        uint32_t queued = 0;
        auto flush = [&] {
            sampler.traceRuns(runs, traced, span);
            for (const auto& run : runs) {
                PixelStats& ps = stats(run.x, run.y);
                for (uint32_t k = 0; k < run.count; ++k) {
                    int slot = ps.add(run.out[k], view, slopes, pool);
                    sink(run.x, run.y, run.out[k], slot);
                    localRays += run.out[k].rays;
                }
            }
            runs.clear();
            queued = 0;
        };
        for (int y = y0; y < y1; ++y) {
            if (!sampler.tracesRow(y)) continue;
            for (int x = x0; x < x1; ++x) {
                SampleRange r = range(x, y);
                localSamples += r.count;
                if (r.count == 0) continue;
                runs.push_back({x, y, r.first, r.count, nullptr});
                queued += r.count;
                if (queued >= 256) flush();
            }
        }
        if (!runs.empty()) flush();
        rays += localRays;
        if (progress) progress->add(localSamples * uint64_t(sampler.ranks()));  // rank 0's share, scaled
    });
    exchangeStats(sampler.distribution(), stats);
    return rays;
}

}  // namespace wedge::render
