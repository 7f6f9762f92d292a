// The flatland soft-shadow light field of Wu et al. 2017, Sec. 3 and Fig. 4 (after Egan et al.
// 2011, Fig. 7): a light along y, a receiver line at distance d1 from it, and occluder lines with
// gaps at distances d2 < d1. f(x, y) is the visibility between receiver point x and light point y
// (eq. 1's integrand without I). A ray from light point y to receiver point x crosses the
// occluder plane at y + (d2/d1)(x - y) = (d2/d1)(x + s y) with s = d1/d2 - 1, so a single
// occluder gives f(x, y) = g(x + s y), whose spectrum lies on the line Omega_y = s Omega_x; several
// occluders fill the double wedge between s_min and s_max (Sec. 3).
//
// Conventions. The light spans y in [-L, L] with a Gaussian profile I(y) of std sigma_y = L/2
// (L = 2 sigma_y, as in the paper), so Omega_y^max = 2/sigma_y = 4/L. f is sampled on an n x n
// grid over x, y in [-R, R] (R = 2 L by default), each sample the average of ss x ss sub-samples
// (anti-aliasing). The spectrum is that of f itself, |FFT(f(x, y) h(x) h(y))|^2 with h a Hann
// window (against leakage at the domain's edges); eq. 1's integration against I(y) would then
// band-limit it to |Omega_y| <= Omega_y^max, which the figure marks. Arrays are stored with x
// along the fast axis and y increasing with the row index; the spectrum likewise with Omega_x,
// Omega_y increasing and the zero frequency at (n/2, n/2). The grid spacing is equal in x and y,
// so a line Omega_y = s Omega_x has slope s in bins as well.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"

namespace wedge::analysis {

struct FlatlandSetup {
    double lightSize = 1;                    // L (half the light's length)
    double receiverDistance = 2;             // d1, light to receiver
    std::vector<double> occluderDistances;   // d2 per occluder, light to occluder, 0 < d2 < d1
    int size = 512;                          // n, samples per axis
    double extent = 0;                       // R, half-size of the (x, y) domain; 0: 2 L
    double feature = 0;                      // mean slat / gap width on an occluder; 0: L / 8
    uint64_t seed = 1;                       // slat pattern
    int supersample = 4;                     // ss x ss sub-samples per grid point

    double halfExtent() const { return extent > 0 ? extent : 2 * lightSize; }
    double featureSize() const { return feature > 0 ? feature : 0.125 * lightSize; }
};

/// Throws wedge::Error on non-positive sizes, d2 outside (0, d1), n outside [16, 4096].
void validateSetup(const FlatlandSetup& setup);

/// Slope s = d1/d2 - 1 of the occluder at distance d2 (Sec. 3).
double occluderSlope(double d1, double d2);

/// One occluder line: alternating open and blocked intervals of random widths.
class SlatPattern {
public:
    SlatPattern(double from, double to, double feature, uint64_t seed);
    /// 1 where position t on the occluder is open, 0 where blocked.
    double transmittance(double t) const;

private:
    std::vector<double> m_edges;  // sorted; [m_edges[2k], m_edges[2k+1]) is blocked
};

struct FlatlandField {
    int n = 0;
    double halfExtent = 0;       // R
    double spacing = 0;          // 2 R / n, the same in x and y
    std::vector<double> f;       // visibility, n x n, index iy * n + ix, y increasing with iy
    std::vector<double> slopes;  // s per occluder
};

/// Samples f(x, y) at x, y = -R + (i + 1/2) spacing.
FlatlandField sampleFlatland(const FlatlandSetup& setup);

struct FlatlandSpectrum {
    int n = 0;
    double binWidth = 0;         // Delta Omega = 2 pi / (2 R), per bin, on both axes
    std::vector<double> power;   // |F|^2, n x n, index ky * n + kx, zero frequency at (n/2, n/2)
};

/// |FFT(f h h)|^2 with FFTW (one plan per call), centred.
FlatlandSpectrum flatlandSpectrum(const FlatlandField& field);

/// Fraction of the spectrum's energy (outside the zero-frequency bin's neighbourhood of radius
/// `dcRadius` bins) that lies within `halfWidth` bins of the line Omega_y = s Omega_x, counting
/// the line's aliases in the periodic DFT spectrum.
double energyNearSlope(const FlatlandSpectrum& spec, double s, double halfWidth, double dcRadius = 2);
/// The same for the double wedge between the slopes sLo <= sHi (Omega_y = s Omega_x, s in
/// [sLo, sHi]), widened by `halfWidth` bins.
double energyInWedge(const FlatlandSpectrum& spec, double sLo, double sHi, double halfWidth, double dcRadius = 2);

/// Energy per direction: `bins` angular bins over theta = atan(Omega_y / Omega_x) in
/// (-90, 90] degrees, normalised to sum to one (zero-frequency neighbourhood excluded).
std::vector<double> energyPerAngle(const FlatlandSpectrum& spec, int bins, double dcRadius = 2);

/// The figure: the occlusion image f (x right, y up, light extent |y| <= L marked) beside
/// log10 |F|^2 (Omega_x right, Omega_y up) with the predicted lines Omega_y = s Omega_x dashed.
Image3f flatlandFigure(const FlatlandField& field, const FlatlandSpectrum& spec, double lightSize);

}  // namespace wedge::analysis
