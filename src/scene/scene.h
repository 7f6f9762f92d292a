// The built scene: the only owner of Embree. Turns a SceneDesc into Embree geometry (triangle
// meshes, sphere points, both with two time steps when they move) and answers the three ray
// queries the sampler needs: closest hit, occlusion, and the nearest occluder's distance along
// a shadow segment (for the AAF/MAAF slopes).
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
    Vec3f shadingNormal;  // unit interpolated corner normal (meshes that have them), else the geometric one
    uint32_t material = 0;
    uint32_t object = 0;  // surface id: one per mesh shape (OBJ group) or primitive, one per sphere
    Vec3f albedo;         // the material's, textured at the hit (scene/checker.h)
    const RigidMotion* motion = nullptr;  // how the hit object moves over the shutter, or null: it is still
};

/// Up to 16 rays as structure of arrays, for Embree's 16-wide packet queries. Lanes with
/// valid[i] = 0 are ignored.
struct RayPacket {
    static constexpr int kSize = 16;
    alignas(64) int valid[kSize] = {};
    Vec3f org[kSize], dir[kSize];
    float tFar[kSize] = {}, time[kSize] = {};
    void set(int lane, const Vec3f& o, const Vec3f& d, float tMax, float t) {
        valid[lane] = -1;
        org[lane] = o;
        dir[lane] = d;
        tFar[lane] = tMax;
        time[lane] = t;
    }
    bool any() const {
        for (int v : valid)
            if (v) return true;
        return false;
    }
};

/// A ray from its origin to tFar along a unit direction, at a shutter time: one element of a
/// ray stream (Scene's stream queries).
struct RaySegment {
    Vec3f org, dir;
    float tFar = 0, time = 0;
};

/// The rays of a render as Embree was asked to trace them, by kind: what the throughput
/// benchmark (bench/embree_ceiling.cpp) traces again with Embree alone, to measure how fast the
/// sampling stage could be. Filled by PathSampler::logRays (one thread).
struct RayLog {
    enum Kind { kPrimary, kShadow, kBounce, kBounceShadow, kKinds };
    std::vector<RaySegment> rays[kKinds];
    void add(Kind kind, const RayPacket& p) {
        for (int i = 0; i < RayPacket::kSize; ++i)
            if (p.valid[i]) rays[kind].push_back({p.org[i], p.dir[i], p.tFar[i], p.time[i]});
    }
    void add(Kind kind, const RaySegment* r, size_t n) { rays[kind].insert(rays[kind].end(), r, r + n); }
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
    /// By object id (Hit::object, FrameBuffers::object): 1 where that object moves or turns over
    /// the shutter (the camera's motion aside).
    const std::vector<uint8_t>& objectMoves() const { return m_objectMoves; }
    /// By object id: half its world bounding box's extent along each axis, at shutter open (a
    /// sphere's own radius on each).
    const std::vector<Vec3f>& objectHalfExtents() const { return m_objectHalfExtents; }

    /// time in [0, 1] over the shutter.
    bool intersect(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time, Hit& hit) const;
    bool occluded(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time) const;
    /// Distance from org to the nearest occluder within [tNear, tFar], or kInf where none.
    float nearestOccluder(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time) const;

    /// Closest hits of one pixel's camera rays (tNear = 0), coherent: one 16-wide packet.
    void intersect(const RayPacket& rays, Hit hits[RayPacket::kSize], bool found[RayPacket::kSize]) const;
    /// The queries over a stream of n rays (tNear = 0; Embree's rtcOccluded1M / rtcIntersect1M),
    /// each ray's answer what it gets alone. On Sponza's shadow rays a stream of 256 (16 pixels'
    /// samples) is 1.2-1.4x as fast as one pixel's 16-wide packet (bench/embree_ceiling.cpp,
    /// docs/sampling-speed.md).
    void occluded(const RaySegment* rays, size_t n, bool* occluded) const;
    /// Closest hits of a stream (found[i] false where none).
    void intersect(const RaySegment* rays, size_t n, Hit* hits, bool* found) const;
    /// The nearest occluder's distance along each segment of a stream (kInf where none): one
    /// closest-hit query, without a hit record.
    void nearestOccluders(const RaySegment* rays, size_t n, float* t) const;
    /// The Embree scene itself (benchmarks trace against it directly).
    RTCScene embree() const { return m_scene; }

private:
    /// The m_geometry entry of a hit: its instance's where it hit a moving mesh.
    static unsigned hitGeometry(unsigned geomID, unsigned instID) { return instID != RTC_INVALID_GEOMETRY_ID ? instID : geomID; }
    /// Asks the memory for what fillHit will read of a primitive.
    void prefetchHit(unsigned geomID, unsigned primID) const;
    /// `time`: the ray's, normalised over the shutter (0 at open, 1 at close).
    void fillHit(const Vec3f& org, const Vec3f& dir, float t, float time, unsigned geomID, unsigned primID,
                 const Vec3f& ng, float u, float v, Hit& hit) const;

    struct GeometryInfo {
        const uint32_t* materialIds = nullptr;  // per primitive, or null with a constant material
        const uint32_t* shapeIds = nullptr;     // per primitive: object = object + shapeIds[prim]
        uint32_t material = 0;
        uint32_t object = 0;
        bool sphere = false;
        const Vec3f* cornerNormals = nullptr;  // 3 per primitive, or null: flat shading
        RigidMotion motion;  // meshes: over the whole shutter (spheres: their own, m_sphereMotion)
        const Vec2f* cornerUVs = nullptr;  // 3 per primitive, or null
        bool moves = false, turns = false;  // (motion.moves(), turns(); spheres: whether any moves, m_sphereMotion)
    };

    SceneDesc m_desc;
    RTCDevice m_device = nullptr;
    RTCScene m_scene = nullptr;
    std::vector<GeometryInfo> m_geometry;  // by Embree geometry id in m_scene (a moving mesh: its instance's)
    std::vector<RTCScene> m_moving;        // each moving mesh's own scene, instanced in m_scene
    std::vector<uint32_t> m_sphereMaterials;
    std::vector<RigidMotion> m_sphereMotion;  // by primitive, where a sphere moves (else empty)
    std::vector<uint8_t> m_objectMoves;       // objectMoves()
    std::vector<Vec3f> m_objectHalfExtents;   // objectHalfExtents()
    Vec3f m_lo{kInf}, m_hi{-kInf};
    float m_extent = 1.f;
};

}  // namespace wedge::scene
