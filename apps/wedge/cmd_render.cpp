// wedge render SCENE [--method ...] [--spp N] [--seed S] [--threads T] [-o OUT]... [--stats F] [--quiet]
#include <cstdio>
#include <memory>

#include "apps/wedge/commands.h"
#include "apps/wedge/common.h"
#include "apps/wedge/mpi_session.h"
#include "apps/wedge/render_flags.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/image_io.h"
#include "render/memory_estimate.h"
#include "render/output.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"

namespace wedge::app {

namespace {

struct RenderArgs {
    std::string scene;
    std::vector<std::string> outputs;
    std::string stats;
    RenderFlags flags;
};

void runRender(const RenderArgs& a) {
    // Under mpirun every rank renders its share (docs/mpi.md); rank 0 alone speaks and writes.
    const MpiSession& mpi = MpiSession::get();
    const bool root = mpi.rank() == 0;
    render::RenderOptions opt = a.flags.renderOptions();
    opt.distribution = mpi.distribution();
    if (!root) {
        opt.quiet = true;
        opt.aovDir.clear();
    }
    for (const auto& o : a.outputs) io::checkOutputPath(o, render::outputExtensions());
    if (!a.stats.empty()) io::checkOutputPath(a.stats, {".json"});

    ThreadLimit limit(a.flags.threads);
    scene::SceneDesc desc = scene::loadScene(a.scene);
    if (root) printWarnings(desc);
    a.flags.applyTo(desc);
    // The resolution against the memory limit before the scene is built: a 16384 x 16384 render
    // needs about 300 GB, and was an out-of-memory kill.
    render::checkRenderMemory(desc, opt);
    scene::Scene scene(std::move(desc));
    const uint64_t bytesBefore = mpi.bytesExchanged();
    render::RenderResult result = render::render(scene, opt);
    if (mpi.active()) result.extra.emplace_back("mpi_bytes_exchanged", double(mpi.bytesExchanged() - bytesBefore));
    if (!root) return;
    if (const size_t bad = render::nonFinitePixels(result); bad > 0)
        std::fprintf(stderr, "wedge: warning: %zu pixels have non-finite (NaN or infinite) samples or colour\n", bad);
    if (const std::string unlit = render::unlitWarning(scene.desc(), result); !unlit.empty())
        std::fprintf(stderr, "wedge: warning: %s: %s\n", a.scene.c_str(), unlit.c_str());

    for (const auto& o : a.outputs) render::writeOutput(result, o);
    if (!a.stats.empty()) writeJsonFile(a.stats, render::statsJson(result, a.scene));
    if (!opt.quiet) std::fputs(render::timingSummary(result).c_str(), stdout);
}

}  // namespace

void registerRender(CLI::App& app) {
    auto args = std::make_shared<RenderArgs>();
    CLI::App* cmd = app.add_subcommand("render", "Render a scene file or built-in scene");
    addMaxMemory(cmd);
    cmd->add_option("scene", args->scene, "Scene file (JSON) or built-in name (see 'wedge scenes')")->required();
    cmd->add_option("-o,--output", args->outputs, "Output image (.exr with all buffers, .png, .pfm); repeatable");
    cmd->add_option("--stats", args->stats, "Write timings and counts as JSON");
    addRenderFlags(*cmd, args->flags);
    cmd->callback([args] { runRender(*args); });
}

}  // namespace wedge::app
