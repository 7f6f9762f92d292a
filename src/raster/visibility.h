// The stochastic rasterizer: visibility samples in (x, y, u, v, t) against time-continuous
// triangles (linear motion over the shutter) seen through a thin lens. Each pixel has `spp`
// samples whose film offset, lens point (concentric disc) and shutter time come from the
// deterministic PixelSampler (pairs 0, 1, 2), so the result does not depend on the thread count.
// Triangles are binned into 8x8-pixel tiles by their conservative screen bounds over the whole
// shutter and lens (raster_geometry.h). Inside a tile the samples are bucketed by time slab and
// lens region; for each slab a triangle gets the lens interval (per axis) from which its bounding
// box can reach the tile (the vertex images move linearly with the lens coordinate, so the interval
// follows from the six vertex images at the slab ends), and only the samples of the buckets it
// overlaps, inside its slab bounds and lens interval, are tested. The coverage test intersects the sample's lens ray
// with the triangle at the sample's time (the ray is moved by -motion t instead of the triangle),
// which is the 5D edge-function test with the thin-lens shear, and the depth test keeps the
// nearest hit (ties: the earlier triangle). A surviving sample stores its triangle and the
// barycentrics of the hit, which decoupled sampling maps to shading space.
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.h"
#include "core/sampler.h"
#include "raster/raster_geometry.h"

namespace wedge::raster {

constexpr uint32_t kNoPrim = 0xffffffffu;
constexpr int kTileSize = 8;  // pixels; the top level of the traversal
constexpr int kLeafSize = 2;  // pixels; the leaf level of the traversal

/// One visibility sample's position in (x, y, u, v, t).
struct SamplePoint {
    float px, py;  // film position, pixels
    float lu, lv;  // lens position on the unit disc (u along camera right, v along camera up)
    float tau;     // normalised shutter time in [0, 1)
};

inline SamplePoint samplePoint(uint32_t seed, int width, int x, int y, uint32_t index) {
    PixelSampler sampler(seed, uint32_t(y) * uint32_t(width) + uint32_t(x));
    Vec2f film = sampler.get2D(index, 0);
    Vec2f lens = sampler.get2D(index, 1);
    Vec2f disc = concentricDisc(lens.x, lens.y);
    return {float(x) + film.x, float(y) + film.y, disc.x, disc.y, sampler.get1D(index, 2)};
}

struct VisibilitySample {
    float depth = kInf;  // world units along forward
    uint32_t prim = kNoPrim;
    float b1 = 0, b2 = 0;  // barycentrics of the hit (vertex 1 and 2)
    Vec3f bary() const { return {1.f - b1 - b2, b1, b2}; }
};

struct VisibilityBuffer {
    int width = 0, height = 0, spp = 0;
    uint32_t seed = 0;
    std::vector<VisibilitySample> samples;  // index ((y * width) + x) * spp + s
    uint64_t sampleTests = 0;   // sample-triangle coverage tests run
    uint64_t boundRejects = 0;  // sample-triangle pairs in a visited bucket rejected by the slab and lens bounds
    uint64_t visibleSamples = 0;

    size_t index(int x, int y, int s) const { return (size_t(y) * width + x) * spp + s; }
};

VisibilityBuffer rasterize(const RasterScene& scene, int spp, uint32_t seed, Progress* progress = nullptr);

/// All sample indices in screen traversal order: 8x8 tiles in row-major order, inside a tile its
/// 2x2 leaf blocks in row-major order, inside a leaf its pixels in row-major order, inside a pixel
/// its samples by index.
std::vector<uint32_t> screenTraversalOrder(int width, int height, int spp);

}  // namespace wedge::raster
