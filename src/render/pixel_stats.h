// Per-pixel reduction of path samples into the FrameBuffers planes: the Monte Carlo estimate,
// the demodulated direct and indirect light, the G-buffer, and the slope statistics of the
// initial samples (shadow slopes from the nearest occluders, bounce distances, defocus slopes).
//
// Samples are grouped by the surface they hit (object, normal within 20 degrees, tangent
// plane): the first kSlots surfaces a pixel sees get a slot each; the pixel's primary surface
// is the slot with the most samples, the others become FrameBuffers::other. Filters see only
// primary surfaces, so a silhouette pixel (half bar, half floor, or a defocused edge) is never
// filtered with one surface's neighbours as if it were all one surface; further surfaces and
// misses are kept as an unfiltered colour (FrameBuffers::rest).
//
// Only the first slot lives in the pixel: the others come from a SlotPool, allocated for the
// pixels whose samples see a second surface (silhouettes and defocused edges: 5% of cornell's
// pixels at 512x512, 54% of sponza's). Keeping all three inline made the statistics 592 bytes
// a pixel (155 MB at 512x512), and this machine pays for memory by the page it first touches:
// 11% of a MAAF render's CPU samples were the kernel zeroing them (`perf record`, cornell
// 512x512).
#pragma once

#include <algorithm>
#include <array>
#include <memory>

#include <tbb/concurrent_vector.h>

#include "core/buffers.h"
#include "core/image.h"
#include "render/path_sampler.h"

namespace wedge::render {

struct SurfaceSlot {
    uint32_t n = 0, object = 0;
    Vec3f firstNormal{0.f}, firstPosition{0.f};
    float planeTolerance = 0;  // world distance off the first sample's tangent plane still on this surface
    Vec3f albedo{0.f}, rhoDirect{0.f}, rhoIndirect{0.f}, direct{0.f}, indirect{0.f}, normal{0.f}, position{0.f};
    float depth = 0;
    float visible = 0, unoccluded = 0;  // sums of luminance(direct_s) and unoccluded_s
    // Slopes (only from samples added with slopes = true).
    float d1Sum = 0;
    uint32_t nSlopes = 0, nShadow = 0, nOccluded = 0, nBounce = 0;
    float s1 = 0, s2 = kInf;            // max d1/d2min - 1, min d1/d2max - 1
    float lightSigma = kInf;            // smallest ViewGeometry::Light::sigma of the occluded samples' lights
    float zMin = kInf, zMax = 0;        // bounce hit distances
    float suMin = kInf, suMax = -kInf;  // defocus slopes
    // Texture: the sum of the samples' squared albedo luminance, and the albedo and count of the
    // primary-only samples on this surface (PixelStats::addPrimary), which the stored albedo and
    // coverage take in.
    float albedoSq = 0;
    Vec3f textureAlbedo{0.f};
    uint32_t textureN = 0;

    /// The relative variance of the albedo's luminance over this surface's path samples: 0 on
    /// an untextured surface.
    float albedoVariance() const {
        if (n < 2) return 0.f;
        const float mean = luminance(albedo) / float(n);
        return mean > 0 ? std::max(0.f, albedoSq / float(n) - mean * mean) / (mean * mean) : 0.f;
    }

    /// Same surface: same object, normal within 20 degrees, and on the first sample's tangent
    /// plane (a box face in front of a parallel wall of the same mesh is another surface).
    bool matches(const TracedSample& s) const {
        return n > 0 && s.object == object && dot(s.normal, firstNormal) >= kSameSurfaceCos &&
               std::abs(dot(s.position - firstPosition, firstNormal)) <= planeTolerance;
    }
    void add(const TracedSample& s, const ViewGeometry& view, bool slopes);
};

/// What a slot without samples reads as (constant-initialised: no guard in the hot loops).
inline constexpr SurfaceSlot kEmptySlot{};

/// The surface slots after the first: kSlots - 1 at a time, at addresses that stay put while
/// other threads allocate (tbb::concurrent_vector never moves its elements). Which block a pixel
/// gets depends on the threads' order; what is in it does not.
class SlotPool {
public:
    static constexpr int kBlock = FrameBuffers::kOtherSurfaces;
    SurfaceSlot* allocate() { return m_blocks.emplace_back()->data(); }
    size_t blocks() const { return m_blocks.size(); }

private:
    tbb::concurrent_vector<std::array<SurfaceSlot, kBlock>> m_blocks;
};

struct PixelStats {
    Vec3f color{0.f}, emission{0.f}, light{0.f};  // light: sum of albedo * (direct + indirect)
    float lumSum = 0, lumSq = 0;
    uint32_t n = 0, nEmitter = 0;  // nEmitter: samples that saw an emitter
    uint32_t nMiss = 0;            // samples that hit nothing (no light: the scene has no environment)
    uint32_t primaryMiss = 0;      // primary samples (addPrimary) that hit nothing
    float suLo = kInf, suHi = -kInf;  // defocus slopes of every sample added with slopes (all surfaces, misses)
    float suAbsMin = kInf;            // the smallest |defocus slope| among them
    static constexpr int kSlots = 1 + SlotPool::kBlock;
    SurfaceSlot first;            // slot 0
    SurfaceSlot* more = nullptr;  // slots 1 .. kSlots - 1, from the SlotPool once a second surface is seen

    const SurfaceSlot& slot(int k) const { return k == 0 ? first : more ? more[k - 1] : kEmptySlot; }

    /// Adds a sample; returns the surface slot it went to (0 .. kSlots - 1) or -1 (background or
    /// a surface beyond the slots). `pool` supplies the further slots when a second surface shows.
    int add(const TracedSample& s, const ViewGeometry& view, bool slopes, SlotPool& pool);
    /// The slot with the most samples (the first of equals).
    int primary() const {
        int best = 0;
        for (int k = 1; k < kSlots; ++k)
            if (slot(k).n > slot(best).n) best = k;
        return best;
    }
    /// The slot add() put (or would put) the sample in, once every slot exists or the sample is
    /// one this pixel already took: slots never change after their first sample, so tracing a
    /// pixel's sample again finds the slot it went to. -1: background or a surface beyond the slots.
    int slotOf(const TracedSample& s) const {
        if (!s.hit) return -1;
        for (int k = 0; k < kSlots; ++k)
            if (slot(k).matches(s)) return k;
        return -1;
    }
    /// A primary sample (PathSampler::primaryHits: a camera ray alone): its albedo joins its
    /// surface's, if it is one this pixel's path samples found, and it counts towards the
    /// coverage of that surface, or of the pixel's misses (store()). False where it goes
    /// nowhere: a miss, or a surface the path samples did not see (whose light nothing knows).
    bool addPrimary(const TracedSample& s) {
        if (!s.hit) {
            ++primaryMiss;
            return false;
        }
        const int k = slotOf(s);
        if (k < 0) return false;
        SurfaceSlot& sl = k == 0 ? first : more[k - 1];
        sl.textureAlbedo += s.albedo;
        ++sl.textureN;
        return true;
    }
    /// Whether the samples saw a surface and something else (another surface or nothing).
    bool mixed() const { return first.n > 0 && first.n < n; }
    /// The largest albedoVariance() among the pixel's surfaces.
    float albedoVariance() const {
        float v = 0;
        for (int k = 0; k < kSlots; ++k) v = std::max(v, slot(k).albedoVariance());
        return v;
    }
    /// Extra samples that bring a pixel partly covering an emitter up to `target`: no filter can
    /// reach emitted light, and a bright edge seen by few samples dominates any relative error.
    uint32_t emitterTopUp(uint32_t target) const {
        return (nEmitter > 0 && nEmitter < n && n < target) ? target - n : 0;
    }
    /// Extra samples for a pixel whose samples saw more than one surface (or a surface and the
    /// background): no per-surface filter reaches how they mix, so such a pixel is sampled until
    /// the relative variance of its mean, var / ((mean^2 + epsilon) n), falls to `tau`, at most
    /// up to `target` samples in all (epsilon: relMSE's 0.01, MethodContext::luminanceUnit).
    uint32_t mixedTopUp(float tau, uint32_t target, float epsilon = 0.01f) const {
        if (n == 0 || first.n == n || n >= target) return 0;
        float mean = lumSum / float(n), var = std::max(0.f, lumSq / float(n) - mean * mean);
        float need = var / ((mean * mean + epsilon) * tau);
        return need > float(n) ? uint32_t(std::min(need, float(target))) - n : 0;
    }
    /// Writes this pixel into every plane of `fb`.
    void store(FrameBuffers& fb, int x, int y, const ViewGeometry& view) const;
};

/// Every pixel's statistics with the pool of their further slots (not copyable: the pixels
/// point into the pool).
class PixelStatsImage : public Image<PixelStats> {
public:
    PixelStatsImage() = default;
    PixelStatsImage(int width, int height) : Image<PixelStats>(width, height), m_pool(std::make_unique<SlotPool>()) {}
    PixelStatsImage(const PixelStatsImage&) = delete;
    PixelStatsImage& operator=(const PixelStatsImage&) = delete;
    PixelStatsImage(PixelStatsImage&&) noexcept = default;
    PixelStatsImage& operator=(PixelStatsImage&&) noexcept = default;
    SlotPool& pool() { return *m_pool; }
    const SlotPool& pool() const { return *m_pool; }

private:
    std::unique_ptr<SlotPool> m_pool;  // on the heap: moving the image leaves the slots where they are
};

}  // namespace wedge::render
