#include "filter/wedge_field.h"

#include "core/parallel.h"

namespace wedge::filter {

WedgeField prefilterWedges(const FrameBuffers& fb, const WedgeOptions& o) {
    const int W = fb.width, H = fb.height;
    WedgeField wf{Image1f(W, H), Image1f(W, H), Image1f(W, H), Image1f(W, H),
                  Image1f(W, H), Image1f(W, H), Image1f(W, H), Image1f(W, H)};
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            size_t p = size_t(y) * W + x;
            float s1 = 0, s2 = kInf, sigma = kInf, zMin = kInf, zMax = 0, suMin = kInf, suMax = -kInf;
            bool ownShadow = fb.sMin[p] < kInf, ownBounce = fb.zMin[p] < kInf;
            const bool keepShadow = ownShadow && (o.fillOnly || fb.occluded[p] >= o.ownShadowOccluded);
            float hitSum = 0;  // fractions of bounce rays that hit, summed over the window's surface
            int hitCount = 0;
            for (int dy = -o.radius; dy <= o.radius; ++dy) {
                int yy = y + dy;
                if (yy < 0 || yy >= H) continue;
                for (int dx = -o.radius; dx <= o.radius; ++dx) {
                    int xx = x + dx;
                    if (xx < 0 || xx >= W) continue;
                    size_t q = size_t(yy) * W + xx;
                    if (q != p && !sameSurface(fb, p, q, o.normalCos)) continue;
                    if (fb.object[q] < 0) continue;
                    if (!keepShadow && fb.sMin[q] < kInf) {
                        s1 = std::max(s1, fb.sMax[q]);
                        s2 = std::min(s2, fb.sMin[q]);
                        sigma = std::min(sigma, fb.lightSigma[q]);
                    }
                    if (fb.zMin[q] < kInf) {
                        zMin = std::min(zMin, fb.zMin[q]);
                        zMax = std::max(zMax, fb.zMax[q]);
                    }
                    hitSum += fb.bounced[q];
                    ++hitCount;
                    suMin = std::min(suMin, fb.suMin[q]);
                    suMax = std::max(suMax, fb.suMax[q]);
                }
            }
            if (keepShadow) { s1 = fb.sMax[p]; s2 = fb.sMin[p]; sigma = fb.lightSigma[p]; }
            // The neighbourhood's hit fraction, not the pixel's own, decides: neighbouring pixels
            // then decide alike, and filter widths do not alternate from pixel to pixel.
            const bool keepBounce = ownBounce && (o.fillOnly || hitSum >= o.ownBounceHit * float(hitCount));
            if (keepBounce) { zMin = fb.zMin[p]; zMax = fb.zMax[p]; }
            wf.s1[p] = s1;
            wf.s2[p] = s2;
            wf.lightSigma[p] = sigma;
            wf.zMin[p] = zMin;
            wf.zMax[p] = zMax;
            wf.suMin[p] = suMin <= suMax ? suMin : 0.f;
            wf.suMax[p] = suMin <= suMax ? suMax : 0.f;
        }
    });
    // Pixels still without a shadow or bounce wedge (lit, or no bounce hit) take the wedge of the
    // surface around them, so that every pixel inside a filter's window accumulates with the
    // same components as the pixel the filter is centred on (MAAF assumes they vary smoothly).
    if (o.fillRadius > o.radius) {
        // Separable: along rows, then along columns of the row results. Each pass compares a
        // neighbour's surface with the pixel the pass is centred on.
        struct Fill {
            float s1, s2, sigma, z1, z2;
        };
        Image<Fill> row(W, H), col(W, H);
        auto pass = [&](const Image<Fill>& src, Image<Fill>& dst, bool vertical) {
            parallelRows(H, [&](int y) {
                for (int x = 0; x < W; ++x) {
                    size_t p = size_t(y) * W + x;
                    Fill f{0, kInf, kInf, kInf, 0};
                    if (fb.object[p] >= 0)
                        for (int k = -o.fillRadius; k <= o.fillRadius; ++k) {
                            int xx = vertical ? x : x + k, yy = vertical ? y + k : y;
                            if (xx < 0 || xx >= W || yy < 0 || yy >= H) continue;
                            size_t q = size_t(yy) * W + xx;
                            if (!sameSurface(fb, p, q, o.normalCos)) continue;
                            const Fill& g = src[q];
                            if (g.s2 < kInf) {
                                f.s1 = std::max(f.s1, g.s1);
                                f.s2 = std::min(f.s2, g.s2);
                                f.sigma = std::min(f.sigma, g.sigma);
                            }
                            if (g.z1 < kInf) { f.z1 = std::min(f.z1, g.z1); f.z2 = std::max(f.z2, g.z2); }
                        }
                    dst[p] = f;
                }
            });
        };
        Image<Fill> own(W, H);
        for (size_t p = 0; p < own.size(); ++p) own[p] = {wf.s1[p], wf.s2[p], wf.lightSigma[p], wf.zMin[p], wf.zMax[p]};
        pass(own, row, false);
        pass(row, col, true);
        parallelRows(H, [&](int y) {
            for (int x = 0; x < W; ++x) {
                size_t p = size_t(y) * W + x;
                if (fb.object[p] < 0) continue;
                if (wf.s2[p] >= kInf) { wf.s1[p] = col[p].s1; wf.s2[p] = col[p].s2; wf.lightSigma[p] = col[p].sigma; }
                if (wf.zMin[p] >= kInf) { wf.zMin[p] = col[p].z1; wf.zMax[p] = col[p].z1 < kInf ? col[p].z2 : 0.f; }
            }
        });
    }

    // Focal plane: the defocus slope takes both signs within focalRadius (separable min/max).
    Image1f lo(W, H), hi(W, H);
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            float a = kInf, b = -kInf;
            for (int xx = std::max(0, x - o.focalRadius); xx <= std::min(W - 1, x + o.focalRadius); ++xx) {
                size_t q = size_t(y) * W + xx;
                if (fb.object[q] < 0) continue;
                a = std::min(a, fb.suMin[q]);
                b = std::max(b, fb.suMax[q]);
            }
            lo(x, y) = a;
            hi(x, y) = b;
        }
    });
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            float a = kInf, b = -kInf;
            for (int yy = std::max(0, y - o.focalRadius); yy <= std::min(H - 1, y + o.focalRadius); ++yy) {
                a = std::min(a, lo(x, yy));
                b = std::max(b, hi(x, yy));
            }
            wf.focalStraddle(x, y) = (a < 0 && b > 0) ? 1.f : 0.f;
        }
    });
    return wf;
}

}  // namespace wedge::filter
