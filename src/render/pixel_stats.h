// Per-pixel reduction of path samples into the FrameBuffers planes: the Monte Carlo estimate,
// the demodulated direct and indirect light, the G-buffer, and the slope statistics of the
// initial samples (shadow slopes from occluder spans, bounce distances, defocus slopes).
#pragma once

#include "core/buffers.h"
#include "render/path_sampler.h"

namespace wedge::render {

struct PixelStats {
    Vec3f color{0.f}, emission{0.f}, albedo{0.f}, rhoDirect{0.f}, rhoIndirect{0.f}, direct{0.f}, indirect{0.f};
    Vec3f normal{0.f}, position{0.f};
    float depth = 0, lumSum = 0, lumSq = 0;
    uint32_t n = 0, nHit = 0, object = 0;
    // Slopes (only from samples added with slopes = true).
    float d1Sum = 0;
    uint32_t nShadow = 0, nOccluded = 0, nBounce = 0;
    float s1 = 0, s2 = kInf;                   // max d1/d2min - 1, min d1/d2max - 1
    float zMin = kInf, zMax = 0;               // bounce hit distances
    float suMin = kInf, suMax = -kInf;         // defocus slopes

    void add(const TracedSample& s, const ViewGeometry& view, bool slopes);
    /// Writes this pixel into every plane of `fb`.
    void store(FrameBuffers& fb, int x, int y, const ViewGeometry& view) const;
};

}  // namespace wedge::render
