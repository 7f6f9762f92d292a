#include "render/pixel_stats.h"

namespace wedge::render {

void PixelStats::add(const TracedSample& s, const ViewGeometry& view, bool slopes) {
    ++n;
    const SampleRecord& r = s.record;
    Vec3f light = r.direct + r.indirect;
    color += s.emission + s.albedo * light;
    float l = luminance(light);
    lumSum += l;
    lumSq += l * l;
    if (!s.hit) return;
    if (nHit == 0) object = s.object;
    ++nHit;
    emission += s.emission;
    albedo += s.albedo;
    rhoDirect += s.albedo * r.direct;
    rhoIndirect += s.albedo * r.indirect;
    direct += r.direct;
    indirect += r.indirect;
    normal += s.normal;
    position += s.position;
    depth += s.depth;
    if (!slopes) return;
    float su = view.defocusSlope(s.depth);
    suMin = std::min(suMin, su);
    suMax = std::max(suMax, su);
    if (s.shadowTested) {
        ++nShadow;
        if (s.occluded) {
            // NOTES (AAF 2012 code): d2min = d1 - t_far, d2max = d1 - t_near, s = d1/d2 - 1.
            ++nOccluded;
            d1Sum += s.d1;
            float d2min = std::max(s.d1 - s.tFar, 1e-3f * s.d1);
            float d2max = std::max(s.d1 - s.tNear, 1e-3f * s.d1);
            s1 = std::max(s1, s.d1 / d2min - 1.f);
            s2 = std::min(s2, s.d1 / d2max - 1.f);
        }
    }
    if (s.bounceHit) {
        ++nBounce;
        zMin = std::min(zMin, s.bounceDistance);
        zMax = std::max(zMax, s.bounceDistance);
    }
}

void PixelStats::store(FrameBuffers& fb, int x, int y, const ViewGeometry& view) const {
    float invN = n > 0 ? 1.f / float(n) : 0.f;
    fb.color(x, y) = color * invN;
    fb.emission(x, y) = emission * invN;
    fb.albedo(x, y) = albedo * invN;
    // Demodulate so that albedo * direct reproduces the estimate of sum(albedo_s * direct_s) / n.
    auto demodulate = [&](const Vec3f& rho, const Vec3f& plain) {
        Vec3f out;
        for (int c = 0; c < 3; ++c) out[c] = albedo[c] > 1e-6f ? rho[c] / albedo[c] : plain[c] * invN;
        return out;
    };
    fb.direct(x, y) = demodulate(rhoDirect, direct);
    fb.indirect(x, y) = demodulate(rhoIndirect, indirect);
    float invHit = nHit > 0 ? 1.f / float(nHit) : 0.f;
    fb.normal(x, y) = nHit > 0 ? normalize(normal) : Vec3f(0.f);
    fb.position(x, y) = position * invHit;
    fb.depth(x, y) = nHit > 0 ? depth * invHit : 0.f;
    fb.spp(x, y) = float(n);
    fb.object(x, y) = nHit > 0 ? float(object) : -1.f;
    float mean = lumSum * invN;
    fb.variance(x, y) = n > 1 ? std::max(0.f, lumSq * invN - mean * mean) / float(n - 1) : 0.f;
    fb.d1(x, y) = nOccluded > 0 ? d1Sum / float(nOccluded) : 0.f;
    fb.sMax(x, y) = nOccluded > 0 ? s1 : 0.f;
    fb.sMin(x, y) = nOccluded > 0 ? s2 : kInf;
    fb.occluded(x, y) = nShadow > 0 ? float(nOccluded) / float(nShadow) : 0.f;
    fb.zMin(x, y) = nBounce > 0 ? zMin : kInf;
    fb.zMax(x, y) = nBounce > 0 ? zMax : kInf;
    fb.suMin(x, y) = nHit > 0 && suMin <= suMax ? suMin : 0.f;
    fb.suMax(x, y) = nHit > 0 && suMin <= suMax ? suMax : 0.f;
    fb.footprint(x, y) = nHit > 0 ? view.pixelFootprint(fb.depth(x, y)) : 0.f;
}

}  // namespace wedge::render
