// The surface shader of the rasterizer: diffuse reflection of the scene's area lights,
// unshadowed (the pipeline has no visibility queries between surfaces and lights; shadows are out
// of scope for what it measures, shading cost and cache size), times the textured albedo, plus
// the material's emission. The irradiance of a uniform polygonal emitter is exact: Lambert's
// formula E = (L / 2) sum_k theta_k (n . gamma_k) over the polygon's edges after clipping it to the
// receiver's hemisphere. The shader is a pure function of (triangle, surface point, footprint),
// so a memoized result equals a recomputed one.
#pragma once

#include "raster/raster_geometry.h"

namespace wedge::raster {

/// Outgoing radiance towards the camera of the point with surface barycentrics `bary` at
/// normalised shutter time `tau`, textures filtered over the world footprint (footA, footB).
Vec3f shadeSurface(const RasterScene& scene, const RasterTriangle& tri, const Vec3f& bary, float tau,
                   const Vec3f& footA, const Vec3f& footB);

}  // namespace wedge::raster
