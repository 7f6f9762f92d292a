// A progress bar with ETA on stderr. Work units are added from any thread; redrawing is
// rate-limited and done by whichever thread crosses the next redraw time. Silent when disabled
// (--quiet) or when stderr is not wanted. add() is also where a cancelled render stops
// (core/cancel.h).
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include "core/timer.h"

namespace wedge {

class Progress {
public:
    Progress(std::string label, uint64_t total, bool enabled);
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    void add(uint64_t units);
    /// Draws the final 100% line and a newline (idempotent).
    void done();

private:
    void draw(uint64_t done, bool final);

    std::string m_label;
    uint64_t m_total;
    bool m_enabled;
    bool m_finished = false;
    std::atomic<uint64_t> m_done{0};
    std::atomic<double> m_nextDraw{0.0};
    std::mutex m_drawMutex;
    Timer m_timer;
};

}  // namespace wedge
