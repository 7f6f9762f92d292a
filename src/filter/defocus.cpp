#include "filter/defocus.h"

#include <cmath>

#include "core/parallel.h"

namespace wedge::filter {

Image3f defocusFilter(const Image3f& color, const FrameBuffers& fb, const DefocusOptions& o) {
    const int W = color.width(), H = color.height();
    // value(q): the radiance the pass filters at pixel q.
    auto pass = [&](auto&& value, Image3f& dst, bool vertical) {
        parallelRows(H, [&](int y) {
            for (int x = 0; x < W; ++x) {
                const size_t p = size_t(y) * W + x;
                const float b = fb.defocus[p];
                const int radius = std::min(o.maxRadius, int(b / o.lensOmega));
                if (radius < 1) {
                    dst[p] = value(p);
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
                    sum += value(q) * w;
                    wsum += w;
                }
                dst[p] = sum / wsum;  // wsum >= 1: the centre is always accepted
            }
        });
    };
    // Emitted light is left out: the pixels at an emitter's edge are sampled densely already, and
    // next to a bright emitter any spread of it dominates the relative error of its neighbours.
    Image3f rows(W, H), out(W, H);
    pass([&](size_t q) { return color[q] - fb.emission[q]; }, rows, false);
    pass([&](size_t q) { return rows[q]; }, out, true);
    parallelRows(H, [&](int y) {
        for (size_t i = size_t(y) * W; i < size_t(y + 1) * W; ++i) out[i] += fb.emission[i];
    });
    return out;
}

}  // namespace wedge::filter
