// Image error metrics for comparing a rendering against a reference, as the filtering papers
// report them (definitions in shared/papers/NOTES.md, "Error metrics"):
//   relMSE = mean over pixels and channels of (x - r)^2 / (r^2 + eps), eps = 0.01, on linear
//            radiance, WITHOUT the factor 0.5 some papers add;
//   SMAPE  = mean over pixels and channels of |x - r| / (|x| + |r| + eps), eps = 0.01, linear;
//   PSNR   = 10 log10(1 / MSE) on tone-mapped images in [0, 1] (infinite for identical images);
//   SSIM   = Wang et al. 2004 with an 11x11 Gaussian window (sigma 1.5), C1 = (0.01 L)^2,
//            C2 = (0.03 L)^2, L = 1, on tone-mapped images, averaged over pixels and channels.
// Tone mapping is the one PNG output uses: clamp to [0, 1], then the sRGB transfer curve. Near
// the border the SSIM window is cut to the image and renormalised, so every pixel (and images
// smaller than the window) gets a value.
#pragma once

#include <string>
#include <vector>

#include "core/image.h"

namespace wedge::metrics {

constexpr float kRelMseEpsilon = 0.01f;
constexpr float kSmapeEpsilon = 0.01f;

/// Linear radiance -> display value in [0, 1] (clamp, sRGB curve).
float toneMap(float linear);
Image3f toneMapped(const Image3f& linear);

/// All metrics require equal sizes (a programmer error otherwise: compare() validates input).
double relMse(const Image3f& test, const Image3f& reference, float eps = kRelMseEpsilon);
double smape(const Image3f& test, const Image3f& reference, float eps = kSmapeEpsilon);
/// Mean squared error of already tone-mapped images.
double mseDisplay(const Image3f& testDisplay, const Image3f& referenceDisplay);
/// PSNR in dB of the tone-mapped images; +infinity when they are identical.
double psnr(const Image3f& test, const Image3f& reference);
/// Mean SSIM of the tone-mapped images.
double ssim(const Image3f& test, const Image3f& reference);
/// SSIM of two single-channel images with values in [0, 1], per pixel.
Image1f ssimMap(const Image1f& x, const Image1f& y);

/// Per-pixel relative squared error (x - r)^2 / (r^2 + eps), averaged over the channels; its
/// mean is relMse().
Image1f relativeErrorMap(const Image3f& test, const Image3f& reference, float eps = kRelMseEpsilon);
/// Half the relative squared difference of two renders made alike but for independent seeds,
/// (a - b)^2 / (2 (r^2 + eps)) averaged over the channels, per pixel. E[(a - b)^2] = 2 Var a, so
/// its mean estimates the variance part of a's relMSE against r; the rest of that relMSE is the
/// squared bias plus the reference's own noise (referenceNoise):
///   E[relMSE(a, r)] = bias^2 + variance + reference noise   (all in relMSE units).
Image1f seedVarianceMap(const Image3f& a, const Image3f& b, const Image3f& reference, float eps = kRelMseEpsilon);
/// Per pixel, (a - r)(b - r) / (r^2 + eps) averaged over the channels, for the same two renders:
/// since their errors are independent, E[(a - r)(b - r)] = bias^2 + Var r, so this is the squared
/// bias where it sits (plus the reference's own noise), without the variance that (a - r)^2 holds.
/// Its mean estimates what relMSE - seedVariance does. Noisy per pixel (negative where the two
/// errors differ in sign); a heat map of it shows where a filter's bias is.
Image1f seedBiasMap(const Image3f& a, const Image3f& b, const Image3f& reference, float eps = kRelMseEpsilon);
/// The mean of a per-pixel map (an error or variance map's relMSE-style total).
double mapMean(const Image1f& map);
/// The mean of seedVarianceMap().
double seedVariance(const Image3f& a, const Image3f& b, const Image3f& reference, float eps = kRelMseEpsilon);
/// log10 of an error map, floored at 10^lo (for heat maps over [lo, hi] decades).
Image1f log10Map(const Image1f& values, float lo);

/// The reference's own share of a relMSE measured against it. A Monte Carlo reference r made of
/// two independent halves A (nA samples) and B (nB samples), r = (nA A + nB B) / (nA + nB), has
/// per-pixel variance Var r = E[(A - B)^2] nA nB / (nA + nB)^2; since a method's error is
/// independent of the reference's, E[relMSE(x, r)] = relMSE(x, truth) + mean(Var r / (r^2 + eps)).
/// Returns that mean, estimated from the halves' squared differences (to first order in the
/// reference's relative variance, which also enters the denominators).
double referenceNoise(const Image3f& halfA, int nA, const Image3f& halfB, int nB, float eps = kRelMseEpsilon);
/// The reference both halves make, (nA A + nB B) / (nA + nB).
Image3f combineHalves(const Image3f& halfA, int nA, const Image3f& halfB, int nB);

/// Where the error sits: relMSE split over pixel classes of the test render's own planes
/// (`wedge render -o x.exr` writes them): background (object < 0), mixed (coverage < 1: the
/// samples saw more than one surface, or a surface and the background), edge (within
/// `edgeRadius` pixels of a mixed pixel or of a pixel on another object), penumbra
/// (slope.occluded strictly between 0 and 1: some but not all of the initial samples' shadow rays
/// were blocked, the pixels where a shadow filter's width and components matter, defocused or
/// not), defocused (slope.defocus above one pixel per lens radius) and interior (the rest). Each
/// pixel falls in the first class that holds for it. With `variance` (seedVarianceMap of the test
/// render and one with another seed), each class also gets its variance part; with `noise` (the
/// reference's own noise per pixel: seedVarianceMap of the reference and a second reference made
/// alike with another seed), its reference-noise part.
struct RegionError {
    std::string name;
    double pixels = 0;    // fraction of the image's pixels
    double share = 0;     // fraction of the summed relative squared error
    double relMse = 0;    // mean over the class's pixels
    double variance = 0;  // mean of `variance` over the class's pixels (0 without it)
    double noise = 0;     // mean of `noise` over the class's pixels (0 without it)
};
struct RegionPlanes {
    const Image1f& object;
    const Image1f& coverage;
    const Image1f& defocus;   // slope.defocus
    const Image1f& occluded;  // slope.occluded
};
std::vector<RegionError> regionErrors(const Image3f& test, const Image3f& reference, const RegionPlanes& planes,
                                      int edgeRadius = 2, float eps = kRelMseEpsilon,
                                      const Image1f* variance = nullptr, const Image1f* noise = nullptr);
/// The class names in index order ("background", ..., "interior").
const std::vector<std::string>& regionNames();
/// Each pixel's class (an index into regionNames()), from a render's planes: the first half of
/// regionErrors(), so that a render's classes can be kept without its planes.
Image<uint8_t> regionClasses(const RegionPlanes& planes, int edgeRadius = 2);
/// The second half: the split over classes from regionClasses(). Throws Error on size mismatch.
std::vector<RegionError> regionErrors(const Image3f& test, const Image3f& reference, const Image<uint8_t>& classes,
                                      float eps = kRelMseEpsilon, const Image1f* variance = nullptr,
                                      const Image1f* noise = nullptr);

/// Every metric of an image with a NaN or infinite pixel is NaN or meaningless: throws
/// wedge::Error naming `name` (a file), the count and the first such pixel instead.
void requireFinite(const Image3f& img, const std::string& name);
/// The checks `wedge compare` (and the Python module's compare()) make before measuring: both
/// images finite, and of one size (else an Error naming both).
void checkComparable(const Image3f& test, const std::string& testName, const Image3f& reference,
                     const std::string& referenceName);

struct Metrics {
    double relMse = 0, smape = 0, psnr = 0, ssim = 0;
};
/// Every metric at once; throws wedge::Error when the sizes differ.
Metrics compare(const Image3f& test, const Image3f& reference);

}  // namespace wedge::metrics
