#include "filter/maaf_components.h"

#include <algorithm>
#include <cmath>

namespace wedge::filter {

std::vector<MaafComponent> maafComponents(int pairs, const WedgeShape& w) {
    std::vector<MaafComponent> comps(size_t(std::max(pairs, 0)));
    maafComponents(pairs, w, comps.data());
    return comps;
}

void maafComponents(int pairs, const WedgeShape& w, MaafComponent* out) {
    const double K = 2.0 * pairs - 1.0;  // number of filters, 2N-1
    const double Om = w.omegaYMax;
    for (int p = 0; p < pairs; ++p) {
        MaafComponent c;
        c.p = p;
        c.cy = Om * (2.0 * p / K);  // eq. 6
        c.sy = Om / K;              // eq. 8
        // Omega_x range of the band Omega_y in [(2p-1), (2p+1)] Om/K inside the wedge.
        double lo = p == 0 ? -Om / (K * w.sMin) : Om * (2.0 * p - 1.0) / (K * w.sMax);
        double hi = Om * (2.0 * p + 1.0) / (K * w.sMin);
        c.cx = 0.5 * (lo + hi);  // eq. 7 (sgn_p = +1 for p > 0, 0 for p = 0)
        c.sx = 0.5 * (hi - lo);  // eq. 8; for p = 0 it is (Om / s_min) / K as the text says
        if (p == 0) c.cx = 0;
        if (w.lens) {
            // Eq. 24, corrected: map the Omega_x range through the lens wedge.
            double ulo = p == 0 ? -w.suMax * hi : w.suMin * lo;
            double uhi = w.suMax * hi;
            if (w.omegaUMax > 0) {
                ulo = std::max(ulo, -w.omegaUMax);
                uhi = std::min(uhi, w.omegaUMax);
                if (uhi < ulo) ulo = uhi;  // band entirely beyond the lens bandwidth: degenerate
            }
            c.cu = p == 0 ? 0 : 0.5 * (ulo + uhi);
            c.su = std::max(0.5 * (uhi - ulo), 1e-12);
        }
        // Eq. 10: a Gaussian over the whole double wedge.
        c.mu = fourierGaussian(c.cx, Om / w.sMin) * fourierGaussian(c.cy, Om);
        out[p] = c;
    }
}

namespace {
double sinc(double x) { return std::abs(x) < 1e-8 ? 1.0 : std::sin(x) / x; }
}  // namespace

double parallelogramSpectrum(double w, double e1, double e2) { return sinc(0.5 * w * e1) * sinc(0.5 * w * e2); }

double triangleSpectrum(double w, double e1, double e2) {
    const double c = (e1 + e2) / 3;  // the centroid's projection
    return triangleSpectrumAt(w, -c, e1 - c, e2 - c);
}

double triangleSpectrumAt(double w, double x0, double x1, double x2) {
    // Sorted: x[0] <= x[1] <= x[2].
    double x[3] = {x0, x1, x2};
    std::sort(x, x + 3);
    const double spread = x[2] - x[0];
    if (std::abs(w) * spread < 1e-4) {
        // E[e^{iwy}] = e^{iw mean} E[e^{iw(y - mean)}] = e^{iw mean} (1 - w^2 Var(y) / 2 + O((w spread)^3)),
        // whose imaginary third-order term moves the real part by O((w spread)^3) too.
        const double mean = (x[0] + x[1] + x[2]) / 3;
        const double var = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] - x[0] * x[1] - x[0] * x[2] - x[1] * x[2]) / 18;
        return std::cos(w * mean) * (1 - 0.5 * w * w * var);
    }
    // With e = e^{iwy}: e[a, b] = (e(b) - e(a)) / (b - a) = i w e^{iw(a+b)/2} sinc(w (b - a) / 2),
    // 2 f[x0, x1, x2] = -(2 / w^2) (e[x1, x2] - e[x0, x1]) / (x2 - x0), whose real part is
    // 2 / (w (x2 - x0)) (sin(w m12) sinc(w h12) - sin(w m01) sinc(w h01)), m the midpoints and
    // h the half-lengths; stable once w (x2 - x0) is not tiny (sorting makes it the largest gap).
    const double m12 = 0.5 * (x[1] + x[2]), h12 = 0.5 * (x[2] - x[1]);
    const double m01 = 0.5 * (x[0] + x[1]), h01 = 0.5 * (x[1] - x[0]);
    return 2 / (w * spread) * (std::sin(w * m12) * sinc(w * h12) - std::sin(w * m01) * sinc(w * h01));
}

double discSpectrum(double w) {
    double a = std::abs(w);
    return a < 1e-8 ? 1.0 : 2.0 * std::cyl_bessel_j(1.0, a) / a;
}

double fourierGaussian(double w, double sigma) { return std::exp(-0.5 * w * w / (sigma * sigma)); }

double maafSpectrum(const std::vector<MaafComponent>& comps, double wx, double wy, bool box) {
    double sum = 0;
    for (const auto& c : comps) {
        for (int sign : {1, -1}) {
            if (c.p == 0 && sign < 0) continue;
            double dx = wx - sign * c.cx, dy = wy - sign * c.cy;
            if (box) sum += (std::abs(dx) <= c.sx && std::abs(dy) <= c.sy) ? 1.0 : 0.0;
            else sum += c.mu * fourierGaussian(dx, c.sx) * fourierGaussian(dy, c.sy);
        }
    }
    return sum;
}

namespace {
/// Unit-integral Gaussian of standard deviation 1/sigma: the primal pair of G(.; sigma).
double primalGaussian(double a, double sigma) {
    return sigma / std::sqrt(2.0 * M_PI) * std::exp(-0.5 * a * a * sigma * sigma);
}
}  // namespace

double maafPrimal(const std::vector<MaafComponent>& comps, double a, double b) {
    double sum = 0;
    for (const auto& c : comps) {
        double g = c.mu * primalGaussian(a, c.sx) * primalGaussian(b, c.sy);
        // Eqs. 12-13: the pair (p, -p) is 2 cos(C_x a + C_y b) g(a) g(b); the centre is g(a) g(b).
        sum += c.p == 0 ? g : 2.0 * std::cos(c.cx * a + c.cy * b) * g;
    }
    return sum;
}

double maafBoxCoverageEq18(int N, double sMin, double sMax, bool asPrinted) {
    double sAvg = 2.0 / (1.0 / sMin + 1.0 / sMax);  // harmonic mean
    double h = (N - 0.5) * (N - 0.5);
    double term1 = N * (N - 1.0) / h;
    double centre = asPrinted ? 1.0 / (sMin * sMin) : 1.0 / sMin;
    double term2 = (centre + 2.0 * (N - 1.0) / sAvg) / ((1.0 / sMin - 1.0 / sMax) * h);
    return 1.0 / (term1 + term2);
}

}  // namespace wedge::filter
