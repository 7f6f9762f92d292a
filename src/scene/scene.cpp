#include "scene/scene.h"

#include <cstdio>
#include <cstring>
#include <string>

#include "core/error.h"

namespace wedge::scene {

namespace {

void embreeError(void*, RTCError code, const char* str) {
    // Embree reports API misuse and out-of-memory here; both are fatal for a render.
    std::fprintf(stderr, "wedge: Embree error %d: %s\n", int(code), str ? str : "");
}

/// Intersection context that records every hit and rejects it, so traversal visits all of them.
struct SpanContext {
    RTCIntersectContext context;
    float tNear, tFar;
    bool any;
};

void spanFilter(const RTCFilterFunctionNArguments* args) {
    auto* ctx = reinterpret_cast<SpanContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        float t = RTCRayN_tfar(args->ray, args->N, i);  // the candidate hit distance
        ctx->tNear = std::min(ctx->tNear, t);
        ctx->tFar = std::max(ctx->tFar, t);
        ctx->any = true;
        args->valid[i] = 0;  // reject: keep traversing
    }
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
    rtcSetSceneFlags(m_scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(m_scene, RTC_BUILD_QUALITY_HIGH);

    uint32_t object = 0;
    for (const TriangleMesh& mesh : m_desc.meshes) {
        bool moving = mesh.velocity != Vec3f(0.f);
        RTCGeometry geom = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetGeometryBuildQuality(geom, moving ? RTC_BUILD_QUALITY_MEDIUM : RTC_BUILD_QUALITY_HIGH);
        unsigned steps = moving ? 2 : 1;
        rtcSetGeometryTimeStepCount(geom, steps);
        for (unsigned s = 0; s < steps; ++s) {
            // Embree allocates the buffer with the padding its SIMD loads need.
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, s, RTC_FORMAT_FLOAT3,
                                                                  3 * sizeof(float), mesh.positions.size()));
            Vec3f offset = mesh.velocity * float(s);
            for (size_t i = 0; i < mesh.positions.size(); ++i) {
                Vec3f p = mesh.positions[i] + offset;
                v[3 * i] = p.x; v[3 * i + 1] = p.y; v[3 * i + 2] = p.z;
                m_lo = vmin(m_lo, p);
                m_hi = vmax(m_hi, p);
            }
        }
        auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(uint32_t), mesh.triangleCount()));
        std::memcpy(idx, mesh.indices.data(), mesh.indices.size() * sizeof(uint32_t));
        rtcCommitGeometry(geom);
        unsigned id = rtcAttachGeometry(m_scene, geom);
        rtcReleaseGeometry(geom);  // the scene holds the reference now
        if (m_geometry.size() <= id) m_geometry.resize(id + 1);
        m_geometry[id] = {mesh.materialIds.data(), mesh.shapeIds.data(), 0, object, false};
        uint32_t shapes = 0;
        for (uint32_t sId : mesh.shapeIds) shapes = std::max(shapes, sId + 1);
        object += std::max(shapes, 1u);
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
                Vec3f c = sp.center + sp.velocity * float(s);
                v[4 * i] = c.x; v[4 * i + 1] = c.y; v[4 * i + 2] = c.z; v[4 * i + 3] = sp.radius;
                m_lo = vmin(m_lo, c - Vec3f(sp.radius));
                m_hi = vmax(m_hi, c + Vec3f(sp.radius));
            }
        }
        rtcCommitGeometry(geom);
        unsigned id = rtcAttachGeometry(m_scene, geom);
        rtcReleaseGeometry(geom);
        for (auto& s : m_desc.spheres) m_sphereMaterials.push_back(s.material);
        if (m_geometry.size() <= id) m_geometry.resize(id + 1);
        m_geometry[id] = {m_sphereMaterials.data(), nullptr, 0, object, true};
        object += uint32_t(m_desc.spheres.size());
    }
    rtcCommitScene(m_scene);
    if (rtcGetDeviceError(m_device) != RTC_ERROR_NONE) throw Error("Embree: failed to build the scene");
    m_extent = std::max(1e-6f, length(m_hi - m_lo));
}

Scene::~Scene() {
    if (m_scene) rtcReleaseScene(m_scene);
    if (m_device) rtcReleaseDevice(m_device);
}

bool Scene::intersect(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time, Hit& hit) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = makeRayHit(org, dir, tNear, tFar, time);
    rtcIntersect1(m_scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    const GeometryInfo& g = m_geometry[rh.hit.geomID];
    hit.t = rh.ray.tfar;
    hit.position = org + dir * rh.ray.tfar;
    Vec3f ng(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    // Embree's Ng is the counter-clockwise normal for triangles and points outward for spheres
    // (tests/scene_test.cpp checks both), which is our front side.
    hit.normal = normalize(ng);
    hit.material = g.materialIds ? g.materialIds[rh.hit.primID] : g.material;
    // Spheres: one surface each; meshes: one per shape.
    hit.object = g.object + (g.sphere ? rh.hit.primID : (g.shapeIds ? g.shapeIds[rh.hit.primID] : 0));
    return true;
}

bool Scene::occluded(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray = makeRayHit(org, dir, tNear, tFar, time).ray;
    rtcOccluded1(m_scene, &ctx, &ray);
    return ray.tfar < 0;  // Embree sets tfar to -inf on a hit
}

OccluderSpan Scene::occluders(const Vec3f& org, const Vec3f& dir, float tNear, float tFar, float time) const {
    SpanContext sc;
    rtcInitIntersectContext(&sc.context);
    sc.context.filter = spanFilter;
    sc.tNear = kInf;
    sc.tFar = 0;
    sc.any = false;
    RTCRayHit rh = makeRayHit(org, dir, tNear, tFar, time);
    rtcIntersect1(m_scene, &sc.context, &rh);
    return {sc.any, sc.tNear, sc.tFar};
}

}  // namespace wedge::scene
