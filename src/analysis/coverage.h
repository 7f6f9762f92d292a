// Coverage (eq. 15) and accuracy (eq. 14) of a Fourier filter against the filled double wedge T
// (Wu et al. 2017, Sec. 5), computed numerically, and the paper's closed forms for boxes (eqs. 16,
// 18) next to the true geometry.
//
// The numerical integral over the Fourier plane runs over rows Omega_y = const (Gauss-Legendre
// nodes on the pieces between the filter's kinks, so box filters are integrated exactly) and, in
// each row, over the wedge's Omega_x interval(s) (Gauss-Legendre again, split at box edges). The
// denominator of eq. 15, the integral of |W| over the whole plane, is in closed form (W >= 0 for
// every filter here). measureOnGrid is the plain midpoint-grid version, kept as a cross-check.
//
// Eq. 15 integrates |W| over the whole plane. CoverageDomain::WedgeBox instead integrates it over
// the wedge's bounding box |Omega_x| <= Omega/s_min, |Omega_y| <= Omega, as a program that samples
// only that window would; it is not the paper's definition, but it brings the Gaussian numbers
// closer to the paper's Table 2 (docs/analysis.md). Box filters are unaffected: all of them
// (the FSF parallelogram included) lie inside that window.
#pragma once

#include "analysis/fourier_filters.h"

namespace wedge::analysis {

enum class CoverageDomain { Plane, WedgeBox };

struct FilterMetrics {
    double coverage = 0;        // gamma, eq. 15, with the requested CoverageDomain
    double accuracy = 0;        // alpha, eq. 14
    double inWedge = 0;         // integral of |W| over T
    double total = 0;           // integral of |W| over the requested domain
    double totalPlane = 0;      // integral of |W| over the whole plane (closed form)
    double totalWedgeBox = 0;   // integral of |W| over |Omega_x| <= Omega/s_min, |Omega_y| <= Omega
    double squaredError = 0;    // integral of (W - 1)^2 over T
    double wedgeArea = 0;       // integral of 1 over T (numerically; equals wedgeArea())

    double coverageIn(CoverageDomain d) const {
        return inWedge / (d == CoverageDomain::Plane ? totalPlane : totalWedgeBox);
    }
};

struct Quadrature {
    int ySub = 4, yNodes = 8;   // pieces per kink-free Omega_y segment, Gauss-Legendre nodes per piece
    int xSub = 2, xNodes = 16;  // pieces per kink-free piece of a row's wedge interval, nodes per piece
};

FilterMetrics measureFilter(const FourierFilter& filter, CoverageDomain domain = CoverageDomain::Plane,
                            const Quadrature& q = {});
/// The same on an n x n midpoint grid over the filter's (and the wedge's) bounding box (whole-plane
/// coverage only; totalWedgeBox is left at 0).
FilterMetrics measureOnGrid(const FourierFilter& filter, int n);

/// Box coverages in closed form.
/// Eq. 16 as printed: gamma_AAF = (s_min / 4)(1 - s_min / s_max), from an AAF area 4 (Omega/s_min)^2.
double aafBoxCoverageEq16(double sMin, double sMax);
/// The true ratio: the AAF box |Omega_x| <= Omega/s_min, |Omega_y| <= Omega has area
/// 4 Omega^2 / s_min, so gamma_AAF = (1/4)(1 - s_min / s_max).
double aafBoxCoverageExact(double sMin, double sMax);
/// Eq. 16: gamma_FSF = 1/2 (the tight parallelogram has twice the wedge's area).
double fsfBoxCoverageExact();

/// Gauss-Legendre nodes and weights on [-1, 1].
void gaussLegendre(int n, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace wedge::analysis
