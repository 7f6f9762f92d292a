#include "io/output_file.h"

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "core/error.h"

namespace fs = std::filesystem;

namespace wedge::io {

namespace {

/// The temporaries being written, for the signal handler: fixed slots of fixed size, since a
/// handler may not allocate or lock. `claimed` hands a slot to one writer; the handler reads
/// `path` only while `ready` is set, after it is complete.
struct TempSlot {
    std::atomic<bool> claimed{false}, ready{false};
    char path[4096];
};
std::array<TempSlot, 64> g_temps;

/// Registers a temporary for the handler's clean-up while it exists (none if the slots are
/// full or the path too long: then an interrupt may leave that one temporary behind).
class TempRegistration {
public:
    explicit TempRegistration(const std::string& path) {
        if (path.size() >= sizeof(TempSlot::path)) return;
        for (TempSlot& s : g_temps) {
            bool expected = false;
            if (!s.claimed.compare_exchange_strong(expected, true)) continue;
            std::memcpy(s.path, path.c_str(), path.size() + 1);
            s.ready.store(true);
            m_slot = &s;
            return;
        }
    }
    ~TempRegistration() {
        if (!m_slot) return;
        m_slot->ready.store(false);
        m_slot->claimed.store(false);
    }
    TempRegistration(const TempRegistration&) = delete;
    TempRegistration& operator=(const TempRegistration&) = delete;

private:
    TempSlot* m_slot = nullptr;
};

void writeAll(int fd, const char* text) {
    for (size_t n = std::strlen(text); n > 0;) {
        const ssize_t w = ::write(fd, text, n);
        if (w <= 0) return;
        text += w;
        n -= size_t(w);
    }
}

extern "C" void onTerminate(int sig) {
    // Async-signal-safe calls only: unlink, write, _exit.
    for (TempSlot& s : g_temps)
        if (s.ready.load()) ::unlink(s.path);
    writeAll(2, sig == SIGINT ? "wedge: interrupted by SIGINT; no output written past this point\n"
                              : "wedge: terminated by SIGTERM; no output written past this point\n");
    ::_exit(128 + sig);
}

}  // namespace

void atomicWrite(const std::string& path, const std::function<void(const std::string& tmp)>& write) {
    static std::atomic<int> counter{0};
    const std::string tmp = path + ".tmp" + std::to_string(getpid()) + "-" + std::to_string(counter++);
    TempRegistration registration(tmp);
    try {
        write(tmp);
        std::error_code ec;
        fs::rename(tmp, path, ec);
        if (ec) throw Error(path, "cannot write: " + ec.message());
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
}

void writeTextFile(const std::string& path, const std::string& text) {
    atomicWrite(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) throw Error(path, std::string("cannot open for writing: ") + std::strerror(errno));
        out << text;
        out.close();  // the last buffer reaches the disk here
        if (!out) throw Error(path, std::string("cannot write: ") + std::strerror(errno));
    });
}

void installSignalHandlers() {
    struct sigaction sa {};
    sa.sa_handler = onTerminate;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    std::signal(SIGXFSZ, SIG_IGN);
}

}  // namespace wedge::io
