// The stochastic rasterizer of visibility.h: tile binning, per-tile sample buckets by time slab and
// lens region, lens intervals per triangle and slab, the thin-lens ray test and the depth test.
#include "raster/visibility.h"

#include <algorithm>
#include <atomic>

#include <tbb/parallel_for.h>

namespace wedge::raster {

namespace {

/// Lens bins per axis for the per-tile sample buckets (time slabs x lens bins x lens bins).
constexpr int kLensBins = 4;
constexpr int kBuckets = kTimeSlabs * kLensBins * kLensBins;

/// A sample with its camera-space lens ray, computed once per tile.
struct TileSample {
    float px, py, tau, lu, lv;
    Vec3f origin, dir;
    uint32_t index;  // in the visibility buffer
};

int lensBin(float l) { return std::clamp(int((l + 1.f) * 0.5f * kLensBins), 0, kLensBins - 1); }

/// Hull of the lens coordinates l in [-1, 1] for which some point x0 + phi l (over `n` points) is
/// <= hi, intersected with the hull of those for which some point is >= lo: a conservative interval
/// of l where the points' bounding interval can overlap [lo, hi].
void lensInterval(const float* x0, const float* phi, int n, float lo, float hi, float& l0, float& l1) {
    auto hull = [&](float bound, bool below, float& a, float& b) {
        a = kInf;
        b = -kInf;
        for (int j = 0; j < n; ++j) {
            float ja = -1.f, jb = 1.f;
            float d = bound - x0[j];  // need phi l <= d (below) or phi l >= d (above)
            if (!below) d = -d;
            float p = below ? phi[j] : -phi[j];  // now: p l <= d
            if (std::abs(p) < 1e-12f) {
                if (d < 0) continue;
            } else if (p > 0) {
                jb = std::min(1.f, d / p);
            } else {
                ja = std::max(-1.f, d / p);
            }
            if (ja > jb) continue;
            a = std::min(a, ja);
            b = std::max(b, jb);
        }
    };
    float a0, b0, a1, b1;
    hull(hi, true, a0, b0);
    hull(lo, false, a1, b1);
    l0 = std::max(a0, a1);
    l1 = std::min(b0, b1);
}

}  // namespace

VisibilityBuffer rasterize(const RasterScene& scene, int spp, uint32_t seed, Progress* progress) {
    const RasterCamera& cam = scene.camera;
    VisibilityBuffer vis;
    vis.width = cam.width();
    vis.height = cam.height();
    vis.spp = spp;
    vis.seed = seed;
    vis.samples.assign(size_t(vis.width) * vis.height * spp, VisibilitySample{});

    int tilesX = (vis.width + kTileSize - 1) / kTileSize, tilesY = (vis.height + kTileSize - 1) / kTileSize;
    // Binning in triangle order keeps every bin sorted, which fixes the depth-tie winner.
    std::vector<std::vector<uint32_t>> bins(size_t(tilesX) * tilesY);
    for (uint32_t i = 0; i < scene.triangles.size(); ++i) {
        const Bounds2& b = scene.triangles[i].bounds;
        if (b.empty() || b.x1 < 0 || b.y1 < 0 || b.x0 >= vis.width || b.y0 >= vis.height) continue;
        int x0 = std::max(0, int(std::floor(b.x0))), x1 = std::min(vis.width - 1, int(std::floor(b.x1)));
        int y0 = std::max(0, int(std::floor(b.y0))), y1 = std::min(vis.height - 1, int(std::floor(b.y1)));
        for (int ty = y0 / kTileSize; ty <= y1 / kTileSize; ++ty)
            for (int tx = x0 / kTileSize; tx <= x1 / kTileSize; ++tx) bins[size_t(ty) * tilesX + tx].push_back(i);
    }

    std::atomic<uint64_t> tests{0}, rejects{0}, visible{0};
    float focus = cam.focusDistance();
    bool lens = cam.apertureRadius() > 0;
    tbb::parallel_for(0, tilesX * tilesY, [&](int tile) {
        int tx = tile % tilesX, ty = tile / tilesX;
        int px0 = tx * kTileSize, py0 = ty * kTileSize;
        int px1 = std::min(vis.width, px0 + kTileSize), py1 = std::min(vis.height, py0 + kTileSize);
        // The tile's samples, bucketed by (time slab, lens bin u, lens bin v) so that a triangle
        // visits only the buckets its bounds for that slab and lens region allow.
        std::vector<TileSample> ts;
        ts.reserve(size_t(px1 - px0) * (py1 - py0) * spp);
        std::vector<uint32_t> start(kBuckets + 1, 0);
        std::vector<int> bucketOf;
        for (int y = py0; y < py1; ++y)
            for (int x = px0; x < px1; ++x)
                for (int s = 0; s < spp; ++s) {
                    SamplePoint sp = samplePoint(seed, vis.width, x, y, uint32_t(s));
                    TileSample t;
                    t.px = sp.px;
                    t.py = sp.py;
                    t.tau = sp.tau;
                    t.lu = sp.lu;
                    t.lv = sp.lv;
                    t.index = uint32_t(vis.index(x, y, s));
                    cam.ray(sp.px, sp.py, sp.lu, sp.lv, t.origin, t.dir);
                    int slab = std::min(kTimeSlabs - 1, int(t.tau * kTimeSlabs));
                    int b = (slab * kLensBins + lensBin(t.lu)) * kLensBins + lensBin(t.lv);
                    bucketOf.push_back(b);
                    ++start[b + 1];
                    ts.push_back(t);
                }
        for (int b = 0; b < kBuckets; ++b) start[b + 1] += start[b];
        std::vector<TileSample> sorted(ts.size());
        {
            std::vector<uint32_t> fill(start.begin(), start.end() - 1);
            for (size_t i = 0; i < ts.size(); ++i) sorted[fill[bucketOf[i]]++] = ts[i];
        }

        uint64_t localTests = 0, localRejects = 0;
        for (uint32_t prim : bins[tile]) {
            const RasterTriangle& tri = scene.triangles[prim];
            Vec3f e1 = tri.p[1] - tri.p[0], e2 = tri.p[2] - tri.p[0];
            for (int k = 0; k < kTimeSlabs; ++k) {
                const Bounds2& sb = tri.slab[k];
                if (sb.x1 < px0 || sb.x0 > px1 || sb.y1 < py0 || sb.y0 > py1) continue;
                // Lens region from which the triangle can reach this tile during the slab: the six
                // vertex images at the slab ends bound it (raster_geometry.h), per lens axis.
                float u0 = -1, u1 = 1, v0 = -1, v1 = 1;
                if (lens && tri.nearSafe) {
                    float x0[6], y0[6], phi[6], negPhi[6];
                    for (int j = 0; j < 6; ++j) {
                        const Vec3f& l = tri.lensLine[k + j / 3][j % 3];
                        x0[j] = l.x;
                        y0[j] = l.y;
                        phi[j] = l.z;
                        negPhi[j] = -l.z;  // y = y0 - phi v
                    }
                    lensInterval(x0, phi, 6, float(px0), float(px1), u0, u1);
                    if (u0 > u1) continue;
                    lensInterval(y0, negPhi, 6, float(py0), float(py1), v0, v1);
                    if (v0 > v1) continue;
                }
                for (int ub = lensBin(u0); ub <= lensBin(u1); ++ub)
                    for (int vb = lensBin(v0); vb <= lensBin(v1); ++vb) {
                        int b = (k * kLensBins + ub) * kLensBins + vb;
                        for (uint32_t i = start[b]; i < start[b + 1]; ++i) {
                            const TileSample& t = sorted[i];
                            if (!sb.contains(t.px, t.py) || t.lu < u0 || t.lu > u1 || t.lv < v0 || t.lv > v1) {
                                ++localRejects;
                                continue;
                            }
                            ++localTests;
                            // Moller-Trumbore, two-sided, against the triangle at time tau.
                            Vec3f pvec = cross(t.dir, e2);
                            float det = dot(e1, pvec);
                            if (std::abs(det) < 1e-20f) continue;
                            float invDet = 1.f / det;
                            Vec3f tvec = t.origin - tri.motion * t.tau - tri.p[0];
                            float u = dot(tvec, pvec) * invDet;
                            if (u < 0.f || u > 1.f) continue;
                            Vec3f qvec = cross(tvec, e1);
                            float v = dot(t.dir, qvec) * invDet;
                            if (v < 0.f || u + v > 1.f) continue;
                            float depth = dot(e2, qvec) * invDet * focus;  // the ray's z grows by F per unit t
                            if (!(depth > kNearDepth)) continue;
                            VisibilitySample& vs = vis.samples[t.index];
                            if (depth < vs.depth) vs = {depth, prim, u, v};
                        }
                    }
            }
        }
        uint64_t localVisible = 0;
        for (const TileSample& t : ts) localVisible += vis.samples[t.index].prim != kNoPrim;
        tests += localTests;
        rejects += localRejects;
        visible += localVisible;
        if (progress) progress->add(1);
    });
    vis.sampleTests = tests;
    vis.boundRejects = rejects;
    vis.visibleSamples = visible;
    return vis;
}

std::vector<uint32_t> screenTraversalOrder(int width, int height, int spp) {
    std::vector<uint32_t> order;
    order.reserve(size_t(width) * height * spp);
    constexpr int kLeaves = kTileSize / kLeafSize;
    for (int ty = 0; ty * kTileSize < height; ++ty)
        for (int tx = 0; tx * kTileSize < width; ++tx)
            for (int ly = 0; ly < kLeaves; ++ly)
                for (int lx = 0; lx < kLeaves; ++lx)
                    for (int py = 0; py < kLeafSize; ++py)
                        for (int px = 0; px < kLeafSize; ++px) {
                            int x = tx * kTileSize + lx * kLeafSize + px, y = ty * kTileSize + ly * kLeafSize + py;
                            if (x >= width || y >= height) continue;
                            for (int s = 0; s < spp; ++s) order.push_back(uint32_t((size_t(y) * width + x) * spp + s));
                        }
    return order;
}

}  // namespace wedge::raster
