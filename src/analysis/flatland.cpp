// Flatland soft-shadow light field and its spectrum (Wu et al. 2017, Sec. 3, Fig. 4); see
// flatland.h for the geometry and the conventions.
#include "analysis/flatland.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>

#include "io/plot.h"
#include "core/error.h"

namespace wedge::analysis {

using io::besideEachOther;
using io::Canvas;
using io::displayColor;
using io::LinePlot;
using io::PlotSeries;
using io::rampColor;
using io::renderPlot;

namespace {

/// splitmix64: a small, well-mixed generator for the slat patterns.
struct SplitMix {
    uint64_t state;
    uint64_t next() {
        uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    }
    double uniform() { return (next() >> 11) * 0x1.0p-53; }
};

/// Shortest distance from (px, py) (in bins, centred) to the line Omega_y = s Omega_x or to one
/// of its aliases in the periodic DFT spectrum that passes within twice the Nyquist range.
double aliasDistance(double px, double py, double s, int n) {
    const double norm = std::sqrt(1 + s * s);
    double best = std::abs(py - s * px) / norm;
    for (int a = -1; a <= 1; ++a) {
        double qx = px + a * n;  // the continuous frequency this bin may alias from
        if (std::abs(qx) > n) continue;
        for (int b = -1; b <= 1; ++b) {
            double qy = py + b * n;
            if ((a == 0 && b == 0) || std::abs(qy) > n) continue;
            best = std::min(best, std::abs(qy - s * qx) / norm);
        }
    }
    return best;
}

/// Visits every bin outside the zero-frequency disk with its centred coordinates.
template <class Fn>
void forBins(const FlatlandSpectrum& spec, double dcRadius, Fn&& fn) {
    const int n = spec.n, h = n / 2;
    for (int ky = 0; ky < n; ++ky)
        for (int kx = 0; kx < n; ++kx) {
            double px = kx - h, py = ky - h;
            if (px * px + py * py <= dcRadius * dcRadius) continue;
            fn(px, py, spec.power[size_t(ky) * n + kx]);
        }
}

std::mutex g_fftwPlanMutex;  // FFTW's planner is not thread-safe

}  // namespace

void validateSetup(const FlatlandSetup& s) {
    auto positive = [](double v) { return std::isfinite(v) && v > 0; };
    if (!positive(s.lightSize)) throw Error("--light-size", "expected a positive size");
    if (!positive(s.receiverDistance)) throw Error("--receiver-distance", "expected a positive distance");
    if (s.occluderDistances.empty()) throw Error("--occluders", "expected at least one occluder distance");
    for (double d2 : s.occluderDistances)
        if (!(std::isfinite(d2) && d2 > 0 && d2 < s.receiverDistance))
            throw Error("--occluders", "each distance from the light must lie in (0, d1 = " +
                                           std::to_string(s.receiverDistance) + "), got " + std::to_string(d2));
    if (s.size < 16 || s.size > 4096 || s.size % 2 != 0)
        throw Error("--size", "expected an even number of samples per axis in 16..4096");
    if (s.extent != 0 && !positive(s.extent)) throw Error("--extent", "expected a positive half-size");
    if (s.feature != 0 && !positive(s.feature)) throw Error("--feature", "expected a positive width");
    if (s.supersample < 1 || s.supersample > 16) throw Error("--supersample", "expected 1..16");
    if (s.halfExtent() / s.featureSize() > 1e6) throw Error("--feature", "too small for the domain");
}

double occluderSlope(double d1, double d2) { return d1 / d2 - 1.0; }

SlatPattern::SlatPattern(double from, double to, double feature, uint64_t seed) {
    SplitMix rng{seed};
    // Widths uniform in [0.25, 1.75] x feature: broadband, no single period.
    double t = from - feature * 2 * rng.uniform();
    while (t < to) {
        double blocked = feature * (0.25 + 1.5 * rng.uniform());
        double open = feature * (0.25 + 1.5 * rng.uniform());
        m_edges.push_back(t);
        m_edges.push_back(t + blocked);
        t += blocked + open;
    }
}

double SlatPattern::transmittance(double t) const {
    // Number of edges <= t: odd inside a blocked interval.
    size_t k = std::upper_bound(m_edges.begin(), m_edges.end(), t) - m_edges.begin();
    return (k % 2 == 1) ? 0.0 : 1.0;
}

FlatlandField sampleFlatland(const FlatlandSetup& setup) {
    validateSetup(setup);
    const int n = setup.size, ss = setup.supersample;
    const double R = setup.halfExtent(), d1 = setup.receiverDistance;
    FlatlandField field;
    field.n = n;
    field.halfExtent = R;
    field.spacing = 2 * R / n;
    field.f.assign(size_t(n) * n, 0.0);

    std::vector<SlatPattern> patterns;
    for (size_t k = 0; k < setup.occluderDistances.size(); ++k) {
        field.slopes.push_back(occluderSlope(d1, setup.occluderDistances[k]));
        // Crossings y + (d2/d1)(x - y) are convex combinations of x and y: inside [-R, R].
        patterns.emplace_back(-R, R, setup.featureSize(), setup.seed * 0x100000001b3ULL + 0x9e37 * (k + 1));
    }
    for (int iy = 0; iy < n; ++iy)
        for (int ix = 0; ix < n; ++ix) {
            double sum = 0;
            for (int sy = 0; sy < ss; ++sy)
                for (int sx = 0; sx < ss; ++sx) {
                    double x = -R + (ix + (sx + 0.5) / ss) * field.spacing;
                    double y = -R + (iy + (sy + 0.5) / ss) * field.spacing;
                    double v = 1;
                    for (size_t k = 0; k < patterns.size() && v > 0; ++k) {
                        double r = setup.occluderDistances[k] / d1;
                        v *= patterns[k].transmittance(y + r * (x - y));  // ray light y -> receiver x
                    }
                    sum += v;
                }
            field.f[size_t(iy) * n + ix] = sum / (ss * ss);
        }
    return field;
}

FlatlandSpectrum flatlandSpectrum(const FlatlandField& field) {
    const int n = field.n;
    FlatlandSpectrum spec;
    spec.n = n;
    spec.binWidth = 2 * M_PI / (2 * field.halfExtent);
    spec.power.assign(size_t(n) * n, 0.0);

    std::vector<double> hann(n);
    for (int i = 0; i < n; ++i) hann[i] = 0.5 - 0.5 * std::cos(2 * M_PI * (i + 0.5) / n);

    double* in = fftw_alloc_real(size_t(n) * n);
    fftw_complex* out = fftw_alloc_complex(size_t(n) * (n / 2 + 1));
    if (!in || !out) throw std::bad_alloc();
    fftw_plan plan;
    {
        std::lock_guard<std::mutex> lock(g_fftwPlanMutex);
        plan = fftw_plan_dft_r2c_2d(n, n, in, out, FFTW_ESTIMATE);  // rows = y (slow), columns = x
    }
    for (int iy = 0; iy < n; ++iy)
        for (int ix = 0; ix < n; ++ix) {
            // (-1)^(ix+iy) moves the zero frequency to (n/2, n/2) (n even) or next to it.
            double sign = ((ix + iy) % 2 == 0) ? 1.0 : -1.0;
            in[size_t(iy) * n + ix] = sign * field.f[size_t(iy) * n + ix] * hann[ix] * hann[iy];
        }
    fftw_execute(plan);
    // r2c keeps kx in [0, n/2]; the rest follows from Hermitian symmetry F(-k) = conj F(k). With
    // the (-1)^(ix+iy) modulation, output index k holds the centred frequency k - n/2.
    const int half = n / 2 + 1;
    for (int ky = 0; ky < n; ++ky)
        for (int kx = 0; kx < half; ++kx) {
            const fftw_complex& c = out[size_t(ky) * half + kx];
            double p = c[0] * c[0] + c[1] * c[1];
            spec.power[size_t(ky) * n + kx] = p;
            int mx = (n - kx) % n, my = (n - ky) % n;  // k' = -k about frequency 0 before centring
            // Centred index of -(k - n/2) is n - k (mod n) for even n.
            spec.power[size_t(my) * n + mx] = p;
        }
    {
        std::lock_guard<std::mutex> lock(g_fftwPlanMutex);
        fftw_destroy_plan(plan);
    }
    fftw_free(in);
    fftw_free(out);
    return spec;
}

double energyNearSlope(const FlatlandSpectrum& spec, double s, double halfWidth, double dcRadius) {
    double near = 0, total = 0;
    forBins(spec, dcRadius, [&](double px, double py, double p) {
        total += p;
        if (aliasDistance(px, py, s, spec.n) <= halfWidth) near += p;
    });
    return total > 0 ? near / total : 0;
}

double energyInWedge(const FlatlandSpectrum& spec, double sLo, double sHi, double halfWidth, double dcRadius) {
    double in = 0, total = 0;
    forBins(spec, dcRadius, [&](double px, double py, double p) {
        total += p;
        double qx = px, qy = py;
        if (qy < 0 || (qy == 0 && qx < 0)) { qx = -qx; qy = -qy; }
        // Inside the sector between the lines, or within halfWidth of either line.
        bool inside = qx > 0 && qy >= sLo * qx && qy <= sHi * qx;
        if (inside || aliasDistance(px, py, sLo, spec.n) <= halfWidth || aliasDistance(px, py, sHi, spec.n) <= halfWidth)
            in += p;
    });
    return total > 0 ? in / total : 0;
}

std::vector<double> energyPerAngle(const FlatlandSpectrum& spec, int bins, double dcRadius) {
    std::vector<double> e(std::max(bins, 1), 0.0);
    double total = 0;
    forBins(spec, dcRadius, [&](double px, double py, double p) {
        double theta = std::atan2(py, px);  // fold (Omega_x, Omega_y) ~ (-Omega_x, -Omega_y)
        if (theta <= -M_PI / 2) theta += M_PI;
        if (theta > M_PI / 2) theta -= M_PI;
        int b = std::clamp(int((theta + M_PI / 2) / M_PI * bins), 0, bins - 1);
        e[b] += p;
        total += p;
    });
    if (total > 0)
        for (double& v : e) v /= total;
    return e;
}

Image3f flatlandFigure(const FlatlandField& field, const FlatlandSpectrum& spec, double lightSize) {
    const int n = field.n;
    const Vec3f black(0.f), white(1.f);
    const Vec3f lineColors[4] = {displayColor(1.f, 0.25f, 0.2f), displayColor(0.2f, 0.9f, 1.f),
                                 displayColor(1.f, 0.6f, 0.f), displayColor(1.f, 0.3f, 1.f)};
    const int pad = 24;  // room for the captions above each panel

    // Occlusion image: x to the right, y up (row 0 at the top is y = +R).
    Canvas occ(n, n + pad, white);
    for (int iy = 0; iy < n; ++iy)
        for (int ix = 0; ix < n; ++ix) {
            float v = float(field.f[size_t(iy) * n + ix]);
            occ.setPixel(ix, pad + (n - 1 - iy), Vec3f(0.03f + 0.9f * v));
        }
    const Vec3f amber = displayColor(1.f, 0.75f, 0.1f);
    for (double yl : {-lightSize, lightSize}) {
        double row = pad + (n - 1) - ((yl + field.halfExtent) / field.spacing - 0.5);
        if (row >= pad && row < pad + n) occ.line(0, row, n - 1, row, amber, 1, 6);
    }
    occ.text(4, 6, "F(X,Y): X RIGHT, Y UP; LIGHT |Y|<=L DASHED", black);

    // Spectrum: log10 power over a 7-decade range below its maximum (zero frequency excluded).
    double maxP = 0;
    for (int ky = 0; ky < n; ++ky)
        for (int kx = 0; kx < n; ++kx)
            if (kx != n / 2 || ky != n / 2) maxP = std::max(maxP, spec.power[size_t(ky) * n + kx]);
    const double hiL = std::log10(std::max(maxP, 1e-300)), loL = hiL - 7;
    Canvas sp(n, n + pad, white);
    for (int ky = 0; ky < n; ++ky)
        for (int kx = 0; kx < n; ++kx) {
            double l = std::log10(std::max(spec.power[size_t(ky) * n + kx], 1e-300));
            sp.setPixel(kx, pad + (n - 1 - ky), rampColor(float((l - loL) / (hiL - loL))));
        }
    // Predicted lines Omega_y = s Omega_x through the centre (kx, ky) = (n/2, n/2).
    const double cx = n / 2, cyRow = pad + (n - 1) - n / 2;
    for (size_t k = 0; k < field.slopes.size(); ++k) {
        double s = field.slopes[k];
        double ex = n / 2.0, ey = s * ex;
        if (std::abs(ey) > n / 2.0) { ey = std::copysign(n / 2.0, ey); ex = ey / s; }
        sp.line(cx - ex, cyRow + ey, cx + ex, cyRow - ey, lineColors[k % 4], 1, 5);
        char label[48];
        std::snprintf(label, sizeof label, "S=%.2f", s);
        int lx = int(std::clamp(cx + ex * 0.8, 0.0, n - 50.0)), ly = int(std::clamp(cyRow - ey * 0.8 - 10, double(pad), pad + n - 10.0));
        sp.text(lx, ly, label, lineColors[k % 4]);
    }
    // The light's band limit |Omega_y| <= 4/L (eq. 1 integrates f against I(y)).
    const double bandBins = (4.0 / lightSize) / spec.binWidth;
    if (bandBins >= 8 && bandBins < n / 2)
        for (double sgn : {1.0, -1.0}) sp.line(0, cyRow - sgn * bandBins, n - 1, cyRow - sgn * bandBins, white, 1, 3);
    sp.text(4, 6, "LOG10 |F|^2: OMEGA_X RIGHT, OMEGA_Y UP", black);

    return besideEachOther({occ.image(), sp.image()});
}

}  // namespace wedge::analysis
