// The three reconstruction filters of Wu et al. 2017 as functions on the 2D Fourier plane
// (Omega_x, Omega_y), for measuring how well they fit the double wedge (Sec. 5): axis-aligned
// (AAF, eq. 2), sheared (FSF, eq. 4) and multiple axis-aligned (MAAF, eq. 9 with eqs. 6-8, 10).
// Each comes as a box (unweighted indicator, the "box/parallelogram" filters of Table 1 and
// eqs. 16-18) or as Gaussians (Table 2). MAAF is evaluated through filter::maafComponents and
// filter::maafSpectrum, the code the renderer uses.
//
// Widths. A box's half-widths are the paper's "widths": AAF |Omega_x| <= Omega/s_min,
// |Omega_y| <= Omega; FSF |Omega_x - Omega_y/s_avg| <= (Omega/2)(1/s_min - 1/s_max), |Omega_y| <=
// Omega (the tight parallelogram of Sec. 5); MAAF component p: (sigma_x^p, sigma_y^p) of eq. 8.
// Gaussians are peak-one, G(w; sigma) = exp(-w^2 / (2 sigma^2)), with sigma = the same half-width
// (eqs. 2, 8), except FSF whose eq. 4 prints sigma = Omega (1/s_min - 1/s_max), twice the
// parallelogram's half-width; GaussianConvention chooses between the printed form and others.
#pragma once

#include <string>
#include <vector>

#include "filter/maaf_components.h"

namespace wedge::analysis {

enum class FilterKind { Aaf, Fsf, Maaf };
enum class FilterShape { Box, Gaussian };

std::string toString(FilterKind kind);
std::string toString(FilterShape shape);
/// "aaf" | "fsf" | "maaf", "box" | "gaussian"; throws wedge::Error otherwise.
FilterKind parseFilterKind(const std::string& text);
FilterShape parseFilterShape(const std::string& text);

/// The double wedge T of Sec. 3: the spectra of g(x + s y), s in [sMin, sMax], lie on
/// Omega_y = s Omega_x; T is their union for |Omega_y| <= omegaYMax.
struct DoubleWedge {
    double omegaYMax = 1;
    double sMin = 1, sMax = 2;
};

/// Throws wedge::Error unless 0 < sMin < sMax (finite) and omegaYMax > 0.
void validateWedge(const DoubleWedge& wedge);
/// Area of T: Omega^2 (1/s_min - 1/s_max) (Sec. 5).
double wedgeArea(const DoubleWedge& wedge);
/// The Omega_x interval of the upper lobe of T at Omega_y = wy > 0: [wy/s_max, wy/s_min].
inline bool insideWedge(const DoubleWedge& w, double wx, double wy) {
    if (wy < 0) { wx = -wx; wy = -wy; }
    return wy <= w.omegaYMax && wx * w.sMin <= wy && wy <= wx * w.sMax;
}

/// How the Gaussian filters are normalised (Table 2 depends on this; the paper does not say).
struct GaussianConvention {
    double sigmaScale = 1;          // Gaussian std = sigmaScale x the box half-width
    bool fsfSigmaAsPrinted = true;  // eq. 4: std Omega (1/s_min - 1/s_max); false: the half-width
    bool maafWeights = true;        // eq. 10 weights mu_p; false: mu_p = 1
};

class FourierFilter {
public:
    /// components: 1 for AAF and FSF; K = 2N - 1 (odd, >= 1) for MAAF. Throws wedge::Error on a
    /// bad wedge or component count.
    FourierFilter(FilterKind kind, FilterShape shape, int components, const DoubleWedge& wedge,
                  const GaussianConvention& convention = {});

    FilterKind kind() const { return m_kind; }
    FilterShape shape() const { return m_shape; }
    int components() const { return m_components; }
    const DoubleWedge& wedge() const { return m_wedge; }
    /// MAAF's components p = 0..N-1 (eqs. 6-10) as used here (Gaussian convention applied).
    const std::vector<filter::MaafComponent>& maafComponents() const { return m_comps; }

    /// W(Omega_x, Omega_y).
    double operator()(double wx, double wy) const;
    /// W at the points (wxs[i], wy) of one row; faster for MAAF (only nearby components).
    void evalRow(double wy, const std::vector<double>& wxs, std::vector<double>& out) const;
    /// The integral of W along the row Omega_y = wy over Omega_x in [a, b], in closed form (box
    /// overlaps; erf for the Gaussians).
    double rowIntegral(double wy, double a, double b) const;
    /// The integral of |W| over the whole plane, in closed form (every W here is >= 0):
    /// box areas, or sum of mu 2 pi sigma_x sigma_y for the Gaussians.
    double integral() const;
    /// Omega_y values where a row's integrals have kinks (box edges, MAAF band edges).
    std::vector<double> yBreaks() const;
    /// Omega_x values where W is discontinuous along the row Omega_y = wy (box edges).
    void rowBreaks(double wy, std::vector<double>& out) const;
    /// A rectangle [-extentX, extentX] x [-extentY, extentY] outside which W < 1e-12 max W.
    double extentX() const;
    double extentY() const;

private:
    void nearbyComponents(double wy, std::vector<filter::MaafComponent>& out) const;

    FilterKind m_kind;
    FilterShape m_shape;
    int m_components;
    DoubleWedge m_wedge;
    GaussianConvention m_conv;
    double m_sx = 0, m_sy = 0;  // AAF / FSF: Omega_x (sheared) and Omega_y widths
    double m_invSAvg = 0;       // FSF: 1 / s_avg, s_avg the harmonic mean of s_min, s_max
    std::vector<filter::MaafComponent> m_comps;
};

}  // namespace wedge::analysis
