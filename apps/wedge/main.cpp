// wedge: command line. Flags -> options -> one library call -> files.
#include <cstdio>
#include <new>

#include "apps/wedge/commands.h"
#include "core/error.h"
#include "io/output_file.h"

int main(int argc, char** argv) {
    wedge::io::installSignalHandlers();
    CLI::App app{"wedge: sparse sampling and Fourier-derived reconstruction filters for distribution effects"};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "Show help for every subcommand");
    wedge::app::registerRender(app);
    wedge::app::registerScenes(app);
    wedge::app::registerCompare(app);
    wedge::app::registerExperiment(app);
    wedge::app::registerAnalyze(app);
    wedge::app::registerRaster(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "wedge: error: %s\n", e.what());
        if (e.get_name() == "RequiredError" || e.get_name() == "ExtrasError")
            std::fprintf(stderr, "run 'wedge --help' or 'wedge <command> --help' for usage\n");
        return 2;
    } catch (const wedge::Error& e) {
        std::fprintf(stderr, "wedge: error: %s\n", e.what());
        return 2;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "wedge: error: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "wedge: internal error: %s\n", e.what());
        return 1;
    }
    return 0;
}
