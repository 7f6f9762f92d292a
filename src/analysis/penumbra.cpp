#include "analysis/penumbra.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

#include "core/error.h"
#include "filter/maaf_components.h"

namespace wedge::analysis {

void validatePenumbra(const PenumbraSetup& s) {
    auto positive = [](double v, const char* field) {
        if (!(v > 0) || !std::isfinite(v)) throw Error(field, "expected a positive number, got " + std::to_string(v));
    };
    positive(s.lightHalfLength, "--light-half-length");
    positive(s.lightAspect, "--light-aspect");
    positive(s.slope, "--slope");
    positive(s.mu, "--mu");
    positive(s.spatialScale, "--spatial-scale");
    if (s.filterSMin < 0 || s.filterSMax < 0 || (s.filterSMin > 0) != (s.filterSMax > 0))
        throw Error("--smin/--smax", "give both, positive, or neither");
    if (s.filterSMin > s.filterSMax) throw Error("--smin/--smax", "expected smin <= smax");
    if (s.window < 0 || !std::isfinite(s.window)) throw Error("--window", "expected 0 (unbounded) or a positive width");
    if (s.points < 3 || s.points > 10001) throw Error("--points", "expected 3 to 10001 positions");
    if (s.spp < 0 || s.spp > 4096) throw Error("--spp", "expected 0 (independent samples) to 4096 samples per pixel");
    if (s.spp > 0 && (!(s.pixelWidth > 0) || !std::isfinite(s.pixelWidth)))
        throw Error("--pixel-width", "expected a positive pixel width with --spp");
    if (s.spp == 0 && s.pixelWidth != 0) throw Error("--pixel-width", "only with --spp (the stratified samples' pixels)");
}

double PenumbraKernel::Term::envelope(double a) const { return weight * sx * std::exp(-0.5 * sx * sx * a * a); }

double PenumbraKernel::operator()(double a, double y) const {
    if (std::abs(a) > reach) return 0;
    double k = 0;
    for (const Term& t : terms) k += t.envelope(a) * std::cos(t.cx * a - t.cy * y);
    return k;
}

PenumbraKernel penumbraKernel(int pairs, const PenumbraSetup& set) {
    validatePenumbra(set);
    if (pairs < 1 || pairs > filter::kMaafMaxPairs) throw Error("pairs", "expected 1 to " + std::to_string(filter::kMaafMaxPairs));
    const double L = set.lightHalfLength, s = set.slope;
    // The 2D light is 2L long (along the axis) and 2L / aspect wide; sigma = sqrt(area) / 2 as
    // the renderer (NOTES: the light as a Gaussian for the analysis).
    const double sigma = std::sqrt(2 * L * 2 * L / set.lightAspect) / 2, omegaY = set.mu / sigma;
    filter::WedgeShape w;
    w.omegaYMax = omegaY;
    w.sMin = set.filterSMin > 0 ? set.filterSMin : s;
    w.sMax = set.filterSMax > 0 ? set.filterSMax : s;
    PenumbraKernel kernel;
    double sxMin = std::numeric_limits<double>::infinity();
    for (const auto& c : filter::maafComponents(pairs, w)) {
        // The renderer's mu_p for a light 2L long seen along its length.
        const double mu = filter::componentWeight(c, set.weights, [&] { return filter::parallelogramSpectrum(c.cy, 2 * L, 0); });
        kernel.terms.push_back({(c.p == 0 ? 1.0 : 2.0) * mu, c.sx * set.spatialScale, c.cx, c.cy});
        sxMin = std::min(sxMin, c.sx * set.spatialScale);
    }
    kernel.reach = set.window > 0 ? set.window : 8.0 / sxMin;  // primal std of a component: 1 / (its sx)
    return kernel;
}

namespace {

/// stratifiedVariance's midpoint quadrature: positions per pixel, and light positions per
/// stratum (enough for 512 over the light, at least 4).
constexpr int kStratifiedPixelPoints = 16;
int stratumPoints(int spp) { return std::max(4, 512 / spp); }

/// rho Var(sum_i k_i (v_i - m)) with the samples stratified: the sum over the cells (a pixel of
/// width D, one of the spp strata of the light) of the variance of k (v - m) within the cell,
/// times rho = spp / D (so that it is the same quantity as E[k^2 (v - m)^2], the independent
/// samples'). By midpoint quadrature in each cell.
double stratifiedVariance(const PenumbraKernel& kernel, const PenumbraSetup& set, double x, double m) {
    constexpr int kQx = kStratifiedPixelPoints;
    const int n = set.spp, qy = stratumPoints(n);
    const double D = set.pixelWidth, L = set.lightHalfLength, s = set.slope, stratum = 2 * L / n;
    // cos(C_x a - C_y y) = cos(C_x a) cos(C_y y) + sin(C_x a) sin(C_y y): the y factors per light
    // position, the a factors (with the Gaussian) per position in the pixel.
    const size_t terms = kernel.terms.size();
    std::vector<double> cy(size_t(n) * qy * terms), sy(cy.size()), ys(size_t(n) * qy);
    for (int i = 0; i < n * qy; ++i) {
        ys[i] = -L + (i + 0.5) * (stratum / qy);
        for (size_t t = 0; t < terms; ++t) {
            cy[size_t(i) * terms + t] = std::cos(kernel.terms[t].cy * ys[i]);
            sy[size_t(i) * terms + t] = std::sin(kernel.terms[t].cy * ys[i]);
        }
    }
    std::vector<double> ca(terms), sa(terms), sumZ(n), sumZ2(n);
    double total = 0;
    const long p0 = long(std::floor((x - kernel.reach) / D)), p1 = long(std::floor((x + kernel.reach) / D));
    for (long p = p0; p <= p1; ++p) {
        std::fill(sumZ.begin(), sumZ.end(), 0.0);
        std::fill(sumZ2.begin(), sumZ2.end(), 0.0);
        for (int u = 0; u < kQx; ++u) {
            const double xs = (double(p) + (u + 0.5) / kQx) * D, a = x - xs;
            if (std::abs(a) > kernel.reach) continue;  // k = 0 there
            for (size_t t = 0; t < terms; ++t) {
                const auto& term = kernel.terms[t];
                const double g = term.envelope(a);
                ca[t] = g * std::cos(term.cx * a);
                sa[t] = g * std::sin(term.cx * a);
            }
            for (int i = 0; i < n * qy; ++i) {
                double k = 0;
                for (size_t t = 0; t < terms; ++t) k += ca[t] * cy[size_t(i) * terms + t] + sa[t] * sy[size_t(i) * terms + t];
                const double z = k * ((xs + s * ys[i] > 0 ? 1.0 : 0.0) - m);
                sumZ[size_t(i / qy)] += z;
                sumZ2[size_t(i / qy)] += z * z;
            }
        }
        const double q = double(kQx) * qy;
        for (int j = 0; j < n; ++j) total += std::max(0.0, sumZ2[j] / q - (sumZ[j] / q) * (sumZ[j] / q));
    }
    return total * D / n;  // rho Var(sum) / rho^2 = sum_cells Var_cell / rho, rho = spp / D
}

}  // namespace

PenumbraResponse penumbraResponse(int pairs, const PenumbraSetup& set) {
    const PenumbraKernel kernel = penumbraKernel(pairs, set);
    if (set.spp > 0) {
        // The stratified quadrature's kernel evaluations (stratifiedVariance): bounded, so that a
        // tiny pixel width is an error, not a computation of hours.
        const double pixels = 2 * kernel.reach / set.pixelWidth + 2;
        const double work = pixels * kStratifiedPixelPoints * set.spp * stratumPoints(set.spp) * double(kernel.terms.size()) * set.points;
        if (work > 2e9)
            throw Error("--pixel-width", "the kernel reaches over " + std::to_string(int64_t(pixels)) +
                                             " pixels of this width: the stratified variance would take too long "
                                             "(wider pixels, or fewer --spp or --points)");
    }
    const double L = set.lightHalfLength, s = set.slope;
    // Kernel k(a, y) on a grid of offsets a (midpoints, symmetric about 0) and light positions y.
    double sxMax = 0, cxMax = 0;
    for (const auto& t : kernel.terms) {
        sxMax = std::max(sxMax, t.sx);
        cxMax = std::max(cxMax, std::abs(t.cx));
    }
    const double reach = kernel.reach;
    double h = std::min(1.0 / (8 * sxMax), s * L / 100);
    if (cxMax > 0) h = std::min(h, 2 * M_PI / (24 * cxMax));
    // The grid of offsets spans the kernel's reach at a step that resolves its finest Gaussian,
    // the penumbra and the fastest cosine. A reach far beyond that (a spatial scale near 0, a
    // window of 1e30) overflowed the count and crashed; bounded (256 light positions an offset:
    // at most 512 MB of kernel values).
    constexpr double kMaxOffsets = 262144;
    const double offsets = 2 * std::ceil(reach / h);
    if (!(offsets <= kMaxOffsets)) {
        char why[200];
        std::snprintf(why, sizeof why, "the kernel reaches %g and its finest detail needs a step of %g: more than %g offsets", reach, h,
                      kMaxOffsets);
        throw Error("--spatial-scale/--window", std::string(why) + " (a larger --spatial-scale or a smaller --window)");
    }
    const int na = int(offsets), ny = 256;
    h = 2 * reach / na;
    std::vector<double> a(na), y(ny), k(size_t(na) * ny);
    for (int j = 0; j < na; ++j) a[j] = -reach + (j + 0.5) * h;
    for (int i = 0; i < ny; ++i) y[i] = -L + (i + 0.5) * (2 * L / ny);
    for (int j = 0; j < na; ++j)
        for (int i = 0; i < ny; ++i) k[size_t(j) * ny + i] = kernel(a[j], y[i]);
    double sumK = 0, sumK2 = 0;
    for (double v : k) {
        sumK += v;
        sumK2 += v * v;
    }

    PenumbraResponse r;
    r.components = 2 * pairs - 1;
    const double half = 1.25 * s * L;
    double bias2 = 0, hard = 0, variance = 0;
    int nHard = 0;
    for (int t = 0; t < set.points; ++t) {
        const double x = -half + 2 * half * t / (set.points - 1);
        // Sums of k and k^2 over the lit samples: a sample at x' = x - a with light point y sees
        // the light where x' + s y > 0.
        double litK = 0, litK2 = 0;
        for (int j = 0; j < na; ++j)
            for (int i = 0; i < ny; ++i)
                if (x - a[j] + s * y[i] > 0) {
                    const double v = k[size_t(j) * ny + i];
                    litK += v;
                    litK2 += v * v;
                }
        const double m = litK / sumK;
        const double truth = std::clamp((x / s + L) / (2 * L), 0.0, 1.0);
        // E[k^2 (v - m)^2] with v in {0, 1}: lit (1 - m)^2 + unlit m^2; the sums carry h / ny.
        const double e2 = litK2 * (1 - m) * (1 - m) + (sumK2 - litK2) * m * m;
        const double meanK = sumK * h / ny;  // E[k]
        const double independent = (e2 * h / ny) / (meanK * meanK);
        r.varianceIndependent += independent;
        const double v = set.spp > 0 ? stratifiedVariance(kernel, set, x, m) / (meanK * meanK) : independent;
        r.var.push_back(v);
        variance += v;
        r.x.push_back(x);
        r.truth.push_back(truth);
        r.mean.push_back(m);
        bias2 += (m - truth) * (m - truth);
        if (truth > 0.02 && truth < 0.98) {
            hard += truth < 0.5 ? truth - m : m - truth;
            ++nHard;
        }
    }
    r.rmsBias = std::sqrt(bias2 / set.points);
    r.hardness = nHard > 0 ? hard / nHard : 0;
    r.variance = variance / set.points;
    r.varianceIndependent /= set.points;
    return r;
}

double breakEvenDensity(const PenumbraResponse& a, const PenumbraResponse& b) {
    const double dBias2 = a.rmsBias * a.rmsBias - b.rmsBias * b.rmsBias, dVar = b.variance - a.variance;
    if (dVar <= 0) return 0;
    if (dBias2 <= 0) return std::numeric_limits<double>::infinity();
    return dVar / dBias2;
}

}  // namespace wedge::analysis
