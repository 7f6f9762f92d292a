// The render flags of render_flags.h: their checks and help texts, and the RenderOptions they set.
#include "apps/wedge/render_flags.h"

#include <filesystem>

#include "apps/wedge/common.h"
#include "core/error.h"
#include "filter/maaf.h"

namespace wedge::app {

render::RenderOptions RenderFlags::renderOptions() const {
    render::RenderOptions opt = options;
    if (spp != 0) opt.spp = spp;
    if (seed >= 0) opt.seed = uint32_t(seed);
    if (!opt.aovDir.empty() && !std::filesystem::is_directory(opt.aovDir))
        throw Error("--aov " + opt.aovDir, "not a directory");
    return opt;
}

void RenderFlags::applyTo(scene::SceneDesc& desc) const { applyResolution(desc, resolution); }

void addRenderFlags(CLI::App& cmd, RenderFlags& flags) {
    std::string methodList;
    for (auto& m : render::methods()) methodList += (methodList.empty() ? "" : "|") + m;
    cmd.add_option("--method", flags.options.method, "Reconstruction method: " + methodList)
        ->check(CLI::IsMember(render::methods()));
    cmd.add_option("--spp", flags.spp, "Samples per pixel (mc: default the scene's render.spp; atrous: 16) or initial samples per pixel (aaf, maaf: 16)")
        ->check(numberIn(1, 1 << 20));
    cmd.add_option("--seed", flags.seed, "Random seed (default: the scene's render.seed)")->check(numberIn(0, 4294967295.0));
    cmd.add_option("--threads", flags.threads, "Worker threads (0: all cores)")->check(numberIn(0, 1024));
    cmd.add_option("--resolution", flags.resolution, "Override the camera resolution, WxH");
    cmd.add_option("--aov", flags.options.aovDir, "Write PNG debug maps (filter widths, spp, slopes) into this directory");
    addMethodFlags(cmd, flags.options);
    cmd.add_flag("-q,--quiet", flags.options.quiet, "No progress bar and no summary");
}

void addMethodFlags(CLI::App& cmd, render::RenderOptions& r) {
    cmd.add_option("--max-extra-spp", r.maxExtraSpp, "aaf/maaf: cap on the adaptive samples per pixel their rates ask for (default 16; the papers use 100; the top-ups of mixed pixels to 64 and of emitter edges are not capped)")
        ->check(numberIn(0, 1 << 16));
    cmd.add_option("--texture-spp", r.textureSpp,
                   "aaf/maaf/atrous: camera rays alone per pixel for the albedo where a pixel's samples saw a texture "
                   "(default 64; 0: none; with --layers only where the pixel's samples are sharp and still, or aaf's and maaf's image is their own)")
        ->check(numberIn(0, 1 << 16));
    cmd.add_option("--maaf-components", r.maafComponents, "maaf: filters per 2D/3D subspace (3, 5 or 7; 1: the central, axis-aligned filter alone)")
        ->check(CLI::IsMember({1, 3, 5, 7}));
    cmd.add_flag("--maaf-paper-rates", r.maafPaperRates,
                 "maaf: the paper's pipeline: adaptive samples only at the focal plane (Sec. 6.2), MAAF's central filter "
                 "where there are no outer components and outer components for shadows too, not AAF's rates and filter");
    cmd.add_flag("!--no-focal-fallback", r.maafFocalFallback,
                 "maaf: keep all components where the defocus slope changes sign (shows the ringing)");
    cmd.add_flag("--maaf-windows", r.maafWindows,
                 "maaf: weigh light and lens samples by eq. 20's Gaussian windows (biased for uniform lights)");
    cmd.add_option("--maaf-radius", r.maafRadius, "maaf: spatial filter window in pixels (default 10)")
        ->check(CLI::Range(1, filter::kMaafMaxWindowRadius));
    cmd.add_flag("!--no-maaf-fit", r.maafFit,
                 "maaf: all components everywhere, also where the window cannot hold them (the paper's configuration)");
    cmd.add_flag("--maaf-keep-records", r.maafKeepRecords,
                 "maaf: keep every pixel's initial samples instead of tracing the outer-component pixels' again "
                 "(the same image; more memory, faster only where the memory was touched before)");
    cmd.add_flag("!--maaf-dense", r.maafSparse,
                 "maaf: compute the indirect light's frames, components and accumulations in every pixel, not only "
                 "within the filter's window of the pixels with outer components (the same image; for checks)");
    cmd.add_flag("--maaf-shadow-components", r.maafShadowComponents,
                 "maaf: outer components in the direct light's (shadow) filter too, where the shadow slopes within "
                 "the filter's reach span at most 1.5x (ahead of AAF on isolated penumbrae of 2-3 px; not the default: "
                 "docs/maaf.md)");
    cmd.add_flag("!--no-maaf-light-centre", r.maafLightCentre,
                 "maaf: measure the direct light's sample coordinates from the light's centre, not from where each "
                 "receiver's unoccluded light is centred on it (before 2026-11-28; only shadow components read them)");
    cmd.add_option("--maaf-weights", r.maafWeights,
                   "maaf: component weights mu_p: the sampling densities' spectra (default), eq. 10's Gaussian, or 1")
        ->check(CLI::IsMember({"sampling", "eq10", "unit"}));
    cmd.add_option("--atrous-iterations", r.atrousIterations, "atrous: wavelet levels")->check(CLI::Range(1, 10));
    cmd.add_option("--sigma-color", r.atrousSigmaColor, "atrous: colour edge-stopping sigma")->check(numberIn(1e-6, 1e6));
    cmd.add_option("--sigma-normal", r.atrousSigmaNormal, "atrous: normal edge-stopping sigma")->check(numberIn(1e-6, 1e6));
    cmd.add_option("--sigma-position", r.atrousSigmaPosition, "atrous: position edge-stopping sigma (in pixel footprints)")
        ->check(numberIn(1e-6, 1e6));
    cmd.add_flag("!--no-variance", r.atrousVarianceGuided,
                 "atrous: plain colour edge-stopping instead of variance-guided (SVGF-style)");
    cmd.add_option("--sampler", r.sampler,
                   "The path samples' numbers: sobol (default: Owen-scrambled Sobol points, stratified per pixel) or "
                   "independent (independent uniform numbers, to measure what the stratification is worth)")
        ->check(CLI::IsMember({"sobol", "independent"}));
    cmd.add_option("--layers", r.layers,
                   "auto (default: up to 64 spp on for mc and atrous, and for aaf and maaf where the scene moves or at least 15% of the "
                   "pixels' initial samples saw several surfaces, one defocused), on: the layered reconstruction of "
                   "defocus and motion blur across pixels, off: each pixel's own samples (and aaf's and maaf's defocus filter)")
        ->check(CLI::IsMember({"auto", "on", "off"}));
}

}  // namespace wedge::app
