// The expected output of MAAF's spatial filter across a flatland penumbra, per number of
// components, with the renderer's conventions: what Fig. 10 of Wu et al. 2017 shows in images
// ("3 filters: shadows too hard, 5 already accurate"), measured as bias and noise instead.
//
// Flatland: a receiver x, a light y uniform on [-L, L], one occluder edge, visibility
// v(x, y) = [x + s y > 0] (the wedge of slope s, maaf_components.h). Samples are spread
// uniformly in x at density rho (per unit length) with y drawn from the light, as the renderer
// draws them (no windows, filter/maaf.h "Windows"). The filter at x is the ratio
//   sum_i k(x - x_i, y_i) v_i / sum_i k(x - x_i, y_i),
//   k(a, y) = sum_p c_p mu_p g_p(a) cos(C_x^p a - C_y^p y),  |a| <= window,
// of the renderer (filter/maaf.h: eq. 21 per axis, c_0 = 1, c_p = 2, g_p a unit-integral
// Gaussian of Fourier std spatialScale x sigma_x^p). By quadrature over (x', y):
//  - its expectation m(x) = E[k v] / E[k] (to first order in 1/n), against the exact penumbra
//    (x / s + L) / (2 L) clamped to [0, 1];
//  - its variance, rho Var = E[k^2 (v - m)^2] / E[k]^2 (the delta method), so that the mean
//    squared error at density rho is bias^2 + variance / rho. That is the variance of
//    independent samples (a Poisson process in x, y drawn from the whole light).
//  - With `spp`, the variance of the renderer's samples instead: pixels of `pixelWidth` in x,
//    each with spp samples stratified along the light (one in each of spp equal strata of y, x
//    uniform in the pixel), as the renderer's Owen-scrambled Sobol points are in every
//    elementary interval (core/sampler.h). The sum's variance is then the sum over the cells
//    (pixel, stratum) of the variance within each cell, Var = sum_cells Var_cell(k (v - m)) /
//    (sum E[k])^2, which for an edge is far below the independent samples': only the strata
//    the edge crosses vary. (Stratification does not change the expectation.)
// Hardness is the mean signed error over the penumbra's inner 96%, counted positive where the
// filtered edge is steeper than the truth (above it in the lit half, below it in the dark half).
#pragma once

#include <string>
#include <vector>

#include "filter/maaf.h"

namespace wedge::analysis {

struct PenumbraSetup {
    double lightHalfLength = 0.5;  // L: the light spans y in [-L, L] along the axis
    double lightAspect = 1;        // length / width of the 2D parallelogram light (sets sigma = sqrt(area) / 2)
    double slope = 0.6;            // s of the occluder edge: the penumbra spans |x| <= s L
    double filterSMin = 0, filterSMax = 0;  // the filter's wedge; 0: the edge's own slope
    double mu = 2;                 // Omega_y^max = mu / sigma (as the renderer)
    double spatialScale = 2.449490;  // MaafOptions::spatialScale
    filter::MaafWeights weights = filter::MaafWeights::Sampling;
    double window = 0;             // |x - x'| <= window; 0: unbounded (8 std of the widest Gaussian)
    int points = 61;               // output positions across [-1.25 s L, 1.25 s L]
    int spp = 0;                   // > 0: samples per pixel, stratified along the light; 0: independent samples
    double pixelWidth = 0;         // the pixel's width in x (with spp)
};

/// The filter's kernel k(a, y) for N = `pairs` (2N - 1 components), zero beyond `reach`.
struct PenumbraKernel {
    struct Term {
        double weight, sx, cx, cy;  // weight c_p mu_p, the Gaussian's Fourier std, the centre (C_x, C_y)
        /// The weighted spatial Gaussian at offset a (its modulation cos(C_x a - C_y y) apart).
        double envelope(double a) const;
    };
    std::vector<Term> terms;
    double reach = 0;  // |a| beyond which k = 0 (the window, or 8 std of the widest Gaussian)
    double operator()(double a, double y) const;
};
PenumbraKernel penumbraKernel(int pairs, const PenumbraSetup& setup);

struct PenumbraResponse {
    int components = 1;            // 2N - 1
    std::vector<double> x, truth, mean;  // per output position
    double rmsBias = 0;            // over all output positions
    double hardness = 0;           // see above
    std::vector<double> var;       // rho Var per output position (stratified with spp)
    double variance = 0;           // mean of rho Var over the output positions (stratified with spp)
    double varianceIndependent = 0;  // ... of independent samples (= variance without spp)
};

/// Checks the setup; throws Error naming the field.
void validatePenumbra(const PenumbraSetup& setup);
/// The expected filter output for N = `pairs` (2N - 1 components).
PenumbraResponse penumbraResponse(int pairs, const PenumbraSetup& setup);

/// Sample density (per unit length of x) below which filter `a` has the lower mean squared error
/// than `b` on average over the penumbra, given a's lower variance and higher bias: the root of
/// bias_a^2 + V_a / rho = bias_b^2 + V_b / rho (the variances of the response: stratified with
/// spp, where rho then counts the rows a 2D filter also averages along the edge). Infinity when a
/// is no more biased than b, 0 when it is not less noisy.
double breakEvenDensity(const PenumbraResponse& a, const PenumbraResponse& b);

}  // namespace wedge::analysis
