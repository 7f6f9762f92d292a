#include "render/pixel_stats.h"

namespace wedge::render {

void SurfaceSlot::add(const TracedSample& s, const ViewGeometry& view, bool slopes) {
    if (n == 0) {
        object = s.object;
        firstNormal = s.normal;
        firstPosition = s.position;
        planeTolerance = 4.f * view.pixelFootprint(s.depth);
    }
    ++n;
    const SampleRecord& r = s.record;
    albedo += s.albedo;
    albedoSq += sqr(luminance(s.albedo));
    rhoDirect += s.albedo * r.direct;
    rhoIndirect += s.albedo * r.indirect;
    direct += r.direct;
    indirect += r.indirect;
    normal += s.normal;
    position += s.position;
    depth += s.depth;
    visible += luminance(r.direct);
    unoccluded += r.unoccluded;
    if (!slopes) return;
    ++nSlopes;
    float su = view.defocusSlope(s.depth);
    suMin = std::min(suMin, su);
    suMax = std::max(suMax, su);
    if (s.shadowTested) {
        ++nShadow;
        if (s.occluded && !s.selfShadowed) {
            // s = d1/d2 - 1 with d2 the occluder's distance from the light (NOTES, AAF 2012);
            // s1 the largest over the pixel's samples, s2 the smallest. The authors' code took
            // each ray's nearest and farthest occluder (d2max = d1 - t_near, d2min = d1 - t_far);
            // here each ray's nearest alone, one closest-hit query instead of two: a farther
            // occluder hidden behind it on the same ray is seen by the pixel's other rays, or
            // not at all. Measured (AAF, 512x512, relMSE against 1024-spp references): cornell,
            // conference, sponza, bunny, cornell-sphere +0.0-0.2%, grids +1.0% (stacked slats),
            // 0.2-1.3% fewer samples, the initial stage 5-13% faster (docs/sampling-speed.md).
            ++nOccluded;
            d1Sum += s.d1;
            const float d2 = std::max(s.d1 - s.tOccluder, 1e-3f * s.d1);
            s1 = std::max(s1, s.d1 / d2 - 1.f);
            s2 = std::min(s2, s.d1 / d2 - 1.f);
            lightSigma = std::min(lightSigma, view.lights[r.light].sigma);
        }
    }
    if (s.bounceHit) {
        ++nBounce;
        zMin = std::min(zMin, s.bounceDistance);
        zMax = std::max(zMax, s.bounceDistance);
    }
}

int PixelStats::add(const TracedSample& s, const ViewGeometry& view, bool slopes, SlotPool& pool) {
    ++n;
    const SampleRecord& r = s.record;
    Vec3f l = r.direct + r.indirect;
    color += s.emission + s.albedo * l;
    emission += s.emission;
    if (maxComponent(s.emission) > 0) ++nEmitter;
    light += s.albedo * l;
    float lum = luminance(l);
    lumSum += lum;
    lumSq += lum * lum;
    if (slopes) {
        float su = view.defocusSlope(s.hit ? s.depth : kInf);
        suLo = std::min(suLo, su);
        suHi = std::max(suHi, su);
        suAbsMin = std::min(suAbsMin, std::abs(su));
    }
    if (!s.hit) {
        ++nMiss;
        return -1;
    }
    if (first.n == 0 || first.matches(s)) {
        first.add(s, view, slopes);
        return 0;
    }
    if (!more) more = pool.allocate();
    for (int k = 1; k < kSlots; ++k) {
        SurfaceSlot& sl = more[k - 1];
        if (sl.n == 0 || sl.matches(s)) {
            sl.add(s, view, slopes);
            return k;
        }
    }
    return -1;  // a surface beyond the slots: only in the colour (FrameBuffers::rest)
}

void PixelStats::store(FrameBuffers& fb, int x, int y, const ViewGeometry& view) const {
    const size_t p = size_t(y) * fb.width + x;
    const float invN = n > 0 ? 1.f / float(n) : 0.f;
    const int primarySlot = primary();
    const SurfaceSlot& m = slot(primarySlot);
    fb.color[p] = color * invN;
    fb.emission[p] = emission * invN;
    fb.spp[p] = float(n);
    float mean = lumSum * invN;
    // The smallest circle of confusion among the samples, also where they straddle the focal
    // plane (a defocused silhouette over a background beyond the focus): 0 only where a sample
    // is in focus. Measured against taking 0 wherever they straddle (512x512, relMSE): AAF
    // cornell-sphere 0.000160 -> 0.000151, bunny 0.000124 -> 0.000122, MAAF 0.000200 -> 0.000190,
    // 0.000137 -> 0.000135; cornell, conference, sponza, grids the same to 3 digits.
    fb.defocus[p] = suLo > suHi ? 0.f : suAbsMin;
    fb.variance[p] = n > 1 ? std::max(0.f, lumSq * invN - mean * mean) / float(n - 1) : 0.f;
    Vec3f slotLight(0.f);
    for (int k = 0; k < kSlots; ++k) slotLight += slot(k).rhoDirect + slot(k).rhoIndirect;
    fb.rest[p] = (light - slotLight) * invN;
    // Demodulate so that albedo * direct reproduces a slot's mean of albedo_s * direct_s.
    auto demodulate = [](const SurfaceSlot& s, const Vec3f& rho, const Vec3f& plain) {
        Vec3f out;
        for (int c = 0; c < 3; ++c) out[c] = s.albedo[c] > 1e-6f ? rho[c] / s.albedo[c] : plain[c] / float(s.n);
        return out;
    };
    // Coverage: with primary samples (addPrimary), each surface's share of the samples that
    // landed on the pixel's surfaces or on nothing, over path and primary samples together,
    // scaled by the path samples' share of those (the rest, surfaces beyond the slots, keeps
    // its own). Without them the path samples' share.
    uint32_t slotsN = nMiss, primaryN = primaryMiss;
    for (int k = 0; k < kSlots; ++k) {
        slotsN += slot(k).n;
        primaryN += slot(k).textureN;
    }
    const float coverageScale = primaryN > 0 ? float(slotsN) * invN / float(slotsN + primaryN) : 0.f;
    // The planes every kept surface has (the primary's in fb, the others' in fb.other).
    auto storeSurface = [&](const SurfaceSlot& s, Image3f& albedo, Image3f& direct, Image3f& indirect, Image3f& normal,
                            Image3f& position, Image1f& object, Image1f& coverage) {
        if (s.n == 0) {
            albedo[p] = direct[p] = indirect[p] = normal[p] = position[p] = Vec3f(0.f);
            object[p] = -1;
            coverage[p] = 0;
            return;
        }
        const float inv = 1.f / float(s.n);
        coverage[p] = primaryN > 0 ? float(s.n + s.textureN) * coverageScale : float(s.n) * invN;
        // The path samples' albedo with the texture samples' (PixelStats::addPrimary); the
        // light stays demodulated by the path samples' own (above), a ratio estimator.
        albedo[p] = s.textureN == 0 ? s.albedo * inv : (s.albedo + s.textureAlbedo) / float(s.n + s.textureN);
        direct[p] = demodulate(s, s.rhoDirect, s.direct);
        indirect[p] = demodulate(s, s.rhoIndirect, s.indirect);
        normal[p] = normalize(s.normal);
        position[p] = s.position * inv;
        object[p] = float(s.object);
    };
    for (int k = 0, o = 0; k < kSlots; ++k) {
        if (k == primarySlot) continue;
        FrameBuffers::OtherSurface& other = fb.other[o++];
        storeSurface(slot(k), other.albedo, other.direct, other.indirect, other.normal, other.position, other.object,
                     other.coverage);
    }
    storeSurface(m, fb.albedo, fb.direct, fb.indirect, fb.normal, fb.position, fb.object, fb.coverage);
    if (m.n == 0) {  // nothing hit: background
        fb.depth[p] = fb.footprint[p] = fb.visibility[p] = fb.unoccluded[p] = 0;
        fb.d1[p] = fb.sMax[p] = fb.occluded[p] = fb.bounced[p] = fb.suMin[p] = fb.suMax[p] = 0;
        fb.sMin[p] = fb.zMin[p] = fb.zMax[p] = fb.lightSigma[p] = kInf;
        return;
    }
    const float invM = 1.f / float(m.n);
    fb.depth[p] = m.depth * invM;
    fb.unoccluded[p] = m.unoccluded * invM;
    fb.visibility[p] = m.unoccluded > 0 ? m.visible / m.unoccluded : 0.f;
    fb.footprint[p] = view.pixelFootprint(fb.depth[p]);
    fb.d1[p] = m.nOccluded > 0 ? m.d1Sum / float(m.nOccluded) : 0.f;
    fb.sMax[p] = m.nOccluded > 0 ? m.s1 : 0.f;
    fb.sMin[p] = m.nOccluded > 0 ? m.s2 : kInf;
    fb.lightSigma[p] = m.lightSigma;
    fb.occluded[p] = m.nShadow > 0 ? float(m.nOccluded) / float(m.nShadow) : 0.f;
    fb.zMin[p] = m.nBounce > 0 ? m.zMin : kInf;
    fb.zMax[p] = m.nBounce > 0 ? m.zMax : kInf;
    fb.bounced[p] = m.nSlopes > 0 ? float(m.nBounce) / float(m.nSlopes) : 0.f;
    bool su = m.suMin <= m.suMax;
    fb.suMin[p] = su ? m.suMin : 0.f;
    fb.suMax[p] = su ? m.suMax : 0.f;
}

}  // namespace wedge::render
