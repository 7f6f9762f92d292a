// Wall-clock stage timings for --stats and the progress bar.
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <vector>

namespace wedge {

class Timer {
public:
    Timer() : m_start(std::chrono::steady_clock::now()) {}
    double seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
    }
    void reset() { m_start = std::chrono::steady_clock::now(); }

private:
    std::chrono::steady_clock::time_point m_start;
};

/// Named stage durations, in the order they were first recorded.
class StageTimes {
public:
    void add(const std::string& stage, double seconds) {
        for (auto& [name, s] : m_stages)
            if (name == stage) { s += seconds; return; }
        m_stages.emplace_back(stage, seconds);
    }
    double get(const std::string& stage) const {
        for (auto& [name, s] : m_stages)
            if (name == stage) return s;
        return 0;
    }
    const std::vector<std::pair<std::string, double>>& stages() const { return m_stages; }

private:
    std::vector<std::pair<std::string, double>> m_stages;
};

}  // namespace wedge
