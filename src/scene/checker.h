// The "checker" texture of the scene format, as a point function. Meshes carry no texture
// coordinates, so a surface's rest-pose point (where the scene puts it at shutter open, so that
// the texture moves with the object) is projected onto the coordinate plane most facing its
// normal and scaled by texture_scale: one checker cell per 1/texture_scale world units. Light
// cells reflect the material's albedo, dark ones kCheckerDark of it. The ray tracer samples it at
// each hit (its samples are the filter); the rasterizer band-limits it over a shading footprint
// (raster/checker_texture.h).
#pragma once

#include <cmath>
#include <cstdint>

#include "core/math.h"
#include "scene/scene_desc.h"

namespace wedge::scene {

/// Reflectance of the dark checker cells relative to the material's albedo.
constexpr float kCheckerDark = 0.2f;

/// The world axes (iu, iv) of the coordinate plane most facing normal `n`.
inline void checkerAxes(const Vec3f& n, int& iu, int& iv) {
    const float ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
    const int drop = ax >= ay && ax >= az ? 0 : (ay >= az ? 1 : 2);
    iu = drop == 0 ? 1 : 0;
    iv = drop == 2 ? 1 : 2;
}

/// The checker's square wave: +1 on [2k, 2k + 1), -1 on [2k + 1, 2k + 2).
inline float checkerSquareWave(float x) { return (int64_t(std::floor(x)) & 1) ? -1.f : 1.f; }

/// The material's reflectance at rest-pose point `pRest` of a surface with normal `n`.
inline Vec3f albedoAt(const Material& m, const Vec3f& pRest, const Vec3f& n) {
    if (m.texture != "checker") return m.albedo;
    int iu, iv;
    checkerAxes(n, iu, iv);
    const float s = m.textureScale;
    const bool light = checkerSquareWave(pRest[iu] * s) * checkerSquareWave(pRest[iv] * s) > 0;
    return light ? m.albedo : m.albedo * kCheckerDark;
}

}  // namespace wedge::scene
