// Numerical coverage (eq. 15) and accuracy (eq. 14); see coverage.h for the quadrature.
#include "analysis/coverage.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace wedge::analysis {

void gaussLegendre(int n, std::vector<double>& nodes, std::vector<double>& weights) {
    nodes.assign(n, 0);
    weights.assign(n, 0);
    for (int i = 0; i < (n + 1) / 2; ++i) {
        // Newton on P_n from the Chebyshev-like first guess; converges in a few steps.
        double x = std::cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1;
        for (int it = 0; it < 100; ++it) {
            double p0 = 1, p1 = x;
            for (int k = 2; k <= n; ++k) {
                double p2 = ((2.0 * k - 1) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (x * p1 - p0) / (x * x - 1);
            double dx = p1 / dp;
            x -= dx;
            if (std::abs(dx) < 1e-16) break;
        }
        nodes[i] = -x;
        nodes[n - 1 - i] = x;
        weights[i] = weights[n - 1 - i] = 2.0 / ((1 - x * x) * dp * dp);
    }
}

namespace {

/// Splits [a, b] at the breaks inside it and then each piece into `sub` equal parts; appends
/// Gauss-Legendre nodes and weights for the whole.
void appendNodes(double a, double b, const std::vector<double>& breaks, int sub, const std::vector<double>& gx,
                 const std::vector<double>& gw, std::vector<double>& xs, std::vector<double>& ws) {
    // Breaks that differ by rounding only (e.g. a band edge computed as C_y - sigma_y and as the
    // next band's C_y + sigma_y) would leave a sliver whose nodes fall in a one-ulp gap between
    // boxes; merge them.
    const double tol = 1e-12 * std::max(std::abs(a), std::abs(b));
    std::vector<double> cuts{a};
    for (double c : breaks)
        if (c > a + tol && c < b - tol) cuts.push_back(c);
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end(), [&](double u, double v) { return v - u <= tol; }), cuts.end());
    cuts.push_back(b);
    for (size_t k = 0; k + 1 < cuts.size(); ++k) {
        double lo = cuts[k], hi = cuts[k + 1];
        if (!(hi > lo)) continue;
        double h = (hi - lo) / sub;
        for (int s = 0; s < sub; ++s) {
            double mid = lo + (s + 0.5) * h;
            for (size_t i = 0; i < gx.size(); ++i) {
                xs.push_back(mid + 0.5 * h * gx[i]);
                ws.push_back(0.5 * h * gw[i]);
            }
        }
    }
}

}  // namespace

FilterMetrics measureFilter(const FourierFilter& filter, CoverageDomain domain, const Quadrature& q) {
    const DoubleWedge& w = filter.wedge();
    const double om = w.omegaYMax;
    std::vector<double> gyx, gyw, gxx, gxw;
    gaussLegendre(q.yNodes, gyx, gyw);
    gaussLegendre(q.xNodes, gxx, gxw);

    std::vector<double> yBreaks = filter.yBreaks();
    yBreaks.push_back(0.0);
    std::vector<double> ys, yw;
    appendNodes(-om, om, yBreaks, q.ySub, gyx, gyw, ys, yw);

    FilterMetrics m;
    std::vector<double> rowBreaks, xs, xw, values;
    double boxTotal = 0;  // integral of W over the wedge's bounding box (CoverageDomain::WedgeBox)
    for (size_t j = 0; j < ys.size(); ++j) {
        const double wy = ys[j];
        // The wedge's Omega_x interval on this row: between the lines Omega_y = s Omega_x.
        double a = wy / w.sMax, b = wy / w.sMin;
        if (wy < 0) std::swap(a, b);
        filter.rowBreaks(wy, rowBreaks);
        xs.clear();
        xw.clear();
        appendNodes(a, b, rowBreaks, q.xSub, gxx, gxw, xs, xw);
        filter.evalRow(wy, xs, values);
        double inW = 0, err = 0, area = 0;
        for (size_t i = 0; i < xs.size(); ++i) {
            inW += xw[i] * std::abs(values[i]);
            err += xw[i] * (values[i] - 1) * (values[i] - 1);
            area += xw[i];
        }
        m.inWedge += yw[j] * inW;
        m.squaredError += yw[j] * err;
        m.wedgeArea += yw[j] * area;
        boxTotal += yw[j] * filter.rowIntegral(wy, -om / w.sMin, om / w.sMin);
    }
    m.totalPlane = filter.integral();
    m.totalWedgeBox = boxTotal;
    m.total = domain == CoverageDomain::Plane ? m.totalPlane : m.totalWedgeBox;
    m.coverage = m.inWedge / m.total;                           // eq. 15
    m.accuracy = 1.0 - std::sqrt(m.squaredError / m.wedgeArea);  // eq. 14
    return m;
}

FilterMetrics measureOnGrid(const FourierFilter& filter, int n) {
    if (n < 2) throw Error("grid", "needs at least 2 x 2 cells");
    const DoubleWedge& w = filter.wedge();
    const double ex = std::max(filter.extentX(), w.omegaYMax / w.sMin) * 1.001;
    const double ey = std::max(filter.extentY(), w.omegaYMax) * 1.001;
    const double hx = 2 * ex / n, hy = 2 * ey / n;
    FilterMetrics m;
    std::vector<double> xs(n), values;
    for (int i = 0; i < n; ++i) xs[i] = -ex + (i + 0.5) * hx;
    for (int j = 0; j < n; ++j) {
        const double wy = -ey + (j + 0.5) * hy;
        filter.evalRow(wy, xs, values);
        for (int i = 0; i < n; ++i) {
            double v = values[i];
            m.total += std::abs(v);
            if (insideWedge(w, xs[i], wy)) {
                m.inWedge += std::abs(v);
                m.squaredError += (v - 1) * (v - 1);
                m.wedgeArea += 1;
            }
        }
    }
    const double cell = hx * hy;
    m.total *= cell;
    m.totalPlane = m.total;
    m.inWedge *= cell;
    m.squaredError *= cell;
    m.wedgeArea *= cell;
    m.coverage = m.inWedge / m.total;
    m.accuracy = 1.0 - std::sqrt(m.squaredError / m.wedgeArea);
    return m;
}

double aafBoxCoverageEq16(double sMin, double sMax) { return 0.25 * sMin * (1.0 - sMin / sMax); }

double aafBoxCoverageExact(double sMin, double sMax) { return 0.25 * (1.0 - sMin / sMax); }

double fsfBoxCoverageExact() { return 0.5; }

}  // namespace wedge::analysis
