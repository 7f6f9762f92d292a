#include "core/memory_limit.h"

#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <unistd.h>

#include "core/error.h"

namespace wedge {

namespace {

std::atomic<uint64_t> g_limit{0};  // 0: the machine's memory

uint64_t physicalMemory() {
    const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
    // Where the system cannot say, no limit rather than a made-up one.
    if (pages <= 0 || pageSize <= 0) return UINT64_MAX;
    return uint64_t(pages) * uint64_t(pageSize);
}

}  // namespace

uint64_t memoryLimit() {
    const uint64_t set = g_limit.load(std::memory_order_relaxed);
    if (set != 0) return set;
    static const uint64_t machine = physicalMemory();
    return machine;
}

void setMemoryLimit(uint64_t bytes) { g_limit.store(bytes, std::memory_order_relaxed); }

uint64_t parseMemorySize(const std::string& text, const std::string& where) {
    const char* s = text.c_str();
    char* end = nullptr;
    const double value = std::strtod(s, &end);
    std::string unit(end);
    for (char& c : unit) c = char(std::tolower((unsigned char)c));
    double scale = 0;
    if (unit.empty() || unit == "b") scale = 1;
    else if (unit == "k" || unit == "kb" || unit == "kib") scale = 1024.0;
    else if (unit == "m" || unit == "mb" || unit == "mib") scale = 1024.0 * 1024;
    else if (unit == "g" || unit == "gb" || unit == "gib") scale = 1024.0 * 1024 * 1024;
    else if (unit == "t" || unit == "tb" || unit == "tib") scale = 1024.0 * 1024 * 1024 * 1024;
    const double bytes = value * scale;
    // 2^63: beyond it the conversion to an integer is undefined; no machine has that much.
    if (end == s || scale == 0 || !(bytes >= 1) || !(bytes < 9.2e18))
        throw Error(where, "'" + text + "' is not a memory size (expected a positive number of bytes with an "
                                         "optional unit K, M, G or T, e.g. 8G)");
    return uint64_t(bytes);
}

std::string formatBytes(double bytes) {
    static const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    int u = 0;
    while (bytes >= 1024 && u < 6) {
        bytes /= 1024;
        ++u;
    }
    char text[48];
    std::snprintf(text, sizeof text, u == 0 ? "%.0f %s" : "%.1f %s", bytes, units[u]);
    return text;
}

std::string overMemoryLimit(const std::string& what, uint64_t bytes) {
    const uint64_t limit = memoryLimit();
    if (bytes <= limit) return "";
    const bool set = g_limit.load(std::memory_order_relaxed) != 0;
    return what + " needs " + formatBytes(double(bytes)) + ", more than the memory limit of " +
           formatBytes(double(limit)) +
           (set ? " (--max-memory)" : " (the machine's memory; --max-memory sets another limit)");
}

void checkMemory(const std::string& where, const std::string& what, uint64_t bytes) {
    if (std::string why = overMemoryLimit(what, bytes); !why.empty()) throw Error(where, why);
}

}  // namespace wedge
