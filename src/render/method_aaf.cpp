// --method aaf: axis-aligned filtering with adaptive sampling for soft shadows, indirect light
// and depth of field together (filter/aaf.h has the formulas). Stages: initial sampling (with
// the occluders' distances for the slopes), prefilter (slope fill, bandwidths, rates), adaptive sampling,
// filter (direct and indirect separately, demodulated, then multiplied by albedo; last, the
// defocus filter of the composited radiance, filter/defocus.h).
#include <cmath>

#include "core/parallel.h"
#include "filter/aaf.h"
#include "io/image_io.h"
#include "render/aov.h"
#include "render/methods.h"
#include "render/sampling.h"

namespace wedge::render {

void renderAaf(const MethodContext& ctxIn, RenderResult& result) {
    MethodContext ctx = ctxIn;  // (settleLayers may let the light field go)
    const ViewGeometry& view = ctx.view;
    const int W = view.width, H = view.height;
    const uint32_t n0 = uint32_t(ctx.spp);
    const int cap = std::max(ctx.options.maxExtraSpp, 0);
    FrameBuffers& fb = result.buffers;

    // 1. Initial sampling: the nearest occluders give the shadow slopes (the stage includes first
    // touching the pixel statistics: 0.02-0.33 s at 512x512 on this machine).
    Timer t;
    PixelStatsImage stats(W, H);
    {
        Progress progress("aaf initial", uint64_t(W) * H * n0, !ctx.options.quiet);
        LightFieldStage record(ctx.lightField, [&](size_t) { return n0; });
        result.rays += samplePixels(
            ctx.sampler, stats, view, [&](int, int) { return SampleRange{0, n0}; }, true, true,
            [&](int x, int y, const TracedSample& s, int slot) { record.record(x, y, s, slot); }, &progress);
    }
    storeStats(stats, ctx, fb);
    settleLayers(ctx, stats, result);
    result.seconds.add("sampling_initial", t.seconds());

    // 2. Prefilter: fill slopes from neighbours, bandwidths and sampling rates.
    t.reset();
    filter::AafOptions ao;
    filter::WedgeField wedges = filter::prefilterWedges(fb, filter::aafWedgeOptions());
    filter::AafParams params = filter::aafParams(fb, wedges, view, ao);
    Image<uint32_t> extra(W, H);
    shareEmissions(ctx.lightField, ctx.sampler.distribution());
    const Image<uint32_t> emitterExtra = emitterTopUps(stats, kEmitterEdgeSpp, ctx.lightField);
    const Image<float> pooling = blurPooling(ctx.lightField, view, bentPixels(ctx), ctx.sampler.distribution());
    const Image<uint32_t> mixedExtra = mixedTopUps(stats, pooling, ctx.luminanceUnit);
    const Image<uint32_t> emitterEdges = emitterTopUps(stats, kEmitterEdgeRays, ctx.lightField);  // (denseEmission)
    uint64_t extraTotal = 0;
    for (size_t i = 0; i < extra.size(); ++i) {
        float need = std::max({params.sppDirect[i], params.sppIndirect[i], params.sppLens[i]});
        extra[i] = std::max(uint32_t(std::clamp(int(std::ceil(need)) - int(n0), 0, cap)),
                            std::max(emitterExtra[i], mixedExtra[i]));
        extraTotal += extra[i];
    }
    result.seconds.add("prefilter", t.seconds());

    // 3. Adaptive sampling.
    t.reset();
    {
        Progress progress("aaf adaptive", extraTotal, !ctx.options.quiet && extraTotal > 0);
        LightFieldStage record = adaptiveLightFieldStage(ctx, stats, emitterExtra, extra);
        result.rays += samplePixels(
            ctx.sampler, stats, view, [&](int x, int y) { return SampleRange{n0, extra(x, y)}; }, false, false,
            [&](int x, int y, const TracedSample& s, int slot) { record.record(x, y, s, slot); }, &progress);
    }
    textureSamples(ctx, stats, result);
    storeStats(stats, ctx, fb);
    finishLightField(ctx, stats);
    result.rays += denseEmission(ctx, emitterEdges, fb);
    stats = PixelStatsImage();  // freed before the filter's buffers: a lower peak, fewer fresh pages
    result.seconds.add("sampling_adaptive", t.seconds());
    result.seconds.add("sampling", result.seconds.get("sampling_initial") + result.seconds.get("sampling_adaptive"));

    // 4. Filter direct and indirect separately (demodulated), then remodulate.
    t.reset();
    filter::FilterFrames frames = filter::computeFrames(fb, view);
    // Direct light as in report eq. 3.2: filter the visibility (weighted by the unoccluded light
    // the samples saw), multiply by the closed-form unoccluded irradiance.
    Image3f visibility =
        filter::aafFilter(visibilityImage(fb), params.omegaDirect, fb, frames.direct, ao, &fb.unoccluded);
    Image3f indirect = filter::aafFilter(fb.indirect, params.omegaIndirect, fb, frames.indirect, ao);
    result.color = composeFilteredLight(ctx, visibility, indirect, result);
    result.seconds.add("filter", t.seconds() - result.seconds.get("layers"));  // the layered reconstruction is its own stage

    if (!ctx.options.aovDir.empty()) {
        const std::string& dir = ctx.options.aovDir;
        Image1f beta(W, H), betaInd(W, H);
        for (size_t i = 0; i < beta.size(); ++i) {
            beta[i] = fb.object[i] < 0 ? 0 : filter::aafRadiusPixels(params.omegaDirect[i], frames.direct[i].step[0], ao.maxRadius);
            betaInd[i] = fb.object[i] < 0 ? 0 : filter::aafRadiusPixels(params.omegaIndirect[i], frames.indirect[i].step[0], ao.maxRadius);
        }
        writeAov(dir, "aaf_beta_direct", beta, 0, float(ao.maxRadius));
        writeAov(dir, "aaf_beta_indirect", betaInd, 0, float(ao.maxRadius));
        writeWedgeAovs(dir, "aaf", fb, wedges);
    }
}

}  // namespace wedge::render
