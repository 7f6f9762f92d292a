// The band-limited checker texture: closed-form box and tent filters of the square wave and the
// anisotropic tap layout over a shading cell's footprint (see checker_texture.h; the footprint is
// the AAS shading cell of Vaidyanathan et al. 2012, Sec. 3.4, or one pixel for DS).
#include "raster/checker_texture.h"

namespace wedge::raster {

namespace {

/// Integral of sq from 0 to x: a triangle wave of period 2 rising on [0, 1], falling on [1, 2].
double squareWaveIntegral(double x) {
    double m = x - 2.0 * std::floor(0.5 * x);
    return 1.0 - std::abs(m - 1.0);
}

/// Integral of the triangle wave from 0 to x: u(m) on a period, plus 1 per whole period.
double squareWaveSecondIntegral(double x) {
    double n = std::floor(0.5 * x), m = x - 2.0 * n;
    return n + (m <= 1.0 ? 0.5 * m * m : 2.0 * m - 0.5 * m * m - 1.0);
}

}  // namespace

float boxFilteredSquareWave(float x, float halfWidth) {
    if (halfWidth < 1e-4f) return scene::checkerSquareWave(x);
    if (halfWidth > 1e4f) return 0.f;
    double x0 = double(x) - 2.0 * std::floor(0.5 * double(x)), w = halfWidth;  // sq has period 2
    return float((squareWaveIntegral(x0 + w) - squareWaveIntegral(x0 - w)) / (2.0 * w));
}

float tentFilteredSquareWave(float x, float halfWidth) {
    if (halfWidth < 1e-3f) return boxFilteredSquareWave(x, 0.5f * halfWidth);
    if (halfWidth > 1e4f) return 0.f;
    // The tent of half-width w is box(w) * box(w); its integral against sq is the second difference
    // of the second antiderivative, (U(x + w) - 2 U(x) + U(x - w)) / w^2. Shifting x by a period adds
    // the same constant to the three terms, so reduce it first to keep the difference exact.
    double x0 = double(x) - 2.0 * std::floor(0.5 * double(x)), w = halfWidth;
    return float((squareWaveSecondIntegral(x0 + w) - 2.0 * squareWaveSecondIntegral(x0) +
                  squareWaveSecondIntegral(x0 - w)) / (w * w));
}

float filteredChecker(Vec2f uv, Vec2f fa, Vec2f fb) {
    float la = std::hypot(fa.x, fa.y), lb = std::hypot(fb.x, fb.y);
    Vec2f major = la >= lb ? fa : fb, minor = la >= lb ? fb : fa;
    float lMajor = std::max(la, lb), lMinor = std::min(la, lb);
    // The filter is the tent box(footprint) * box(footprint) over the footprint parallelogram (what
    // bilinear reconstruction of a texture prefiltered at the footprint's scale gives). A nearly
    // isotropic footprint gets one separable tent over its bounding box; an elongated one gets up
    // to 16 taps along its major axis, weighted by the major-axis tent, each a separable tent over
    // the bounding box of its share of the parallelogram.
    if (lMajor <= 1.5f * lMinor || lMajor < 1e-6f) {
        float ex = std::abs(fa.x) + std::abs(fb.x), ey = std::abs(fa.y) + std::abs(fb.y);
        return 0.5f * (1.f + tentFilteredSquareWave(uv.x, ex) * tentFilteredSquareWave(uv.y, ey));
    }
    int taps = int(std::clamp(std::ceil(2.f * lMajor / std::max(lMinor, 1e-6f)), 2.f, float(kMaxTextureTaps)));
    float ex = std::abs(minor.x) + 2.f * std::abs(major.x) / taps;
    float ey = std::abs(minor.y) + 2.f * std::abs(major.y) / taps;
    float sum = 0, weights = 0;
    for (int i = 0; i < taps; ++i) {
        float o = -1.f + (2.f * float(i) + 1.f) / taps;
        float w = 1.f - std::abs(o);
        sum += w * tentFilteredSquareWave(uv.x + major.x * o, ex) * tentFilteredSquareWave(uv.y + major.y * o, ey);
        weights += w;
    }
    return 0.5f * (1.f + sum / weights);
}

Vec3f texturedAlbedo(const scene::Material& m, const Vec3f& pRest, const Vec3f& faceNormal, const Vec3f& footA,
                     const Vec3f& footB) {
    if (m.texture != "checker") return m.albedo;
    int iu, iv;
    scene::checkerAxes(faceNormal, iu, iv);
    float s = m.textureScale;
    float c = filteredChecker({pRest[iu] * s, pRest[iv] * s}, {footA[iu] * s, footA[iv] * s}, {footB[iu] * s, footB[iv] * s});
    return m.albedo * (scene::kCheckerDark + (1.f - scene::kCheckerDark) * c);
}

}  // namespace wedge::raster
