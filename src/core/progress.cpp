#include "core/progress.h"

#include <cstdio>

#include "core/cancel.h"

namespace wedge {

Progress::Progress(std::string label, uint64_t total, bool enabled)
    : m_label(std::move(label)), m_total(total > 0 ? total : 1), m_enabled(enabled) {}

Progress::~Progress() { done(); }

void Progress::add(uint64_t units) {
    throwIfCancelled();
    uint64_t d = m_done.fetch_add(units) + units;
    if (!m_enabled) return;
    double now = m_timer.seconds();
    if (now < m_nextDraw.load(std::memory_order_relaxed)) return;
    std::unique_lock lock(m_drawMutex, std::try_to_lock);
    if (!lock.owns_lock()) return;
    m_nextDraw = now + 0.2;
    draw(d, false);
}

void Progress::done() {
    if (m_finished) return;
    m_finished = true;
    if (!m_enabled) return;
    std::lock_guard lock(m_drawMutex);
    draw(m_total, true);
}

void Progress::draw(uint64_t done, bool final) {
    double f = std::min(1.0, double(done) / double(m_total));
    double elapsed = m_timer.seconds();
    double eta = f > 0 ? elapsed * (1 - f) / f : 0;
    constexpr int kWidth = 30;
    int filled = int(f * kWidth);
    char bar[kWidth + 1];
    for (int i = 0; i < kWidth; ++i) bar[i] = i < filled ? '#' : '.';
    bar[kWidth] = 0;
    if (final)
        std::fprintf(stderr, "\r%-18s [%s] 100%%  %6.2fs          \n", m_label.c_str(), bar, elapsed);
    else
        std::fprintf(stderr, "\r%-18s [%s] %3d%%  ETA %5.1fs   ", m_label.c_str(), bar, int(f * 100), eta);
    std::fflush(stderr);
}

}  // namespace wedge
