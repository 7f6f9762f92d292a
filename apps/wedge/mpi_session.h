// The MPI job a `wedge` process belongs to (docs/mpi.md). Started by `mpirun -n N`, the ranks
// render together (render/distribution.h); started without mpirun (or built without MPI),
// there is one rank and nothing of MPI is touched.
//
// Failures: every collective a render makes is preceded by an agreement (agree(0)); a rank
// that fails (bad input, an exception) goes straight to main's final agreement with its exit
// code, which meets the others' next agreement, so every rank learns of it, leaves with the
// same exit code, and only the lowest failing rank prints its message. A rank that dies ends
// the job through mpirun; a rank that waits longer than WEDGE_MPI_TIMEOUT seconds (default
// 3600, 0: forever) for the others inside a render aborts the job with a message; MPI's own
// errors abort it with MPI's message.
#pragma once

#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "render/distribution.h"

namespace wedge::app {

/// Thrown on the ranks that learn in an agreement that another rank failed: they exit with
/// `code` without a message of their own (the failing rank prints it).
class OtherRankFailed : public std::exception {
public:
    explicit OtherRankFailed(int code) : code(code) {}
    const char* what() const noexcept override { return "another rank failed"; }
    int code;
};

class MpiSession : public render::Distribution {
public:
    /// The process's session; init() first.
    static MpiSession& get();
    /// Joins the MPI job when mpirun (or another MPI launcher) started this process.
    void init(int* argc, char*** argv);
    /// Leaves it (MPI_Finalize); safe to call when never joined.
    void finalize();

    bool active() const { return m_ranks > 1; }
    int rank() const override { return m_rank; }
    int ranks() const override { return m_ranks; }
    std::vector<std::vector<char>> allgather(const std::vector<char>& mine) const override;
    uint64_t bytesExchanged() const override { return m_bytes; }
    /// The distribution a render uses: null in one process.
    const render::Distribution* distribution() const { return active() ? this : nullptr; }

    struct Outcome {
        int code = 0;         // the largest exit code of every rank
        int firstFailed = -1; // the lowest rank whose code was not 0, -1: none
    };
    /// Every rank's exit code (a collective). `timeout`: abort the job with a message after
    /// that many seconds of waiting (0: wait forever).
    Outcome agree(int code, double timeout) const;
    /// Whether this rank prints a message of `outcome`: the lowest failing one.
    bool reports(const Outcome& outcome) const { return outcome.firstFailed == m_rank; }
    /// WEDGE_MPI_TIMEOUT, seconds.
    double timeout() const { return m_timeout; }

private:
    int m_rank = 0, m_ranks = 1;
    bool m_joined = false;
    double m_timeout = 3600;
    // Fault injection for the tests (tests/mpi_test.cpp): WEDGE_MPI_FAULT=RANK:fail makes that
    // rank throw at its first exchange, RANK:hang makes it sleep there, RANK:die kills it.
    int m_faultRank = -1;
    std::string m_fault;
    mutable uint64_t m_bytes = 0;
};

}  // namespace wedge::app
