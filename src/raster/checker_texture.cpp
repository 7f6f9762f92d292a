#include "raster/checker_texture.h"

namespace wedge::raster {

namespace {

/// Integral of sq from 0 to x: a triangle wave of period 2 rising on [0, 1], falling on [1, 2].
float squareWaveIntegral(float x) {
    float m = x - 2.f * std::floor(0.5f * x);
    return 1.f - std::abs(m - 1.f);
}

float squareWave(float x) { return (int64_t(std::floor(x)) & 1) ? -1.f : 1.f; }

}  // namespace

float boxFilteredSquareWave(float x, float halfWidth) {
    if (halfWidth < 1e-4f) return squareWave(x);
    if (halfWidth > 1e4f) return 0.f;
    return (squareWaveIntegral(x + halfWidth) - squareWaveIntegral(x - halfWidth)) / (2.f * halfWidth);
}

float filteredChecker(Vec2f uv, Vec2f fa, Vec2f fb) {
    float la = std::hypot(fa.x, fa.y), lb = std::hypot(fb.x, fb.y);
    Vec2f major = la >= lb ? fa : fb, minor = la >= lb ? fb : fa;
    float lMajor = std::max(la, lb), lMinor = std::min(la, lb);
    int taps = 1;
    if (lMajor > 1e-6f) taps = int(std::clamp(std::ceil(lMajor / std::max(lMinor, 1e-6f)), 1.f, float(kMaxTextureTaps)));
    // Each tap covers 1/taps of the major axis and the whole minor axis; its axis-aligned box is
    // the bounding box of that sub-parallelogram.
    float hx = 0.5f * (std::abs(minor.x) + std::abs(major.x) / taps);
    float hy = 0.5f * (std::abs(minor.y) + std::abs(major.y) / taps);
    float sum = 0;
    for (int i = 0; i < taps; ++i) {
        float o = (float(i) + 0.5f) / taps - 0.5f;
        float x = uv.x + major.x * o, y = uv.y + major.y * o;
        sum += boxFilteredSquareWave(x, hx) * boxFilteredSquareWave(y, hy);
    }
    return 0.5f * (1.f + sum / taps);
}

Vec3f texturedAlbedo(const scene::Material& m, const Vec3f& pRest, const Vec3f& faceNormal, const Vec3f& footA,
                     const Vec3f& footB) {
    if (m.texture != "checker") return m.albedo;
    Vec3f an(std::abs(faceNormal.x), std::abs(faceNormal.y), std::abs(faceNormal.z));
    int drop = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
    int iu = drop == 0 ? 1 : 0, iv = drop == 2 ? 1 : 2;
    float s = m.textureScale;
    float c = filteredChecker({pRest[iu] * s, pRest[iv] * s}, {footA[iu] * s, footA[iv] * s}, {footB[iu] * s, footB[iv] * s});
    return m.albedo * (kCheckerDark + (1.f - kCheckerDark) * c);
}

}  // namespace wedge::raster
