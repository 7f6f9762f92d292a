// The primary (defocus) filter of factored axis-aligned filtering (MYRD14, as reconstructed in
// shared/papers/NOTES.md: "filter irradiance with the secondary filter, multiply by texture, then
// apply the primary filter"): after the per-surface filters, the composited radiance is filtered
// in image space where every lens sample of a pixel saw defocused geometry.
//
// A pixel whose lens samples all have |s_u| >= b (pixels per unit lens coordinate, over every
// surface and miss it saw) sees the scene through a disc of radius b pixels: the image there is
// the scene convolved with that disc, whose spectrum 2 J1(b w) / (b w) has its first zero at
// w = 3.83 / b and sidelobes below 13%. The kernel is AAF's, exp(-3 r^2 Omega^2), whose response
// is exp(-w^2 / (12 Omega^2)), cut at r Omega = 1, with Omega = Omega_u / b. Omega_u = 2 passes
// 74% at the disc's first zero and 93% at half of it (where the disc itself passes 58%): a
// filter inside the band the defocus leaves. (The lens bandwidth of 6 used for the shadow and
// indirect filters, from a Gaussian lens of a third of the radius, is far more conservative:
// measured with the AAF method at 512x512, relMSE without this filter / Omega_u = 3.83 / 2.5 /
// 2 / 1.5: conference 0.00136 / 0.00135 / 0.00121 / 0.00112 / 0.00106, sponza 0.00171 / 0.00156
// / 0.00146 / 0.00141 / 0.00132, cornell 0.000237 / 0.000237 / 0.000228 / 0.000225 / 0.000220;
// 2 is the last value inside the argument above.) The support is
// b / 2 pixels: a silhouette blurred over a circle of confusion of radius 20 px is filtered over
// 10. b is the smallest |s_u| among the pixel's samples, also where they straddle the focal
// plane (a defocused silhouette over a background beyond the focus: both layers are blurred by
// at least b); where one of them is in focus, b = 0 and the filter is the identity. A
// neighbour whose own b is less than half the pixel's (sharper content) is left out, and emitted
// light is not filtered (emitter edges are sampled densely already, and next to a bright emitter
// any spread of it dominates its neighbours' relative error).
//
// The per-surface filters cannot reach what this one does: the partial coverage of a defocused
// silhouette (several surfaces in one pixel) and texture averaged over few lens samples.
#pragma once

#include "core/buffers.h"

namespace wedge::filter {

struct DefocusOptions {
    float lensOmega = 2.f;   // Omega_u: the band limit is Omega_u / b (see above)
    int maxRadius = 10;      // pixels
    float sharperRatio = 2.f;  // reject neighbours whose b is below the pixel's / this
};

/// Two separable passes (image x, then y) of the defocus filter over `color`.
Image3f defocusFilter(const Image3f& color, const FrameBuffers& fb, const DefocusOptions& options = {});

}  // namespace wedge::filter
