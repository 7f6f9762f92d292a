// Closed-form irradiance of area lights without occlusion (Lambert's polygon formula,
// with the polygon clipped to the receiver's upper hemisphere). The a-priori filters multiply
// their filtered visibility by it, as AAF does with r(x) in aaf-wang-2013-report.md eq. 3.2,
// so that the smooth 1/r^2 and cosine fall-off is exact rather than blurred.
#pragma once

#include <vector>

#include "scene/scene_desc.h"

namespace wedge::scene {

/// Irradiance at x (unit normal n) from every light, ignoring occluders. One-sided emission.
/// Light by light; LightIrradiance gives the same faster where lights form groups.
Vec3f unoccludedIrradiance(const std::vector<AreaLight>& lights, const Vec3f& x, const Vec3f& n);

/// unoccludedIrradiance for many receivers. Lambert's sum runs over the lights' edges, and an
/// edge two lights of a group (scene::lightGroups: coplanar, facing alike, one radiance) share
/// is walked once each way and cancels: a group that lies wholly above a receiver's horizon is
/// summed over its outline alone (a fan of n triangles: n edges instead of 3n). A group the
/// horizon cuts is clipped light by light, as unoccludedIrradiance does.
class LightIrradiance {
public:
    explicit LightIrradiance(const std::vector<AreaLight>& lights) : LightIrradiance(lights, lightGroups(lights)) {}
    /// With the lights' groups already found (lightGroups(lights)).
    LightIrradiance(const std::vector<AreaLight>& lights, const std::vector<uint32_t>& groups);
    Vec3f operator()(const Vec3f& x, const Vec3f& n) const;

private:
    struct Group {
        Vec3f point, normal, radiance;          // a corner of its first light, its plane (0: a sphere), its radiance
        std::vector<Vec3f> from, to;            // the outline: edges no other light of the group walks back
        std::vector<AreaLight> lights;
    };
    std::vector<Group> m_groups;
};

}  // namespace wedge::scene
