// Rendering over several processes (MPI ranks, docs/mpi.md). The library knows no MPI: a
// Distribution is the few collective operations a render needs, implemented over MPI by the
// command line (apps/wedge/mpi_session.cpp) and absent (null) in one process.
//
// Decomposition: rank r traces the rows y with y % ranks == r, in every sampling stage. Every
// pixel's samples are keyed by (seed, pixel, sample index) and traced and folded in order by
// exactly one rank, so its statistics are bit for bit those of one process. After each sampling
// stage the owners' per-pixel state (PixelStats, the light field's samples, the sample records
// a method keeps) is copied to every rank, which then runs the cheap stages (prefilters,
// filters, the layered reconstruction) on the same data as one process: the image is
// bit-identical, with no halos and nothing traced twice. Interleaved rows balance every stage
// (the adaptive ones included) without moving pixels between ranks from stage to stage.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

namespace wedge {
class LightFieldSamples;
class StageTimes;
}

namespace wedge::render {

class PixelStatsImage;

class Distribution {
public:
    virtual ~Distribution() = default;
    virtual int rank() const = 0;
    virtual int ranks() const = 0;
    /// Every rank's `mine`, in rank order. A collective: every rank calls it at the same point.
    /// Throws when another rank failed (the job then ends; nothing is exchanged).
    virtual std::vector<std::vector<char>> allgather(const std::vector<char>& mine) const = 0;
    /// Bytes this process sent and received through allgather so far.
    virtual uint64_t bytesExchanged() const = 0;
};

/// Whether rank `rank` of `ranks` traces row y.
inline bool ownsRow(int y, int rank, int ranks) { return ranks <= 1 || y % ranks == rank; }

/// Copies the rows this rank owns to every other rank: row(y) returns {pointer, bytes} of row
/// y's data, the same layout on every rank (bytes may differ from row to row). No-op without a
/// distribution.
template <class RowFn>
void exchangeRows(const Distribution* d, int height, RowFn&& row) {
    if (!d || d->ranks() <= 1) return;
    const int rank = d->rank(), ranks = d->ranks();
    size_t total = 0;
    for (int y = rank; y < height; y += ranks) total += row(y).second;
    std::vector<char> mine(total);
    size_t at = 0;
    for (int y = rank; y < height; y += ranks) {
        const auto [data, bytes] = row(y);
        if (bytes) std::memcpy(mine.data() + at, data, bytes);
        at += bytes;
    }
    const std::vector<std::vector<char>> all = d->allgather(mine);
    for (int r = 0; r < ranks; ++r) {
        if (r == rank) continue;
        at = 0;
        for (int y = r; y < height; y += ranks) {
            const auto [data, bytes] = row(y);
            if (at + bytes > all[r].size()) throw std::length_error("exchangeRows: rank sent fewer bytes than expected");
            if (bytes) std::memcpy(data, all[r].data() + at, bytes);
            at += bytes;
        }
    }
}

/// Rows of a plain image-shaped array (T trivially copyable, `width` elements a row, or
/// `perPixel` * width).
template <class T>
void exchangeImageRows(const Distribution* d, T* data, int width, int height, size_t perPixel = 1) {
    const size_t rowBytes = size_t(width) * perPixel * sizeof(T);
    exchangeRows(d, height, [&](int y) { return std::pair<char*, size_t>{reinterpret_cast<char*>(data) + size_t(y) * rowBytes, rowBytes}; });
}

/// Every pixel's statistics (their further slots included) from the rank that owns its row.
void exchangeStats(const Distribution* d, PixelStatsImage& stats);
/// Every pixel's light-field samples, all stages, and its bentReach, from the rank that owns its row.
void exchangeLightField(const Distribution* d, LightFieldSamples& lf);
/// Every rank's `mine`, in rank order ({mine} without a distribution).
std::vector<uint64_t> gatherCounts(const Distribution* d, uint64_t mine);
/// Replaces every rank's stage times by rank 0's (the same stages everywhere), so that what is
/// decided on times (wedge experiment's equal-time searches) is decided alike on every rank.
void shareRootTimes(const Distribution* d, StageTimes& times);

}  // namespace wedge::render
