#include "scene/scene.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/error.h"
#include "scene/checker.h"

namespace wedge::scene {

namespace {

void embreeError(void*, RTCError code, const char* str) {
    // Embree reports API misuse and out-of-memory here; both are fatal for a render.
    std::fprintf(stderr, "wedge: Embree error %d: %s\n", int(code), str ? str : "");
}

RTCRayHit makeRayHit(const Vec3f& o, const Vec3f& d, float tNear, float tFar, float time) {
    RTCRayHit rh;
    rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
    rh.ray.tnear = tNear;
    rh.ray.tfar = tFar;
    rh.ray.time = time;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

}  // namespace

Scene::Scene(SceneDesc desc) : m_desc(std::move(desc)) {
    m_device = rtcNewDevice(nullptr);
    if (!m_device) throw Error("Embree: cannot create a device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(m_device, embreeError, nullptr);  // right after creation, as Embree's tutorials do
    m_scene = rtcNewScene(m_device);
    rtcSetSceneBuildQuality(m_scene, RTC_BUILD_QUALITY_HIGH);

    // Time step 0 at shutter open, 1 at close (rays carry the normalised shutter time); an
    // object moves by velocity x (close - open) in between (scene_desc.h).
    const float shutter = m_desc.camera.shutterLength();
    uint32_t object = 0;
    for (const TriangleMesh& mesh : m_desc.meshes) {
        const RigidMotion motion = mesh.motion(shutter);
        const bool moving = motion.moves();
        const Vec3f displacement = motion.displacement;
        float reach = 0;  // a turning mesh's farthest point from its pivot
        // A moving mesh moves rigidly (it translates, and may turn): it is its own scene, built once
        // at shutter open with the scene's quality, and instanced with a transform per time step. (As a triangle mesh
        // with two vertex time steps it took Embree's motion-blur BVH, at medium quality: the
        // moving Sponza of docs/sponza-pan.json traced at about half the rays per second of the
        // still one; docs/sampling-speed.md, "A moving mesh as a moving instance".)
        RTCGeometry geom = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
        {
            // Embree allocates the buffer with the padding its SIMD loads need.
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                  3 * sizeof(float), mesh.positions.size()));
            for (size_t i = 0; i < mesh.positions.size(); ++i) {
                const Vec3f p = mesh.positions[i];
                v[3 * i] = p.x; v[3 * i + 1] = p.y; v[3 * i + 2] = p.z;
                m_lo = vmin(m_lo, vmin(p, p + displacement));
                m_hi = vmax(m_hi, vmax(p, p + displacement));
                if (motion.turns()) reach = std::max(reach, length(p - motion.pivot));
            }
            if (motion.turns())  // every point stays within `reach` of the moving pivot
                for (const Vec3f& c : {motion.pivot, motion.pivot + displacement}) {
                    m_lo = vmin(m_lo, c - Vec3f(reach));
                    m_hi = vmax(m_hi, c + Vec3f(reach));
                }
        }
        auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(uint32_t), mesh.triangleCount()));
        std::memcpy(idx, mesh.indices.data(), mesh.indices.size() * sizeof(uint32_t));
        rtcCommitGeometry(geom);
        unsigned id;
        if (moving) {
            RTCScene own = rtcNewScene(m_device);
            rtcSetSceneBuildQuality(own, RTC_BUILD_QUALITY_HIGH);
            rtcAttachGeometry(own, geom);
            rtcCommitScene(own);
            m_moving.push_back(own);
            RTCGeometry instance = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(instance, own);
            if (!motion.turns()) {
                rtcSetGeometryTimeStepCount(instance, 2);
                for (unsigned step = 0; step < 2; ++step) {
                    const Vec3f d = displacement * float(step);
                    const float xfm[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, d.x, d.y, d.z};  // 3x4, column-major
                    rtcSetGeometryTransform(instance, step, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
                }
            } else {
                // A turn: quaternion decompositions, which Embree interpolates with a slerp of the
                // rotation (a matrix interpolated linearly would shrink the object between the
                // steps), p -> R (p - pivot) + pivot + d t. The slerp takes the shorter way, so the
                // steps are at most a quarter turn apart.
                const unsigned steps = 2 + unsigned(std::abs(motion.radians) / (0.5f * kPi));
                rtcSetGeometryTimeStepCount(instance, steps);
                for (unsigned step = 0; step < steps; ++step) {
                    const float t = float(step) / float(steps - 1), half = 0.5f * motion.radians * t;
                    const Vec3f q = motion.axis * std::sin(half), at = motion.pivot + displacement * t;
                    RTCQuaternionDecomposition xfm;
                    rtcInitQuaternionDecomposition(&xfm);
                    rtcQuaternionDecompositionSetShift(&xfm, -motion.pivot.x, -motion.pivot.y, -motion.pivot.z);
                    rtcQuaternionDecompositionSetQuaternion(&xfm, std::cos(half), q.x, q.y, q.z);
                    rtcQuaternionDecompositionSetTranslation(&xfm, at.x, at.y, at.z);
                    rtcSetGeometryTransformQuaternion(instance, step, &xfm);
                }
            }
            rtcCommitGeometry(instance);
            id = rtcAttachGeometry(m_scene, instance);
            rtcReleaseGeometry(instance);
        } else {
            id = rtcAttachGeometry(m_scene, geom);
        }
        rtcReleaseGeometry(geom);  // the scene holds the reference now
        if (m_geometry.size() <= id) m_geometry.resize(id + 1);
        m_geometry[id] = {mesh.materialIds.data(), mesh.shapeIds.data(), 0, object, false,
                          mesh.cornerNormals.size() == mesh.indices.size() ? mesh.cornerNormals.data() : nullptr,
                          motion,
                          mesh.cornerUVs.size() == mesh.indices.size() ? mesh.cornerUVs.data() : nullptr,
                          motion.moves(), motion.turns()};
        uint32_t shapes = 0;
        for (uint32_t sId : mesh.shapeIds) shapes = std::max(shapes, sId + 1);
        // Each shape's bounds at shutter open (objectHalfExtents).
        std::vector<Vec3f> lo(std::max(shapes, 1u), Vec3f(kInf)), hi(std::max(shapes, 1u), Vec3f(-kInf));
        for (size_t t = 0; t < mesh.triangleCount(); ++t) {
            const uint32_t k = mesh.shapeIds.empty() ? 0u : mesh.shapeIds[t];
            for (int c = 0; c < 3; ++c) {
                const Vec3f& p = mesh.positions[mesh.indices[3 * t + size_t(c)]];
                lo[k] = vmin(lo[k], p), hi[k] = vmax(hi[k], p);
            }
        }
        for (uint32_t k = 0; k < std::max(shapes, 1u); ++k)
            m_objectHalfExtents.push_back(lo[k].x <= hi[k].x ? (hi[k] - lo[k]) * 0.5f : Vec3f(0.f));
        object += std::max(shapes, 1u);
        m_objectMoves.resize(object, uint8_t(moving));
    }

    if (!m_desc.spheres.empty()) {
        bool moving = false;
        for (auto& s : m_desc.spheres) moving |= s.velocity != Vec3f(0.f);
        RTCGeometry geom = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        unsigned steps = moving ? 2 : 1;
        rtcSetGeometryTimeStepCount(geom, steps);
        for (unsigned s = 0; s < steps; ++s) {
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, s, RTC_FORMAT_FLOAT4,
                                                                  4 * sizeof(float), m_desc.spheres.size()));
            for (size_t i = 0; i < m_desc.spheres.size(); ++i) {
                const Sphere& sp = m_desc.spheres[i];
                Vec3f c = sp.center + sp.velocity * shutter * float(s);
                v[4 * i] = c.x; v[4 * i + 1] = c.y; v[4 * i + 2] = c.z; v[4 * i + 3] = sp.radius;
                m_lo = vmin(m_lo, c - Vec3f(sp.radius));
                m_hi = vmax(m_hi, c + Vec3f(sp.radius));
            }
        }
        rtcCommitGeometry(geom);
        unsigned id = rtcAttachGeometry(m_scene, geom);
        rtcReleaseGeometry(geom);
        for (auto& s : m_desc.spheres) m_sphereMaterials.push_back(s.material);
        if (moving)
            for (auto& s : m_desc.spheres) m_sphereMotion.push_back({s.velocity * shutter});
        if (m_geometry.size() <= id) m_geometry.resize(id + 1);
        GeometryInfo& g = m_geometry[id];
        g = GeometryInfo{};
        g.materialIds = m_sphereMaterials.data(), g.object = object, g.sphere = true, g.moves = moving;
        object += uint32_t(m_desc.spheres.size());
        for (auto& s : m_desc.spheres) m_objectMoves.push_back(s.velocity * shutter != Vec3f(0.f));
        for (auto& s : m_desc.spheres) m_objectHalfExtents.push_back(Vec3f(s.radius));
    }
    rtcCommitScene(m_scene);
    if (rtcGetDeviceError(m_device) != RTC_ERROR_NONE) throw Error("Embree: failed to build the scene");
    m_extent = std::max(1e-6f, length(m_hi - m_lo));
}

Scene::~Scene() {
    if (m_scene) rtcReleaseScene(m_scene);
    for (RTCScene own : m_moving) rtcReleaseScene(own);
    if (m_device) rtcReleaseDevice(m_device);
}

void Scene::fillHit(const Vec3f& org, const Vec3f& dir, float t, float time, unsigned geomID, unsigned primID,
                    const Vec3f& ng, float u, float v, Hit& hit) const {
    const GeometryInfo& g = m_geometry[geomID];
    hit.t = t;
    hit.position = org + dir * t;
    // Embree's Ng is the counter-clockwise normal for triangles and points outward for spheres
    // (tests/scene_test.cpp checks both), which is our front side.
    // The object that moves, if it does (null: still). A turning mesh's normals are its own at
    // shutter open (Embree gives an instance's Ng in the instanced scene's space), turned with it.
    const RigidMotion* motion = !g.moves ? nullptr : g.sphere ? &m_sphereMotion[primID] : &g.motion;
    hit.motion = motion && motion->moves() ? motion : nullptr;  // (a still sphere among moving ones)
    const bool turns = g.turns;
    hit.normal = normalize(turns ? hit.motion->turn(ng, time) : ng);
    hit.shadingNormal = hit.normal;
    if (g.cornerNormals) {
        // Embree's barycentrics: p = (1 - u - v) p0 + u p1 + v p2.
        const Vec3f* n = g.cornerNormals + 3 * size_t(primID);
        Vec3f s = n[0] * (1.f - u - v) + n[1] * u + n[2] * v;
        if (turns) s = hit.motion->turn(s, time);
        float len = length(s);
        if (len > 0) hit.shadingNormal = s / len;
    }
    hit.material = g.materialIds ? g.materialIds[primID] : g.material;
    // Spheres: one surface each; meshes: one per shape.
    hit.object = g.object + (g.sphere ? primID : (g.shapeIds ? g.shapeIds[primID] : 0));
    const Material& m = m_desc.materials[hit.material];
    if (m.map && g.cornerUVs) {
        const Vec2f* uv = g.cornerUVs + 3 * size_t(primID);
        const float w0 = 1.f - u - v;
        hit.albedo = m.albedo * m.map->lookup({w0 * uv[0].x + u * uv[1].x + v * uv[2].x, w0 * uv[0].y + u * uv[1].y + v * uv[2].y});
    } else if (m.texture.empty()) {
        hit.albedo = m.albedo;
    } else {
        // The texture is attached to the object: look it up where the point was at shutter open
        // (with the normal it had then, which picks the checker's plane).
        hit.albedo = hit.motion ? albedoAt(m, hit.motion->atOpen(hit.position, time), hit.motion->turn(hit.normal, -time))
                                : albedoAt(m, hit.position, hit.normal);
    }
}

bool Scene::intersect(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time, Hit& hit) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = makeRayHit(org, dir, tNear, tFar, time);
    rtcIntersect1(m_scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    fillHit(org, dir, rh.ray.tfar, time, hitGeometry(rh.hit.geomID, rh.hit.instID[0]), rh.hit.primID, Vec3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z), rh.hit.u,
            rh.hit.v, hit);
    return true;
}

void Scene::intersect(const RayPacket& rays, Hit hits[RayPacket::kSize], bool found[RayPacket::kSize]) const {
    // One pixel's camera rays: coherent, a 16-wide packet.
    alignas(64) RTCRayHit16 rh;
    for (int i = 0; i < RayPacket::kSize; ++i) {
        rh.ray.org_x[i] = rays.org[i].x;
        rh.ray.org_y[i] = rays.org[i].y;
        rh.ray.org_z[i] = rays.org[i].z;
        rh.ray.dir_x[i] = rays.dir[i].x;
        rh.ray.dir_y[i] = rays.dir[i].y;
        rh.ray.dir_z[i] = rays.dir[i].z;
        rh.ray.tnear[i] = 0.f;
        rh.ray.tfar[i] = rays.valid[i] ? rays.tFar[i] : -kInf;
        rh.ray.time[i] = rays.time[i];
        rh.ray.mask[i] = 0xffffffffu;
        rh.ray.id[i] = unsigned(i);
        rh.ray.flags[i] = 0;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect16(rays.valid, m_scene, &ctx, &rh);
    // A hit's per-primitive data (corner normals, material, uv) is a cache miss on a large
    // mesh: requested for all lanes first, so that the misses overlap.
    for (int i = 0; i < RayPacket::kSize; ++i)
        if (rays.valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID)
            prefetchHit(hitGeometry(rh.hit.geomID[i], rh.hit.instID[0][i]), rh.hit.primID[i]);
    for (int i = 0; i < RayPacket::kSize; ++i) {
        found[i] = rays.valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
        if (found[i])
            fillHit(rays.org[i], rays.dir[i], rh.ray.tfar[i], rays.time[i], hitGeometry(rh.hit.geomID[i], rh.hit.instID[0][i]), rh.hit.primID[i],
                    Vec3f(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]), rh.hit.u[i], rh.hit.v[i], hits[i]);
    }
}

namespace {

/// Scratch for the stream queries, one per thread (a stream is at most a few hundred rays).
std::vector<RTCRayHit>& streamScratch(size_t n) {
    thread_local std::vector<RTCRayHit> scratch;
    if (scratch.size() < n) scratch.resize(n);
    return scratch;
}

}  // namespace

void Scene::prefetchHit(unsigned geomID, unsigned primID) const {
    const GeometryInfo& g = m_geometry[geomID];
    if (g.cornerNormals) __builtin_prefetch(g.cornerNormals + 3 * size_t(primID));
    if (g.materialIds) __builtin_prefetch(g.materialIds + primID);
    if (g.cornerUVs) __builtin_prefetch(g.cornerUVs + 3 * size_t(primID));
}

void Scene::intersect(const RaySegment* rays, size_t n, Hit* hits, bool* found) const {
    if (n == 0) return;
    std::vector<RTCRayHit>& rh = streamScratch(n);
    for (size_t i = 0; i < n; ++i) rh[i] = makeRayHit(rays[i].org, rays[i].dir, 0.f, rays[i].tFar, rays[i].time);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);  // incoherent
    rtcIntersect1M(m_scene, &ctx, rh.data(), unsigned(n), sizeof(RTCRayHit));
    for (size_t i = 0; i < n; ++i)
        if (rh[i].hit.geomID != RTC_INVALID_GEOMETRY_ID) prefetchHit(hitGeometry(rh[i].hit.geomID, rh[i].hit.instID[0]), rh[i].hit.primID);
    for (size_t i = 0; i < n; ++i) {
        found[i] = rh[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
        if (found[i])
            fillHit(rays[i].org, rays[i].dir, rh[i].ray.tfar, rays[i].time, hitGeometry(rh[i].hit.geomID, rh[i].hit.instID[0]), rh[i].hit.primID,
                    Vec3f(rh[i].hit.Ng_x, rh[i].hit.Ng_y, rh[i].hit.Ng_z), rh[i].hit.u, rh[i].hit.v, hits[i]);
    }
}

void Scene::occluded(const RaySegment* rays, size_t n, bool* occluded) const {
    if (n == 0) return;
    std::vector<RTCRayHit>& rh = streamScratch(n);
    for (size_t i = 0; i < n; ++i) rh[i].ray = makeRayHit(rays[i].org, rays[i].dir, 0.f, rays[i].tFar, rays[i].time).ray;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);  // incoherent
    rtcOccluded1M(m_scene, &ctx, &rh[0].ray, unsigned(n), sizeof(RTCRayHit));
    for (size_t i = 0; i < n; ++i) occluded[i] = rh[i].ray.tfar < 0;
}

void Scene::nearestOccluders(const RaySegment* rays, size_t n, float* t) const {
    if (n == 0) return;
    std::vector<RTCRayHit>& rh = streamScratch(n);
    for (size_t i = 0; i < n; ++i) rh[i] = makeRayHit(rays[i].org, rays[i].dir, 0.f, rays[i].tFar, rays[i].time);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcIntersect1M(m_scene, &ctx, rh.data(), unsigned(n), sizeof(RTCRayHit));
    for (size_t i = 0; i < n; ++i) t[i] = rh[i].hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh[i].ray.tfar : kInf;
}

bool Scene::occluded(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray = makeRayHit(org, dir, tNear, tFar, time).ray;
    rtcOccluded1(m_scene, &ctx, &ray);
    return ray.tfar < 0;  // Embree sets tfar to -inf on a hit
}

float Scene::nearestOccluder(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time) const {
    // A stream of one, so that both paths are the same code.
    const RaySegment ray{org + dir * tNear, dir, tFar - tNear, time};
    float t;
    nearestOccluders(&ray, 1, &t);
    return t + tNear;
}

}  // namespace wedge::scene
