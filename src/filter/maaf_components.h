// MAAF component filters (Wu et al. 2017, Sec. 4 and Sec. 6.2): the centres, widths and weights
// of the 2N-1 axis-aligned Gaussians that cover a double wedge in the Fourier domain. Shared by
// the renderer's MAAF filter and by `wedge analyze`, so the analysis measures the filter the
// renderer uses.
//
// Conventions. A wedge in (Omega_x, Omega_y) holds the spectrum of f(x, y) = g(x + s y) for
// slopes s in [s_min, s_max] (so the spectrum lies on Omega_y = s Omega_x), |Omega_y| <= Omega_y^max.
// Fourier-domain Gaussians are peak-one: G(w; sigma) = exp(-w^2 / (2 sigma^2)). Their primal
// counterparts are unit-integral Gaussians of standard deviation 1/sigma, so the two are a
// Fourier pair and eq. 13's pairwise primal form needs no further constants.
//
// Misprint in the paper's eq. 24 (the lens axis): it reads s^u_min/s^u_max and s^u_max/s^u_min,
// which is dimensionless and does not follow the construction the text describes (keep each
// component's Omega_x range, map it through the lens wedge Omega_u = s^u Omega_x). The
// construction gives, with the Omega_x range [lo_p, hi_p] of eqs. 7-8,
//   Omega_u range = [s^u_min lo_p, s^u_max hi_p]  =>  C_u = (s^u_min lo_p + s^u_max hi_p) / 2,
//   sigma_u = (s^u_max hi_p - s^u_min lo_p) / 2,
// i.e. eq. 24 with s^u_min/s^y_max and s^u_max/s^y_min. That is what is implemented (and
// checked against the wedge geometry in tests/filter_test.cpp).
#pragma once

#include <vector>

namespace wedge::filter {

/// Component p (p >= 0; component -p is its mirror image through the origin).
struct MaafComponent {
    int p = 0;
    double cx = 0, cy = 0, cu = 0;  // centres C_x^p (eq. 7), C_y^p (eq. 6), C_u^p (eq. 24, corrected)
    double sx = 1, sy = 1, su = 1;  // Fourier-domain half-widths / standard deviations (eqs. 8, 24)
    double mu = 1;                  // weight mu_p (eq. 10)
};

struct WedgeShape {
    double omegaYMax = 1;             // bandwidth along the secondary axis (light / lens / angle)
    double sMin = 1, sMax = 2;        // slopes of the (x, y) wedge, 0 < sMin <= sMax
    bool lens = false;                // add the lens axis of Sec. 6.2
    double suMin = 0, suMax = 0;      // slopes of the (x, u) wedge, 0 <= suMin <= suMax
    double omegaUMax = 0;             // lens bandwidth; bands beyond it are clipped
};

/// The N components p = 0..N-1 of MAAF with 2N-1 filters (N pairs counting the centre).
/// Eqs. 6-8 place them; eq. 10 weighs them; the lens axis follows eq. 24 (corrected, above).
std::vector<MaafComponent> maafComponents(int pairs, const WedgeShape& wedge);
/// The same into out[0..pairs) without allocating (the renderer calls it for every pixel).
void maafComponents(int pairs, const WedgeShape& wedge, MaafComponent* out);

/// Characteristic functions E[cos(w y)] of the densities MAAF's samples are drawn from, the
/// spectra the component weights follow by default (maaf.h):
/// y = the projection onto a unit axis of a point uniform on a parallelogram whose edges project
/// to lengths e1 and e2 (a light): sinc(w e1 / 2) sinc(w e2 / 2);
double parallelogramSpectrum(double w, double e1, double e2);
/// y = the projection, taken from the centroid, of a point uniform on the triangle (0, e1, e2)
/// whose edges from its first corner project to the signed lengths e1 and e2 (a triangle light):
/// the real part of its characteristic function, 2 f[x0, x1, x2] for f = -e^{iwy} / w^2 by the
/// Hermite-Genocchi formula. Unlike a parallelogram's, the density is not symmetric about its
/// centre, and a kernel of cosines reproduces its symmetric part only.
double triangleSpectrum(double w, double e1, double e2);
/// The same for a triangle whose corners project to x0, x1, x2, taken from the origin: the real
/// part of E[e^{iwy}], which for a part of a larger light (a group of lights, ViewGeometry::Light)
/// is measured from the whole light's centroid. triangleSpectrum(w, e1, e2) is
/// triangleSpectrumAt(w, -c, e1 - c, e2 - c) with c = (e1 + e2) / 3.
double triangleSpectrumAt(double w, double x0, double x1, double x2);
/// y = one coordinate of a point uniform on the unit disc (the lens; a cosine-weighted direction
/// projected onto its tangent plane): 2 J1(|w|) / |w|.
double discSpectrum(double w);

/// Peak-one Fourier Gaussian G(w; sigma).
double fourierGaussian(double w, double sigma);

/// MAAF in the Fourier domain (eq. 9), summed over p = -(N-1)..N-1, in 2D (Omega_x, Omega_y).
/// box = true evaluates unweighted boxes of half-widths (sx, sy) instead of weighted Gaussians.
double maafSpectrum(const std::vector<MaafComponent>& comps, double wx, double wy, bool box);

/// MAAF in the primal domain (eq. 19 / eq. 13): sum of the centre term g(a) g(b) and the pairs
/// 2 cos(C_x a + C_y b) g(a) g(b), with unit-integral Gaussians of std 1/sigma. This is the
/// inverse Fourier transform of maafSpectrum (Gaussian case) under
/// F^{-1}[W](a, b) = (1 / (2 pi)^2) int int W e^{+j (Omega_x a + Omega_y b)}.
double maafPrimal(const std::vector<MaafComponent>& comps, double a, double b);

/// Box coverage of MAAF in closed form (eq. 18). As printed, its centre term is 1/s_min^2; the
/// area of the centre box (eq. 8: 4 sigma_x^0 sigma_y^0 = 4 (Omega/K)^2 / s_min) gives 1/s_min,
/// which is what asPrinted = false uses. Both reduce to the paper's gamma_AAF (eq. 16) at N = 1,
/// and eq. 16 inherits the same extra factor s_min (the AAF box |Omega_x| <= Omega/s_min,
/// |Omega_y| <= Omega has area 4 Omega^2 / s_min, not 4 (Omega/s_min)^2).
double maafBoxCoverageEq18(int pairs, double sMin, double sMax, bool asPrinted);

}  // namespace wedge::filter
