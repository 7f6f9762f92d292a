// The edge-avoiding à-trous wavelet filter of Dammertz, Sewtz, Hanika and Lensch (HPG 2010;
// shared/papers/atrous-dammertz-2010-slides.md), the image-space baseline the Fourier-derived
// filters are compared with. Level i convolves with the B3-spline kernel h = 1/16 [1 4 6 4 1]
// (outer product, 5x5) whose taps lie 2^i pixels apart ("with holes"), weighted by an
// edge-stopping function w(p, q) = w_n w_x w_rt and renormalised:
//   c_{i+1}(p) = sum_q h_i(q) w(p, q) c_i(q) / sum_q h_i(q) w(p, q)        (slides, "Edge Stopping Function")
// It filters demodulated light (direct + indirect, without albedo); the caller multiplies by
// albedo and adds emission.
//
// The edge-stopping function lives in edgeStoppingWeight(), apart from the loop (as Falcor's
// SVGF keeps computeWeight apart), and differs from the slides in three places, each chosen
// because the slides' form does not carry over to a renderer with depth of field and unknown
// radiance scale:
//  - normal: w_n = exp(-|n_p - n_q|^2 / sigma_n^2), as the GLSL listing, but without dividing by
//    the step width (that division lets coarse levels smooth across 90 degree creases);
//  - position: the distance of x_q from the tangent plane of p, in units of sigma_x times p's
//    pixel footprint times the step width: w_x = exp(-(n_p . (x_q - x_p))^2 / (sigma_x fp 2^i)^2).
//    Plain |x_p - x_q| grows with the tap distance on a flat wall and would stop the filter
//    there; the plane distance is zero on a plane and large across depth discontinuities;
//  - colour: sigma_rt is given in units of the noise standard deviation, so one value works for
//    every scene. Plain mode (the slides): w_rt = exp(-|c_p - c_q|^2 / (sigma_c s_i)^2) with s_i
//    the image's mean noise level at level 0 halved per level (each level averages away noise).
//    Variance-guided mode (SVGF, Schied et al. 2017, Sec. 4.4): on luminance,
//    w_l = exp(-|l_p - l_q| / (sigma_c sqrt(g3x3(Var_i(p))) + eps)), with the variance carried
//    through the levels as Var_{i+1} = sum (h w)^2 Var_i / (sum h w)^2.
// Pixels without a surface hit (footprint 0) never mix with pixels that have one.
#pragma once

#include "core/buffers.h"
#include "core/image.h"

namespace wedge::filter {

struct AtrousParams {
    int iterations = 5;         // wavelet levels; the kernel reaches 2 (2^levels - 1) pixels
    float sigmaColor = 4.f;     // noise standard deviations
    float sigmaNormal = 0.1f;   // on |n_p - n_q|
    float sigmaPosition = 1.f;  // pixel footprints per unit step width
    bool varianceGuided = true;
};

/// The guide values the edge-stopping function compares at one pixel.
struct EdgeGuide {
    Vec3f normal, position;
    float footprint = 0;  // world size of a pixel at the hit; 0 where nothing was hit
    float luminance = 0;
    Vec3f color;
};

/// w(p, q) at step width `step` (pixels between taps). `colorScale` is the colour sigma of this
/// level in signal units: sigma_c s_i (plain) or sigma_c sqrt(g3x3 Var_i(p)) (variance-guided).
float edgeStoppingWeight(const EdgeGuide& p, const EdgeGuide& q, const AtrousParams& params, int step, float colorScale);

struct AtrousInput {
    const Image3f& signal;     // demodulated light to filter
    const Image3f& normal;     // unit normals (zero where nothing was hit)
    const Image3f& position;   // world positions
    const Image1f& footprint;  // world size of a pixel at the hit
    const Image1f& variance;   // of each pixel's mean luminance (of `signal`)
};

/// Filters `input.signal`; throws wedge::Error when the planes differ in size or the parameters
/// are out of range.
Image3f atrousFilter(const AtrousInput& input, const AtrousParams& params);

/// The à-trous method on rendered buffers: emission + albedo * filter(direct + indirect).
Image3f atrousFilter(const FrameBuffers& fb, const AtrousParams& params);

}  // namespace wedge::filter
