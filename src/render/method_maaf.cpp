// --method maaf: multiple axis-aligned filters (filter/maaf.h) as in Sec. 6.2 of the paper.
// Stages: initial sampling (16 path samples per pixel with the nearest occluders, folded into the
// pixel statistics); prefilter: AAF's slopes (with --maaf-paper-rates MAAF's, over a 5x5
// window), the pixels whose indirect filter has outer components, the components (by default
// only within the filter's window of those pixels) and AAF's rates; adaptive sampling at AAF's
// rates in every pixel (with --maaf-paper-rates only where the wedge degenerates at the focal
// plane, Sec. 6.2), and the emitter and mixed-pixel top-ups; the initial samples of the pixels with outer components
// traced again (their adaptive samples are kept when taken); then the accumulation of eq. 23
// over each pixel's samples (the plain sums of the statistics where the pixel uses the central
// component only); filter: AAF's, then eq. 21 on both image axes where the effect has outer
// components (by default only the indirect light's has them; with --maaf-paper-rates eq. 21
// everywhere, for direct and indirect light), multiplied by albedo; last, the defocus filter of
// the composited radiance (filter/defocus.h).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <unistd.h>

#include "core/error.h"
#include "core/parallel.h"
#include "filter/aaf.h"
#include "filter/maaf.h"
#include "io/image_io.h"
#include "render/aov.h"
#include "render/methods.h"
#include "render/sampling.h"

namespace wedge::render {

namespace {

/// Memory the machine can still give us, from /proc/meminfo (0 if unknown).
size_t availableMemory() {
    std::ifstream in("/proc/meminfo");
    std::string key;
    size_t kb = 0;
    std::string unit;
    while (in >> key >> kb >> unit)
        if (key == "MemAvailable:") return kb * 1024;
    long pages = sysconf(_SC_AVPHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && size > 0 ? size_t(pages) * size_t(size) : 0;
}

}  // namespace

void renderMaaf(const MethodContext& ctxIn, RenderResult& result) {
    MethodContext ctx = ctxIn;  // (settleLayers may let the light field go)
    const ViewGeometry& view = ctx.view;
    const int W = view.width, H = view.height;
    const uint32_t n0 = uint32_t(ctx.spp);
    const int cap = std::max(ctx.options.maxExtraSpp, 0);
    filter::MaafOptions mo;
    mo.pairs = (ctx.options.maafComponents + 1) / 2;
    mo.apertureWindows = ctx.options.maafWindows;
    mo.weights = filter::parseMaafWeights(ctx.options.maafWeights, "--maaf-weights");
    mo.focalFallback = ctx.options.maafFocalFallback;
    mo.maxRadius = ctx.options.maafRadius;
    mo.fitComponents = ctx.options.maafFit;
    // Outer components in the direct light's (shadow) filter: in the paper's pipeline everywhere;
    // in AAF's pipeline (the default) only with --maaf-shadow-components, and then only where
    // the shadow slopes within the filter's reach span at most 1.5x (shadowSpan). Measured at
    // AAF's rates against 1024-spp references (docs/maaf.md, "The direct light's effective
    // centre"): on an isolated 2-3 px plank penumbra they cut relMSE to 0.34-0.64x AAF's (once
    // their light coordinates are measured from where the receiver's light is centred,
    // filter::lightIrradianceCentre; before, 0.95-1.0x); on the six scenes at 256x256 -0.2% to
    // 0%, but at 512x512 grids-shadows +2.6% / +3.1% (seeds 2 / 1: the post's contact shadow),
    // so they are not the default. Without the span rule the six scenes at 256x256 measured
    // -1.5% (cornell-sphere) to +7% (bunny) and +19-23% (grids-shadows).
    mo.shadowComponents = ctx.options.maafPaperRates || ctx.options.maafShadowComponents;
    mo.shadowSpan = ctx.options.maafPaperRates ? 0.f : 1.5f;
    // Indirect outer components only where the nearest bounce hit is at least 5 pixel sizes away
    // (half the clamp). Measured against 1024-spp references (relMSE against AAF's, seeds 1 and 2
    // at 256x256; docs/maaf.md, "Outer components near contacts"), every pixel / half the clamp /
    // the whole clamp: cornell at 512x512 +3.5% / -0.3% / -0.7%, at 256x256 -2.5% / -1.4% /
    // -0.3%; cornell-sphere -2.6% / -1.9% / -0.9% and -4.0% / -0.6% / +0.1%; conference -0.8% /
    // -0.8% / -0.3% and -2.8% / -1.8% / -0.9%. The paper's pipeline keeps every pixel's.
    mo.outerMinBounce = ctx.options.maafPaperRates ? 0.f : 0.5f;
    // A moving surface's pixels use the central component only (in the paper's pipeline too: the
    // paper has no motion); MaafOptions::movingObjects.
    mo.movingObjects = ctx.scene.objectMoves();
    // Without outer components the direct light's filter is AAF's (below): no MAAF widths for it.
    mo.directEffect = mo.shadowComponents;
    if (mo.maxRadius < 1 || mo.maxRadius > filter::kMaafMaxWindowRadius)
        throw Error("--maaf-radius", "expected 1 to " + std::to_string(filter::kMaafMaxWindowRadius) + " pixels, got " +
                                         std::to_string(mo.maxRadius));
    if (mo.pairs < 1 || mo.pairs > filter::kMaafMaxPairs)
        throw Error("--maaf-components", "expected 1, 3, 5 or 7 components");

    // Without indirect light and without shadow components (the default, or several lights or a
    // sphere light, whose direct filter is central), no pixel can have outer
    // components, and MAAF's pipeline below is AAF's pixel for pixel (the same image: checked on
    // grids-shadows and on conference without its bounce), only slower by its components and
    // second frames (grids-shadows at 512x512: 0.88x AAF's efficiency). So it is AAF's render,
    // with MAAF's statistics saying that nothing was outer.
    if (!ctx.options.maafPaperRates && (!mo.shadowComponents || !filter::singlePlanarLight(view)) && !mo.apertureWindows &&
        !ctx.scene.desc().render.indirect) {
        renderAaf(ctx, result);
        for (const char* key : {"maaf_accumulator_bytes_bound", "maaf_initial_record_bytes", "maaf_sample_record_bytes",
                                "maaf_accumulator_bytes", "maaf_outer_component_pixels", "maaf_shadow_outer_pixels"})
            result.extra.emplace_back(key, 0.0);
        result.extra.emplace_back("maaf_components", double(2 * mo.pairs - 1));
        result.extra.emplace_back("maaf_retrace", ctx.options.maafKeepRecords ? 0.0 : 1.0);
        return;
    }

    // Memory: two accumulators (direct, indirect), the pixel statistics, per-pixel central
    // widths, the filter's intermediate bands, and the initial samples' records when they are
    // kept (below). Refuse before allocating more than the machine has.
    const size_t pixels = size_t(W) * H;
    const size_t accBytes = filter::MaafAccumulator::bytes(W, H, mo.pairs, 1) + filter::MaafAccumulator::bytes(W, H, mo.pairs, 3);
    // (The pixel statistics at their most: every pixel seeing a second surface.)
    const size_t otherBytes = pixels * (sizeof(PixelStats) + SlotPool::kBlock * sizeof(SurfaceSlot) +
                                        size_t(2 * mo.pairs) * 6 * sizeof(float) + 256);
    auto checkMemory = [&](size_t need, const char* what) {
        const size_t avail = availableMemory();
        if (avail > 0 && need > avail)
            throw Error("--method maaf", "needs " + std::to_string(need >> 20) + " MiB more for the " + what + " at " +
                                             std::to_string(W) + "x" + std::to_string(H) + " with " +
                                             std::to_string(2 * mo.pairs - 1) + " components and " + std::to_string(n0) +
                                             " initial spp, but only " + std::to_string(avail >> 20) + " MiB are available");
    };
    // The pixels with outer components need their initial samples one by one, and which pixels
    // those are is known only after the prefilter. By default those pixels' initial samples are
    // traced again after the prefilter (the sampler is deterministic per pixel and sample index;
    // bit-identical images); --maaf-keep-records keeps a 36-byte record of every pixel's initial
    // samples instead (151 MB at 512x512, 299 MB at 720x720). Memory first touched is what costs
    // here: in fresh processes started 4 s apart (so that the pages freed before had gone back to
    // the hypervisor), tracing again was faster on five of the six 512x512 scenes (cornell 3.0-3.2 s
    // against 3.5 s, bunny 3.6-3.7 s against 4.0-4.6 s) and level on sponza (8.1 s against
    // 7.4-8.0 s), with 118-137 MB less at the peak (docs/maaf.md, "MAAF's sample records").
    const bool retrace = !ctx.options.maafKeepRecords;
    const size_t initialRecordBytes = pixels * n0 * sizeof(filter::MaafSample);
    checkMemory(accBytes + otherBytes + (retrace ? 0 : initialRecordBytes),
                retrace ? "accumulations and pixel statistics" : "accumulations, pixel statistics and sample records");
    result.extra.emplace_back("maaf_components", double(2 * mo.pairs - 1));
    result.extra.emplace_back("maaf_accumulator_bytes_bound", double(accBytes));
    result.extra.emplace_back("maaf_retrace", retrace ? 1.0 : 0.0);
    result.extra.emplace_back("maaf_initial_record_bytes", retrace ? 0.0 : double(initialRecordBytes));

    // 1. Initial sampling: 16 path samples with the nearest occluders (the stage includes first
    // touching the pixel statistics, as in AAF).
    Timer t;
    PixelStatsImage stats(W, H);
    FrameBuffers& fb = result.buffers;
    LargeVector<filter::MaafSample> initial(retrace ? 0 : pixels * n0);
    {
        Progress progress("maaf initial", uint64_t(pixels) * n0, !ctx.options.quiet);
        std::vector<uint32_t> fill(retrace ? 0 : pixels, 0);
        LightFieldStage record(ctx.lightField, [&](size_t) { return n0; });
        result.rays += samplePixels(
            ctx.sampler, stats, view, [&](int, int) { return SampleRange{0, n0}; }, true, true,
            [&](int x, int y, const TracedSample& s, int slot) {
                record.record(x, y, s, slot);
                if (retrace) return;
                const size_t p = size_t(y) * W + x;
                initial[p * n0 + fill[p]++] = filter::MaafSample::pack(s.record, view, slot);
            },
            &progress);
    }
    storeStats(stats, ctx, fb);
    settleLayers(ctx, stats, result);
    result.seconds.add("sampling_initial", t.seconds());

    // 2a. Prefilter: slopes (AAF's; with --maaf-paper-rates over a 5x5 window, below), frames,
    // components, adaptive counts.
    t.reset();
    filter::WedgeOptions wo;  // the paper pipeline's slopes
    wo.radius = 2;
    wo.fillRadius = mo.maxRadius;  // lit pixels take the wedge of the shadow next to them
    // Max / min over 5x5 (robust where few samples saw an occluder, NOTES), except where at least
    // half the shadow rays did. Measured (512x512, relMSE against 1024-spp references) with the
    // threshold 0.1 / 0.25 / 0.5 / 0.75 / never: conference 0.000886 / 0.000887 / 0.000887 /
    // 0.000890 / 0.000890, sponza 0.001123 / 0.001123 / 0.001104 / 0.001092 / 0.001168, bunny
    // 0.000146 / 0.000135 / 0.000136 / 0.000135 / 0.000139.
    wo.ownShadowOccluded = 0.5f;
    // Bounce distances likewise: a pixel keeps its own where at least 3/4 of the bounce rays hit
    // on average over its window (a well-sampled hemisphere), otherwise the window's min / max.
    // The window's min spreads a few rays' near hits (cornell: the back of the light, 0.01 below
    // the ceiling) to pixels that never see them, with more outer components and more variance
    // there. Measured (512x512, relMSE against 1024-spp references), window min -> the pixel's
    // own hit fraction deciding -> the window's mean deciding (kept; the pixel's own made filter
    // widths alternate from pixel to pixel and left dark dots beside cornell's light): cornell
    // 0.000113 -> 0.0000990 -> 0.0000965, conference 0.000677 -> 0.000637 -> 0.000637, sponza
    // 0.000902 -> 0.000899 -> 0.000899, grids 0.000273 -> 0.000273 -> 0.000273, cornell-sphere
    // 0.000166 -> 0.000145 -> 0.000145, bunny 0.000126 -> 0.000132 -> 0.000128. The pixel's own
    // at thresholds 0.5 / 0.6 / 0.9: cornell 0.0000959 / 0.0000959 / 0.000109, bunny 0.000148 /
    // 0.000140 / 0.000126; 1: cornell 0.000112.
    wo.ownBounceHit = 0.75f;
    // By default AAF's pipeline runs everywhere: its slope prefilter, its sampling rates and
    // (below) its filter, and MAAF's filter replaces AAF's only in the pixels whose fit gives
    // outer components, so that where the central component alone would be used, MAAF costs and
    // samples what AAF does (issue 28). --maaf-paper-rates keeps the paper's pipeline: MAAF's
    // slopes, its central filter everywhere and adaptive samples only at the focal plane (Sec. 6.2).
    const bool paper = ctx.options.maafPaperRates;
    const filter::WedgeField wedges = filter::prefilterWedges(fb, paper ? wo : filter::aafWedgeOptions());
    // Where the direct light's filter may have outer components: where the shadow slopes within
    // its reach agree (MaafOptions::shadowSpan; AAF's pipeline).
    Image<uint8_t> agree;
    if (mo.directEffect && mo.shadowSpan > 0) agree = filter::shadowSlopesAgree(fb, wedges, mo);
    const Image<uint8_t>* agreeMask = agree.empty() ? nullptr : &agree;
    // Sparse (the default in AAF's pipeline): MAAF's filter reads the frames, components and
    // accumulations only within its window (maxRadius) of the pixels with outer components, so
    // those are decided first, per effect (filter::maafIndirectOuter, maafDirectOuter: from the
    // wedge and the pixel's own frame) and the rest is computed only in that region. Without any
    // such pixel the render is AAF's. MAAF's prefilter time over AAF's at 512x512, medians of 12
    // rounds: cornell 0.23 -> 0.07 s, conference 0.14 -> 0.08 s, the same image bytes
    // (docs/maaf.md, "Sparse components"; --maaf-dense: every pixel's).
    const bool sparse = ctx.options.maafSparse && !paper && !mo.apertureWindows && ctx.options.aovDir.empty();
    Image<uint8_t> outerDirect, outerIndirect, outerMask, region;
    size_t outerCount = 0, directCount = 0, indirectCount = 0;
    filter::MaafOptions moParams = mo;
    if (sparse) {
        outerIndirect = filter::maafIndirectOuter(fb, wedges, view, mo);
        outerDirect = mo.directEffect ? filter::maafDirectOuter(fb, wedges, view, mo, agreeMask) : Image<uint8_t>(W, H);
        outerMask = Image<uint8_t>(W, H);
        for (size_t i = 0; i < pixels; ++i) {
            outerMask[i] = outerDirect[i] | outerIndirect[i];
            directCount += outerDirect[i];
            indirectCount += outerIndirect[i];
            outerCount += outerMask[i];
        }
        region = filter::dilateBox(outerMask, mo.maxRadius);
        // No direct outer components anywhere: the direct light is AAF's, with no frames or widths.
        if (directCount == 0) moParams.directEffect = false;
    }
    const Image<uint8_t>* where = sparse ? &region : nullptr;
    filter::FilterFrames frames;
    if (!sparse || outerCount > 0)
        frames = filter::computeFrames(fb, view, moParams.directEffect, where);  // (the direct light's only if MAAF filters it)
    filter::MaafParams params = !sparse || outerCount > 0
                                    ? filter::maafParams(fb, wedges, frames, view, moParams, where, agreeMask)
                                    : filter::MaafParams{filter::MaafEffect(W, H), filter::MaafEffect(W, H), Image1f()};
    const filter::AafOptions ao;
    const filter::AafParams rates = filter::aafParams(fb, wedges, view, ao);
    Image<uint32_t> extra(W, H);
    shareEmissions(ctx.lightField, ctx.sampler.distribution());
    const Image<uint32_t> emitterExtra = emitterTopUps(stats, kEmitterEdgeSpp, ctx.lightField);
    const Image<float> pooling = blurPooling(ctx.lightField, view, bentPixels(ctx), ctx.sampler.distribution());
    const Image<uint32_t> mixedExtra = mixedTopUps(stats, pooling, ctx.luminanceUnit);
    const Image<uint32_t> emitterEdges = emitterTopUps(stats, kEmitterEdgeRays, ctx.lightField);  // (denseEmission)
    uint64_t extraTotal = 0;
    // Whether an effect's filter at pixel p has outer components on either image axis.
    auto outerComponents = [](const filter::MaafEffect& effect, size_t p) { return effect.pairs(p, 0) > 1 || effect.pairs(p, 1) > 1; };
    auto anyOuter = [&](const filter::MaafEffect& effect) {
        for (size_t i = 0; i < pixels; ++i)
            if (outerComponents(effect, i)) return true;
        return false;
    };
    for (size_t i = 0; i < pixels; ++i) {
        // AAF's (MYRD14's) rates in every pixel, as --method aaf takes them. With the paper's
        // rule (Sec. 6.2), only where the wedge degenerates at the focal plane, since there the
        // filter is the central, axis-aligned one.
        const bool rated = !paper || params.fallback[i] > 0;
        const float need = rated ? std::max({rates.sppDirect[i], rates.sppIndirect[i], rates.sppLens[i]}) : 0.f;
        extra[i] = std::max(uint32_t(std::clamp(int(std::ceil(need)) - int(n0), 0, cap)),
                            std::max(emitterExtra[i], mixedExtra[i]));
        extraTotal += extra[i];
    }
    result.seconds.add("prefilter_slopes", t.seconds());

    // Pixels whose accumulation has outer components (or windows) need their samples one by
    // one; the others use the pixel statistics' plain sums (below).
    auto outer = [&](size_t p) -> bool {
        if (sparse) return outerMask[p];
        return mo.apertureWindows || outerComponents(params.direct, p) || outerComponents(params.indirect, p);
    };

    // Records of the pixels with outer components (4-19% of the pixels in the 512x512 scenes):
    // their adaptive samples as they are taken, and their initial samples traced again below
    // when the initial records were not kept (those are read where they are).
    const uint32_t again = retrace ? n0 : 0;  // initial samples per outer pixel in `records`
    std::vector<uint64_t> offset(pixels + 1, 0);
    for (size_t i = 0; i < pixels; ++i) offset[i + 1] = offset[i] + (outer(i) ? again + extra[i] : 0);
    checkMemory(offset[pixels] * sizeof(filter::MaafSample), "sample records of the pixels with outer components");
    LargeVector<filter::MaafSample> records(offset[pixels]);
    result.extra.emplace_back("maaf_sample_record_bytes", double(records.size() * sizeof(filter::MaafSample)));

    // 3. Adaptive sampling at the focal plane, and the top-ups (most adaptive samples go to
    // pixels without outer components: the focal plane's fallback and the top-ups).
    t.reset();
    {
        Progress progress("maaf adaptive", extraTotal, !ctx.options.quiet && extraTotal > 0);
        std::vector<uint32_t> fill(pixels, 0);
        LightFieldStage record = adaptiveLightFieldStage(ctx, stats, emitterExtra, extra);
        result.rays += samplePixels(
            ctx.sampler, stats, view, [&](int x, int y) { return SampleRange{n0, extra(x, y)}; }, false, false,
            [&](int x, int y, const TracedSample& s, int slot) {
                record.record(x, y, s, slot);
                size_t p = size_t(y) * W + x;
                if (outer(p)) records[offset[p] + again + fill[p]++] = filter::MaafSample::pack(s.record, view, slot);
            },
            &progress);
    }
    textureSamples(ctx, stats, result);
    storeStats(stats, ctx, fb);
    finishLightField(ctx, stats);
    result.rays += denseEmission(ctx, emitterEdges, fb);
    result.seconds.add("sampling_adaptive", t.seconds());

    // 3b. Without the initial records, the initial samples of the pixels with outer components
    // traced again (PixelStats::slotOf finds the surface each one went to; tests/render_test.cpp).
    t.reset();
    std::atomic<uint64_t> retracedRays{0};
    if (retrace) parallelRows(H, [&](int y) {
        if (!ctx.sampler.tracesRow(y)) return;  // over several ranks, each its own rows
        uint64_t rays = 0;
        // The row's pixels with outer components, traced together (PathSampler::traceMany).
        std::vector<PathSampler::SampleRun> runs;
        for (int x = 0; x < W; ++x)
            if (outer(size_t(y) * W + x)) runs.push_back({x, y, 0, n0, nullptr});
        std::vector<TracedSample> traced;
        ctx.sampler.traceRuns(runs, traced, false);
        for (const auto& run : runs) {
            const size_t p = size_t(y) * W + run.x;
            for (uint32_t k = 0; k < n0; ++k) {
                rays += run.out[k].rays;
                records[offset[p] + k] = filter::MaafSample::pack(run.out[k].record, view, stats[p].slotOf(run.out[k]));
            }
        }
        retracedRays += rays;
    });
    result.rays += retracedRays;
    // Over several ranks (render/distribution.h), the records of the other ranks' rows.
    if (!retrace) exchangeImageRows(ctx.sampler.distribution(), initial.data(), W, H, n0);
    exchangeRows(ctx.sampler.distribution(), H, [&](int y) {
        return std::pair<char*, size_t>{reinterpret_cast<char*>(records.data() + offset[size_t(y) * W]),
                                        (offset[size_t(y + 1) * W] - offset[size_t(y) * W]) * sizeof(filter::MaafSample)};
    });
    if (retrace) result.seconds.add("sampling_retrace", t.seconds());
    result.seconds.add("sampling", result.seconds.get("sampling_initial") + result.seconds.get("sampling_adaptive") +
                                       result.seconds.get("sampling_retrace"));

    // 2b. Accumulation of eq. 23 over the samples on each pixel's primary surface, as means:
    // the initial samples from their records (or traced again), then the adaptive ones.
    t.reset();
    // An effect without outer components anywhere is AAF's alone (by default; below).
    std::optional<filter::MaafAccumulator> accDirect, accIndirect;
    if (sparse) {
        if (directCount > 0) accDirect.emplace(params.direct, mo.pairs, 1, &region);
        if (indirectCount > 0) accIndirect.emplace(params.indirect, mo.pairs, 3, &region);
    } else {
        if (paper || anyOuter(params.direct)) accDirect.emplace(params.direct, mo.pairs, 1);
        if (paper || anyOuter(params.indirect)) accIndirect.emplace(params.indirect, mo.pairs, 3);
    }
    result.extra.emplace_back("maaf_accumulator_bytes", double((accDirect ? accDirect->allocatedBytes() : 0) +
                                                               (accIndirect ? accIndirect->allocatedBytes() : 0)));
    std::atomic<uint64_t> outerPixels{0};  // pixels whose accumulation has outer components
    std::atomic<uint64_t> shadowOuterPixels{0};  // those whose direct light's filter has them
    if (accDirect || accIndirect) parallelRows(H, [&](int y) {
        uint64_t outerInRow = 0, shadowOuterInRow = 0;
        std::vector<Vec2f> centres;
        for (int x = 0; x < W; ++x) {
            size_t p = size_t(y) * W + x;
            if (sparse && !region[p]) continue;  // no storage: the filter does not read it
            const int primary = stats[p].primary();
            // Central component only on both axes (most pixels: the window fit): eq. 23 is the
            // primary surface's plain sums, which the pixel statistics already hold.
            const render::SurfaceSlot& slot = stats[p].slot(primary);
            if (!outer(p)) {
                if (slot.n > 0) {
                    const float inv = 1.f / float(slot.n), visible = slot.visible * inv;
                    const float indirectMean[3] = {slot.indirect.x * inv, slot.indirect.y * inv, slot.indirect.z * inv};
                    if (accDirect) accDirect->setCentral(p, &visible, slot.unoccluded * inv);
                    if (accIndirect) accIndirect->setCentral(p, indirectMean, 1.f);
                }
                continue;
            }
            ++outerInRow;
            if (accDirect && outerComponents(params.direct, p)) ++shadowOuterInRow;
            const filter::MaafPixel direct = params.direct.pixel(p), indirect = params.indirect.pixel(p);
            // (Without the direct light's frames its coordinates are not used: no accDirect.)
            const filter::AxisFrame &frameIndirect = frames.indirect[p],
                                    &frameDirect = frames.direct.size() > 0 ? frames.direct[p] : frameIndirect;
            uint32_t counted = 0;
            // The direct light's coordinates from where the pixel's unoccluded light is centred
            // on each light (filter::lightIrradianceCentre), computed for the lights its samples
            // chose.
            centres.assign(accDirect ? view.lights.size() : 0, {kInf, kInf});
            auto accumulate = [&](const filter::MaafSample& m) {
                if (m.slot != primary) return;
                float yDirect[2], yIndirect[2], u[2];
                Vec2f centre{0.f, 0.f};
                if (accDirect && ctx.options.maafLightCentre) {
                    Vec2f& c = centres[m.light];
                    if (c.x == kInf) c = filter::lightIrradianceCentre(view.lights[m.light], fb.position[p], fb.normal[p]);
                    centre = c;
                }
                m.coordinates(view, frameDirect, frameIndirect, yDirect, yIndirect, u, centre);
                const float visibility = m.visibility();
                if (accDirect) accDirect->add(p, &visibility, m.unoccluded, yDirect, u, direct);
                if (accIndirect) accIndirect->add(p, m.indirect, 1.f, yIndirect, u, indirect);
                ++counted;
            };
            if (!retrace)
                for (uint32_t i = 0; i < n0; ++i) accumulate(initial[p * n0 + i]);
            for (uint64_t i = offset[p]; i < offset[p + 1]; ++i) accumulate(records[i]);
            if (counted > 0) {
                if (accDirect) accDirect->scale(p, 1.f / float(counted));
                if (accIndirect) accIndirect->scale(p, 1.f / float(counted));
            }
        }
        outerPixels += outerInRow;
        shadowOuterPixels += shadowOuterInRow;
    });
    // Free what the filter no longer needs before it allocates its buffers: a lower peak and
    // fewer freshly touched pages.
    LargeVector<filter::MaafSample>().swap(initial);  // (= {} would keep the capacity)
    LargeVector<filter::MaafSample>().swap(records);
    stats = PixelStatsImage();
    result.extra.emplace_back("maaf_outer_component_pixels", double(outerPixels));
    result.extra.emplace_back("maaf_shadow_outer_pixels", double(shadowOuterPixels));
    result.seconds.add("prefilter_accumulation", t.seconds());
    result.seconds.add("prefilter",
                       result.seconds.get("prefilter_slopes") + result.seconds.get("prefilter_accumulation"));

    // 4. Filter (eq. 21 on both axes), direct and indirect separately, then remodulate.
    t.reset();
    // Direct light as in AAF (report eq. 3.2): filtered visibility x closed-form unoccluded light.
    Timer part;
    Image3f visibility, indirect;
    if (paper) {
        visibility = accDirect->filter(params.direct, fb, frames.direct, visibilityImage(fb), mo);
        result.seconds.add("filter_direct", part.seconds());
        part.reset();
        indirect = accIndirect->filter(params.indirect, fb, frames.indirect, fb.indirect, mo);
        result.seconds.add("filter_indirect", part.seconds());
    } else {
        // AAF's filter everywhere (as --method aaf: its frames from the final buffers, its
        // bandwidths), then MAAF's eq. 21 in the pixels whose effect has outer components.
        const filter::FilterFrames aafFrames = filter::computeFrames(fb, view);
        auto maafWhereOuter = [&](const std::optional<filter::MaafAccumulator>& acc, const filter::MaafEffect& effect,
                                  const Image<filter::AxisFrame>& axes, Image3f aaf, const Image<uint8_t>& outerHere) {
            if (!acc) return aaf;
            if (sparse) return acc->filter(effect, fb, axes, aaf, mo, &outerHere);
            Image<uint8_t> where(W, H);
            for (size_t i = 0; i < pixels; ++i) where[i] = outerComponents(effect, i);
            return acc->filter(effect, fb, axes, aaf, mo, &where);
        };
        visibility = maafWhereOuter(
            accDirect, params.direct, frames.direct,
            filter::aafFilter(visibilityImage(fb), rates.omegaDirect, fb, aafFrames.direct, ao, &fb.unoccluded), outerDirect);
        result.seconds.add("filter_direct", part.seconds());
        part.reset();
        indirect = maafWhereOuter(accIndirect, params.indirect, frames.indirect,
                                  filter::aafFilter(fb.indirect, rates.omegaIndirect, fb, aafFrames.indirect, ao), outerIndirect);
        result.seconds.add("filter_indirect", part.seconds());
    }
    part.reset();
    result.color = composeFilteredLight(ctx, visibility, indirect, result);
    // Remodulation and the defocus filter; the layered reconstruction, if any, is its own stage.
    const double layers = result.seconds.get("layers");
    result.seconds.add("filter_compose", part.seconds() - layers);
    result.seconds.add("filter", t.seconds() - layers);

    if (!ctx.options.aovDir.empty()) {
        const std::string& dir = ctx.options.aovDir;
        // Per effect: the central component's standard deviation in pixels along image x (at
        // most the window), and the number of components on the axis with more (a horizontal
        // shadow edge has its outer components along image y only).
        auto effectAovs = [&](const filter::MaafEffect& effect, const Image<filter::AxisFrame>& axes, const std::string& name) {
            Image1f width(W, H), components(W, H);
            for (size_t i = 0; i < pixels; ++i) {
                if (fb.object[i] < 0) continue;  // 0 in both maps
                width[i] = std::min(float(mo.maxRadius), 1.f / (effect.centralSx(i, 0) * axes[i].step[0]));
                components[i] = float(2 * std::max(effect.pairs(i, 0), effect.pairs(i, 1)) - 1);
            }
            writeAov(dir, "maaf_central_width_" + name, width, 0, float(mo.maxRadius));
            writeAov(dir, "maaf_components_" + name, components, 0, float(2 * mo.pairs - 1));
        };
        if (mo.directEffect) effectAovs(params.direct, frames.direct, "direct");
        effectAovs(params.indirect, frames.indirect, "indirect");
        writeAov(dir, "maaf_fallback", params.fallback, 0, 1);
        writeWedgeAovs(dir, "maaf", fb, wedges);
    }
}

}  // namespace wedge::render
