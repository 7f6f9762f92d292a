#include "apps/wedge/mpi_session.h"

#include <chrono>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <thread>

#include "core/error.h"

#ifdef WEDGE_HAVE_MPI
#include <mpi.h>
#endif

namespace wedge::app {

namespace {

/// The number of processes the launcher says it started (1 when not started by one).
int launcherSize() {
    for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"})
        if (const char* v = std::getenv(var)) return std::max(1, std::atoi(v));
    return 1;
}

/// This process's rank as the launcher numbered it (0 when not started by one).
[[maybe_unused]] int launcherRank() {
    for (const char* var : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
        if (const char* v = std::getenv(var)) return std::max(0, std::atoi(v));
    return 0;
}

#ifdef WEDGE_HAVE_MPI
void onMpiError(MPI_Comm* comm, int* code, ...) {
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    MPI_Error_string(*code, text, &len);
    int rank = -1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    std::fprintf(stderr, "wedge: error (rank %d): MPI: %.*s; ending the job\n", rank, len, text);
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, 1);
}
#endif

}  // namespace

MpiSession& MpiSession::get() {
    static MpiSession session;
    return session;
}

void MpiSession::init(int* argc, char*** argv) {
    const int size = launcherSize();
#ifdef WEDGE_HAVE_MPI
    if (size <= 1) return;  // no launcher: one process, MPI untouched (MPI_Init alone starts a runtime)
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided);
    m_joined = true;
    MPI_Errhandler handler;
    MPI_Comm_create_errhandler(onMpiError, &handler);
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, handler);
    MPI_Comm_rank(MPI_COMM_WORLD, &m_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &m_ranks);
    if (const char* t = std::getenv("WEDGE_MPI_TIMEOUT")) {
        char* end = nullptr;
        const double v = std::strtod(t, &end);
        if (end == t || *end || !(v >= 0)) {
            if (m_rank == 0) std::fprintf(stderr, "wedge: warning: WEDGE_MPI_TIMEOUT: expected seconds (>= 0), got '%s'; using 3600\n", t);
        } else {
            m_timeout = v;
        }
    }
    if (const char* f = std::getenv("WEDGE_MPI_FAULT")) {
        const std::string s = f;
        const size_t colon = s.find(':');
        if (colon != std::string::npos) {
            m_faultRank = std::atoi(s.substr(0, colon).c_str());
            m_fault = s.substr(colon + 1);
        }
    }
#else
    (void)argc;
    (void)argv;
    if (size > 1) {
        m_rank = launcherRank();  // main reports the error on rank 0 alone
        throw Error("mpirun", "this wedge was built without MPI, and mpirun started " + std::to_string(size) +
                                  " copies of it (install libopenmpi-dev, e.g. with scripts/install-deps.sh, and rebuild)");
    }
#endif
}

void MpiSession::finalize() {
#ifdef WEDGE_HAVE_MPI
    if (m_joined) MPI_Finalize();
#endif
    m_joined = false;
}

MpiSession::Outcome MpiSession::agree(int code, double timeout) const {
    Outcome out;
    out.code = code;
    out.firstFailed = code != 0 ? m_rank : -1;
#ifdef WEDGE_HAVE_MPI
    if (!m_joined) return out;
    // Max of the codes and of (ranks - rank) over the failing ranks: the lowest failing rank.
    int send[2] = {code, code != 0 ? m_ranks - m_rank : 0}, recv[2] = {0, 0};
    MPI_Request request;
    MPI_Iallreduce(send, recv, 2, MPI_INT, MPI_MAX, MPI_COMM_WORLD, &request);
    const auto start = std::chrono::steady_clock::now();
    int done = 0;
    for (int polls = 0;; ++polls) {
        MPI_Test(&request, &done, MPI_STATUS_IGNORE);
        if (done) break;
        const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (timeout > 0 && waited > timeout) {
            std::fprintf(stderr,
                         "wedge: error (rank %d): waited %.0f s for the other ranks (WEDGE_MPI_TIMEOUT); ending the job\n",
                         m_rank, waited);
            std::fflush(stderr);
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        // Spin briefly (a stage's end is usually within milliseconds on every rank), then sleep.
        if (polls > 1000) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    out.code = recv[0];
    out.firstFailed = recv[1] > 0 ? m_ranks - recv[1] : -1;
#else
    (void)timeout;
#endif
    return out;
}

std::vector<std::vector<char>> MpiSession::allgather(const std::vector<char>& mine) const {
    std::vector<std::vector<char>> all(static_cast<size_t>(m_ranks));
#ifdef WEDGE_HAVE_MPI
    if (m_rank == m_faultRank) {
        if (m_fault == "hang")
            for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
        if (m_fault == "die") std::raise(SIGKILL);
        throw std::runtime_error("injected failure (WEDGE_MPI_FAULT)");
    }
    // Every exchange starts with an agreement: a rank that failed meets it from main's last one.
    if (const Outcome o = agree(0, m_timeout); o.code != 0) throw OtherRankFailed(o.code);
    const uint64_t size = mine.size();
    std::vector<uint64_t> sizes(static_cast<size_t>(m_ranks));
    MPI_Allgather(&size, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
    for (int r = 0; r < m_ranks; ++r) all[size_t(r)].resize(sizes[size_t(r)]);
    // In rounds of at most INT_MAX / ranks bytes a rank, so that counts and displacements fit an int.
    const uint64_t chunk = uint64_t(INT_MAX) / uint64_t(m_ranks);
    std::vector<int> counts(static_cast<size_t>(m_ranks)), displs(static_cast<size_t>(m_ranks));
    std::vector<char> buffer;
    for (uint64_t at = 0;; at += chunk) {
        int total = 0;
        for (int r = 0; r < m_ranks; ++r) {
            const uint64_t s = sizes[size_t(r)];
            counts[size_t(r)] = int(at < s ? std::min(chunk, s - at) : 0);
            displs[size_t(r)] = total;
            total += counts[size_t(r)];
        }
        if (total == 0) break;
        buffer.resize(size_t(total));
        const int mineCount = counts[size_t(m_rank)];
        MPI_Allgatherv(mine.data() + std::min<uint64_t>(at, size), mineCount, MPI_BYTE, buffer.data(), counts.data(),
                       displs.data(), MPI_BYTE, MPI_COMM_WORLD);
        for (int r = 0; r < m_ranks; ++r)
            std::copy(buffer.begin() + displs[size_t(r)], buffer.begin() + displs[size_t(r)] + counts[size_t(r)],
                      all[size_t(r)].begin() + std::ptrdiff_t(at));
        m_bytes += uint64_t(mineCount) * uint64_t(m_ranks - 1) + uint64_t(total - mineCount);
    }
#else
    all[0] = mine;
#endif
    return all;
}

}  // namespace wedge::app
