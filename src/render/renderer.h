// One entry point for every method: render(scene, options) -> RenderResult. Methods share the
// path sampler and the buffers; `mc` is plain Monte Carlo, the ground truth at high spp.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/buffers.h"
#include "core/timer.h"
#include "scene/scene.h"

namespace wedge::render {

class Distribution;

struct RenderOptions {
    std::string method = "mc";
    std::optional<int> spp;          // mc: samples per pixel; aaf/maaf: initial samples per pixel
    std::optional<uint32_t> seed;    // default: the scene's render.seed
    bool quiet = false;
    // aaf/maaf: at most this many adaptive samples per pixel after the initial ones. The papers
    // cap at 100 (AAF 2013, MAAF Sec. 6.2); 16 is the measured optimum of the efficiency
    // 1 / (relMSE x seconds) on cornell, conference, sponza and grids at their own resolutions
    // (docs/measurements.md, "Adaptive sampling cap"): beyond it the samples cost more time than they remove error.
    static constexpr int kDefaultMaxExtraSpp = 16;
    int maxExtraSpp = kDefaultMaxExtraSpp;
    // aaf, maaf, atrous (without the layered reconstruction): primary-only samples (camera rays
    // alone) per pixel where the pixel's path samples saw their surface's albedo vary (a
    // texture), for the albedo the filtered light is multiplied by (render/methods.h,
    // textureSamples); 0: none.
    int textureSpp = 64;
    int maafComponents = 5;          // 2N-1 filters per 2D/3D subspace
    bool maafFocalFallback = true;   // fall back to the central filter where the defocus slope changes sign
    // MAAF's pipeline as the paper has it (--maaf-paper-rates): its slopes, its central filter
    // everywhere, outer components for shadows too and adaptive samples only at the focal plane
    // (Sec. 6.2). By default AAF's slopes, rates and filter run everywhere and MAAF's filter only
    // where the indirect light's has outer components (method_maaf.cpp).
    bool maafPaperRates = false;
    bool maafWindows = false;        // eq. 20's Gaussian windows over light and lens samples
    int maafRadius = 10;             // the spatial filter's window, pixels (NOTES: the reimplementation's 10)
    bool maafFit = true;             // only as many components per axis as that window resolves (filter/maaf.h)
    // Keep a record of every pixel's initial samples instead of tracing again the initial
    // samples of the pixels with outer components (render/method_maaf.cpp: same image, more memory).
    bool maafKeepRecords = false;
    // In AAF's pipeline, the indirect light's frames, components and accumulations only within
    // the filter's window of the pixels with outer components (render/method_maaf.cpp: the same
    // image); false computes them in every pixel (--maaf-dense, for checks).
    bool maafSparse = true;
    // The direct light's coordinates measured from where each receiver's unoccluded light is
    // centred on the light (filter::lightIrradianceCentre), not from the light's centre
    // (--no-maaf-light-centre: before 2026-11-28). Only the direct light's outer components read them.
    bool maafLightCentre = true;
    // Outer components in the direct light's filter in AAF's pipeline, where the shadow slopes
    // within its reach agree (filter::MaafOptions::shadowSpan; --maaf-shadow-components); by
    // default the indirect light's only. The paper's pipeline has them everywhere.
    bool maafShadowComponents = false;
    std::string maafWeights = "sampling";  // mu_p: sampling | eq10 | unit (filter/maaf.h, "Weights")
    // à-trous
    int atrousIterations = 5;
    float atrousSigmaColor = 4.f, atrousSigmaNormal = 0.5f, atrousSigmaPosition = 1.f;
    bool atrousVarianceGuided = true;
    std::string aovDir;              // debug maps (PNG) when non-empty
    // The path samples' numbers: "sobol" (Owen-scrambled Sobol points, stratified per pixel:
    // core/sampler.h) or "independent" (independent uniform numbers, for measuring what the
    // stratification is worth: docs/maaf.md, "Stratified samples").
    std::string sampler = "sobol";
    // The layered reconstruction of defocus and motion blur across pixels (filter/layers.h),
    // where the camera has a lens or the scene moves: "on", "off" (each pixel composes its own
    // samples by surface, and aaf and maaf apply their defocus filter) or "auto", up to
    // kLayersAutoSpp samples per pixel: on for mc and atrous; for aaf and maaf on where the
    // scene moves (their filters have none over the shutter: a motion-blurred silhouette kept
    // its samples' noise, and AAF without layers measured 0.77-0.87x MC's efficiency on
    // docs/bunny-motion.json), and where only the lens blurs, on where at least
    // kLayersMixedShare of the pixels' initial samples saw several surfaces, one of them
    // defocused (layeredIfMixed): the layers gain at defocused silhouettes and, where the image
    // has few, cost more than they gain. docs/layers.md, "`auto` for the filters where the
    // scene moves" and "... and where defocused silhouettes are many".
    std::string layers = "auto";
    /// Several ranks rendering one image together (render/distribution.h; the command line's
    /// MPI ranks): every rank calls render() with the same options and gets the same result
    /// (rank 0's stage times, its own `threads`).
    /// Null: one process.
    const Distribution* distribution = nullptr;
    /// `auto` reconstructs with layers up to this many samples per pixel: where it was measured
    /// (16-64), and where the samples it keeps (24 bytes each) fit: a 4096-spp reference at
    /// 512x512 would keep 26 GB and take the stage minutes for what plain Monte Carlo already has.
    static constexpr int kLayersAutoSpp = 64;
    /// aaf and maaf under `auto` where only the lens blurs reconstruct with layers where at
    /// least this share of the pixels saw several surfaces in their initial samples, one of
    /// them defocused by a circle of at least 1.5 px (kLayerBlurFrom): 0-6% on cornell, bunny,
    /// cornell-sphere, docs/textured.json and conference at 256x256 with a smaller lens (its
    /// mixed pixels there in-focus edges), 20-43% on conference and sponza at 512x512,
    /// docs/conference-wide.json and docs/bunny-near.json. docs/layers.md, "`auto` for the
    /// filters where defocused silhouettes are many".
    static constexpr float kLayersMixedShare = 0.15f;
    /// Whether a method at `spp` samples per pixel may reconstruct with layers under this
    /// setting: whether it keeps the light field, at least through its initial samples
    /// (layeredIfMixed).
    bool layered(int spp) const { return layers == "on" || (layers == "auto" && spp <= kLayersAutoSpp); }
    /// Whether that waits for the initial samples: aaf and maaf under `auto` where nothing moves
    /// reconstruct with layers only where at least kLayersMixedShare of the pixels saw several
    /// surfaces, one of them defocused (render/methods.h, settleLayers).
    bool layeredIfMixed(int spp, bool sceneMoves) const {
        return layers == "auto" && layered(spp) && (method == "aaf" || method == "maaf") && !sceneMoves;
    }
};

struct RenderResult {
    std::string method;
    Image3f color;
    FrameBuffers buffers;
    StageTimes seconds;  // per stage, "total" added at the end
    double sppAverage = 0;
    uint64_t rays = 0;  // over every rank
    std::vector<uint64_t> raysPerRank;  // the rays each rank traced ({rays} in one process)
    int threads = 0;
    std::vector<std::pair<std::string, double>> extra;  // method-specific figures for --stats
    Image<uint8_t> texturePixels;  // with a light field: where a pixel took texture samples (filter::kTextureSurface, kSharpTextured); empty where none did
    Image<uint8_t> methodPixels;   // with a light field, for aaf and maaf: the pixels left to their own composition (filter::pixelsAwayFromSilhouettes); empty otherwise
    /// The method-specific figure `key`, if the method gave it.
    std::optional<double> figure(const std::string& key) const {
        for (const auto& [k, v] : extra)
            if (k == key) return v;
        return std::nullopt;
    }
};

/// The methods `render` knows, in the order `wedge render --help` lists them.
std::vector<std::string> methods();

/// The samples per pixel `render` uses for these options: --spp, else the scene's for mc and 16
/// for the filtering methods.
int renderSpp(const scene::SceneDesc& desc, const RenderOptions& options);
/// Whether `render` keeps the light field (every sample, for the layered reconstruction): where
/// the options reconstruct with layers at `spp` and there is something to reconstruct across
/// pixels, a lens or motion (without either every layer is sharp: each pixel's own samples).
bool keepsLightField(const scene::SceneDesc& desc, const RenderOptions& options, int spp);
/// Whether a kept light field keeps its samples' sagittas too (LightFieldSag, 4 bytes a sample):
/// where an object of the scene turns (TracedSample::sag).
bool keepsSags(const scene::SceneDesc& desc);
/// The largest radiance component of the scene's lights and emissive materials (the light
/// field's radianceScale).
float brightestEmitter(const scene::SceneDesc& desc);

RenderResult render(const scene::Scene& scene, const RenderOptions& options);

}  // namespace wedge::render
