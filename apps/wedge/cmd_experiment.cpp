// wedge experiment SCENE --methods mc,aaf,maaf,atrous --spp N --reference-spp M --out DIR
//                  [--equal-time] [--equal-quality] [--resolution WxH] [--quiet] ...
// Flags -> ExperimentOptions -> render::runExperiment (src/render/experiment.h), which writes
// DIR/results.json, DIR/index.html, DIR/table.md and DIR/images/.
#include <fstream>
#include <iterator>
#include <memory>

#include "apps/wedge/commands.h"
#include "apps/wedge/common.h"
#include "apps/wedge/mpi_session.h"
#include "apps/wedge/render_flags.h"
#include "core/error.h"
#include "core/parallel.h"
#include "render/experiment.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"

namespace wedge::app {

namespace {

struct ExperimentArgs {
    render::ExperimentOptions options;
    std::string resolution;
    int threads = 0;
    long long seed = -1;
};

std::string shellQuote(const std::string& s) {
    if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_./,=:") ==
                          std::string::npos)
        return s;
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

/// This process's command line (Linux /proc), argv[0] shown as "wedge"; empty if unreadable.
std::string commandLine() {
    std::ifstream in("/proc/self/cmdline", std::ios::binary);
    std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::string line;
    size_t start = 0;
    for (int i = 0; start < all.size(); ++i) {
        size_t end = all.find('\0', start);
        if (end == std::string::npos) end = all.size();
        line += i == 0 ? std::string("wedge") : " " + shellQuote(all.substr(start, end - start));
        start = end + 1;
    }
    return line;
}

void runExperiment(ExperimentArgs& a) {
    render::ExperimentOptions& o = a.options;
    if (o.methods.empty()) o.methods = render::methods();
    if (a.seed >= 0) o.seed = uint32_t(a.seed);
    render::checkExperimentOptions(o);

    // Under mpirun every rank runs the experiment and each render is split over them
    // (docs/mpi.md); rank 0 alone prints and writes.
    const MpiSession& mpi = MpiSession::get();
    o.base.distribution = mpi.distribution();
    if (mpi.rank() != 0) {
        o.quiet = true;
        o.writes = false;
    }

    ThreadLimit limit(a.threads);
    scene::SceneDesc desc = scene::loadScene(o.sceneName);
    if (mpi.rank() == 0) printWarnings(desc);
    applyResolution(desc, a.resolution);
    scene::Scene scene(std::move(desc));
    render::runExperiment(scene, o);
}

}  // namespace

void registerExperiment(CLI::App& app) {
    auto args = std::make_shared<ExperimentArgs>();
    CLI::App* cmd = app.add_subcommand(
        "experiment", "Render a scene with several methods against a reference; equal-time and equal-quality report");
    addMaxMemory(cmd);
    cmd->add_option("scene", args->options.sceneName, "Scene file (JSON) or built-in name (see 'wedge scenes')")
        ->required();
    cmd->add_option("--methods", args->options.methods, "Comma-separated methods (default: all; unavailable ones are skipped)")
        ->delimiter(',');
    cmd->add_option("--spp", args->options.spp, "Base samples per pixel of every method (initial spp for aaf/maaf)")
        ->check(numberIn(1, 1 << 20))
        ->capture_default_str();
    cmd->add_option("--reference-spp", args->options.referenceSpp, "Samples per pixel of the MC reference")
        ->check(numberIn(1, 1 << 20))
        ->capture_default_str();
    cmd->add_option("--out", args->options.outDir, "Output directory (created if missing)")->required();
    cmd->add_option("--cache", args->options.cacheDir, "Directory of cached references (default: OUT/cache)");
    cmd->add_flag("--equal-time", args->options.equalTime, "Find each method's spp at the anchor's total time");
    cmd->add_flag("--equal-quality", args->options.equalQuality, "Find each method's spp at the anchor's relMSE");
    cmd->add_option("--anchor", args->options.anchor,
                    "Method the others are matched to (default: maaf, else aaf, else atrous, else the first)");
    cmd->add_option("--max-spp", args->options.maxSpp, "Upper bound of the searches (default: reference spp / 4)")
        ->check(nonNegativeNumber());
    cmd->add_option("--tolerance", args->options.tolerance, "Relative spp resolution of the searches")
        ->check(numberIn(0.0, 10.0));
    cmd->add_option("--repeat", args->options.repeat, "Renders per probe (and re-timings per row); the fastest counts")
        ->check(CLI::Range(1, 20));
    cmd->add_option("--resolution", args->resolution, "Override the camera resolution, WxH");
    cmd->add_option("--seed", args->seed, "Random seed of the methods (default: the scene's render.seed)")
        ->check(numberIn(0, 4294967295.0));
    cmd->add_option("--threads", args->threads, "Worker threads (0: all cores)")->check(numberIn(0, 1024));
    addMethodFlags(*cmd, args->options.base);
    cmd->add_flag("-q,--quiet", args->options.quiet, "No progress on stderr and no table on stdout");
    cmd->callback([args] {
        args->options.commandLine = commandLine();
        runExperiment(*args);
    });
}

}  // namespace wedge::app
