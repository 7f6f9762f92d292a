// wedge render SCENE [--method ...] [--spp N] [--seed S] [--threads T] [-o OUT]... [--stats F] [--quiet]
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "apps/wedge/commands.h"
#include "apps/wedge/common.h"
#include "core/error.h"
#include "core/parallel.h"
#include "filter/maaf.h"
#include "io/image_io.h"
#include "render/output.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"

namespace wedge::app {

namespace {

struct RenderArgs {
    std::string scene;
    std::vector<std::string> outputs;
    std::string stats;
    std::string resolution;
    int threads = 0;
    int spp = 0;
    long long seed = -1;
    render::RenderOptions options;
};

void runRender(const RenderArgs& a) {
    render::RenderOptions opt = a.options;
    if (a.spp != 0) opt.spp = a.spp;
    if (a.seed >= 0) opt.seed = uint32_t(a.seed);
    for (const auto& o : a.outputs) io::checkOutputPath(o, render::outputExtensions());
    if (!a.stats.empty()) io::checkOutputPath(a.stats, {".json"});
    if (!opt.aovDir.empty() && !std::filesystem::is_directory(opt.aovDir))
        throw Error("--aov " + opt.aovDir, "not a directory");

    ThreadLimit limit(a.threads);
    scene::SceneDesc desc = scene::loadScene(a.scene);
    printWarnings(desc);
    applyResolution(desc, a.resolution);
    scene::Scene scene(std::move(desc));
    render::RenderResult result = render::render(scene, opt);

    for (const auto& o : a.outputs) render::writeOutput(result, o);
    if (!a.stats.empty()) writeJsonFile(a.stats, render::statsJson(result, a.scene));
    if (!opt.quiet) std::fputs(render::timingSummary(result).c_str(), stdout);
}

}  // namespace

void registerRender(CLI::App& app) {
    auto args = std::make_shared<RenderArgs>();
    CLI::App* cmd = app.add_subcommand("render", "Render a scene file or built-in scene");
    cmd->add_option("scene", args->scene, "Scene file (JSON) or built-in name (see 'wedge scenes')")->required();
    std::string methodList;
    for (auto& m : render::methods()) methodList += (methodList.empty() ? "" : "|") + m;
    cmd->add_option("--method", args->options.method, "Reconstruction method: " + methodList)
        ->check(CLI::IsMember(render::methods()));
    cmd->add_option("--spp", args->spp, "Samples per pixel (mc: default the scene's render.spp; atrous: 16) or initial samples per pixel (aaf, maaf: 16)")
        ->check(numberIn(1, 1 << 20));
    cmd->add_option("--seed", args->seed, "Random seed (default: the scene's render.seed)")->check(numberIn(0, 4294967295.0));
    cmd->add_option("--threads", args->threads, "Worker threads (0: all cores)")->check(numberIn(0, 1024));
    cmd->add_option("-o,--output", args->outputs, "Output image (.exr with all buffers, .png, .pfm); repeatable");
    cmd->add_option("--stats", args->stats, "Write timings and counts as JSON");
    cmd->add_option("--resolution", args->resolution, "Override the camera resolution, WxH");
    cmd->add_option("--aov", args->options.aovDir, "Write PNG debug maps (filter widths, spp, slopes) into this directory");
    cmd->add_option("--max-extra-spp", args->options.maxExtraSpp, "aaf/maaf: cap on adaptive samples per pixel (default 16; the papers use 100)")
        ->check(numberIn(0, 1 << 16));
    cmd->add_option("--maaf-components", args->options.maafComponents, "maaf: filters per 2D/3D subspace (3, 5 or 7; 1: the central, axis-aligned filter alone)")
        ->check(CLI::IsMember({1, 3, 5, 7}));
    cmd->add_flag("--maaf-paper-rates", args->options.maafPaperRates,
                  "maaf: adaptive samples only at the focal plane (Sec. 6.2), not also where a filter has outer components");
    cmd->add_flag("!--no-focal-fallback", args->options.maafFocalFallback,
                  "maaf: keep all components where the defocus slope changes sign (shows the ringing)");
    cmd->add_flag("--maaf-windows", args->options.maafWindows,
                  "maaf: weigh light and lens samples by eq. 20's Gaussian windows (biased for uniform lights)");
    cmd->add_option("--maaf-radius", args->options.maafRadius, "maaf: spatial filter window in pixels (default 10)")
        ->check(CLI::Range(1, filter::kMaafMaxWindowRadius));
    cmd->add_flag("!--no-maaf-fit", args->options.maafFit,
                  "maaf: all components everywhere, also where the window cannot hold them (the paper's configuration)");
    cmd->add_flag("--maaf-keep-records", args->options.maafKeepRecords,
                  "maaf: keep every pixel's initial samples instead of tracing the outer-component pixels' again "
                  "(the same image; more memory, faster only where the memory was touched before)");
    cmd->add_option("--maaf-weights", args->options.maafWeights,
                    "maaf: component weights mu_p: the sampling densities' spectra (default), eq. 10's Gaussian, or 1")
        ->check(CLI::IsMember({"sampling", "eq10", "unit"}));
    cmd->add_option("--atrous-iterations", args->options.atrousIterations, "atrous: wavelet levels")
        ->check(CLI::Range(1, 10));
    cmd->add_option("--sigma-color", args->options.atrousSigmaColor, "atrous: colour edge-stopping sigma")
        ->check(numberIn(1e-6, 1e6));
    cmd->add_option("--sigma-normal", args->options.atrousSigmaNormal, "atrous: normal edge-stopping sigma")
        ->check(numberIn(1e-6, 1e6));
    cmd->add_option("--sigma-position", args->options.atrousSigmaPosition,
                    "atrous: position edge-stopping sigma (in pixel footprints)")
        ->check(numberIn(1e-6, 1e6));
    cmd->add_flag("!--no-variance", args->options.atrousVarianceGuided,
                  "atrous: plain colour edge-stopping instead of variance-guided (SVGF-style)");
    cmd->add_option("--layers", args->options.layers,
                    "auto (default: on for mc and atrous, off for aaf and maaf), on: the layered reconstruction of "
                    "defocus and motion blur across pixels, off: each pixel's own samples (and aaf's and maaf's defocus filter)")
        ->check(CLI::IsMember({"auto", "on", "off"}));
    cmd->add_flag("-q,--quiet", args->options.quiet, "No progress bar and no summary");
    cmd->callback([args] { runRender(*args); });
}

}  // namespace wedge::app
