#include "filter/atrous.h"

#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"

namespace wedge::filter {

namespace {

constexpr float kB3[5] = {1.f / 16, 4.f / 16, 6.f / 16, 4.f / 16, 1.f / 16};  // B3 spline

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

Image3f atrousFilter(const AtrousInput& in, const AtrousParams& params) {
    checkInput(in, params);
    const int w = in.signal.width(), h = in.signal.height();
    const size_t n = size_t(w) * h;

    // Plain mode: the image's noise level (standard deviation of a pixel mean) over hit pixels.
    double varianceSum = 0;
    size_t hits = 0;
    for (size_t i = 0; i < n; ++i)
        if (in.footprint[i] > 0) {
            varianceSum += in.variance[i];
            ++hits;
        }
    const float noise0 = hits > 0 ? float(std::sqrt(varianceSum / double(hits))) : 0.f;

    // Planes of structures: the loop over pixels reads each guide component contiguously.
    struct Planes {
        std::vector<float> nx, ny, nz, px, py, pz, fp, r, g, b, lum;
    } pl;
    for (auto* v : {&pl.nx, &pl.ny, &pl.nz, &pl.px, &pl.py, &pl.pz, &pl.fp, &pl.r, &pl.g, &pl.b, &pl.lum}) v->resize(n);
    for (size_t i = 0; i < n; ++i) {
        pl.nx[i] = in.normal[i].x, pl.ny[i] = in.normal[i].y, pl.nz[i] = in.normal[i].z;
        pl.px[i] = in.position[i].x, pl.py[i] = in.position[i].y, pl.pz[i] = in.position[i].z;
        pl.fp[i] = in.footprint[i];
        pl.r[i] = in.signal[i].x, pl.g[i] = in.signal[i].y, pl.b[i] = in.signal[i].z;
    }
    std::vector<float> nr(n), ng(n), nb(n), invPlane(n), invLuminance(n), invColor2(n);
    Image1f variance = in.variance, nextVariance(w, h);
    auto guideAt = [&pl](size_t i) {
        EdgeGuide e;
        e.normal = {pl.nx[i], pl.ny[i], pl.nz[i]};
        e.position = {pl.px[i], pl.py[i], pl.pz[i]};
        e.footprint = pl.fp[i];
        e.luminance = pl.lum[i];
        e.color = {pl.r[i], pl.g[i], pl.b[i]};
        return e;
    };

    for (int level = 0; level < params.iterations; ++level) {
        const int step = 1 << level;
        Image1f guideVariance = params.varianceGuided ? blurVariance3x3(variance) : Image1f();
        const float plainScale = params.sigmaColor * noise0 / float(step);
        parallelRows(h, [&](int y) {
            for (size_t i = size_t(y) * w; i < size_t(y + 1) * w; ++i) {
                pl.lum[i] = luminance({pl.r[i], pl.g[i], pl.b[i]});
                EdgeScales s = EdgeScales::at(
                    guideAt(i), params, step,
                    params.varianceGuided ? params.sigmaColor * std::sqrt(guideVariance[i]) : plainScale);
                invPlane[i] = s.invPlane;
                invLuminance[i] = s.invLuminance;
                invColor2[i] = s.invColor2;
            }
        });
        const float invNormal2 = 1.f / (params.sigmaNormal * params.sigmaNormal);
        // Raw pointers, so that the compiler sees that the accumulators alias nothing it reads.
        const float *nx = pl.nx.data(), *ny = pl.ny.data(), *nz = pl.nz.data(), *px = pl.px.data(),
                    *py = pl.py.data(), *pz = pl.pz.data(), *fp = pl.fp.data(), *lum = pl.lum.data(),
                    *r = pl.r.data(), *g = pl.g.data(), *b = pl.b.data(), *var = variance.data(),
                    *ip = invPlane.data(), *il = invLuminance.data(), *ic = invColor2.data();
        auto guide = [=](size_t i) {
            EdgeGuide e;
            e.normal = {nx[i], ny[i], nz[i]};
            e.position = {px[i], py[i], pz[i]};
            e.footprint = fp[i];
            e.luminance = lum[i];
            e.color = {r[i], g[i], b[i]};
            return e;
        };
        parallelRows(h, [&, guide, invNormal2, ip, il, ic, r, g, b, var](int y) {
            // Accumulators of one row: sum of h w c (rgb), sum of h w, sum of (h w)^2 Var.
            std::vector<float> acc(5 * size_t(w), 0.f);
            float* __restrict sr = acc.data();
            float* __restrict sg = sr + w;
            float* __restrict sb = sg + w;
            float* __restrict sw = sb + w;
            float* __restrict sv = sw + w;
            const size_t row = size_t(y) * w;
            for (int j = -2; j <= 2; ++j) {
                const int yy = y + j * step;
                if (yy < 0 || yy >= h) continue;
                for (int i = -2; i <= 2; ++i) {
                    const int dx = i * step;
                    const int x0 = std::max(0, -dx), x1 = std::min(w, w - dx);
                    const float hw = kB3[i + 2] * kB3[j + 2];
                    const size_t tapRow = size_t(yy) * w + dx;  // tap of pixel x: tapRow + x
                    // The accumulators alias none of the planes (the compiler cannot prove it).
                    // GCC's hint only: clang ignores it with a warning, and its own
                    // (vectorize(assume_safety)) warns wherever instrumentation stops it.
#if !defined(__clang__)
#pragma GCC ivdep
#endif
                    for (int x = x0; x < x1; ++x) {
                        const size_t p = row + x, q = tapRow + x;
                        const EdgeScales s{invNormal2, ip[p], il[p], ic[p]};
                        const float wq = hw * edgeStoppingWeight(guide(p), guide(q), s);
                        sr[x] += wq * r[q];
                        sg[x] += wq * g[q];
                        sb[x] += wq * b[q];
                        sw[x] += wq;
                        sv[x] += wq * wq * var[q];
                    }
                }
            }
            // The centre tap has weight h(0) > 0, so sw > 0.
            for (int x = 0; x < w; ++x) {
                const float inv = 1.f / sw[x];
                nr[row + x] = sr[x] * inv;
                ng[row + x] = sg[x] * inv;
                nb[row + x] = sb[x] * inv;
                nextVariance[row + x] = sv[x] * inv * inv;
            }
        });
        std::swap(pl.r, nr);
        std::swap(pl.g, ng);
        std::swap(pl.b, nb);
        std::swap(variance, nextVariance);
    }
    Image3f out(w, h);
    for (size_t i = 0; i < n; ++i) out[i] = {pl.r[i], pl.g[i], pl.b[i]};
    return out;
}

Image3f atrousLight(const FrameBuffers& fb, const AtrousParams& params) {
    Image3f light(fb.width, fb.height);
    for (size_t i = 0; i < light.size(); ++i) light[i] = fb.direct[i] + fb.indirect[i];
    return atrousFilter(AtrousInput{light, fb.normal, fb.position, fb.footprint, fb.variance}, params);
}

Image3f atrousCompose(const FrameBuffers& fb, const Image3f& light) {
    Image3f color(fb.width, fb.height);
    for (size_t i = 0; i < color.size(); ++i) color[i] = fb.compose(i, light[i], Vec3f(0.f));
    return color;
}

Image3f atrousFilter(const FrameBuffers& fb, const AtrousParams& params) { return atrousCompose(fb, atrousLight(fb, params)); }

}  // namespace wedge::filter
