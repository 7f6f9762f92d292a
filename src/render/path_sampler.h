// The path sample of the MAAF paper (Sec. 6.2, after MYRD14): a primary ray through a lens
// sample; at its hit one light sample with a shadow ray (direct light); one cosine-weighted
// diffuse bounce whose hit is lit by its own light sample and shadow ray (one bounce of
// indirect light). Emission counts only where the camera sees an emitter, never at bounce
// hits, so nothing is counted twice. Random numbers come from PixelSampler, so a sample depends
// only on (seed, pixel, sample index).
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "core/buffers.h"
#include "core/light_field.h"
#include "core/sampler.h"
#include "render/camera.h"
#include "scene/light_irradiance.h"
#include "scene/scene.h"

namespace wedge::render {

class Distribution;

/// The largest turn in depth (radians over the shutter: the turn times the sine of the angle
/// between its axis and the line of sight) for which a sample records its sagitta
/// (TracedSample::sag). Beyond it more of a body's points are hidden and revealed within the
/// shutter, and in a layer's sharp image, which holds every point where it is at mid-shutter,
/// they lie under the points in front of them then, whose trajectories the rays read there.
/// Measured with MC, relMSE against 1024-spp references, straight -> curved trajectories
/// (docs/layers.md, "Curved trajectories"): docs/bunny-turn.json's bunny turning 40 degrees
/// -13% and -14% (two seeds), 60 degrees -12% and -14%, 90 degrees +19% and +28%;
/// docs/turning-room.json (a bunny turning 60 degrees, a box 120 about a diagonal) -6%.
/// (And only turns of at most half a turn in all: beyond, the arc runs past its chord's ends,
/// which no parabola through them and its middle follows; a bar spinning 200 degrees in the
/// image plane measured +11% curved.)
constexpr float kCurvedTurnInDepth = 1.0471976f;  // 60 degrees

/// Everything one path sample produced: the record the filters see, plus the per-sample facts
/// the pixel statistics (slopes, G-buffer) are built from.
struct TracedSample {
    SampleRecord record;
    bool hit = false;
    Vec3f emission{0.f}, albedo{0.f}, normal{0.f}, position{0.f};
    float depth = 0;
    uint32_t object = 0;
    // Where on the film (the position in the pixel, [0, 1)^2) and when (the shutter time, [0,
    // 1]) it was taken, and how far its hit moves on the screen over the whole shutter (pixels,
    // through the lens centre): the light-field coordinates of the layered reconstruction.
    Vec2f film{0.f, 0.f}, motion{0.f, 0.f};
    float time = 0;
    // How far (pixels) its hit's path on the screen strays from that motion's chord at
    // mid-shutter: the bend of a turning object's arc (or of a turning camera's projection),
    // which the layered reconstruction's straight trajectories miss (LightFieldSamples::bentReach).
    float bend = 0;
    // Where bend > LightFieldSamples::kBentPath (else 0): how much its surface turns towards or
    // away from the camera over the shutter, |cos at close - cos at open| of the angle between
    // its normal and the direction to the camera. A spin in the image plane (a fan, a wheel
    // seen face on) turns nothing towards the camera.
    float faceTurn = 0;
    // On an object turning by at most half a turn, in depth by at most kCurvedTurnInDepth: where its hit is at
    // mid-shutter on the screen, off its chord's middle (pixels; the arc's sagitta, along the
    // chord as well as across it). The layered reconstruction reprojects the sample along the
    // parabola through the chord's ends and that point (filter/layers.cpp, curvedShift). 0
    // elsewhere: a translation's uneven pace in depth is the stage's alongChord, and a camera's
    // turn is not counted.
    Vec2f sag{0.f, 0.f};
    // Shadow ray of the primary hit (only when the light faced the receiver).
    bool shadowTested = false, occluded = false;
    bool selfShadowed = false;     // the light is above the shading normal's horizon but below the facet's
    float d1 = 0;                  // receiver -> light centre
    float tOccluder = kInf;        // the nearest occluder's distance along the shadow ray (slope queries only)
    // Bounce.
    bool bounceHit = false;
    float bounceDistance = kInf;
    uint32_t rays = 0;
};

class PathSampler {
public:
    /// Dimension pairs of PixelSampler, in order of use. kPixel draws the pixel and the lens
    /// position together (PixelSampler::get4DBatch), which takes the place of pair 1; kLight
    /// draws the light's point with the light choice and the shutter time (its dimensions 2-3,
    /// where the scene has several lights or motion).
    enum Pair : uint32_t { kPixel = 0, kLight = 2, kBounce = 3, kBounceLight = 4 };

    PathSampler(const scene::Scene& scene, const Camera& camera, bool indirect, uint32_t seed);

    /// Traces sample `index` of pixel (x, y). With `slopes`, the primary shadow ray finds the
    /// occluder nearest the receiver (TracedSample::tOccluder, for the shadow slopes) instead of
    /// stopping at any.
    TracedSample trace(int x, int y, uint32_t index, bool slopes) const;
    /// Traces samples first .. first+count-1 of pixel (x, y) into out[0..count): traceMany with
    /// one run. The same samples as trace() one by one.
    void traceBatch(int x, int y, uint32_t first, uint32_t count, bool slopes, TracedSample* out) const;
    /// Samples first .. first+count-1 of pixel (x, y), into out[0..count): one of traceMany's runs.
    struct SampleRun {
        int x = 0, y = 0;
        uint32_t first = 0, count = 0;
        TracedSample* out = nullptr;
    };
    /// Traces several pixels' runs together, so that Embree sees their shadow rays as one
    /// stream of up to 256 (faster than 16-wide packets: docs/sampling-speed.md). The same
    /// samples as traceBatch on each run.
    void traceMany(const SampleRun* runs, size_t n, bool slopes) const;
    /// traceMany into `buffer`, grown to hold the runs' samples one run after another, with each
    /// run's `out` pointed at its part.
    void traceRuns(std::vector<SampleRun>& runs, std::vector<TracedSample>& buffer, bool slopes) const;

    /// The mean emitted radiance that the camera rays of samples 0 .. count-1 of pixel (x, y)
    /// see: the emitted part of those path samples, from their primary rays alone (no light
    /// sample, no bounce), at a fraction of their cost.
    /// With `wide`: the part of it whose hits are blurred wide (LightFieldSamples::wideBlur,
    /// from each hit's depth and screen motion, as a path sample's).
    Vec3f meanEmission(int x, int y, uint32_t count, const LightFieldSamples* lf = nullptr, Vec3f* wide = nullptr) const;
    /// The primary hits of samples first .. first+count-1 of pixel (x, y), from their camera rays
    /// alone (no light sample, no bounce): each out[k] has the fields PixelStats::slotOf and the
    /// albedo read (hit, object, normal, position, depth, albedo; rays = 1), the rest default.
    /// What the texture samples are made of (PixelStats::addPrimary). Returns the rays traced.
    uint64_t primaryHits(int x, int y, uint32_t first, uint32_t count, TracedSample* out) const;

    const Camera& camera() const { return m_camera; }
    uint32_t seed() const { return m_seed; }
    /// Independent uniform numbers instead of the stratified Sobol points (PixelSampler;
    /// `--sampler independent`).
    void setIndependentSamples(bool independent) { m_independent = independent; }
    /// Over several ranks (render/distribution.h): this rank traces only its own rows, and the
    /// sampling stages copy what they computed to every rank. Null: one process, every row.
    void distribute(const Distribution* d, int rank, int ranks) {
        m_distribution = d;
        m_rank = rank;
        m_ranks = ranks;
    }
    const Distribution* distribution() const { return m_distribution; }
    int ranks() const { return m_ranks; }
    /// Whether this rank traces row y (render/distribution.h, ownsRow).
    bool tracesRow(int y) const { return m_ranks <= 1 || y % m_ranks == m_rank; }
    /// The samples traced so far whose light (emission, direct, indirect or unoccluded) is not
    /// finite: a scene's extreme numbers overflowing a float on the way. There should be none;
    /// --stats reports them (nonfinite_samples) beside the pixels they reach.
    uint64_t nonFiniteSamples() const { return m_nonFinite.load(std::memory_order_relaxed); }
    /// The samples traced so far that a light sample reached with light, before visibility (at
    /// their hit, or at their bounce's): none in a scene whose lights all face away from what
    /// the camera sees and what it sees lights, which renders black but for its emitters.
    uint64_t litSamples() const { return m_lit.load(std::memory_order_relaxed); }
    const scene::Scene& scene() const { return m_scene; }
    /// Appends every ray traceBatch asks Embree for to `log` (null: none), by kind. One thread
    /// only: for the throughput benchmark, never in a render.
    void logRays(scene::RayLog* log) { m_log = log; }
    ViewGeometry view() const;
    /// The lights' closed-form irradiance at x (normal n), without occlusion
    /// (scene::LightIrradiance, built once with the sampler's light groups).
    Vec3f unoccludedIrradiance(const Vec3f& x, const Vec3f& n) const { return m_irradiance(x, n); }

    /// One light sample for a point p with normal n: a light chosen by `choice` in proportion to
    /// its power, a point on it from u, and what it gives p without visibility.
    struct LightSample {
        Vec3f point;
        Vec3f irradiance;  // E: radiance * cos * cos / r^2 / pdf, zero if facing away
        Vec3f toLight;     // unit
        float distance;
        uint32_t light;    // the scene light
    };
    LightSample sampleLight(const Vec3f& p, const Vec3f& n, Vec2f u, float choice) const;
    /// The most samples a wave holds, and a batch of light samples.
    static constexpr int kLightBatch = 256;
    /// sampleLight(p[k], nrm[k], u[k], choice[k]) into out[k] for k < n <= kLightBatch: the same
    /// samples to the bit, as loops across them that the compiler vectorises (where no light is
    /// a sphere; else one by one).
    void sampleLights(int n, const Vec3f* p, const Vec3f* nrm, const Vec2f* u, const float* choice, LightSample* out) const;

private:
    struct Wave;
    /// sampleLight's sample of a sphere light (`index`), chosen with probability pChoice.
    LightSample sampleSphere(const scene::AreaLight& light, uint32_t index, const Vec3f& p, const Vec3f& n, Vec2f u,
                             float pChoice) const;
    /// The surface of a camera ray's hit into o (hit, albedo, the shading normal turned to the
    /// side of `geometric`, the geometric normal facing the ray; position, depth, object): what
    /// PixelStats::slotOf compares, so traceMany and primaryHits must take it alike. The depth is
    /// from the camera where it is at the sample's shutter time `time` (a moving camera).
    void setPrimaryHit(TracedSample& o, const scene::Hit& hit, const Vec3f& geometric, float time) const;
    /// The path over the shutter of a camera ray's hit at shutter time `time`, through the lens
    /// centre (of the camera where it is when the shutter opens and where when it closes): the
    /// point at the open and at the close, in the world and on the screen. Its screen motion
    /// (TracedSample::motion) is close - open, a chord of its arc where the object turns.
    struct ShutterPath {
        Vec3f atOpen, atClose;
        Vec2f open, close;
    };
    ShutterPath shutterPath(const scene::Hit& hit, float time) const;
    /// The camera rays of samples first .. first+n-1 (n <= 16) of a pixel into `primary`, with
    /// each sample's lens point, light choice and shutter time, and (unless null) the point it
    /// samples on the light, drawn with the choice and time: what traceBatch and meanEmission
    /// share, so that they trace the same rays.
    void cameraRays(const PixelSampler& rng, int x, int y, uint32_t first, int n, scene::RayPacket& primary,
                    Vec2f* lens, float* choice, float* time, Vec2f* uLight, Vec2f* film = nullptr) const;
    Vec3f offset(const Vec3f& p, const Vec3f& n) const { return p + n * m_epsilon; }

    const scene::Scene& m_scene;
    Camera m_camera;
    bool m_indirect;
    uint32_t m_seed;
    bool m_independent = false;
    float m_epsilon;
    bool m_needChoice;  // light choice or shutter time vary
    mutable std::atomic<uint64_t> m_nonFinite{0};
    mutable std::atomic<uint64_t> m_lit{0};
    std::vector<float> m_lightCdf;     // light choice by power: [i + 1] the cumulative share of lights 0..i, [0] = 0
    std::vector<Vec3f> m_lightNormal;  // each light's normal() and area(), once (sampleLight's hot loop)
    std::vector<float> m_lightArea;
    std::vector<Vec3f> m_lightCorner, m_lightEdge1, m_lightEdge2, m_lightRadiance;  // sampleLights' tables
    std::vector<int> m_lightTriangle;
    bool m_anySphere = false;
    std::vector<uint32_t> m_group;     // scene light -> its group, the ViewGeometry light (scene::lightGroups)
    std::vector<Vec3f> m_groupCenter;  // each group's centroid
    std::vector<float> m_groupArea;
    scene::LightIrradiance m_irradiance;
    scene::RayLog* m_log = nullptr;
    const Distribution* m_distribution = nullptr;
    int m_rank = 0, m_ranks = 1;
};

}  // namespace wedge::render
