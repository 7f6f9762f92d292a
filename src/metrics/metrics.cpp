#include "metrics/metrics.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/buffers.h"
#include "core/error.h"

namespace wedge::metrics {

namespace {

void checkSameSize(const Image3f& test, const Image3f& reference) {
    if (!test.sameSize(reference))
        throw Error("compare", "image size mismatch: " + std::to_string(test.width()) + "x" +
                                   std::to_string(test.height()) + " against a " + std::to_string(reference.width()) +
                                   "x" + std::to_string(reference.height()) + " reference");
    if (test.empty()) throw Error("compare", "empty images");
}

/// Unit-sum 1D Gaussian of the SSIM window: 11 taps, sigma 1.5.
constexpr int kSsimRadius = 5;
constexpr double kSsimSigma = 1.5;

std::vector<double> ssimKernel() {
    std::vector<double> k(2 * kSsimRadius + 1);
    for (int i = -kSsimRadius; i <= kSsimRadius; ++i) k[i + kSsimRadius] = std::exp(-0.5 * i * i / (kSsimSigma * kSsimSigma));
    return k;
}

/// Separable Gaussian blur of a double plane; the window is cut at the border and renormalised
/// per pass, which renormalises the 2D window exactly (it stays a product of two 1D windows).
std::vector<double> blur(const std::vector<double>& in, int w, int h, const std::vector<double>& k) {
    std::vector<double> tmp(in.size()), out(in.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double s = 0, ws = 0;
            for (int i = -kSsimRadius; i <= kSsimRadius; ++i) {
                int xx = x + i;
                if (xx < 0 || xx >= w) continue;
                s += k[i + kSsimRadius] * in[size_t(y) * w + xx];
                ws += k[i + kSsimRadius];
            }
            tmp[size_t(y) * w + x] = s / ws;
        }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double s = 0, ws = 0;
            for (int i = -kSsimRadius; i <= kSsimRadius; ++i) {
                int yy = y + i;
                if (yy < 0 || yy >= h) continue;
                s += k[i + kSsimRadius] * tmp[size_t(yy) * w + x];
                ws += k[i + kSsimRadius];
            }
            out[size_t(y) * w + x] = s / ws;
        }
    return out;
}

Image1f channel(const Image3f& img, int c) {
    Image1f out(img.width(), img.height());
    for (size_t i = 0; i < img.size(); ++i) out[i] = img[i][c];
    return out;
}

}  // namespace

float toneMap(float v) {
    if (!(v > 0)) return 0.f;  // also maps NaN to black
    v = std::min(v, 1.f);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

Image3f toneMapped(const Image3f& linear) {
    Image3f out(linear.width(), linear.height());
    for (size_t i = 0; i < linear.size(); ++i)
        out[i] = {toneMap(linear[i].x), toneMap(linear[i].y), toneMap(linear[i].z)};
    return out;
}

double relMse(const Image3f& test, const Image3f& reference, float eps) {
    double sum = 0;
    for (size_t i = 0; i < test.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            double x = test[i][c], r = reference[i][c];
            sum += (x - r) * (x - r) / (r * r + eps);
        }
    return sum / (3.0 * double(test.size()));
}

Image3f combineHalves(const Image3f& halfA, int nA, const Image3f& halfB, int nB) {
    Image3f r(halfA.width(), halfA.height());
    const float wA = float(nA) / float(nA + nB), wB = float(nB) / float(nA + nB);
    for (size_t i = 0; i < r.size(); ++i) r[i] = halfA[i] * wA + halfB[i] * wB;
    return r;
}

double referenceNoise(const Image3f& halfA, int nA, const Image3f& halfB, int nB, float eps) {
    const Image3f r = combineHalves(halfA, nA, halfB, nB);
    const double n = double(nA + nB), k = double(nA) * double(nB) / (n * n);
    double sum = 0;
    for (size_t i = 0; i < r.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            double d = double(halfA[i][c]) - double(halfB[i][c]), v = r[i][c];
            sum += k * d * d / (v * v + eps);
        }
    return r.size() ? sum / (3.0 * double(r.size())) : 0.0;
}

const std::vector<std::string>& regionNames() {
    static const std::vector<std::string> names = {"background", "mixed", "edge", "penumbra", "defocused", "interior"};
    return names;
}

Image<uint8_t> regionClasses(const RegionPlanes& planes, int edgeRadius) {
    const Image1f& object = planes.object;
    const Image1f& coverage = planes.coverage;
    const int W = object.width(), H = object.height();
    if (!coverage.sameSize(object) || !planes.defocus.sameSize(object) || !planes.occluded.sameSize(object))
        throw Error("regions", "the object, coverage, defocus and occluded planes differ in size");
    Image<uint8_t> classes(W, H);
    auto mixed = [&](size_t i) { return object[i] >= 0 && coverage[i] < kFullCoverage; };
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const size_t i = size_t(y) * W + x;
            int k;
            if (object[i] < 0) k = 0;
            else if (mixed(i)) k = 1;
            else {
                bool near = false;
                for (int dy = -edgeRadius; dy <= edgeRadius && !near; ++dy)
                    for (int dx = -edgeRadius; dx <= edgeRadius && !near; ++dx) {
                        const int xx = x + dx, yy = y + dy;
                        if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
                        const size_t q = size_t(yy) * W + xx;
                        near = mixed(q) || object[q] != object[i];
                    }
                const float occ = planes.occluded[i];
                k = near ? 2 : (occ > 0.f && occ < 1.f) ? 3 : planes.defocus[i] > 1.f ? 4 : 5;
            }
            classes[i] = uint8_t(k);
        }
    return classes;
}

std::vector<RegionError> regionErrors(const Image3f& test, const Image3f& reference, const Image<uint8_t>& classes,
                                      float eps, const Image1f* variance, const Image1f* noise) {
    if (!classes.sameSize(test) || !test.sameSize(reference) || (variance && !variance->sameSize(test)) ||
        (noise && !noise->sameSize(test)))
        throw Error("regions", "the pixel classes, the images and the variance or noise maps differ in size");
    const Image1f e = relativeErrorMap(test, reference, eps);
    std::vector<RegionError> r;
    for (const auto& name : regionNames()) r.push_back({name});
    double total = 0;
    for (size_t i = 0; i < classes.size(); ++i) {
        RegionError& c = r[classes[i]];
        c.pixels += 1;
        c.share += e[i];
        if (variance) c.variance += (*variance)[i];
        if (noise) c.noise += (*noise)[i];
        total += e[i];
    }
    const double n = double(classes.size());
    for (auto& c : r) {
        c.relMse = c.pixels > 0 ? c.share / c.pixels : 0.0;
        c.variance = c.pixels > 0 ? c.variance / c.pixels : 0.0;
        c.noise = c.pixels > 0 ? c.noise / c.pixels : 0.0;
        c.share = total > 0 ? c.share / total : 0.0;
        c.pixels = n > 0 ? c.pixels / n : 0.0;
    }
    return r;
}

std::vector<RegionError> regionErrors(const Image3f& test, const Image3f& reference, const RegionPlanes& planes,
                                      int edgeRadius, float eps, const Image1f* variance, const Image1f* noise) {
    return regionErrors(test, reference, regionClasses(planes, edgeRadius), eps, variance, noise);
}

double smape(const Image3f& test, const Image3f& reference, float eps) {
    double sum = 0;
    for (size_t i = 0; i < test.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            double x = test[i][c], r = reference[i][c];
            sum += std::abs(x - r) / (std::abs(x) + std::abs(r) + eps);
        }
    return sum / (3.0 * double(test.size()));
}

double mseDisplay(const Image3f& a, const Image3f& b) {
    double sum = 0;
    for (size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) sum += double(a[i][c] - b[i][c]) * double(a[i][c] - b[i][c]);
    return sum / (3.0 * double(a.size()));
}

double psnr(const Image3f& test, const Image3f& reference) {
    double mse = mseDisplay(toneMapped(test), toneMapped(reference));
    if (mse <= 0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(1.0 / mse);  // peak value L = 1
}

Image1f ssimMap(const Image1f& xImg, const Image1f& yImg) {
    const int w = xImg.width(), h = xImg.height();
    const size_t n = xImg.size();
    constexpr double kL = 1.0, kC1 = (0.01 * kL) * (0.01 * kL), kC2 = (0.03 * kL) * (0.03 * kL);
    std::vector<double> x(n), y(n), xx(n), yy(n), xy(n);
    for (size_t i = 0; i < n; ++i) {
        x[i] = xImg[i];
        y[i] = yImg[i];
        xx[i] = x[i] * x[i];
        yy[i] = y[i] * y[i];
        xy[i] = x[i] * y[i];
    }
    const auto k = ssimKernel();
    auto mx = blur(x, w, h, k), my = blur(y, w, h, k), mxx = blur(xx, w, h, k), myy = blur(yy, w, h, k),
         mxy = blur(xy, w, h, k);
    Image1f out(w, h);
    for (size_t i = 0; i < n; ++i) {
        double vx = std::max(0.0, mxx[i] - mx[i] * mx[i]), vy = std::max(0.0, myy[i] - my[i] * my[i]);
        double cxy = mxy[i] - mx[i] * my[i];
        out[i] = float((2 * mx[i] * my[i] + kC1) * (2 * cxy + kC2) /
                       ((mx[i] * mx[i] + my[i] * my[i] + kC1) * (vx + vy + kC2)));
    }
    return out;
}

double ssim(const Image3f& test, const Image3f& reference) {
    Image3f a = toneMapped(test), b = toneMapped(reference);
    double sum = 0;
    for (int c = 0; c < 3; ++c) {
        Image1f m = ssimMap(channel(a, c), channel(b, c));
        for (size_t i = 0; i < m.size(); ++i) sum += m[i];
    }
    return sum / (3.0 * double(test.size()));
}

namespace {

/// Per pixel, the mean over the channels of term(a, b, r) / (r^2 + eps) for two renders a, b and
/// the reference r.
template <class Term>
Image1f relativeMap(const Image3f& a, const Image3f& b, const Image3f& reference, float eps, Term term) {
    checkSameSize(a, reference);
    checkSameSize(b, reference);
    Image1f out(a.width(), a.height());
    for (size_t i = 0; i < a.size(); ++i) {
        double s = 0;
        for (int c = 0; c < 3; ++c) {
            const double r = reference[i][c];
            s += term(double(a[i][c]), double(b[i][c]), r) / (r * r + eps);
        }
        out[i] = float(s / 3.0);
    }
    return out;
}

}  // namespace

Image1f relativeErrorMap(const Image3f& test, const Image3f& reference, float eps) {
    return relativeMap(test, test, reference, eps, [](double x, double, double r) { return (x - r) * (x - r); });
}

Image1f seedVarianceMap(const Image3f& a, const Image3f& b, const Image3f& reference, float eps) {
    return relativeMap(a, b, reference, eps, [](double x, double y, double) { return 0.5 * (x - y) * (x - y); });
}

Image1f seedBiasMap(const Image3f& a, const Image3f& b, const Image3f& reference, float eps) {
    return relativeMap(a, b, reference, eps, [](double x, double y, double r) { return (x - r) * (y - r); });
}

double mapMean(const Image1f& map) {
    double sum = 0;
    for (size_t i = 0; i < map.size(); ++i) sum += map[i];
    return map.size() ? sum / double(map.size()) : 0.0;
}

double seedVariance(const Image3f& a, const Image3f& b, const Image3f& reference, float eps) {
    return mapMean(seedVarianceMap(a, b, reference, eps));
}

Image1f log10Map(const Image1f& values, float lo) {
    Image1f out(values.width(), values.height());
    const float floor = std::pow(10.f, lo);
    for (size_t i = 0; i < values.size(); ++i)
        out[i] = std::isfinite(values[i]) ? std::log10(std::max(values[i], floor)) : values[i];
    return out;
}

void requireFinite(const Image3f& img, const std::string& name) {
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < img.size(); ++i)
        if (!isFinite(img[i]) && bad++ == 0) first = i;
    if (bad > 0)
        throw Error(name, std::to_string(bad) + " of " + std::to_string(img.size()) +
                              " pixels are not finite (NaN or infinite), the first at x = " +
                              std::to_string(first % size_t(img.width())) + ", y = " +
                              std::to_string(first / size_t(img.width())) + "; no metric is defined");
}

void checkComparable(const Image3f& test, const std::string& testName, const Image3f& reference,
                     const std::string& referenceName) {
    requireFinite(test, testName);
    requireFinite(reference, referenceName);
    if (!test.sameSize(reference))
        throw Error(testName, "image size mismatch: " + std::to_string(test.width()) + "x" +
                                  std::to_string(test.height()) + " against " + std::to_string(reference.width()) +
                                  "x" + std::to_string(reference.height()) + " in " + referenceName);
}

Metrics compare(const Image3f& test, const Image3f& reference) {
    checkSameSize(test, reference);
    return {relMse(test, reference), smape(test, reference), psnr(test, reference), ssim(test, reference)};
}

}  // namespace wedge::metrics
