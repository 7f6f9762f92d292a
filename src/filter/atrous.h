// The edge-avoiding à-trous wavelet filter of Dammertz, Sewtz, Hanika and Lensch (HPG 2010;
// shared/papers/atrous-dammertz-2010-slides.md), the image-space baseline the Fourier-derived
// filters are compared with. Level i convolves with the B3-spline kernel h = 1/16 [1 4 6 4 1]
// (outer product, 5x5) whose taps lie 2^i pixels apart ("with holes"), weighted by an
// edge-stopping function w(p, q) = w_n w_x w_rt and renormalised:
//   c_{i+1}(p) = sum_q h_i(q) w(p, q) c_i(q) / sum_q h_i(q) w(p, q)        (slides, "Edge Stopping Function")
// It filters demodulated light (direct + indirect, without albedo); FrameBuffers::compose puts
// albedo, coverage, emission and the unfiltered off-surface samples back.
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

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "core/buffers.h"
#include "core/image.h"

namespace wedge::filter {

struct AtrousParams {
    int iterations = 5;         // wavelet levels; the kernel reaches 2 (2^levels - 1) pixels
    float sigmaColor = 4.f;     // noise standard deviations
    float sigmaNormal = 0.5f;   // on |n_p - n_q|
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

/// The constants of w(p, .) for one centre pixel p at one level, as Falcor's computeWeight
/// receives its phis.
struct EdgeScales {
    float invNormal2 = 1;    // 1 / sigma_n^2
    float invPlane = 0;      // 1 / (sigma_x footprint_p step); 0 where p has no hit
    float invLuminance = 0;  // variance-guided: 1 / (sigma_c sqrt(g3x3 Var_i(p))); plain: 0
    float invColor2 = 0;     // plain: 1 / (sigma_c s_i)^2; variance-guided: 0

    /// `colorScale`: the colour sigma of this level in signal units, sigma_c s_i (plain) or
    /// sigma_c sqrt(g3x3 Var_i(p)) (variance-guided); `step`: pixels between taps.
    static EdgeScales at(const EdgeGuide& p, const AtrousParams& params, int step, float colorScale) {
        EdgeScales s;
        s.invNormal2 = 1.f / (params.sigmaNormal * params.sigmaNormal);
        s.invPlane = p.footprint > 0 ? 1.f / (params.sigmaPosition * p.footprint * float(step)) : 0.f;
        if (params.varianceGuided) s.invLuminance = 1.f / (colorScale + 1e-10f);
        else s.invColor2 = colorScale > 0 ? 1.f / (colorScale * colorScale) : 0.f;
        return s;
    }
};

/// exp(-x) for x >= 0 without a library call, so that the filter loop vectorises: 2^t with
/// t = -x log2(e) = k + f, k the nearest integer (rounded by adding 1.5 2^23, which leaves k in
/// the low mantissa bits, so no float-to-int conversion is needed) and f in [-1/2, 1/2]; 2^f by
/// its Taylor polynomial of degree 6 (relative error below 1e-5). Exactly 1 at x = 0.
inline float expNegative(float x) {
    constexpr float kRound = 12582912.f;  // 1.5 * 2^23
    const float t = std::max(-x * 1.44269504f, -126.f);
    const float shifted = t + kRound;
    const float f = t - (shifted - kRound);
    const int32_t k = std::bit_cast<int32_t>(shifted) - std::bit_cast<int32_t>(kRound);
    const float p = 1.f + f * (0.693147181f + f * (0.240226507f + f * (0.0555041087f +
                          f * (0.00961812911f + f * (0.00133335581f + f * 0.000154035304f)))));
    return p * std::bit_cast<float>((k + 127) << 23);
}

/// The edge-stopping function w(p, q) = w_n w_x w_rt (terms as in the file comment). Written
/// without branches so that the loop over pixels vectorises; w(p, p) = 1.
inline float edgeStoppingWeight(const EdgeGuide& p, const EdgeGuide& q, const EdgeScales& s) {
    const Vec3f dn = p.normal - q.normal;
    const float plane = dot(p.normal, q.position - p.position) * s.invPlane;  // tangent-plane distance
    const Vec3f dc = p.color - q.color;
    // Variance-guided: SVGF's L1 luminance distance; plain: squared RGB distance (one scale is 0).
    const float colour = std::abs(p.luminance - q.luminance) * s.invLuminance + dot(dc, dc) * s.invColor2;
    const float w = expNegative(dot(dn, dn) * s.invNormal2 + plane * plane + colour);
    return (p.footprint > 0) == (q.footprint > 0) ? w : 0.f;  // hits never mix with misses
}

/// w(p, q) from the parameters (tests, debugging).
inline float edgeStoppingWeight(const EdgeGuide& p, const EdgeGuide& q, const AtrousParams& params, int step,
                                float colorScale) {
    return edgeStoppingWeight(p, q, EdgeScales::at(p, params, step, colorScale));
}

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

/// The primary surfaces' demodulated light (direct + indirect) of `fb`, filtered.
Image3f atrousLight(const FrameBuffers& fb, const AtrousParams& params);

/// fb.compose of every pixel with `light` as its primary surface's filtered light: emission +
/// coverage * albedo * light + the unfiltered off-surface samples.
Image3f atrousCompose(const FrameBuffers& fb, const Image3f& light);

/// The à-trous method on rendered buffers: fb.compose(filter(direct + indirect)), i.e.
/// emission + coverage * albedo * filtered light + the unfiltered off-surface samples.
Image3f atrousFilter(const FrameBuffers& fb, const AtrousParams& params);

}  // namespace wedge::filter
