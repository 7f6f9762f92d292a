// The sampled camera light field: every path sample a render takes, kept compactly with where
// it was taken on the film, the lens and the shutter (x, y, u, v, t), the depth and screen
// motion of what it saw, and what it carries (its albedo, its own reflected radiance, and which
// of its pixel's surfaces it hit). The layered reconstruction (filter/layers.h) reprojects these
// samples along their defocus and motion trajectories across pixels (Lehtinen et al. 2011,
// Munkberg et al. 2014).
//
// 24 bytes a sample (4 more where an object turns: the sagitta of its path, beside it): at
// 720x720 and 31 spp on average (AAF on conference) 386 MB. Colours are
// shared-exponent RGB9E5 (9-bit mantissas, one 5-bit exponent: 1/512 of the largest channel),
// the radiance scaled by a power of two to the scene's lights (radianceScale), lens and film
// positions fixed point. Samples are kept per pixel in the order they were taken,
// in stages (initial, adaptive), so that every pixel's samples and their order depend only on
// (seed, pixel, sample index), never on the threads.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "core/image.h"
#include "core/memory.h"
#include "core/memory_limit.h"

namespace wedge {

/// RGB9E5: three 9-bit mantissas with a shared 5-bit exponent (bias 15), as in the OpenGL
/// EXT_texture_shared_exponent format. Non-negative, finite values up to 65408; negative and
/// non-finite channels are stored as 0.
inline uint32_t packRgb9e5(const Vec3f& c) {
    constexpr float kMax = 65408.f;  // (511 / 512) * 2^16
    auto clampC = [&](float v) { return v > 0.f ? std::min(v, kMax) : 0.f; };  // NaN -> 0
    const float r = clampC(c.x), g = clampC(c.y), b = clampC(c.z);
    const float m = std::max({r, g, b});
    if (!(m > 0.f)) return 0;
    // The shared exponent e (biased by 15): mantissa = v / 2^(e - 15 - 9), at most 511. floor(log2 m)
    // is m's own binary exponent, read from its bits, and 2^k is built from bits too: std::log2
    // and std::ldexp were library calls for every recorded sample (the same bytes, layers_test).
    auto pow2 = [](int k) { return std::bit_cast<float>(uint32_t(k + 127) << 23); };  // 2^k, |k| < 127
    int e = std::max(-16, int((std::bit_cast<uint32_t>(m) >> 23) & 255u) - 127) + 16;
    float scale = pow2(24 - e);
    if (uint32_t(m * scale + 0.5f) >= 512u) scale = pow2(24 - ++e);  // rounding reached 2^9
    auto mant = [&](float v) { return std::min(511u, uint32_t(v * scale + 0.5f)); };
    return mant(r) | (mant(g) << 9) | (mant(b) << 18) | (uint32_t(std::min(e, 31)) << 27);
}

inline Vec3f unpackRgb9e5(uint32_t v) {
    const float scale = std::bit_cast<float>(uint32_t(int(v >> 27) - 24 + 127) << 23);  // 2^(e - 24)
    return {float(v & 511u) * scale, float((v >> 9) & 511u) * scale, float((v >> 18) & 511u) * scale};
}

/// One path sample of the light field.
struct LightFieldSample {
    float depth = 0;         // along the camera's forward axis; kInf where the camera ray missed
    uint32_t albedo = 0;     // RGB9E5
    uint32_t radiance = 0;   // RGB9E5: its own reflected radiance, albedo (direct + indirect)
    int16_t lensU = 0, lensV = 0;      // the lens point on the unit disc, x 32767
    int16_t motionX = 0, motionY = 0;  // screen motion over the whole shutter, 1/8 pixel
    uint16_t timeSurface = 0;          // shutter time in [0, 1] (14 bits) | surface + 1 (2 bits, 0: none)
    uint8_t filmX = 0, filmY = 0;      // the position in its pixel, 1/256 pixel

    static constexpr int kNoSurface = -1;
    static constexpr float kMaxMotion = 4095.f;  // pixels: int16 / 8

    static LightFieldSample pack(Vec2f film, Vec2f lens, float time, float depth, Vec2f motion, const Vec3f& albedo,
                                 const Vec3f& radiance, int surface) {
        // Rounded half away from zero as std::lround, without the call (x + 0.5 is exact in a double).
        auto roundHalfAway = [](float x) { return x >= 0 ? int(double(x) + 0.5) : x < 0 ? -int(0.5 - double(x)) : 0; };  // NaN -> 0
        auto q16 = [&](float v, float s, float lim) { return int16_t(roundHalfAway(std::clamp(v, -lim, lim) * s)); };
        LightFieldSample s;
        s.depth = depth;
        s.albedo = packRgb9e5(albedo);
        s.radiance = packRgb9e5(radiance);
        s.lensU = q16(lens.x, 32767.f, 1.f);
        s.lensV = q16(lens.y, 32767.f, 1.f);
        s.motionX = q16(motion.x, 8.f, kMaxMotion);
        s.motionY = q16(motion.y, 8.f, kMaxMotion);
        const uint32_t t = uint32_t(roundHalfAway(std::clamp(time, 0.f, 1.f) * 16383.f));
        s.timeSurface = uint16_t(t | (uint32_t(std::clamp(surface + 1, 0, 3)) << 14));
        s.filmX = uint8_t(std::clamp(int(film.x * 256.f), 0, 255));
        s.filmY = uint8_t(std::clamp(int(film.y * 256.f), 0, 255));
        return s;
    }
    /// The position in the pixel, at the centre of its 1/256 cell.
    Vec2f film() const { return {(float(filmX) + 0.5f) / 256.f, (float(filmY) + 0.5f) / 256.f}; }
    Vec2f lens() const { return {float(lensU) / 32767.f, float(lensV) / 32767.f}; }
    Vec2f motion() const { return {float(motionX) / 8.f, float(motionY) / 8.f}; }
    float time() const { return float(timeSurface & 0x3fffu) / 16383.f; }
    /// Which of its pixel's surfaces it hit (a FrameBuffers surface once finish() ran: 0 the
    /// primary, 1 + k other[k]), or kNoSurface (a miss, or a surface beyond the kept ones).
    int surface() const { return int(timeSurface >> 14) - 1; }
    void setSurface(int surface) {
        timeSurface = uint16_t((timeSurface & 0x3fffu) | (uint32_t(std::clamp(surface + 1, 0, 3)) << 14));
    }
    bool hit() const { return depth < kInf; }
    /// Whether a sample with these (packed) albedo and radiance carries an emitter's light: one
    /// with no albedo and some radiance (LightFieldSamples::wideBlur).
    static bool carriesEmission(uint32_t albedo, uint32_t radiance) { return albedo == 0u && radiance != 0u; }
    bool carriesEmission() const { return carriesEmission(albedo, radiance); }
};
static_assert(sizeof(LightFieldSample) == 24);
/// Where a turning object's point is at mid-shutter on the screen, off its path's chord's middle
/// (TracedSample::sag), 1/8 pixel: kept beside the samples where an object of the scene turns.
struct LightFieldSag {
    int16_t x = 0, y = 0;
    static LightFieldSag pack(Vec2f sag) {
        auto q = [](float v) {  // (NaN -> 0, as LightFieldSample::pack)
            return !std::isnan(v) ? int16_t(std::lround(std::clamp(v, -LightFieldSample::kMaxMotion, LightFieldSample::kMaxMotion) * 8.f)) : int16_t(0);
        };
        return {q(sag.x), q(sag.y)};
    }
    Vec2f unpack() const { return {float(x) / 8.f, float(y) / 8.f}; }
};
static_assert(std::is_trivially_copyable_v<LightFieldSample> && std::is_trivially_destructible_v<LightFieldSample>,
              "LightFieldSamples leaves its samples unwritten until they are recorded (UnwrittenAllocator)");

/// Every pixel's samples, stage by stage: a stage holds, for each pixel, a run of samples whose
/// length is fixed when the stage is added (the initial spp, the adaptive counts).
class LightFieldSamples {
public:
    LightFieldSamples() = default;
    /// `curved`: keep each sample's sagitta beside it (LightFieldSag; where an object turns).
    /// `radianceScale`: radianceScaleFor(the brightest emitter) (below).
    LightFieldSamples(int width, int height, bool curved = false, float radianceScale = 1.f)
        : m_width(width), m_height(height), m_curved(curved), m_radianceScale(radianceScale),
          m_bentReach(size_t(width) * height, 0.f), m_emission(size_t(width) * height, 0.f),
          m_wideEmission(size_t(width) * height, 0.f) {}
    bool curved() const { return m_curved; }

    /// A sample's radiance is stored times radianceScale() (a power of two, so that the stored
    /// mantissas are those of the radiance itself) and read back times 1 / radianceScale().
    /// RGB9E5 holds values up to 65408: without a scale, a scene whose lights' radiance is 10^6
    /// lost 3% of its mean in the layered reconstruction (MC, docs/posts.json with a small
    /// sphere light), and at 10^13 nearly all of it. The scale keeps the brightest emitter at most
    /// 64 (1 up to there: the built-in and docs/ scenes, at most 60, are stored as before), which
    /// leaves a sample 1000x the brightest radiance before it is clamped, and flushes to 0 only
    /// what is below about 2e-9 of it (2^-24 / 32).
    float radianceScale() const { return m_radianceScale; }
    static float radianceScaleFor(float brightest) {
        if (!(brightest > 64.f)) return 1.f;
        const int k = std::min(120, int(std::ceil(std::log2(std::min(brightest, 3.4e38f)))) - 6);
        return std::ldexp(1.f, -k);
    }

    int width() const { return m_width; }
    int height() const { return m_height; }
    bool empty() const { return m_stages.empty(); }
    int stages() const { return int(m_stages.size()); }

    /// Adds a stage with count(p) samples for pixel p (row-major index); returns its index.
    /// Throws wedge::Error (naming --layers) before allocating when the samples kept so far and
    /// the stage's would pass the memory limit (core/memory_limit.h).
    template <class CountFn>
    int addStage(CountFn&& count) {
        Stage s;
        const size_t pixels = size_t(m_width) * m_height;
        s.offset.resize(pixels + 1);
        s.offset[0] = 0;
        for (size_t p = 0; p < pixels; ++p) s.offset[p + 1] = s.offset[p] + count(p);
        checkMemory("--layers",
                    "keeping every sample (" + std::to_string(s.offset[pixels] + samples()) + " at " + std::to_string(sampleBytes()) + " bytes)",
                    uint64_t(bytes() + s.offset[pixels] * sampleBytes()));
        s.samples = Samples(s.offset[pixels]);  // unwritten: every slot is written once, by its pixel's thread
        if (m_curved) s.sags = Sags(s.offset[pixels]);
        m_stages.push_back(std::move(s));
        return int(m_stages.size()) - 1;
    }
    /// The run of pixel p in stage `stage` (sample k of the stage at [k]).
    LightFieldSample* run(int stage, size_t p) { return m_stages[stage].samples.data() + m_stages[stage].offset[p]; }
    /// ... and their sagittas (curved() only).
    LightFieldSag* sagRun(int stage, size_t p) { return m_stages[stage].sags.data() + m_stages[stage].offset[p]; }
    uint32_t runLength(int stage, size_t p) const {
        return uint32_t(m_stages[stage].offset[p + 1] - m_stages[stage].offset[p]);
    }

    /// fn(const LightFieldSample&) for every sample of pixel p, stage by stage, in order.
    template <class Fn>
    void forEach(size_t p, Fn&& fn) const {
        for (const Stage& s : m_stages)
            for (uint64_t i = s.offset[p]; i < s.offset[p + 1]; ++i) fn(s.samples[i]);
    }
    /// fn(const LightFieldSample&, Vec2f sag) likewise, with each sample's sagitta (0 where the
    /// samples keep none).
    template <class Fn>
    void forEachWithSag(size_t p, Fn&& fn) const {
        for (const Stage& s : m_stages)
            for (uint64_t i = s.offset[p]; i < s.offset[p + 1]; ++i) fn(s.samples[i], m_curved ? s.sags[i].unpack() : Vec2f{0.f, 0.f});
    }
    template <class Fn>
    void forEachMutable(size_t p, Fn&& fn) {
        for (Stage& s : m_stages)
            for (uint64_t i = s.offset[p]; i < s.offset[p + 1]; ++i) fn(s.samples[i]);
    }
    size_t count(size_t p) const {
        size_t n = 0;
        for (const Stage& s : m_stages) n += s.offset[p + 1] - s.offset[p];
        return n;
    }
    size_t samples() const {
        size_t n = 0;
        for (const Stage& s : m_stages) n += s.samples.size();
        return n;
    }
    /// Per pixel, how far (pixels, a square) from it its samples reach once reprojected, of those
    /// whose paths bend more than kBentPath on a surface that turns towards or away from the
    /// camera by more than kFaceTurn (0: none); marked as they are recorded
    /// (LightFieldStage::record). The layered reconstruction follows each sample's chord (its arc only
    /// for turns in depth up to kCurvedTurnInDepth) and
    /// holds one sharp image per layer at mid-shutter, which cannot show the parts of an object
    /// that turn into or out of view over the shutter: aaf and maaf keep their own composition
    /// within that reach (render/renderer.cpp; docs/layers.md, "Arcs").
    float bentReach(size_t p) const { return m_bentReach[p]; }
    void markBent(size_t p, float reach) { m_bentReach[p] = std::max(m_bentReach[p], reach); }
    float* bentReachData() { return m_bentReach.data(); }

    /// A sample that sees an emitter carries its emission where the emitter's light is spread
    /// thin over the pixels it blurs into: its screen motion's radius (2 sqrt of its variance
    /// per axis, m / sqrt(3)) at least kWideEmission pixels, and the share of its blurred image
    /// that the emitter covers at any one lens point and time, p = 4 a b / ((2 a + 2 c + m)
    /// (2 b + 2 c)), at most kWideCoverage: a and b its image's half extents along and across
    /// the motion (its bounding box's, in pixels at the sample's depth), c its circle of
    /// confusion's radius. It is then stored with no albedo, so that it keeps its own radiance
    /// under the filters' light (filter/layers.h), and the layers reconstruct its emission along
    /// its trajectory: a pixel that a small moving light crosses for a moment is found by few of
    /// its own samples, and by few of the camera rays that would estimate it per pixel (p x
    /// kEmitterEdgeRays, render/methods.h). Where p is larger those rays do better: under a
    /// pinhole, the streak of a light 26 px across moving 53 px (p = 0.33) had 5x the relMSE
    /// through the layers (which soften its crisp sides) that it has per pixel, in 0.4x the time;
    /// out of focus, p = 0.10-0.18, the layers gave up to 1.5x the relMSE in a third to half of
    /// the time (docs/layers.md, "Which moving emitters go through the layers"). A still emitter's emission stays with its
    /// pixel, whose emitter edges are sampled densely (render/methods.h, denseEmission): out of
    /// focus too, where the layers' grid softened the crisp rim of a small emitter's disc
    /// (docs/layers.md, "Emitters through the layers").
    /// `focalPixels`, `lensPixels` (apertureRadius x focalPixels) and `inverseFocus` from
    /// ViewGeometry; `objectImage` by object id: half the object's extent along the image's x
    /// and y (world, scene::Scene::objectHalfExtents projected on the camera's right and up).
    static constexpr float kWideEmission = 4.f, kWideCoverage = 0.15f;
    void setView(float focalPixels, float lensPixels, float inverseFocus, std::vector<Vec2f> objectImage) {
        m_focalPixels = focalPixels, m_lensPixels = lensPixels, m_inverseFocus = inverseFocus;
        m_objectImage = std::move(objectImage);
    }
    bool wideBlur(float depth, Vec2f motion, uint32_t object) const {
        if (object >= m_objectImage.size()) return false;
        const float m2 = motion.x * motion.x + motion.y * motion.y;
        if (m2 < 3.f * kWideEmission * kWideEmission) return false;
        const float inverseDepth = 1.f / std::max(depth, 1e-6f), m = std::sqrt(m2);
        const float scale = m_focalPixels * inverseDepth;
        const Vec2f e{m_objectImage[object].x * scale, m_objectImage[object].y * scale};
        const float dx = std::abs(motion.x) / m, dy = std::abs(motion.y) / m;
        const float along = dx * e.x + dy * e.y, across = dy * e.x + dx * e.y;
        const float c = std::abs(m_lensPixels * (inverseDepth - m_inverseFocus));
        return 4.f * e.x * e.y <= kWideCoverage * (2.f * (along + c) + m) * (2.f * (across + c));
    }
    /// What addEmission and setEmission count of an emitted radiance: its channels' mean.
    static float emissionLevel(const Vec3f& e) { return (e.x + e.y + e.z) / 3.f; }
    /// Per pixel, the emission its own samples saw (emissionLevel, summed) and the part of it
    /// that wide samples carry into the layers: the pixel keeps the rest of its emission
    /// (ownEmissionShare, 1 where its samples saw none).
    void addEmission(size_t p, float luminance, bool wide) {
        m_emission[p] += luminance;
        if (wide) m_wideEmission[p] += luminance;
    }
    /// ... replaced by another estimate of the same (render/methods.h, denseEmission).
    void setEmission(size_t p, float luminance, float wide) { m_emission[p] = luminance, m_wideEmission[p] = wide; }
    float ownEmissionShare(size_t p) const {
        return m_emission[p] > 0.f ? std::max(0.f, 1.f - m_wideEmission[p] / m_emission[p]) : 1.f;
    }
    float* emissionData() { return m_emission.data(); }
    float* wideEmissionData() { return m_wideEmission.data(); }

    /// A path that bends more than this (pixels) from its chord's line at mid-shutter is bent.
    /// AAF relMSE at 2 / 3 px against no rule, three seeds each: docs/bunny-turn.json -1..-6% /
    /// -8..-12%; a room with a bunny turning 20 degrees, a box 40 and a bar 67 -13..-25% / 0%.
    static constexpr float kBentPath = 2.f;
    /// ... on a surface that turns towards or away from the camera by more than this (the change
    /// of the cosine, TracedSample::faceTurn). Without it the filters lost the layers on fans
    /// spinning in the image plane before a wall, where the layers measured 1.5-2.4x lower
    /// relMSE than their own image; from 0.3 to 0.4 the same on six scenes with turns (0.05-0.2:
    /// the room above -11..-22% instead of -13..-25%), from 0.6 none is left.
    static constexpr float kFaceTurn = 0.3f;

    size_t bytes() const {
        size_t b = 0;  // (the samples; bentReach's and the emissions' 12 bytes a pixel beside them are not counted)
        for (const Stage& s : m_stages) b += s.samples.size() * sampleBytes() + s.offset.size() * sizeof(uint64_t);
        return b;
    }
    /// A sample's bytes, its sagitta's included where they are kept.
    size_t sampleBytes() const { return sizeof(LightFieldSample) + (m_curved ? sizeof(LightFieldSag) : 0); }

private:
    // Left unwritten when allocated (UnwrittenAllocator): each sample is written once as it is
    // recorded (or copied from its rank), so the pages are first touched by the sampling
    // threads, not zeroed by one thread before (Sponza 512x512, 16 spp: 100 MB).
    using Samples = std::vector<LightFieldSample, UnwrittenAllocator<LightFieldSample>>;
    using Sags = std::vector<LightFieldSag, UnwrittenAllocator<LightFieldSag>>;
    struct Stage {
        std::vector<uint64_t> offset;  // pixels + 1
        Samples samples;
        Sags sags;  // (curved() only) beside samples
    };
    int m_width = 0, m_height = 0;
    bool m_curved = false;
    float m_radianceScale = 1.f;
    std::vector<Stage> m_stages;
    std::vector<float> m_bentReach;
    std::vector<float> m_emission, m_wideEmission;
    float m_focalPixels = 0.f;
    std::vector<Vec2f> m_objectImage;  // (setView)
    float m_lensPixels = 0.f, m_inverseFocus = 0.f;
};

}  // namespace wedge
