#include "render/distribution.h"

#include <type_traits>

#include "core/light_field.h"
#include "core/timer.h"
#include "render/pixel_stats.h"

namespace wedge::render {

static_assert(std::is_trivially_copyable_v<PixelStats> && std::is_trivially_copyable_v<SurfaceSlot>);

void exchangeStats(const Distribution* d, PixelStatsImage& stats) {
    if (!d || d->ranks() <= 1) return;
    const int rank = d->rank(), ranks = d->ranks(), W = stats.width(), H = stats.height();
    // Each pixel: its PixelStats (the `more` pointer only says whether further slots follow),
    // then, if any, its further slots.
    constexpr size_t kMore = sizeof(SurfaceSlot) * SlotPool::kBlock;
    std::vector<char> mine;
    for (int y = rank; y < H; y += ranks)
        for (int x = 0; x < W; ++x) {
            const PixelStats& s = stats(x, y);
            const size_t at = mine.size();
            mine.resize(at + sizeof(PixelStats) + (s.more ? kMore : 0));
            std::memcpy(mine.data() + at, &s, sizeof(PixelStats));
            if (s.more) std::memcpy(mine.data() + at + sizeof(PixelStats), s.more, kMore);
        }
    const std::vector<std::vector<char>> all = d->allgather(mine);
    SlotPool& pool = stats.pool();
    for (int r = 0; r < ranks; ++r) {
        if (r == rank) continue;
        const std::vector<char>& in = all[r];
        size_t at = 0;
        for (int y = r; y < H; y += ranks)
            for (int x = 0; x < W; ++x) {
                if (at + sizeof(PixelStats) > in.size()) throw std::length_error("exchangeStats: short message");
                PixelStats& s = stats(x, y);
                std::memcpy(&s, in.data() + at, sizeof(PixelStats));
                at += sizeof(PixelStats);
                if (s.more) {
                    if (at + kMore > in.size()) throw std::length_error("exchangeStats: short message");
                    s.more = pool.allocate();
                    std::memcpy(s.more, in.data() + at, kMore);
                    at += kMore;
                }
            }
    }
}

void exchangeLightField(const Distribution* d, LightFieldSamples& lf) {
    if (!d || d->ranks() <= 1) return;
    const size_t W = size_t(lf.width());
    for (int stage = 0; stage < lf.stages(); ++stage)
        exchangeRows(d, lf.height(), [&](int y) {
            LightFieldSample* begin = lf.run(stage, size_t(y) * W);
            LightFieldSample* end = lf.run(stage, size_t(y + 1) * W);
            return std::pair<char*, size_t>{reinterpret_cast<char*>(begin), size_t(end - begin) * sizeof(LightFieldSample)};
        });
    if (lf.curved())  // (the sagittas beside the samples)
        for (int stage = 0; stage < lf.stages(); ++stage)
            exchangeRows(d, lf.height(), [&](int y) {
                LightFieldSag* begin = lf.sagRun(stage, size_t(y) * W);
                LightFieldSag* end = lf.sagRun(stage, size_t(y + 1) * W);
                return std::pair<char*, size_t>{reinterpret_cast<char*>(begin), size_t(end - begin) * sizeof(LightFieldSag)};
            });
    // Which pixels' paths bend (LightFieldSamples::bentReach, marked as the samples are
    // recorded): the layered reconstruction reads it for every sample a tile gathers, from any
    // rank's rows. (Only aaf and maaf exchanged it, in bentPixels, before their adaptive
    // samples: mc and à-trous on two ranks gave docs/turning-room.json another image than one
    // process, in the tiles around its turning box.)
    exchangeImageRows(d, lf.bentReachData(), lf.width(), lf.height());
}

std::vector<uint64_t> gatherCounts(const Distribution* d, uint64_t mine) {
    if (!d || d->ranks() <= 1) return {mine};
    std::vector<char> bytes(sizeof mine);
    std::memcpy(bytes.data(), &mine, sizeof mine);
    std::vector<uint64_t> out;
    for (const std::vector<char>& b : d->allgather(bytes)) {
        uint64_t v = 0;
        if (b.size() != sizeof v) throw std::length_error("gatherCounts: short message");
        std::memcpy(&v, b.data(), sizeof v);
        out.push_back(v);
    }
    return out;
}

void shareRootTimes(const Distribution* d, StageTimes& times) {
    if (!d || d->ranks() <= 1) return;
    std::vector<double> mine;
    for (const auto& [name, s] : times.stages()) mine.push_back(s);
    std::vector<char> bytes(mine.size() * sizeof(double));
    if (!mine.empty()) std::memcpy(bytes.data(), mine.data(), bytes.size());
    const std::vector<char> root = d->allgather(bytes)[0];
    if (root.size() != bytes.size()) throw std::length_error("shareRootTimes: rank 0 timed other stages");
    StageTimes shared;
    size_t k = 0;
    for (const auto& [name, s] : times.stages()) {
        double v = 0;
        std::memcpy(&v, root.data() + k++ * sizeof(double), sizeof v);
        shared.add(name, v);
    }
    times = shared;
}

}  // namespace wedge::render
