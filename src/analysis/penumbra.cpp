#include "analysis/penumbra.h"

#include <algorithm>
#include <cmath>
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
}

PenumbraResponse penumbraResponse(int pairs, const PenumbraSetup& set) {
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
    const std::vector<filter::MaafComponent> comps = filter::maafComponents(pairs, w);

    // Kernel k(a, y) on a grid of offsets a (midpoints, symmetric about 0) and light positions y.
    double sxMin = std::numeric_limits<double>::infinity(), sxMax = 0, cxMax = 0;
    for (const auto& c : comps) {
        sxMin = std::min(sxMin, c.sx * set.spatialScale);
        sxMax = std::max(sxMax, c.sx * set.spatialScale);
        cxMax = std::max(cxMax, std::abs(c.cx));
    }
    const double reach = set.window > 0 ? set.window : 8.0 / sxMin;  // primal std of a component: 1 / (its sx)
    double h = std::min(1.0 / (8 * sxMax), s * L / 100);
    if (cxMax > 0) h = std::min(h, 2 * M_PI / (24 * cxMax));
    const int na = 2 * int(std::ceil(reach / h)), ny = 256;
    h = 2 * reach / na;
    std::vector<double> a(na), y(ny), k(size_t(na) * ny);
    for (int j = 0; j < na; ++j) a[j] = -reach + (j + 0.5) * h;
    for (int i = 0; i < ny; ++i) y[i] = -L + (i + 0.5) * (2 * L / ny);
    for (const auto& c : comps) {
        // The renderer's mu_p for a light 2L long seen along its length.
        const double mu = filter::componentWeight(c, set.weights, [&] { return filter::parallelogramSpectrum(c.cy, 2 * L, 0); });
        const double weight = (c.p == 0 ? 1.0 : 2.0) * mu, sx = c.sx * set.spatialScale;
        for (int j = 0; j < na; ++j) {
            const double g = weight * sx * std::exp(-0.5 * sx * sx * a[j] * a[j]);  // unit integral up to 1/sqrt(2 pi)
            for (int i = 0; i < ny; ++i) k[size_t(j) * ny + i] += g * std::cos(c.cx * a[j] - c.cy * y[i]);
        }
    }
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
        variance += (e2 * h / ny) / ((sumK * h / ny) * (sumK * h / ny));
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
    return r;
}

double breakEvenDensity(const PenumbraResponse& a, const PenumbraResponse& b) {
    const double dBias2 = a.rmsBias * a.rmsBias - b.rmsBias * b.rmsBias, dVar = b.variance - a.variance;
    if (dVar <= 0) return 0;
    if (dBias2 <= 0) return std::numeric_limits<double>::infinity();
    return dVar / dBias2;
}

}  // namespace wedge::analysis
