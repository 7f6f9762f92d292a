// --method atrous: Monte Carlo sampling exactly as `mc` (ctx.spp samples per pixel), then the
// edge-avoiding à-trous wavelet filter (filter/atrous.h, Dammertz et al. 2010) over the
// demodulated direct + indirect light of each pixel's primary surface; colour =
// FrameBuffers::compose(filtered light) = emission + coverage * albedo * filtered + off-surface samples.
#include "filter/atrous.h"
#include "render/methods.h"

namespace wedge::render {

void renderAtrous(const MethodContext& ctx, RenderResult& result) {
    sampleUniform(ctx, "atrous sampling", result, true);
    filter::AtrousParams params;
    params.iterations = ctx.options.atrousIterations;
    params.sigmaColor = ctx.options.atrousSigmaColor;
    params.sigmaNormal = ctx.options.atrousSigmaNormal;
    params.sigmaPosition = ctx.options.atrousSigmaPosition;
    params.varianceGuided = ctx.options.atrousVarianceGuided;
    Timer t;
    if (ctx.lightField) {
        // The samples on a pixel's primary surface carry its filtered light, the others their own.
        const FrameBuffers& fb = result.buffers;
        const Image3f light = filter::atrousLight(fb, params);
        result.seconds.add("filter", t.seconds());
        const Image3f perPixel = filter::atrousCompose(fb, light);
        result.color = reconstructFromLayers(ctx, {&light, nullptr, nullptr}, result, &perPixel);
    } else {
        result.color = filter::atrousFilter(result.buffers, params);
        result.seconds.add("filter", t.seconds());
    }
    result.extra.emplace_back("atrous_iterations", params.iterations);
    result.extra.emplace_back("atrous_variance_guided", params.varianceGuided ? 1 : 0);
}

}  // namespace wedge::render
