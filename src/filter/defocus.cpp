#include "filter/defocus.h"

#include <cmath>

#include "core/parallel.h"

namespace wedge::filter {

Image3f defocusFilter(const Image3f& color, const FrameBuffers& fb, const DefocusOptions& o) {
    const int W = color.width(), H = color.height();
    auto pass = [&](const Image3f& src, Image3f& dst, bool vertical) {
        parallelRows(H, [&](int y) {
            for (int x = 0; x < W; ++x) {
                const size_t p = size_t(y) * W + x;
                const float b = fb.defocus[p];
                const int radius = std::min(o.maxRadius, int(b / o.lensOmega));
                if (radius < 1) {
                    dst[p] = src[p];
                    continue;
                }
                const float omega = o.lensOmega / b;  // per pixel
                Vec3f sum(0.f);
                float wsum = 0;
                for (int k = -radius; k <= radius; ++k) {
                    int xx = vertical ? x : x + k, yy = vertical ? y + k : y;
                    if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
                    const size_t q = size_t(yy) * W + xx;
                    if (fb.defocus[q] * o.sharperRatio < b) continue;
                    float rw = float(k) * omega;
                    if (rw * rw > 1.f) continue;
                    float w = std::exp(-3.f * rw * rw);
                    sum += src[q] * w;
                    wsum += w;
                }
                dst[p] = sum / wsum;  // wsum >= 1: the centre is always accepted
            }
        });
    };
    // Emitted light is left out: the pixels at an emitter's edge are sampled densely already, and
    // next to a bright emitter any spread of it dominates the relative error of its neighbours.
    Image3f reflected(W, H), tmp(W, H), out(W, H);
    for (size_t i = 0; i < reflected.size(); ++i) reflected[i] = color[i] - fb.emission[i];
    pass(reflected, tmp, false);
    pass(tmp, out, true);
    for (size_t i = 0; i < out.size(); ++i) out[i] += fb.emission[i];
    return out;
}

}  // namespace wedge::filter
