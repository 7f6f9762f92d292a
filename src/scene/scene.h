// The built scene: the only owner of Embree. Turns a SceneDesc into Embree geometry (triangle
// meshes, sphere points, both with two time steps when they move) and answers the three ray
// queries the sampler needs: closest hit, occlusion, and the span of all occluders along a
// shadow segment (nearest and farthest hit, for the AAF/MAAF slopes).
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <vector>

#include "scene/scene_desc.h"

namespace wedge::scene {

struct Hit {
    float t = kInf;
    Vec3f position;
    Vec3f normal;  // unit geometric normal, front side = counter-clockwise winding / sphere outside
    uint32_t material = 0;
    uint32_t object = 0;  // surface id: one per mesh shape (OBJ group) or primitive, one per sphere
};

/// Nearest and farthest occluder distances along a segment (t measured from its origin).
struct OccluderSpan {
    bool occluded = false;
    float tNear = kInf, tFar = 0.f;
};

class Scene {
public:
    explicit Scene(SceneDesc desc);
    ~Scene();
    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;

    const SceneDesc& desc() const { return m_desc; }
    const Material& material(uint32_t id) const { return m_desc.materials[id]; }
    /// Diagonal of the scene bounds; ray offsets scale with it.
    float extent() const { return m_extent; }
    Vec3f boundsMin() const { return m_lo; }
    Vec3f boundsMax() const { return m_hi; }

    /// time in [0, 1] over the shutter.
    bool intersect(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time, Hit& hit) const;
    bool occluded(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time) const;
    OccluderSpan occluders(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time) const;

private:
    struct GeometryInfo {
        const uint32_t* materialIds = nullptr;  // per primitive, or null with a constant material
        const uint32_t* shapeIds = nullptr;     // per primitive: object = object + shapeIds[prim]
        uint32_t material = 0;
        uint32_t object = 0;
        bool sphere = false;
    };

    SceneDesc m_desc;
    RTCDevice m_device = nullptr;
    RTCScene m_scene = nullptr;
    std::vector<GeometryInfo> m_geometry;  // by Embree geometry id
    std::vector<uint32_t> m_sphereMaterials;
    Vec3f m_lo{kInf}, m_hi{-kInf};
    float m_extent = 1.f;
};

}  // namespace wedge::scene
