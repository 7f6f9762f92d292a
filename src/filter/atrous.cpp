#include "filter/atrous.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "core/parallel.h"

namespace wedge::filter {

namespace {

constexpr float kB3[5] = {1.f / 16, 4.f / 16, 6.f / 16, 4.f / 16, 1.f / 16};  // B3 spline
constexpr float kVarianceEpsilon = 1e-10f;  // keeps the guided colour weight finite where Var = 0

bool hasHit(const EdgeGuide& g) { return g.footprint > 0; }

/// 3x3 Gaussian (1/16 [1 2 1] x [1 2 1]) of the variance, as SVGF smooths it before use; the
/// window is cut at the border and renormalised.
Image1f blurVariance3x3(const Image1f& v) {
    static const float k[3] = {0.25f, 0.5f, 0.25f};
    const int w = v.width(), h = v.height();
    Image1f out(w, h);
    parallelRows(h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            float s = 0, ws = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    float kk = k[dx + 1] * k[dy + 1];
                    s += kk * v(xx, yy);
                    ws += kk;
                }
            out(x, y) = s / ws;
        }
    });
    return out;
}

void checkInput(const AtrousInput& in, const AtrousParams& params) {
    const int w = in.signal.width(), h = in.signal.height();
    auto check = [&](bool same, const char* name) {
        if (!same) throw Error("atrous", std::string("image size mismatch: '") + name + "' differs from the signal");
    };
    check(in.normal.sameSize(w, h), "normal");
    check(in.position.sameSize(w, h), "position");
    check(in.footprint.sameSize(w, h), "footprint");
    check(in.variance.sameSize(w, h), "variance");
    if (params.iterations < 1 || params.iterations > 12)
        throw Error("atrous: iterations", "expected 1 to 12 levels, got " + std::to_string(params.iterations));
    if (!(params.sigmaColor > 0) || !(params.sigmaNormal > 0) || !(params.sigmaPosition > 0))
        throw Error("atrous: sigmas", "expected positive edge-stopping sigmas");
}

}  // namespace

float edgeStoppingWeight(const EdgeGuide& p, const EdgeGuide& q, const AtrousParams& params, int step, float colorScale) {
    if (hasHit(p) != hasHit(q)) return 0.f;
    float exponent = 0;
    if (hasHit(p)) {
        // w_n: normals.
        exponent += lengthSquared(p.normal - q.normal) / sqr(params.sigmaNormal);
        // w_x: distance of q from p's tangent plane, in footprints per step width.
        float plane = dot(p.normal, q.position - p.position);
        exponent += sqr(plane / (params.sigmaPosition * p.footprint * float(step)));
    }
    // w_rt: colour (plain, squared RGB distance) or luminance (variance-guided, SVGF's L1 form).
    if (params.varianceGuided) exponent += std::abs(p.luminance - q.luminance) / (colorScale + kVarianceEpsilon);
    else exponent += colorScale > 0 ? lengthSquared(p.color - q.color) / sqr(colorScale) : 0.f;
    return std::exp(-exponent);
}

Image3f atrousFilter(const AtrousInput& in, const AtrousParams& params) {
    checkInput(in, params);
    const int w = in.signal.width(), h = in.signal.height();
    Image3f current = in.signal, next(w, h);
    Image1f variance = in.variance, nextVariance(w, h);

    // Plain mode: the image's noise level (standard deviation of a pixel mean) over hit pixels.
    double varianceSum = 0;
    size_t hits = 0;
    for (size_t i = 0; i < in.footprint.size(); ++i)
        if (in.footprint[i] > 0) {
            varianceSum += in.variance[i];
            ++hits;
        }
    const float noise0 = hits > 0 ? float(std::sqrt(varianceSum / double(hits))) : 0.f;

    Image1f lum(w, h);
    auto guideAt = [&](int x, int y) {
        EdgeGuide g;
        g.normal = in.normal(x, y);
        g.position = in.position(x, y);
        g.footprint = in.footprint(x, y);
        g.color = current(x, y);
        g.luminance = lum(x, y);
        return g;
    };

    for (int level = 0; level < params.iterations; ++level) {
        const int step = 1 << level;
        for (size_t i = 0; i < lum.size(); ++i) lum[i] = luminance(current[i]);
        Image1f guideVariance = params.varianceGuided ? blurVariance3x3(variance) : Image1f();
        const float plainScale = params.sigmaColor * noise0 / float(step);
        parallelRows(h, [&](int y) {
            for (int x = 0; x < w; ++x) {
                const EdgeGuide p = guideAt(x, y);
                const float colorScale =
                    params.varianceGuided ? params.sigmaColor * std::sqrt(guideVariance(x, y)) : plainScale;
                Vec3f sum(0.f);
                float weightSum = 0, varianceAcc = 0;
                for (int j = -2; j <= 2; ++j) {
                    const int yy = y + j * step;
                    if (yy < 0 || yy >= h) continue;
                    for (int i = -2; i <= 2; ++i) {
                        const int xx = x + i * step;
                        if (xx < 0 || xx >= w) continue;
                        const float hw = kB3[i + 2] * kB3[j + 2];
                        const float wq = (i == 0 && j == 0) ? hw
                                                            : hw * edgeStoppingWeight(p, guideAt(xx, yy), params, step,
                                                                                      colorScale);
                        sum += current(xx, yy) * wq;
                        weightSum += wq;
                        if (params.varianceGuided) varianceAcc += wq * wq * variance(xx, yy);
                    }
                }
                // The centre tap always counts, so weightSum > 0.
                next(x, y) = sum / weightSum;
                if (params.varianceGuided) nextVariance(x, y) = varianceAcc / (weightSum * weightSum);
            }
        });
        std::swap(current, next);
        if (params.varianceGuided) std::swap(variance, nextVariance);
    }
    return current;
}

Image3f atrousFilter(const FrameBuffers& fb, const AtrousParams& params) {
    Image3f light(fb.width, fb.height);
    for (size_t i = 0; i < light.size(); ++i) light[i] = fb.direct[i] + fb.indirect[i];
    Image3f filtered = atrousFilter(AtrousInput{light, fb.normal, fb.position, fb.footprint, fb.variance}, params);
    for (size_t i = 0; i < filtered.size(); ++i) filtered[i] = fb.emission[i] + fb.albedo[i] * filtered[i];
    return filtered;
}

}  // namespace wedge::filter
