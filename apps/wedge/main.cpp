// wedge: command line. Flags -> options -> one library call -> files.
#include <cstdio>
#include <new>
#include <sstream>

#include "apps/wedge/commands.h"
#include "apps/wedge/mpi_session.h"
#include "core/error.h"
#include "io/output_file.h"

namespace {

/// Parses and runs the command; returns the exit code, and the message to print in `message`.
int run(CLI::App& app, int argc, char** argv, std::string& message, bool& agreed) {
    const bool root = wedge::app::MpiSession::get().rank() == 0;
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        std::ostringstream none;
        return root ? app.exit(e) : app.exit(e, none, none);
    } catch (const CLI::CallForAllHelp& e) {
        std::ostringstream none;
        return root ? app.exit(e) : app.exit(e, none, none);
    } catch (const CLI::ParseError& e) {
        message = std::string("wedge: error: ") + e.what() + "\n";
        if (e.get_name() == "RequiredError" || e.get_name() == "ExtrasError")
            message += "run 'wedge --help' or 'wedge <command> --help' for usage\n";
        return 2;
    } catch (const wedge::app::OtherRankFailed& e) {
        agreed = true;  // learnt in an agreement: every rank knows
        return e.code;
    } catch (const wedge::Error& e) {
        message = std::string("wedge: error: ") + e.what() + "\n";
        return 2;
    } catch (const std::bad_alloc&) {
        message = "wedge: error: out of memory\n";
        return 1;
    } catch (const std::exception& e) {
        message = std::string("wedge: internal error: ") + e.what() + "\n";
        return 1;
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    wedge::io::installSignalHandlers();
    wedge::app::MpiSession& mpi = wedge::app::MpiSession::get();
    try {
        mpi.init(&argc, &argv);
    } catch (const wedge::Error& e) {
        if (mpi.rank() == 0) std::fprintf(stderr, "wedge: error: %s\n", e.what());  // once, not per copy
        return 2;
    }
    CLI::App app{"wedge: sparse sampling and Fourier-derived reconstruction filters for distribution effects"};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "Show help for every subcommand");
    wedge::app::registerRender(app);
    wedge::app::registerScenes(app);
    wedge::app::registerCompare(app);
    wedge::app::registerExperiment(app);
    wedge::app::registerAnalyze(app);
    wedge::app::registerRaster(app);
    // Under mpirun, `render` and `experiment` run on every rank together; the other commands on
    // rank 0 alone (docs/mpi.md), while the other ranks wait for its exit code.
    if (mpi.active() && mpi.rank() != 0)
        for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
            if (sub->get_name() != "render" && sub->get_name() != "experiment") sub->callback([] {});

    std::string message;
    bool agreed = false;
    int code = run(app, argc, argv, message, agreed);
    if (mpi.active()) {
        // Every rank leaves with the same exit code; the lowest failing rank prints its message.
        if (!agreed) {
            const wedge::app::MpiSession::Outcome o = mpi.agree(code, 0);
            if (mpi.reports(o) && !message.empty()) {
                // "wedge: error: ..." -> "wedge: error (rank 2): ..."
                const size_t second = message.find(':', message.find(':') + 1);
                if (mpi.rank() != 0 && second != std::string::npos)
                    message.insert(second, " (rank " + std::to_string(mpi.rank()) + ")");
                std::fputs(message.c_str(), stderr);
            }
            code = o.code;
        }
        std::fflush(stdout);
        std::fflush(stderr);
        mpi.finalize();
        return code;
    }
    if (!message.empty()) std::fputs(message.c_str(), stderr);
    return code;
}
