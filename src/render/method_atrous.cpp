// --method atrous: Monte Carlo sampling exactly as `mc` (ctx.spp samples per pixel), then the
// edge-avoiding à-trous wavelet filter (filter/atrous.h, Dammertz et al. 2010) over the
// demodulated direct + indirect light of each pixel's primary surface; colour =
// FrameBuffers::compose(filtered light) = emission + coverage * albedo * filtered + off-surface samples.
#include "filter/atrous.h"
#include "render/methods.h"
#include "render/sampling.h"

namespace wedge::render {

void renderAtrous(const MethodContext& ctx, RenderResult& result) {
    const ViewGeometry& view = ctx.view;
    Image<PixelStats> stats(view.width, view.height);
    {
        Progress progress("atrous sampling", uint64_t(view.width) * view.height * ctx.spp, !ctx.options.quiet);
        Timer t;
        result.rays = samplePixels(
            ctx.sampler, stats, view, [&](int, int) { return SampleRange{0, uint32_t(ctx.spp)}; }, false, true,
            [](int, int, const TracedSample&, int) {}, &progress);
        progress.done();
        storeStats(stats, ctx, result.buffers);
        result.seconds.add("sampling", t.seconds());
    }
    filter::AtrousParams params;
    params.iterations = ctx.options.atrousIterations;
    params.sigmaColor = ctx.options.atrousSigmaColor;
    params.sigmaNormal = ctx.options.atrousSigmaNormal;
    params.sigmaPosition = ctx.options.atrousSigmaPosition;
    params.varianceGuided = ctx.options.atrousVarianceGuided;
    Timer t;
    result.color = filter::atrousFilter(result.buffers, params);
    result.seconds.add("filter", t.seconds());
    result.extra.emplace_back("atrous_iterations", params.iterations);
    result.extra.emplace_back("atrous_variance_guided", params.varianceGuided ? 1 : 0);
}

}  // namespace wedge::render
