// wedge raster SCENE --shading ds|aas|reference --cache-entries K [--spp 16] -o OUT --stats STATS.json [--quiet]
// wedge raster SCENE --sweep-cache 16,64,256,1024,4096 --out DIR
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "apps/wedge/commands.h"
#include "apps/wedge/common.h"
#include "io/output_file.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/image_io.h"
#include "raster/raster_report.h"
#include "scene/scene_loader.h"

namespace wedge::app {

namespace {

/// The scene with its warnings printed, and one more: the rasterizer textures with the
/// procedural checker only, so a material's map_Kd shows as its Kd.
scene::SceneDesc loadRasterScene(const std::string& name) {
    scene::SceneDesc desc = scene::loadScene(name);
    std::vector<std::string> mapped;
    for (const auto& m : desc.materials)
        if (m.map) mapped.push_back(m.name);
    if (!mapped.empty())
        desc.warnings.push_back(desc.file + ": wedge raster renders the map_Kd of " + scene::nameList(mapped) +
                                " as their Kd alone");
    printWarnings(desc);
    return desc;
}

struct RasterArgs {
    std::string scene;
    std::string shading = "aas";
    size_t cacheEntries = 64;
    int spp = 16;
    long long seed = -1;
    int threads = 0;
    std::string resolution;
    std::vector<std::string> outputs;
    std::string referenceOutput;
    std::string stats;
    std::vector<size_t> sweep;
    std::string outDir;
    bool noReference = false;
    float lensCutoff = raster::FrequencyCutoffs{}.lens;
    float shutterCutoff = raster::FrequencyCutoffs{}.shutter;
    float splitEdge = raster::kDefaultMaxEdge;
    bool noGridAlign = false;
    int truthSpp = 0;
    bool quiet = false;
};

raster::RasterOptions options(const RasterArgs& a, const scene::SceneDesc& desc) {
    raster::RasterOptions opt;
    opt.shading = raster::parseShadingMode(a.shading, "--shading");
    opt.cacheEntries = a.cacheEntries;
    opt.spp = a.spp;
    opt.seed = a.seed >= 0 ? uint32_t(a.seed) : desc.render.seed;
    opt.cutoffs.lens = a.lensCutoff;
    opt.cutoffs.shutter = a.shutterCutoff;
    opt.maxTriangleEdge = a.splitEdge;
    opt.alignGrid = !a.noGridAlign;
    opt.truthSpp = a.truthSpp;
    opt.computeReference = !a.noReference || !a.referenceOutput.empty();
    opt.progress = !a.quiet;
    return opt;
}

void runSweep(const RasterArgs& a) {
    namespace fs = std::filesystem;
    if (a.outDir.empty()) throw Error("--sweep-cache", "needs --out DIR for the CSV, the plot and the images");
    if (!a.outputs.empty()) throw Error("-o", "not used with --sweep-cache (the images go to --out DIR)");
    if (!a.stats.empty()) io::checkOutputPath(a.stats, {".json"});
    std::error_code ec;
    if (fs::exists(a.outDir) && !fs::is_directory(a.outDir)) throw Error("--out " + a.outDir, "not a directory");

    ThreadLimit limit(a.threads);
    scene::SceneDesc desc = loadRasterScene(a.scene);
    applyResolution(desc, a.resolution);
    raster::SweepResult sweep = raster::sweepCache(desc, options(a, desc), a.sweep);

    // Made once there is something to write: a sweep refused (bad input, the memory limit) leaves none.
    fs::create_directories(a.outDir, ec);
    if (ec) throw Error("--out " + a.outDir, "cannot create the directory: " + ec.message());
    fs::path dir(a.outDir);
    io::writeTextFile((dir / "sweep.csv").string(), raster::sweepCsv(sweep));
    writeJsonFile((dir / "sweep.json").string(), raster::sweepJson(sweep, a.scene));
    io::writePng((dir / "sweep.png").string(), raster::sweepPlot(sweep, a.scene));
    io::writePng((dir / "ds.png").string(), sweep.dsImage);
    io::writePng((dir / "aas.png").string(), sweep.aasImage);
    io::writePng((dir / "reference.png").string(), sweep.reference);
    if (!sweep.truth.empty()) io::writePng((dir / "truth.png").string(), sweep.truth);
    if (!a.stats.empty()) writeJsonFile(a.stats, raster::sweepJson(sweep, a.scene));
    if (!a.quiet) {
        std::printf("%-8s %14s %14s %9s\n", "entries", "ds quads", "aas quads", "aas/ds");
        for (const auto& r : sweep.rows)
            std::printf("%-8zu %14llu %14llu %9.3f\n", r.cacheEntries, (unsigned long long)r.ds.shadedQuads,
                        (unsigned long long)r.aas.shadedQuads,
                        r.ds.shadedQuads ? double(r.aas.shadedQuads) / double(r.ds.shadedQuads) : 0.0);
        std::printf("relMSE vs reference: ds %.5f, aas %.5f; aas vs ds %.5f (PSNR %.1f dB)", sweep.ds.relMse,
                    sweep.aas.relMse, sweep.aasVsDsRelMse, sweep.aasVsDsPsnr);
        if (!sweep.truth.empty())
            std::printf("; vs truth: ds %.5f, aas %.5f, reference %.5f", sweep.ds.relMseTruth, sweep.aas.relMseTruth,
                        sweep.referenceRelMseTruth);
        std::printf("; %.2f s\n", sweep.seconds);
    }
}

void runRaster(const RasterArgs& a) {
    if (!a.sweep.empty()) return runSweep(a);
    if (!a.outDir.empty()) throw Error("--out", "only used with --sweep-cache (use -o for an image)");
    for (const auto& o : a.outputs) io::checkOutputPath(o, {".png", ".exr", ".pfm"});
    if (!a.referenceOutput.empty()) io::checkOutputPath(a.referenceOutput, {".png", ".exr", ".pfm"});
    if (!a.stats.empty()) io::checkOutputPath(a.stats, {".json"});

    ThreadLimit limit(a.threads);
    scene::SceneDesc desc = loadRasterScene(a.scene);
    applyResolution(desc, a.resolution);
    raster::RasterResult r = raster::renderRaster(desc, options(a, desc));
    if (r.stats.splitBudgetReached)
        std::fprintf(stderr, "wedge: warning: %s: the split of blurred triangles stopped at %zu triangles "
                             "(a very small --split-edge, or fast motion far off screen); the rest are kept whole\n",
                     a.scene.c_str(), raster::kMaxSplitTriangles);

    for (const auto& o : a.outputs) io::writeColor(o, r.image);
    if (!a.referenceOutput.empty()) io::writeColor(a.referenceOutput, r.reference.empty() ? r.image : r.reference);
    if (!a.stats.empty()) writeJsonFile(a.stats, raster::statsJson(r.stats, a.scene));
    if (!a.quiet) {
        const auto& s = r.stats;
        std::printf("%s, %zu entries: %llu shaded quads (%llu invocations), %llu hits, %llu misses", a.shading.c_str(),
                    s.cacheEntries, (unsigned long long)s.cache.shadedQuads, (unsigned long long)s.cache.shaderInvocations,
                    (unsigned long long)s.cache.hits, (unsigned long long)s.cache.misses);
        if (s.relMse >= 0) std::printf(", relMSE %.5f", s.relMse);
        if (s.relMseTruth >= 0) std::printf(" (vs truth %.5f)", s.relMseTruth);
        std::printf(", %.2f s\n", s.seconds);
    }
}

}  // namespace

void registerRaster(CLI::App& app) {
    auto args = std::make_shared<RasterArgs>();
    CLI::App* cmd = app.add_subcommand(
        "raster", "Stochastic rasterizer with decoupled (DS) and adaptive anisotropic (AAS) shading; shading-cost stats");
    addMaxMemory(cmd);
    cmd->add_option("scene", args->scene, "Scene file (JSON) or built-in name (see 'wedge scenes')")->required();
    cmd->add_option("--shading", args->shading, "ds (pixel grid), aas (adaptive anisotropic grid) or reference (every sample)")
        ->check(CLI::IsMember({"ds", "aas", "reference"}))
        ->capture_default_str();
    cmd->add_option("--cache-entries", args->cacheEntries, "Shading-cache entries (cells), LRU")
        ->check(CLI::Range(size_t(1), size_t(1) << 30))
        ->capture_default_str();
    cmd->add_option("--spp", args->spp, "Visibility samples per pixel")->check(CLI::Range(1, 1024))->capture_default_str();
    cmd->add_option("--seed", args->seed, "Random seed (default: the scene's render.seed)")->check(numberIn(0, 4294967295.0));
    cmd->add_option("--threads", args->threads, "Worker threads (0: all cores)")->check(numberIn(0, 1024));
    cmd->add_option("--resolution", args->resolution, "Override the camera resolution, WxH");
    cmd->add_option("-o,--output", args->outputs, "Output image (.png, .exr, .pfm); repeatable");
    cmd->add_option("--reference-out", args->referenceOutput, "Also write the reference (every sample shaded)");
    cmd->add_option("--stats", args->stats, "Write counts, timings and the image error as JSON");
    cmd->add_flag("--no-reference", args->noReference, "Skip the reference render (no rel_mse in the stats)");
    cmd->add_option("--lens-cutoff", args->lensCutoff, "AAS: Omega_A^max of the disc aperture (cycles per lens radius)")
        ->check(positiveNumber())
        ->capture_default_str();
    cmd->add_option("--shutter-cutoff", args->shutterCutoff, "AAS: Omega_S^max of the box shutter (cycles per shutter)")
        ->check(positiveNumber())
        ->capture_default_str();
    cmd->add_option("--split-edge", args->splitEdge,
                    "Split blurred triangles longer than this on the canonical image (pixels; 0: never)")
        ->check(nonNegativeNumber())
        ->capture_default_str();
    cmd->add_flag("--no-grid-align", args->noGridAlign,
                  "AAS: keep every lattice anchored at the screen origin instead of at its triangle's corner");
    cmd->add_option("--truth-spp", args->truthSpp,
                    "Also render a converged reference at this many spp and report rel_mse_vs_truth")
        ->check(CLI::Range(0, 65536));
    cmd->add_option("--sweep-cache", args->sweep, "Comma-separated cache sizes: DS and AAS at each (CSV + plot in --out)")
        ->delimiter(',')
        ->check(CLI::Range(size_t(1), size_t(1) << 30));
    cmd->add_option("--out", args->outDir, "Directory for --sweep-cache results");
    cmd->add_flag("-q,--quiet", args->quiet, "No progress bar and no summary");
    cmd->callback([args] { runRaster(*args); });
}

}  // namespace wedge::app
