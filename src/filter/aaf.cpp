#include "filter/aaf.h"

#include "core/parallel.h"

namespace wedge::filter {

AafParams aafParams(const FrameBuffers& fb, const WedgeField& wf, const ViewGeometry& view, const AafOptions& o) {
    const int W = fb.width, H = fb.height;
    AafParams ap{Image1f(W, H), Image1f(W, H), Image1f(W, H), Image1f(W, H), Image1f(W, H)};
    const bool lens = view.apertureRadius > 0;
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            size_t p = size_t(y) * W + x;
            if (fb.object[p] < 0) continue;
            float d = std::max(fb.footprint[p], 1e-12f);
            float omegaPix = 1.f / d;
            // Defocus: the smallest |s_u| over the pixel's lens samples (0 where they straddle focus).
            float suLo = wf.suMin[p], suHi = wf.suMax[p];
            float suAbsMin = (suLo < 0 && suHi > 0) ? 0.f : std::min(std::abs(suLo), std::abs(suHi));
            float suAbsMax = std::max(std::abs(suLo), std::abs(suHi));
            float omegaLens = lens && suAbsMin > 0 ? o.lensOmega / (suAbsMin * d) : kInf;

            // Soft shadows (NOTES: Omega = min(mu / (sigma s2), 1 / (d (1 + s2)))).
            float s1 = wf.s1[p], s2 = wf.s2[p];
            bool shadow = s2 < kInf;
            // The light whose shadow this is (wedge_field.h: the smallest of several; finite
            // wherever s2 is).
            const float sigma = wf.lightSigma[p];
            float omegaShadow = shadow ? std::min(o.mu / (sigma * std::max(s2, 1e-6f)), 1.f / (d * (1.f + s2))) : 0.f;
            float omegaD = std::min({omegaPix, omegaShadow, omegaLens});
            ap.omegaDirect[p] = omegaD;
            ap.sppDirect[p] = shadow ? 4.f * sqr(1.f / (1.f + s2) + d * omegaD) *
                                           sqr(1.f + sigma * std::min(s1 * omegaD, s1 / (d * (1.f + s1))))
                                     : 0.f;

            // Indirect (report eq. 4.4 with z_min clamped to a few pixel sizes; eq. 4.6 rate).
            float zMin = std::max(wf.zMin[p], o.zMinPixels * d), zMax = std::max(wf.zMax[p], zMin);
            bool bounce = wf.zMin[p] < kInf;
            float omegaInd = bounce ? o.indirectOmega / zMin : 0.f;
            float omegaI = std::min({omegaPix, omegaInd, omegaLens});
            ap.omegaIndirect[p] = omegaI;
            ap.sppIndirect[p] = bounce ? 0.4f * sqr(0.9f * d * omegaI + 0.3f) * sqr(o.indirectOmega) *
                                             sqr(1.f + 0.9f * std::min(zMax / zMin, 1e4f))
                                       : 0.f;

            // Lens: the shadow rate's form with (sigma, s) -> (1/3 lens radius, s_u d).
            float omegaL = std::max(omegaD, omegaI);
            ap.sppLens[p] = lens ? 4.f * sqr(1.f / (1.f + suAbsMin) + d * omegaL) *
                                       sqr(1.f + (1.f / 3.f) * suAbsMax * d * omegaL)
                                 : 0.f;
        }
    });
    return ap;
}

float aafRadiusPixels(float omega, float step, int maxRadius) {
    if (omega <= 0) return float(maxRadius);
    return std::min(float(maxRadius), 1.f / (omega * step));
}

namespace {

constexpr int kMaxRadius = 64;  // the window buffers' half-size (AafOptions::maxRadius is 10)

/// One separable pass along `axis` (0: image x, 1: image y) with the centre pixel's bandwidth.
void pass(const Image3f& src, const Image1f& srcWeight, Image3f& dst, Image1f& dstWeight, int axis, const Image1f& omega,
          const FrameBuffers& fb, const Image<AxisFrame>& frames, const AafOptions& o) {
    const int W = fb.width, H = fb.height;
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            size_t p = size_t(y) * W + x;
            if (fb.object[p] < 0) {
                dst[p] = src[p];
                dstWeight[p] = srcWeight[p];
                continue;
            }
            const AxisFrame& f = frames[p];
            float om = omega[p];
            // Unbounded bandwidth (no wedge): the widest filter the window allows.
            float omFloor = 1.f / (o.maxRadius * f.step[axis]);
            float omEff = std::max(om, omFloor);
            int radius = int(std::min(float(std::min(o.maxRadius, kMaxRadius)), 1.f / (omEff * f.step[axis])));
            // The window's weights (0: not used) and which neighbours another surface cut off.
            float w[2 * kMaxRadius + 1];
            bool cut[2 * kMaxRadius + 1];
            const Vec3f P = fb.position[p];
            for (int k = -radius; k <= radius; ++k) {
                w[k + radius] = 0;
                cut[k + radius] = false;
                int xx = axis == 0 ? x + k : x, yy = axis == 0 ? y : y + k;
                if (xx < 0 || xx >= W || yy < 0 || yy >= H) continue;
                size_t q = size_t(yy) * W + xx;
                if (q == p) {
                    w[k + radius] = srcWeight[q];
                    continue;
                }
                const Vec3f dP = fb.position[q] - P;
                if (!sameSurface(fb, p, q, o.normalCos) || !onTangentPlane(fb, p, dP, o.planeDistance)) {
                    cut[k + radius] = true;
                    continue;
                }
                float oq = std::max(omega[q], 1.f / (o.maxRadius * frames[q].step[axis]));
                if (oq > o.bandwidthRatio * omEff || omEff > o.bandwidthRatio * oq) continue;
                float a0 = dot(dP, f.axis[0]), a1 = dot(dP, f.axis[1]);
                float r2o2 = (a0 * a0 + a1 * a1) * omEff * omEff;
                if (r2o2 > 1.f) continue;  // cut at r Omega > 1 (NOTES)
                w[k + radius] = std::exp(-3.f * r2o2) * srcWeight[q];
            }
            const bool mirror = o.mirrorSurfaceCuts && fb.coverage[p] >= kFullCoverage;
            Vec3f sum(0.f);
            float wsum = 0;
            for (int k = -radius; k <= radius; ++k) {
                if (w[k + radius] <= 0 || (mirror && cut[radius - k])) continue;
                size_t q = axis == 0 ? p + k : size_t(y + k) * W + x;
                sum += src[q] * w[k + radius];
                wsum += w[k + radius];
            }
            // Carry the weight so that the second pass weighs the first pass's sums correctly.
            dst[p] = wsum > 0 ? sum / wsum : Vec3f(0.f);
            dstWeight[p] = wsum;
        }
    });
}

}  // namespace

Image3f aafFilter(const Image3f& signal, const Image1f& omega, const FrameBuffers& fb, const Image<AxisFrame>& frames,
                  const AafOptions& o, const Image1f* weight) {
    Image3f tmp(fb.width, fb.height), out(fb.width, fb.height);
    Image1f ones(fb.width, fb.height, 1.f), tmpWeight(fb.width, fb.height), outWeight(fb.width, fb.height);
    pass(signal, weight ? *weight : ones, tmp, tmpWeight, 0, omega, fb, frames, o);
    // The second pass weighs each intermediate pixel by its first-pass weight sum only when the
    // input was weighted; unweighted, it is the plain separable Gaussian of report eq. 3.7.
    pass(tmp, weight ? tmpWeight : ones, out, outWeight, 1, omega, fb, frames, o);
    return out;
}

}  // namespace wedge::filter
