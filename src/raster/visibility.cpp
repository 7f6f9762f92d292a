#include "raster/visibility.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>

#include <tbb/parallel_for.h>

namespace wedge::raster {

namespace {

/// A sample with its camera-space lens ray, computed once per tile.
struct TileSample {
    float px, py, tau;
    Vec3f origin, dir;
};

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
    tbb::parallel_for(0, tilesX * tilesY, [&](int tile) {
        int tx = tile % tilesX, ty = tile / tilesX;
        int px0 = tx * kTileSize, py0 = ty * kTileSize;
        int px1 = std::min(vis.width, px0 + kTileSize), py1 = std::min(vis.height, py0 + kTileSize);
        int tw = px1 - px0;
        std::vector<TileSample> ts(size_t(tw) * (py1 - py0) * spp);
        for (int y = py0; y < py1; ++y)
            for (int x = px0; x < px1; ++x)
                for (int s = 0; s < spp; ++s) {
                    SamplePoint sp = samplePoint(seed, vis.width, x, y, uint32_t(s));
                    TileSample& t = ts[(size_t(y - py0) * tw + (x - px0)) * spp + s];
                    t.px = sp.px;
                    t.py = sp.py;
                    t.tau = sp.tau;
                    cam.ray(sp.px, sp.py, sp.lu, sp.lv, t.origin, t.dir);
                }
        uint64_t localTests = 0, localRejects = 0;
        for (uint32_t prim : bins[tile]) {
            const RasterTriangle& tri = scene.triangles[prim];
            const Bounds2& b = tri.bounds;
            int x0 = std::max(px0, int(std::floor(b.x0))), x1 = std::min(px1 - 1, int(std::floor(b.x1)));
            int y0 = std::max(py0, int(std::floor(b.y0))), y1 = std::min(py1 - 1, int(std::floor(b.y1)));
            Vec3f e1 = tri.p[1] - tri.p[0], e2 = tri.p[2] - tri.p[0];
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x)
                    for (int s = 0; s < spp; ++s) {
                        const TileSample& t = ts[(size_t(y - py0) * tw + (x - px0)) * spp + s];
                        int slab = std::min(kTimeSlabs - 1, int(t.tau * kTimeSlabs));
                        if (!tri.slab[slab].contains(t.px, t.py)) {
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
                        VisibilitySample& vs = vis.samples[vis.index(x, y, s)];
                        if (depth < vs.depth) vs = {depth, prim, u, v};
                    }
        }
        uint64_t localVisible = 0;
        for (int y = py0; y < py1; ++y)
            for (int x = px0; x < px1; ++x)
                for (int s = 0; s < spp; ++s) localVisible += vis.samples[vis.index(x, y, s)].prim != kNoPrim;
        tests += localTests;
        rejects += localRejects;
        visible += localVisible;
        if (progress) progress->add(1);
    });
    vis.sampleTests = tests;
    vis.slabRejects = rejects;
    vis.visibleSamples = visible;
    return vis;
}

namespace {

uint32_t spreadBits(uint32_t v) {  // 16 bits -> even bit positions
    v &= 0xffffu;
    v = (v | (v << 8)) & 0x00ff00ffu;
    v = (v | (v << 4)) & 0x0f0f0f0fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
}

}  // namespace

std::vector<uint32_t> screenTraversalOrder(int width, int height, int spp) {
    std::vector<uint32_t> order;
    order.reserve(size_t(width) * height * spp);
    constexpr int kLeaves = kTileSize / kLeafSize;
    int tilesX = (width + kTileSize - 1) / kTileSize, tilesY = (height + kTileSize - 1) / kTileSize;
    std::vector<std::pair<uint32_t, uint32_t>> tiles;  // (key, tile index)
    for (int ty = 0; ty < tilesY; ++ty)
        for (int tx = 0; tx < tilesX; ++tx) {
            uint32_t key = std::getenv("MORTON") ? (spreadBits(uint32_t(tx)) | (spreadBits(uint32_t(ty)) << 1))
                                                 : uint32_t(ty * tilesX + tx);
            tiles.push_back({key, uint32_t(ty * tilesX + tx)});
        }
    std::sort(tiles.begin(), tiles.end());
    for (auto [key, t] : tiles) {
        int tx = int(t) % tilesX, ty = int(t) / tilesX;
        for (int ly = 0; ly < kLeaves; ++ly)
            for (int lx = 0; lx < kLeaves; ++lx)
                for (int py = 0; py < kLeafSize; ++py)
                    for (int px = 0; px < kLeafSize; ++px) {
                        int x = tx * kTileSize + lx * kLeafSize + px, y = ty * kTileSize + ly * kLeafSize + py;
                        if (x >= width || y >= height) continue;
                        for (int s = 0; s < spp; ++s) order.push_back(uint32_t((size_t(y) * width + x) * spp + s));
                    }
    }
    return order;
}

}  // namespace wedge::raster
