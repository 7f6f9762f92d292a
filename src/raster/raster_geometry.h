// The scene as the stochastic rasterizer sees it: triangles in camera space at shutter open with
// one displacement over the shutter each (time-continuous triangles, linear motion), their
// conservative screen bounds over the whole shutter and lens and over time slabs, and their
// canonical pose (lens centre, shutter centre) that decoupled sampling (Ragan-Kelley et al. 2011)
// and AAS (Vaidyanathan et al. 2012, eq. 4) shade in. Spheres are tessellated into triangles with
// smooth vertex normals.
#pragma once

#include <cstdint>
#include <vector>

#include "raster/raster_camera.h"
#include "scene/light_irradiance.h"
#include "scene/scene_desc.h"

namespace wedge::raster {

/// An axis-aligned screen rectangle in pixels; empty when x0 > x1.
struct Bounds2 {
    float x0 = kInf, y0 = kInf, x1 = -kInf, y1 = -kInf;

    void extend(float x, float y) {
        x0 = std::min(x0, x);
        y0 = std::min(y0, y);
        x1 = std::max(x1, x);
        y1 = std::max(y1, y);
    }
    void extend(const Bounds2& b) {
        x0 = std::min(x0, b.x0);
        y0 = std::min(y0, b.y0);
        x1 = std::max(x1, b.x1);
        y1 = std::max(y1, b.y1);
    }
    bool empty() const { return !(x0 <= x1 && y0 <= y1); }
    bool contains(float x, float y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
};

/// Depth (world units along forward) in front of which geometry must stay for the analytic
/// bounds and the canonical pose to exist.
constexpr float kNearDepth = 1e-3f;
/// Shutter slabs with their own screen bounds: a sample is tested against a triangle only when it
/// lies inside the bounds of the slab its time falls in.
constexpr int kTimeSlabs = 8;
/// Tessellation of spheres (longitude segments x latitude rings).
constexpr int kSphereSegments = 32, kSphereRings = 16;
/// Triangles longer than this on the canonical image (pixels) are split (see RasterScene).
constexpr float kDefaultMaxEdge = 32.f;
/// Split levels at most: for size, and for triangles that cross the near plane.
constexpr int kMaxSplits = 8, kMaxNearSplits = 5;
/// Triangles the split may produce in all. A triangle far off screen at mid-shutter projects
/// its depth edges long (the image of an edge at lateral offset X grows with X / z^2), so an
/// object that sweeps across the view fast splits to the level limit: with velocities of 100
/// and 400 units per shutter, motion_defocus split into 64K and 979K triangles (2.9 GB, 32 s).
/// Past the budget, triangles are kept whole (scene order, so the same scene splits the same way).
constexpr size_t kMaxSplitTriangles = size_t(1) << 18;

struct RasterTriangle {
    // Camera space at shutter open; vertex i at normalised shutter time tau is p[i] + motion tau.
    Vec3f p[3];
    Vec3f motion;
    // World space at shutter open (the rest pose textures are attached to) and shading normals.
    Vec3f pWorld[3];
    Vec3f motionWorld;
    Vec3f nWorld[3];
    Vec3f faceNormalWorld;  // unit, cross(p1 - p0, p2 - p0)
    uint32_t material = 0;
    uint32_t mesh = 0;
    // The scene triangle this one was split from (RasterScene::parents) and the barycentrics of
    // this triangle's vertices in it.
    uint32_t parent = 0;
    Vec3f parentBary[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

    // Every vertex stays in front of kNearDepth over the shutter: the bounds below are exact and
    // the canonical pose exists. Otherwise the bounds are the whole screen and each sample of the
    // triangle is shaded on its own (the conservative fallback NOTES.md asks for).
    bool nearSafe = true;
    Bounds2 bounds;              // pixels, over the whole shutter and lens
    Bounds2 slab[kTimeSlabs];    // pixels, over [k, k+1] / kTimeSlabs of the shutter and the lens
    // At shutter time k / kTimeSlabs: each vertex's pinhole image (x, y) and circle of confusion
    // phi (z); at lens point (lu, lv) the vertex is imaged at (x + phi lu, y - phi lv).
    Vec3f lensLine[kTimeSlabs + 1][3];

    // Canonical pose: pinhole image (pixels) and depth of each vertex at shutter centre.
    Vec2f sCanon[3];
    float zCanon[3] = {1, 1, 1};

    Vec3f pointCamera(const Vec3f& bary, float tau) const {
        return p[0] * bary.x + p[1] * bary.y + p[2] * bary.z + motion * tau;
    }
    Vec3f pointRest(const Vec3f& bary) const { return pWorld[0] * bary.x + pWorld[1] * bary.y + pWorld[2] * bary.z; }
    /// Canonical screen position (pixels) of the surface point with barycentrics `bary`: the
    /// perspective-correct interpolation sum(b_i Z_i s_i) / sum(b_i Z_i).
    Vec2f canonicalScreen(const Vec3f& bary) const {
        float w0 = bary.x * zCanon[0], w1 = bary.y * zCanon[1], w2 = bary.z * zCanon[2];
        float inv = 1.f / (w0 + w1 + w2);
        return {(w0 * sCanon[0].x + w1 * sCanon[1].x + w2 * sCanon[2].x) * inv,
                (w0 * sCanon[0].y + w1 * sCanon[1].y + w2 * sCanon[2].y) * inv};
    }
    Vec3f toParent(const Vec3f& bary) const {
        return parentBary[0] * bary.x + parentBary[1] * bary.y + parentBary[2] * bary.z;
    }
    /// Screen-space barycentrics (affine in the canonical image) -> surface barycentrics.
    Vec3f surfaceBarycentrics(const Vec3f& lambda) const {
        float w0 = lambda.x / zCanon[0], w1 = lambda.y / zCanon[1], w2 = lambda.z / zCanon[2];
        float inv = 1.f / (w0 + w1 + w2);
        return {w0 * inv, w1 * inv, w2 * inv};
    }
};

/// When the tessellation stage splits a triangle: when its canonical image has an edge longer
/// than maxEdge pixels (0: never) and it is blurred, i.e. somewhere its circle of confusion exceeds
/// minCoc pixels or a vertex moves more than minSpeed pixels over the shutter (both 0: always).
/// The pipeline sets minCoc = Omega_A / Omega_R and minSpeed = Omega_S / Omega_R, the blur below
/// which AAS keeps the pixel rate, so a static in-focus triangle is never split.
struct SplitPolicy {
    float maxEdge = kDefaultMaxEdge;  // pixels
    float minCoc = 0;                 // pixels
    float minSpeed = 0;               // pixels per shutter
};

/// The scene's triangles ready to rasterize. Blurred triangles larger than the policy's edge are
/// split at their edge midpoints, recursively, as a tessellation stage would: AAS bounds the blur
/// of a whole primitive (Sec. 3.2), so a floor quad that crosses the plane in focus would get no
/// reduction anywhere, and a primitive's traversal touches as many cells as the primitive spans.
/// Triangles that cross the near plane are split too (up to kMaxNearSplits levels), and children
/// entirely off screen or behind the camera are dropped.
struct RasterScene {
    explicit RasterScene(const scene::SceneDesc& desc, const SplitPolicy& split = {});

    RasterCamera camera;
    std::vector<RasterTriangle> triangles;  // what is rasterized: the scene's triangles after splitting
    std::vector<RasterTriangle> parents;    // the scene's triangles before splitting (not rasterized)
    std::vector<scene::Material> materials;
    scene::LightIrradiance irradiance;  // the lights' closed-form irradiance (the shader's light)
    size_t culledTriangles = 0;  // degenerate, off screen, or behind the camera for the whole shutter
    bool splitBudgetReached = false;  // kMaxSplitTriangles stopped the split somewhere
};

}  // namespace wedge::raster
