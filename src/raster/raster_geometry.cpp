// Scene description -> rasterizable triangles: camera-space setup, exact conservative bounds over
// the shutter and lens, the canonical pose of Vaidyanathan et al. 2012 (eq. 4), sphere
// tessellation, near-plane clipping, and the blur-driven midpoint split (see raster_geometry.h).
#include "raster/raster_geometry.h"

namespace wedge::raster {

namespace {

/// Screen bounds of a triangle over shutter times [tauA, tauB] and the whole lens. For a fixed
/// lens point a vertex's image (X - A lu) / Z along x is a linear-fractional function of tau,
/// hence monotonic while Z > 0, and it is linear in the lens coordinate: the extremes lie at the
/// interval ends and at lu, lv = +-1, so the bounds below are exact per vertex.
Bounds2 boundsOver(const RasterTriangle& t, const RasterCamera& cam, float tauA, float tauB) {
    Bounds2 b;
    for (float tau : {tauA, tauB})
        for (int i = 0; i < 3; ++i) {
            Vec3f q = t.p[i] + t.motion * tau;
            Vec2f s = cam.project(q);
            float coc = std::abs(cam.circleOfConfusion(q.z));
            b.extend(s.x - coc, s.y - coc);
            b.extend(s.x + coc, s.y + coc);
        }
    return b;
}

/// Screen bounds over [tauA, tauB] and the lens of the part of a triangle in front of the near
/// plane, for a triangle that crosses it but does not move in depth: every surface point then keeps
/// its depth, so the part in front is the same set of points at all times and each point's image is
/// linear in tau and in the lens coordinate; the clipped polygons at the interval ends bound it.
Bounds2 clippedBoundsOver(const RasterTriangle& t, const RasterCamera& cam, float tauA, float tauB) {
    Bounds2 b;
    for (float tau : {tauA, tauB}) {
        Vec3f in[3] = {t.p[0] + t.motion * tau, t.p[1] + t.motion * tau, t.p[2] + t.motion * tau};
        for (int k = 0; k < 3; ++k) {
            const Vec3f& a = in[k];
            const Vec3f& c = in[(k + 1) % 3];
            auto extend = [&](const Vec3f& q) {
                Vec2f s = cam.project(q);
                float coc = std::abs(cam.circleOfConfusion(q.z));
                b.extend(s.x - coc, s.y - coc);
                b.extend(s.x + coc, s.y + coc);
            };
            if (a.z >= kNearDepth) extend(a);
            if ((a.z >= kNearDepth) != (c.z >= kNearDepth)) {
                Vec3f q = a + (c - a) * ((kNearDepth - a.z) / (c.z - a.z));
                q.z = kNearDepth;
                extend(q);
            }
        }
    }
    return b;
}

void tessellateSphere(const scene::Sphere& s, std::vector<Vec3f>& pos, std::vector<Vec3f>& nrm,
                      std::vector<uint32_t>& idx) {
    uint32_t base = uint32_t(pos.size());
    for (int r = 0; r <= kSphereRings; ++r) {
        float theta = kPi * float(r) / kSphereRings;
        for (int k = 0; k <= kSphereSegments; ++k) {
            float phi = 2.f * kPi * float(k) / kSphereSegments;
            Vec3f n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            pos.push_back(s.center + n * s.radius);
            nrm.push_back(n);
        }
    }
    auto vid = [&](int r, int k) { return base + uint32_t(r * (kSphereSegments + 1) + k); };
    for (int r = 0; r < kSphereRings; ++r)
        for (int k = 0; k < kSphereSegments; ++k) {
            // Outward winding; the degenerate triangles at the poles are culled later.
            idx.insert(idx.end(), {vid(r, k), vid(r, k + 1), vid(r + 1, k + 1)});
            idx.insert(idx.end(), {vid(r, k), vid(r + 1, k + 1), vid(r + 1, k)});
        }
}

/// A vertex as the splitter carries it: world position at shutter open, its camera-space image,
/// and the shading normal.
struct SplitVertex {
    Vec3f world, camera, normal;
    Vec3f parentBary;  // barycentrics in the scene's (unsplit) triangle
};

SplitVertex midpoint(const SplitVertex& a, const SplitVertex& b, bool smooth) {
    // Camera-space midpoints of the parent's camera-space vertices: a T-vertex lies on its
    // neighbour's edge up to one rounding, so splitting opens no visible cracks.
    SplitVertex m{(a.world + b.world) * 0.5f, (a.camera + b.camera) * 0.5f, a.normal, (a.parentBary + b.parentBary) * 0.5f};
    if (smooth) m.normal = normalize(a.normal + b.normal);
    return m;
}

}  // namespace

RasterScene::RasterScene(const scene::SceneDesc& desc, const SplitPolicy& policy)
    : camera(desc.camera), materials(desc.materials), irradiance(desc.lights) {
    Bounds2 screen{0.f, 0.f, float(camera.width()), float(camera.height())};
    auto offScreen = [&](const Bounds2& b) {
        return b.empty() || b.x1 < screen.x0 || b.y1 < screen.y0 || b.x0 > screen.x1 || b.y0 > screen.y1;
    };
    auto blurred = [&](const RasterTriangle& t) {
        if (policy.minCoc <= 0 && policy.minSpeed <= 0) return true;
        for (int i = 0; i < 3; ++i) {
            Vec3f q1 = t.p[i] + t.motion;
            Vec2f s0 = camera.project(t.p[i]), s1 = camera.project(q1);
            if (std::hypot(s1.x - s0.x, s1.y - s0.y) > policy.minSpeed) return true;
            if (camera.apertureRadius() > 0 && std::max(std::abs(camera.circleOfConfusion(t.p[i].z)),
                                                        std::abs(camera.circleOfConfusion(q1.z))) > policy.minCoc)
                return true;
        }
        return false;
    };
    // Recursive midpoint split (4 children), so that the per-primitive bounds of AAS describe a
    // small patch and fewer samples need the near-plane fallback.
    auto add = [&](auto&& self, const SplitVertex* v, const Vec3f& faceNormal, const Vec3f& velocity, uint32_t material,
                   uint32_t mesh, bool smooth, int depth, uint32_t parent) -> void {
        RasterTriangle t;
        t.parent = parent;
        for (int i = 0; i < 3; ++i) t.parentBary[i] = v[i].parentBary;
        t.faceNormalWorld = faceNormal;
        for (int i = 0; i < 3; ++i) {
            t.pWorld[i] = v[i].world;
            t.nWorld[i] = v[i].normal;
            t.p[i] = v[i].camera;
        }
        t.motionWorld = velocity;
        t.motion = camera.directionToCamera(velocity);
        t.material = material;
        t.mesh = mesh;
        float zMin = kInf, zMax = -kInf;
        for (int i = 0; i < 3; ++i)
            for (float tau : {0.f, 1.f}) {
                float z = t.p[i].z + t.motion.z * tau;
                zMin = std::min(zMin, z);
                zMax = std::max(zMax, z);
            }
        if (zMax <= kNearDepth) {  // behind the camera for the whole shutter (depth is linear in tau)
            ++culledTriangles;
            return;
        }
        t.nearSafe = zMin > kNearDepth;
        bool split = false;
        if (t.nearSafe) {
            t.bounds = boundsOver(t, camera, 0.f, 1.f);
            if (offScreen(t.bounds)) {
                ++culledTriangles;
                return;
            }
            float maxEdge = 0;
            for (int i = 0; i < 3; ++i) {
                Vec3f q = t.p[i] + t.motion * 0.5f;
                t.sCanon[i] = camera.project(q);
                t.zCanon[i] = q.z;
            }
            for (int i = 0; i < 3; ++i) {
                Vec2f a = t.sCanon[i], b = t.sCanon[(i + 1) % 3];
                maxEdge = std::max(maxEdge, std::hypot(a.x - b.x, a.y - b.y));
            }
            split = policy.maxEdge > 0 && maxEdge > policy.maxEdge && depth < kMaxSplits && blurred(t);
        } else {
            split = depth < kMaxNearSplits;
            if (t.motion.z == 0.f) {  // the clipped part has exact bounds; else the whole screen
                t.bounds = clippedBoundsOver(t, camera, 0.f, 1.f);
                if (offScreen(t.bounds)) {
                    ++culledTriangles;
                    return;
                }
            }
        }
        if (depth == 0) {  // the scene's triangle itself, kept for shading that ignores the split
            t.parent = parent = uint32_t(parents.size());
            parents.push_back(t);
        }
        if (split && triangles.size() >= kMaxSplitTriangles) {
            split = false;
            splitBudgetReached = true;
        }
        if (split) {
            SplitVertex m01 = midpoint(v[0], v[1], smooth), m12 = midpoint(v[1], v[2], smooth),
                        m20 = midpoint(v[2], v[0], smooth);
            const SplitVertex children[4][3] = {{v[0], m01, m20}, {m01, v[1], m12}, {m20, m12, v[2]}, {m01, m12, m20}};
            for (const auto& c : children) self(self, c, faceNormal, velocity, material, mesh, smooth, depth + 1, parent);
            return;
        }
        if (t.nearSafe) {
            for (int k = 0; k < kTimeSlabs; ++k)
                t.slab[k] = boundsOver(t, camera, float(k) / kTimeSlabs, float(k + 1) / kTimeSlabs);
            for (int k = 0; k <= kTimeSlabs; ++k)
                for (int i = 0; i < 3; ++i) {
                    Vec3f q = t.p[i] + t.motion * (float(k) / kTimeSlabs);
                    Vec2f s = camera.project(q);
                    t.lensLine[k][i] = {s.x, s.y, camera.circleOfConfusion(q.z)};
                }
        } else if (t.motion.z == 0.f) {
            for (int k = 0; k < kTimeSlabs; ++k)
                t.slab[k] = clippedBoundsOver(t, camera, float(k) / kTimeSlabs, float(k + 1) / kTimeSlabs);
        } else {
            t.bounds = screen;
            for (auto& s : t.slab) s = screen;
        }
        triangles.push_back(t);
    };
    auto addRoot = [&](const Vec3f* pw, const Vec3f* nw, const Vec3f& velocity, uint32_t material, uint32_t mesh) {
        Vec3f faceNormal = cross(pw[1] - pw[0], pw[2] - pw[0]);
        if (!(length(faceNormal) > 0)) {
            ++culledTriangles;
            return;
        }
        faceNormal = normalize(faceNormal);
        SplitVertex v[3];
        for (int i = 0; i < 3; ++i) {
            v[i] = {pw[i], camera.toCamera(pw[i]), nw ? nw[i] : faceNormal, Vec3f(0.f)};
            v[i].parentBary[i] = 1.f;
        }
        add(add, v, faceNormal, velocity, material, mesh, nw != nullptr, 0, 0);
    };

    // Displacements over the whole shutter (scene_desc.h: velocity is per unit of shutter time).
    const float shutter = desc.camera.shutterLength();
    uint32_t meshIndex = 0;
    for (const auto& m : desc.meshes) {
        for (size_t f = 0; f < m.triangleCount(); ++f) {
            Vec3f pw[3] = {m.positions[m.indices[3 * f]], m.positions[m.indices[3 * f + 1]],
                           m.positions[m.indices[3 * f + 2]]};
            addRoot(pw, nullptr, m.velocity * shutter, m.materialIds[f], meshIndex);
        }
        ++meshIndex;
    }
    for (const auto& s : desc.spheres) {
        std::vector<Vec3f> pos, nrm;
        std::vector<uint32_t> idx;
        tessellateSphere(s, pos, nrm, idx);
        for (size_t f = 0; f < idx.size() / 3; ++f) {
            Vec3f pw[3] = {pos[idx[3 * f]], pos[idx[3 * f + 1]], pos[idx[3 * f + 2]]};
            Vec3f nw[3] = {nrm[idx[3 * f]], nrm[idx[3 * f + 1]], nrm[idx[3 * f + 2]]};
            addRoot(pw, nw, s.velocity * shutter, s.material, meshIndex);
        }
        ++meshIndex;
    }
}

}  // namespace wedge::raster
