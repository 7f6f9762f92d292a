// Closed-form irradiance of area lights without occlusion (Lambert's polygon formula,
// with the polygon clipped to the receiver's upper hemisphere). The a-priori filters multiply
// their filtered visibility by it, as AAF does with r(x) in aaf-wang-2013-report.md eq. 3.2,
// so that the smooth 1/r^2 and cosine fall-off is exact rather than blurred.
#pragma once

#include <vector>

#include "scene/scene_desc.h"

namespace wedge::scene {

/// Irradiance at x (unit normal n) from every light, ignoring occluders. One-sided emission.
Vec3f unoccludedIrradiance(const std::vector<AreaLight>& lights, const Vec3f& x, const Vec3f& n);

}  // namespace wedge::scene
