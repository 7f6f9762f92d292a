// The procedural "checker" texture of the scene format (scene/checker.h: its plane, scale and
// point values), band-limited over a footprint. The checker is 0.5 (1 + sq(u) sq(v)) with sq the
// +-1 square wave; a separable filter of it is the product of the filtered square waves, which
// have closed forms: a box needs sq's antiderivative (a triangle wave), a tent (box * box) its
// second antiderivative (piecewise quadratic). The filter is a tent as wide as twice the footprint
// (a box prefilter at the footprint's scale plus bilinear reconstruction, as texture hardware
// does); an anisotropic footprint (two vectors) is covered by up to 16 tent taps along its major
// axis, as a 16-tap anisotropic filter does (Vaidyanathan et al. 2012, Sec. 4 use one). AAS hands in its shading cell, so its textures
// are band-limited to its shading rate (Sec. 3.4: "input textures are automatically bandlimited").
#pragma once

#include "core/math.h"
#include "scene/checker.h"
#include "scene/scene_desc.h"

namespace wedge::raster {

constexpr int kMaxTextureTaps = 16;

/// sq averaged over [x - halfWidth, x + halfWidth] (the point value for halfWidth -> 0).
float boxFilteredSquareWave(float x, float halfWidth);
/// sq filtered with the tent of half-width `halfWidth` (weight 1 - |t| / halfWidth, normalised).
float tentFilteredSquareWave(float x, float halfWidth);

/// The checker (1 on light cells, 0 on dark ones) at uv, filtered over the footprint spanned by the
/// vectors fa and fb around uv (all in checker-cell units): a tent reaching one footprint out.
float filteredChecker(Vec2f uv, Vec2f fa, Vec2f fb);

/// The material's reflectance at rest-pose point pRest with world footprint vectors footA, footB.
Vec3f texturedAlbedo(const scene::Material& m, const Vec3f& pRest, const Vec3f& faceNormal, const Vec3f& footA,
                     const Vec3f& footB);

}  // namespace wedge::raster
