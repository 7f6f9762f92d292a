#include "filter/layers.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <climits>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "core/error.h"
#include "core/memory.h"
#include "core/memory_limit.h"
#include "core/parallel.h"
#include "core/sampler.h"
#include "filter/maaf.h"  // dilateBox

namespace wedge::filter {

namespace {

/// A sample as a tile reads it.
struct Gathered {
    float x, y;    // film position, pixels
    float u, v, t;
    float mx, my;  // screen motion over the shutter, pixels
    float c;       // defocus slope, pixels per unit lens coordinate
    float invDepth;
    uint32_t albedo, radiance;  // as stored (RGB9E5)
    uint32_t pixel;             // where it was taken (row-major)
    int8_t surface;
    uint8_t cls;  // 0: still; 1 + g: moving, in the tile's motion group g (kMotionGroups)
    uint16_t bin;  // its slope bin in its class's histogram (splitLayers)
    // (The sagitta of a turning object's path, LightFieldSample::sag, is in an array of its own
    // beside the gathered samples, where the light field keeps sagittas: 8 of 60 bytes a sample
    // that every pass over them read, 0 in most scenes.)
};
static_assert(sizeof(Gathered) == 52, "the bin fits in what was padding");

/// A layer whose slopes spread less than this (pixels per unit lens coordinate) is sheared with
/// its mean slope alone; a wider one's rays take the slope of the surface they find.
constexpr float kSlopeSpread = 0.25f;
/// A blurred moving layer whose samples all move at most this far along one grid axis (pixels
/// over the shutter), with every slope within kCrispSlope, keeps that axis crisp (Layer::crisp;
/// LayerOptions::crispAcrossMotion). (kCrispSlope 1.5 measured AAF relMSE +5% and +4% on the
/// held-out camera pans docs/sponza-pan.json and sponza-campan.json, where 0.75 measured +3% and
/// +2% and 0.5 +1% and +0.5%; below 0.75 docs/moving-boxes.json lost all of its gain, its box's
/// slopes reaching 0.7 px: docs/layers.md, "Crisp across the motion".)
constexpr float kCrispMotion = 0.25f, kCrispSlope = 0.75f;
// The largest cells (pixels a side) of a moving layer's grid (LayerOptions::maxGridMargin); a
// layer that needs larger ones fits in no grid.
constexpr int kMaxMovingStep = 8;
// The most reconstruction rays a pixel takes (LayerOptions::rays, mixedRays, movingRays), but
// where its tile's samples see an emitter (emitterRays, up to Rays::kMax).
constexpr int kMaxRays = 128;
/// A sample's screen motion counts as motion above this (pixels over the shutter).
constexpr float kMoving = 0.5f;
/// A tile's moving samples fall in at most this many groups of like motion, each split into
/// layers of its own: samples of one slope but different motion (a slowly moving sphere on a
/// fast floor at its depth, raster-pan) in one layer share its motion grid, and its rays then
/// reproject them with a blend of both motions (the sphere's rim doubled). The groups are the
/// connected parts of the tile's motion field (groupByMotionField); past the last group a part
/// joins the group of the nearest mean motion. (Until 2026-11-29 a sample joined the first group
/// whose first motion was within max(4 px, 50%) of its own: docs/layers.md, "Surfaces moving
/// apart", and "A held-out bunny moving through slats" for why that changed.) Sixteen, not
/// eight: twelve spheres moving twelve ways (docs/many-motion.json) need 9 to 16 in a tile,
/// and with eight the rest joined a group not theirs and were reprojected along its motion:
/// relMSE with layers MC 0.000780 -> 0.000603, AAF 0.000322 -> 0.000165 (docs/layers.md,
/// "Twelve motions in a tile").
constexpr int kMotionGroups = 16;
constexpr int kClasses = 1 + kMotionGroups;
/// A moving layer keeps its radiance in this many bins of shutter time: a moving surface's
/// shading changes as it moves (towards or away from a light), and the reconstruction rays take
/// the radiance of their own time (linear between the bins' centres).
constexpr int kTimeBins = 8;
/// Layers that cross in depth over the shutter (an object moving in depth past another one) are
/// ordered front to back in each of this many bins of shutter time (kOrderMargin).
constexpr int kOrderBins = 8;
/// Two layers cross in depth where in one order bin either one's key (inverse depth) exceeds the
/// other's by this share, and in another bin the other way round.
constexpr float kOrderMargin = 0.01f;
/// A still layer's depth where a moving layer was seen, in cells of this many pixels.
constexpr int kOrderCell = 8;
/// ... from every this-many-th of the tile's gathered samples.
constexpr size_t kOrderStride = 8;
/// Two moving layers are ordered in an order bin by the kOrderCell cells where both were seen in
/// it: one goes first where it is clearly the nearer (kOrderMargin) in at least this many times as
/// many of those cells as the other.
constexpr int kOrderVotes = 3;
/// In a blurred still layer of at least this slope (pixels), the samples of a pixel that saw
/// several surfaces carry their own light, not their pixel's filtered light (radianceOf).
constexpr float kOwnLightSlope = 2.f;
/// ... and every sample of a blurred still layer of at least this slope: its rays' disc averages
/// pi c^2 pixels' samples (3200 at 8 px and 16 spp), more than the filter did, and the pixel's
/// filtered light, already a mean over its own circle of confusion, would blur twice.
constexpr float kOwnLightAll = 8.f;
/// The reconstruction rays' sequence: the powers 1 / phi^k, k = 1..5, of the root of
/// x^6 = x + 1 (phi = 1.13472413840152), modulo 1.
constexpr double kKronecker[5] = {0.8812714616335696, 0.7766393890897683, 0.6844301295853427, 0.6031687406857283,
                                  0.5315553977157914};

/// The shear of a reconstruction ray through a layer's grid, shaped by the grid's own blur. A ray
/// at lens point u (unit disc) reads the grid at y = x + (a + b |u|^2) c u; one at shutter time
/// t, with s = t - 1/2, at y = x - (a + b (2 s)^2) s m.
///
/// The true blur of a surface of slope c is the disc of radius |c|, of one moving by m the
/// segment of length |m|. The grid's own blur (a near-Gaussian of variance g per axis: cells,
/// smoothing, bilinear lookup) widens whatever the rays' shear covers. A plain narrowed disc, a
/// = sqrt(1 - 4 rho^2) and b = 0 with rho = sqrt(g) / |c| (the segment: sqrt(1 - 12 rho^2), rho
/// = sqrt(g) / |m|), gives the blur the true one's second moment but not its shape: the
/// Gaussian rounds the disc's steep rim, so a defocused edge's profile came out too steep in
/// its middle and too long at its ends, by about 1% of the occluder's radiance at rho = 0.16
/// (the thin-lens edge of layers_test at 1024 spp: the column means against the closed form,
/// RMS 0.0032 of the edge's contrast, worst 0.012). Drawing the rays towards the rim (b < 0)
/// compensates. Per rho, a and b minimise the squared difference between the edge profile of
/// the shaped disc (segment) convolved with a Gaussian of sigma rho and that of the unit disc
/// (segment), over monotone maps (a + 3 b >= 0; scripts/shaped_shear.py prints the tables).
/// That takes 25-52% off the RMS of the disc's profile error below rho = 0.45 (0.0053 -> 0.0028
/// of the edge's contrast at rho = 0.15, 0.0134 -> 0.0084 at 0.3; the test's edge at 1024 spp
/// 0.0032 -> 0.0017), and 27-42% off the segment's from rho = 0.06 to 0.2. Past the last entry
/// (rho >= 1/2 for the disc, 1/sqrt(12) for the segment) the grid alone has the true blur's
/// second moment and the ray is not sheared.
struct Shaped {
    float a = 0, b = 0;
};
/// (a, b) at rho from a table at rho = 0, step, ...; none from `limit`, linear between entries.
/// (traceBlurredRays interpolates a layer's table of these likewise, written out there.)
template <int N>
Shaped shaped(float rho, const Shaped (&table)[N], float step, float limit) {
    if (!(rho < limit)) return {};
    const float at = std::min(rho / step, float(N - 1) - 1e-3f);
    const int i = int(at);
    const float f = at - float(i);
    return {table[i].a + f * (table[i + 1].a - table[i].a), table[i].b + f * (table[i + 1].b - table[i].b)};
}
/// The disc's (a, b) at rho = 0, 0.025, ..., 0.475, then no shear at 1/2.
constexpr Shaped kDiscShape[21] = {
    {1.00000f, -0.00000f}, {1.00153f, -0.00417f}, {1.00677f, -0.01492f}, {1.01555f, -0.03761f},
    {1.02771f, -0.06661f}, {1.04971f, -0.11469f}, {1.07619f, -0.17139f}, {1.12727f, -0.27347f},
    {1.17004f, -0.36329f}, {1.17198f, -0.39066f}, {1.15090f, -0.38363f}, {1.12572f, -0.37524f},
    {1.09538f, -0.36513f}, {1.06032f, -0.35344f}, {1.02180f, -0.34060f}, {0.97460f, -0.32487f},
    {0.91818f, -0.30606f}, {0.85231f, -0.28410f}, {0.76514f, -0.25505f}, {0.54811f, -0.18270f},
    {0.f, 0.f}};
/// The segment's (a, b) at rho = 0, 0.02, ..., 0.28, then none at 0.3 (no shear from 1/sqrt(12)).
constexpr Shaped kSegmentShape[16] = {
    {1.00000f, -0.00000f}, {1.00241f, -0.00495f}, {1.00933f, -0.02554f}, {1.02231f, -0.05869f},
    {1.04543f, -0.11810f}, {1.08050f, -0.20810f}, {1.12954f, -0.32840f}, {1.13702f, -0.37901f},
    {1.10708f, -0.36903f}, {1.07402f, -0.35801f}, {1.02882f, -0.34294f}, {0.96843f, -0.32281f},
    {0.89640f, -0.29880f}, {0.74059f, -0.24641f}, {0.41005f, -0.12985f}, {0.f, 0.f}};

/// The grid's own blur without its Gaussian, variance per axis (pixels^2): the cells a sample is
/// splatted into (1/12) and the bilinear lookup (1/6).
constexpr float kCellBlur = 1.f / 12.f + 1.f / 6.f;
/// ... the cells' alone: the blur across a crisp layer's motion (Layer::crisp).
constexpr float kCellOnly = 1.f / 12.f;
/// The true blur of a surface of slope c and screen motion `motion` (pixels), variance per axis
/// (pixels^2): a disc of radius |c| (c^2 / 4) and a segment of length |m| (m^2 / 12).
inline float trueBlurOf(float c, float motion) { return 0.25f * sqr(c) + sqr(motion) / 12.f; }
/// The sharp threshold (pixels^2 per axis): the grid's own blur with the smallest Gaussian, times
/// sharpShare.
inline float sharpThreshold(const LayerOptions& o) { return o.sharpShare * (kCellBlur + sqr(o.sigmaMin)); }
/// The grid's share of a pixel whose layer's samples there have mean slope c and whose layer
/// moves by `motion` (the rest is its own samples', as a sharp layer's): 1 from the sharp
/// threshold on, 0 below sharpBand times its blur radius (the square root of the true blur),
/// linear in the radius between (LayerOptions::sharpBand). At sharpBand 1: 1 at and above the
/// threshold, 0 below it.
inline float sharpWeight(float c, float motion, const LayerOptions& o) {
    const float b = trueBlurOf(c, motion), hi = sharpThreshold(o);
    if (b >= hi) return 1.f;
    const float radius = std::sqrt(b), top = std::sqrt(hi), foot = std::clamp(o.sharpBand, 0.f, 1.f) * top;
    return radius <= foot ? 0.f : (radius - foot) / (top - foot);
}
/// Whether a layer of mean slope c, slopes spreading over `spread` and mean screen motion `motion`
/// (pixels) is sharp: its pixels' own samples alone, the grid's share nil at its farthest slope.
/// (At sharpBand 1: its true blur below the threshold.)
inline bool isSharp(float c, float spread, float motion, const LayerOptions& o) {
    return sharpWeight(std::abs(c) + 0.5f * spread, motion, o) == 0.f;
}

/// Whether a sample's screen motion over the shutter puts it in a motion group (else it is still).
inline bool movesOnScreen(Vec2f m) { return m.x * m.x + m.y * m.y > kMoving * kMoving; }

/// A sample's defocus slope (pixels per unit of lens radius). A non-finite slope, which no valid
/// scene gives, counts as in focus: every sample must fall in a slope bin of its class.
/// From the sample's 1 / max(depth, 1e-6) (0 for a miss) and the view's 1 / focusDistance.
inline float slopeAt(float inverseDepth, const ViewGeometry& view, float inverseFocus) {
    const float slope = view.defocusSlopeAt(inverseDepth, inverseFocus);
    return std::isfinite(slope) ? slope : 0.f;
}
inline float slopeOf(const LightFieldSample& s, const ViewGeometry& view) {
    return slopeAt(1.f / std::max(s.hit() ? s.depth : kInf, 1e-6f), view, 1.f / view.focusDistance);
}

/// The cell of a grid whose cell (i, j) covers the pixels [(gx0 + i) s, (gx0 + i + 1) s) x [(gy0
/// + j) s, (gy0 + j + 1) s) (gw x gh cells, row-major; s the cell's size, 1 / inv pixels: Layer::
/// step) that holds point p, as its column i and row j: whether p is on the grid.
[[gnu::always_inline]] inline bool gridCellAt(int gx0, int gy0, int gw, int gh, Vec2f p, float inv, int& i, int& j) {
    i = int(std::floor(p.x * inv)) - gx0, j = int(std::floor(p.y * inv)) - gy0;
    return i >= 0 && j >= 0 && i < gw && j < gh;
}
/// ... as its index (row-major); -1 off the grid.
inline int gridCell(int gx0, int gy0, int gw, int gh, Vec2f p, float inv = 1.f) {
    int i, j;
    return gridCellAt(gx0, gy0, gw, gh, p, inv, i, j) ? j * gw + i : -1;
}
/// How far along its screen chord m (its motion from the shutter's open to its close) a point
/// moving at constant velocity in space is at time s = t - 1/2 from where it is at mid-shutter,
/// as a multiple of m, where its depth is Z_h (1 + g s) (g: the depth's change over the
/// shutter, relative to the depth at mid-shutter). Under a pinhole a straight path in space
/// projects to a straight path on screen, but not at a constant rate: with x = F X / Z, x(s) -
/// x(0) = w s / (1 + g s) (w the screen velocity at mid-shutter), so the chord is m = w / (1 -
/// g^2 / 4) and the offset m s (1 - g^2 / 4) / (1 + g s); s itself where g = 0. Moving towards
/// the camera (g < 0) a point covers more of its chord late in the shutter, moving away early.
/// (Reprojected along the chord at a constant rate, a sphere moving 1 unit away from a depth of
/// 3.7 over the shutter, its chord 100 px, put its mid-shutter samples 6 px from its others in
/// its sharp image: docs/layers.md, "Objects moving in depth: the rate along the chord".)
/// (s itself where g = 0, without the division: the same value, and most layers are still.)
[[gnu::always_inline]] inline float alongChord(float s, float g) { return g == 0.f ? s : (1.f - 0.25f * g * g) * s / (1.f + g * s); }
/// Whether a sample of inverse depth q at shutter time t lies clearly (kOrderMargin) in front of
/// every point of a moving layer whose nearest sample has inverse depth invDepthMax and whose
/// depth changes at the rate g. Its nearest point's inverse depth at t is that sample's taken at
/// the shutter's open (moving away, g > 0) or close, moved along the rate: invDepthMax (1 + g
/// s0) / (1 + g (t - 1/2)); compared as q (1 + g (t - 1/2)) against the numerator, without a
/// division.
inline bool inFrontOfMoving(float invDepthMax, float g, float q, float t) {
    const float numerator = (1.f + kOrderMargin) * invDepthMax * (1.f + g * (g > 0.f ? -0.5f : 0.5f));
    return q * (1.f + g * (t - 0.5f)) > numerator;
}
/// The largest offset of a point from its mid-shutter position, as a share of its chord, where
/// its depth changes at the rate g (alongChord): (1 + |g| / 2) / 2.
inline float chordReach(float g) { return 0.5f * (1.f + 0.5f * std::abs(g)); }
/// The middle of the chord, as an offset from the mid-shutter point (a share of the chord) where
/// the depth changes at the rate g: (alongChord(1/2, g) + alongChord(-1/2, g)) / 2 = -g / 4.
[[gnu::always_inline]] inline float chordMiddle(float g) { return -0.25f * g; }
/// Where sample s lies in the sharp image of slope c and screen motion (mx, my) of a surface
/// whose depth changes at the relative rate g (alongChord): y = x + c u - m a(t) (film y: y - c
/// v - m_y a(t)), a(t) = alongChord(t - 1/2, g), t - 1/2 where g = 0. (Always inlined, as
/// layerPosition: left to the compiler, a call per sample and layer in the still layers' D pass
/// made docs/bunny-near.json's stage 9% slower.)
[[gnu::always_inline]] inline Vec2f shearOf(const Gathered& s, float c, float mx, float my, float g) {
    const float dt = alongChord(s.t - 0.5f, g);
    return {s.x + c * s.u - mx * dt, s.y - c * s.v - my * dt};
}
/// Where sample s lies in a layer's grid: its own position in a sharp layer, else its shear.
[[gnu::always_inline]] inline Vec2f layerPosition(const Gathered& s, bool sharp, float c, float mx, float my, float g) {
    return sharp ? Vec2f{s.x, s.y} : shearOf(s, c, mx, my, g);
}
/// Arcs of a large turn. The parabola of curvedShift is the arc's limit for a small turn; a
/// point turning at a steady rate by theta over the shutter is, at shutter offset d (its chord's
/// pace a), A(a) m - B(d) e from its mid-shutter place, A(a) = sin(theta a) / (2 sin(theta/2)),
/// B(d) = (1 - cos(theta d)) / (1 - cos(theta/2)): d and 4 d^2 as theta goes to 0, the same ends
/// (m/2 - e), and along the chord the pace of the turn, not a steady one (at a quarter of a
/// 90-degree turn 0.271 of the chord where the parabola puts it at 0.25). A turning layer's
/// theta is its samples' (|e| / |m| = tan(theta/4) / 2, e across the chord), at most half a
/// turn, and A and B are d sinc(theta d) / sinc(theta/2) and 4 d^2 f(theta d) / f(theta/2), f(x) =
/// 2 (1 - cos x) / x^2, each a polynomial in (theta d)^2 to within 3e-6 (plain arithmetic, for
/// motionCells' SIMD loop; the rays' loop with it is not vectorised: traceBlurredRays, kArc).
/// (With the parabola the bars of docs/fan.json turning 90 degrees showed sectors 10% too bright
/// or too dark winding with the turn: docs/layers.md, "Arcs of a large turn".)
struct ArcPace {
    float theta2 = 0, invSincHalf = 1, invBendHalf = 1;  // theta^2, 1 / sinc(theta/2), 1 / f(theta/2)
    static float sinc(float u) { return 1.f - u * (1.f / 6 - u * (1.f / 120 - u * (1.f / 5040 - u * (1.f / 362880)))); }  // u = x^2
    static float bend(float u) { return 1.f - u * (1.f / 12 - u * (1.f / 360 - u * (1.f / 20160 - u * (1.f / 1814400)))); }
    /// For a turn of `theta` radians, at most half a turn, of samples moving at most `motion`
    /// pixels along a chord and `sag` across it: the parabola's d and 4 d^2 (theta 0) where the
    /// arc would move none of their points by a quarter of a pixel from it (the same images and
    /// time as before where a layer turns little or in depth: ArcPace's rays run slower).
    void build(float theta, float motion, float sag) {
        float t = std::clamp(theta, 0.f, kPi);
        if (t > 0.f) {
            const double sinHalf = std::sin(0.5 * t), cosHalf = std::cos(0.5 * t);
            double most = 0;
            for (int i = 1; i <= 16; ++i) {
                const double d = 0.5 * i / 16.0;
                most = std::max(most, std::abs(std::sin(t * d) / (2.0 * sinHalf) - d) * motion +
                                          std::abs((1.0 - std::cos(t * d)) / (1.0 - cosHalf) - 4.0 * d * d) * sag);
            }
            if (most < 0.25) t = 0.f;
        }
        theta2 = t * t;
        invSincHalf = 1.f / sinc(0.25f * theta2);
        invBendHalf = 1.f / bend(0.25f * theta2);
    }
    /// A(a) and B(d) (above).
    [[gnu::always_inline]] float chord(float a) const { return a * sinc(theta2 * a * a) * invSincHalf; }
    [[gnu::always_inline]] float arc(float d) const { return 4.f * d * d * bend(theta2 * d * d) * invBendHalf; }
};
/// Curved trajectories. A turning object's point moves on the screen along an arc, not its
/// chord: at mid-shutter it is off the chord's middle by its sagitta s (TracedSample::sag;
/// along the chord as well as across it: a point turning in depth near a silhouette moves
/// unevenly along it). Its sample is reprojected along the parabola through the chord's ends and
/// that point, y(t) = chord(t) - 4 e (t - 1/2)^2, chord(t) the chord at alongChord's pace,
/// whose mid-shutter point is already m g / 4 along the chord (alongChord), so e = s - m g / 4.
/// Along the chord alone a sample taken at the open or the close of the shutter landed up to
/// |s| from its point's mid-shutter place, and a turning bunny's silhouette, whose points move
/// in depth there, came out sharp and 2 px wide of its blurred edge (docs/layers.md, "Curved
/// trajectories"). Where a sample taken at time t, at its chord's pace a (alongChord), with
/// motion m and effective sagitta e lies in its own layer's sharp image: its shear plus this,
/// 4 e (t - 1/2)^2 on the parabola, and along a large turn's arc its pace's difference from the
/// chord's too (ArcPace: with theta 0, the parabola exactly).
inline Vec2f curvedShift(const ArcPace& pace, Vec2f m, Vec2f e, float a, float t) {
    const float along = pace.chord(a) - a, across = pace.arc(t - 0.5f);
    return {across * e.x - along * m.x, across * e.y - along * m.y};
}
/// The effective sagitta e of a sample in a layer of depth rate g (curvedShift).
inline Vec2f effectiveSag(const Gathered& s, Vec2f sag, float g) { return {sag.x - 0.25f * g * s.mx, sag.y - 0.25f * g * s.my}; }
inline bool curved(Vec2f sag) { return sag.x != 0.f || sag.y != 0.f; }

/// The time bin of shutter time t among `bins`.
inline int timeBinOf(int bins, float t) { return std::min(bins - 1, int(t * float(bins))); }
/// A sample into its cell of a layer's accumulation (Layer::acc: N, the sum of the slopes, then
/// per time bin W and the radiance) and the cell's D: for its own layer and for a sharp twin alike.
inline void splatCell(float* cellAcc, float& d, float c, int bin, const Vec3f& radiance) {
    cellAcc[0] += 1.f;
    cellAcc[1] += c;
    d += 1.f;
    float* a = cellAcc + 2 + 4 * bin;
    a[0] += 1.f;
    a[1] += radiance.x;
    a[2] += radiance.y;
    a[3] += radiance.z;
}

/// The least-squares affine fit m(p) = mean + B (p - centre) of a moving layer's samples' screen
/// motion to their positions in its sharp image. An object moving in depth grows or shrinks on
/// screen over the shutter, so its samples' motion spreads radially, about linearly in their
/// position: a ray at the shutter's open past the rim of its mid-shutter image, where the grid
/// has no samples, takes the motion the rim would have there and finds the rim (with the
/// layer's mean motion it missed it: a sphere moving 1 unit away from a depth of 3.7, the
/// trail's start too bright, docs/layers.md, "Objects moving in depth: the rate along the chord").
struct AffineMotion {
    Vec2f mean, centre;
    float b00 = 0, b01 = 0, b10 = 0, b11 = 0;
    /// The fit at p, its offset from the mean at most `limit` long.
    Vec2f at(Vec2f p, float limit) const {
        const float dx = p.x - centre.x, dy = p.y - centre.y;
        float ox = b00 * dx + b01 * dy, oy = b10 * dx + b11 * dy;
        const float len2 = ox * ox + oy * oy;
        if (len2 > limit * limit) {
            const float k = limit / std::sqrt(len2);
            ox *= k, oy *= k;
        }
        return {mean.x + ox, mean.y + oy};
    }
};

/// The count of a gw x gh grid's cells where `has(i, j)`, summed over rectangles: sat[(j + 1)
/// (gw + 1) + i + 1] counts the cells [0, i] x [0, j] ((gw + 1) x (gh + 1) entries).
template <class Has>
void summedArea(int gw, int gh, std::vector<int>& sat, Has&& has) {
    sat.assign(size_t(gw + 1) * (gh + 1), 0);
    for (int j = 0; j < gh; ++j) {
        int row = 0;
        for (int i = 0; i < gw; ++i) {
            row += has(i, j) ? 1 : 0;
            sat[size_t(j + 1) * (gw + 1) + i + 1] = sat[size_t(j) * (gw + 1) + i + 1] + row;
        }
    }
}

/// Grid cells [x0, x1) x [y0, y1) (empty where x0 >= x1 or y0 >= y1): where a layer's
/// accumulations can be non-zero. Its passes (smoothRun, smoothAcrossEdges, resolveCells) work
/// within it and leave the rest of the grid as it is: zero, or what every empty cell resolves to.
/// A blurred layer's grid is its tile and a margin as wide as its blur reaches, and its samples
/// fill a part of it (an object, a slat): on docs/many-motion.json 4% of its cells, 9% of them
/// with a D; conference at 512x512 35% (docs/layers.md, "Empty cells").
struct CellBox {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x0 >= x1 || y0 >= y1; }
    /// Grown by rx cells each way along x and ry along y, within a gw x gh grid.
    CellBox grown(int rx, int ry, int gw, int gh) const {
        if (empty()) return *this;
        return {std::max(0, x0 - rx), std::max(0, y0 - ry), std::min(gw, x1 + rx), std::min(gh, y1 + ry)};
    }
    CellBox shifted(int dx, int dy) const { return {x0 + dx, y0 + dy, x1 + dx, y1 + dy}; }
    bool contains(int i, int j) const { return i >= x0 && i < x1 && j >= y0 && j < y1; }
    CellBox united(const CellBox& b) const {
        if (empty()) return b;
        if (b.empty()) return *this;
        return {std::min(x0, b.x0), std::min(y0, b.y0), std::max(x1, b.x1), std::max(y1, b.y1)};
    }
};
/// The box of the cells a summed-area table (summedArea) counts, from its last row (per column)
/// and last column (per row).
CellBox summedBox(const std::vector<int>& sat, int gw, int gh) {
    const int* lastRow = &sat[size_t(gh) * (gw + 1)];
    CellBox b{gw, gh, 0, 0};
    for (int i = 0; i < gw; ++i)
        if (lastRow[i + 1] > lastRow[i]) b.x0 = std::min(b.x0, i), b.x1 = i + 1;
    for (int j = 0; j < gh; ++j)
        if (sat[size_t(j + 1) * (gw + 1) + gw] > sat[size_t(j) * (gw + 1) + gw]) b.y0 = std::min(b.y0, j), b.y1 = j + 1;
    return b.empty() ? CellBox{} : b;
}
/// The box of the cells of a grid (gw x gh cells of `stride` channels) whose first channel is not zero.
CellBox nonZeroBox(const std::vector<float>& grid, int gw, int gh, int stride = 1) {
    CellBox b{gw, gh, 0, 0};
    for (int j = 0; j < gh; ++j) {
        const float* row = &grid[size_t(j) * gw * stride];
        int first = 0;
        while (first < gw && row[size_t(first) * stride] == 0.f) ++first;
        if (first == gw) continue;
        int last = gw - 1;
        while (row[size_t(last) * stride] == 0.f) --last;
        b.x0 = std::min(b.x0, first), b.x1 = std::max(b.x1, last + 1), b.y0 = std::min(b.y0, j), b.y1 = j + 1;
    }
    return b.empty() ? CellBox{} : b;
}

struct Layer {
    double sumC = 0, sumMx = 0, sumMy = 0, sumM2 = 0, sumMx2 = 0, sumInvDepth = 0;  // sumM2: of |motion|^2; sumMx2: of its x's square
    float cMin = kInf, cMax = -kInf;
    float invDepthMax = 0;  // of its nearest sample (0: a miss)
    float invDepthMin = kInf;  // of its farthest
    int count = 0;
    bool moving = false;
    // Its motion group's depth over the shutter, Z_h (1 + depthRate (t - 1/2)) (alongChord; 0
    // for a still layer, or where the depth does not change measurably).
    float depthRate = 0;
    bool inFrontOfAll(float q, float t) const { return moving && inFrontOfMoving(invDepthMax, depthRate, q, t); }
    // The shear y = x + c u - m (t - 1/2) (film y: y - c v - m_y (t - 1/2)) and the sharp image's filter.
    float c = 0, mx = 0, my = 0, invDepth = 0;
    // The root mean square of its samples' screen motion: its mean's length where they move
    // alike, more where they do not (an object turning about a point of it moves one way on one
    // side and the other way on the other, its mean motion near nothing: judged by the mean, its
    // layer was sharp and its samples stayed where they were taken).
    float motionRms = 0;
    // ... and its x and y components' (a layer's grid reaches along each axis as far as its motion
    // there: reachAxes in reconstructLayers).
    float motionRmsX = 0, motionRmsY = 0;
    // The largest |x| and |y| of its samples' motion and of their sagittas: how far from its sharp
    // image along each axis a ray at the shutter's ends may look, where the layer turns (its
    // samples carry sagittas; reachAxes in reconstructLayers). A turn's motion grows with the
    // distance from its pivot, so its tips' is the largest, well past the root mean square: a fan
    // turning 90 degrees had its grid end short of its blades' tips, and the rays there read the
    // grid's clamped edge, which filled 64-px boxes outside the disc it sweeps with the tips'
    // colour (docs/layers.md, "A turning fan's tips"). Elsewhere the root mean square stays:
    // the largest measured 10-28% more stage time on docs/sponza-dolly.json and turning-room.json
    // for the same or 3% higher relMSE (there a clamped edge continues a large surface).
    Vec2f motionMax{}, sagMax{};
    // A moving layer's whose depth changes: how far beyond the lens's reach from the tile (per
    // axis, pixels) the sharp positions of those of its samples lie whose paths over the shutter
    // (the lens's disc around them) cross the tile, the farthest of them (reachAxes in
    // reconstructLayers). An object moving in depth grows or shrinks on screen, its motion
    // growing from its middle to its rim, and the points that reach the tile late or early lie
    // farther than the root mean square of the motion says (docs/layers.md, "An object rushing
    // towards the camera").
    Vec2f tileNeed{};
    // Its turning samples' summed |sagitta| across their chords and |motion| (the turn's angle),
    // and their pace along their arcs (ArcPace).
    double arcSag = 0, arcMotion = 0;
    ArcPace arc;
    // The rays' shear, shaped by the grid's own blur (Shaped): a ray at lens point u (unit disc)
    // is sheared by (rayC + rayC2 |u|^2) u, one at time t by (1 + rayT2 (2 s)^2) s rayM, s = t -
    // 1/2. A ray that takes the slope c of the surface it finds is sheared by (A(c) + B(c)
    // |u|^2) u, linear in a table of kShearSteps steps over the layer's slopes (traceBlurred;
    // computing them per ray, a division and the table's lookup, measured 11-19% more time in
    // the stage than the narrowed disc's square root before it, three rounds on conference and
    // cornell).
    float rayC = 0, rayC2 = 0, rayMx = 0, rayMy = 0, rayT2 = 0;
    float gridBlur = 0;  // the grid's own blur, variance per axis (pixels^2)
    // ... what the lens shear is shaped for: gridBlur, or across a crisp layer's motion its cells'
    // alone (1/12: no Gaussian, and the lookup the nearest cell).
    float lensBlur = 0;
    // A blurred moving layer's rays are sheared by motionScale times the screen motion of the
    // surface they find there (motionGrid: per cell the mean motion of the layer's samples,
    // smoothed; where it has none, the affine fit of its samples' motion to their position, so
    // that a ray past the rim of an object growing or shrinking on screen finds the rim): a
    // sphere's front moves faster on screen than its silhouette, and the layer's mean motion
    // stretched its blur (layers.cpp, the splat).
    float motionScale = 1, maxMotion = 0;
    float motionSpread = 0;  // the largest |motion - motionFit.mean| over motionGrid
    std::vector<float> motionGrid;
    // Where its samples are a turning object's: per cell (as motionGrid) the mean effective
    // sagitta of their paths (curvedShift), 0 where it has none; empty where no sample of the
    // layer turns. maxSag: its largest length.
    std::vector<float> sagGrid;
    float maxSag = 0;
    AffineMotion sagFit;  // the affine fit of the effective sagittas to the sharp position, as motionFit
    // The affine fit of its samples' motion to their sharp position, its centre in film pixels:
    // where a ray or a sample behind starts on the layer (motionShift).
    AffineMotion motionFit;
    static constexpr int kShearSteps = 8;
    float shearFrom = 0, shearScale = 0;  // the table's index: (c - shearFrom) shearScale
    Shaped shearTable[kShearSteps + 1];
    /// Whether the layer's slopes spread so far that its rays take the slope of the surface
    /// they find (from shearTable) rather than the layer's.
    bool followsSlope() const { return cMax - cMin >= kSlopeSpread; }
    /// The shaped lens shear (A, B) of the slope c.
    Shaped shear(float c) const {
        if (sqr(c) <= 4.f * lensBlur) return {};
        const Shaped k = shaped(std::sqrt(lensBlur) / std::abs(c), kDiscShape, 0.025f, 0.5f);
        return {c * k.a, c * k.b};
    }
    /// The rays' lens and shutter shear for the grid's blur (gridBlur, lensBlur): the lens's
    /// disc shaped for lensBlur (none where the disc is within it), and the motion's segment
    /// for what of the grid's blur the lens shear does not carry, so that the second moments
    /// add up to the true c^2 / 4 + m^2 / 12: the grid's, the shaped disc's c^2 / 4 - lensBlur
    /// (or nothing, below it) and the shaped segment's (none where the grid's blur alone
    /// reaches it). `motion`: the layer's RMS screen motion (pixels).
    void shapeRays(float motion) {
        if (followsSlope()) buildShearTable();
        const Shaped lens = shear(c);
        rayC = lens.a, rayC2 = lens.b;
        const float rest = gridBlur - std::min(0.25f * sqr(c), lensBlur);
        const Shaped k = motion > 0 ? shaped(std::sqrt(rest) / motion, kSegmentShape, 0.02f, 0.288675f) : Shaped{};
        rayMx = mx * k.a, rayMy = my * k.a;
        motionScale = k.a;
        rayT2 = k.a > 0 ? k.b / k.a : 0.f;
    }
    void buildShearTable() {
        const float step = (cMax - cMin) / float(kShearSteps);
        shearFrom = cMin;
        shearScale = step > 0 ? 1.f / step : 0.f;
        for (int i = 0; i <= kShearSteps; ++i) shearTable[i] = shear(cMin + step * float(i));
    }
    bool sharp = true;
    bool sharpRun = false;  // several still layers, each sharp, merged into one (splitLayers)
    // A blurred layer some of whose pixels lie in the sharp band (LayerOptions::sharpBand): per
    // pixel of its tile (row-major), the grid's share w (sharpWeight of the pixel's mean slope)
    // and, times 1 - w, the alpha and premultiplied light of the pixel's own samples, as a sharp
    // layer's (Blend). Empty: the grid alone.
    std::vector<float> own;
    // The Gaussians of the sharp image (layers.h, step 2): sigma for the radiance and the motion,
    // sigmaCoverage (<= sigma) for N, D and the slope, whose grid blur the rays' shear is shaped for.
    float sigma = 0, sigmaCoverage = 0;
    // A blurred moving layer whose samples move along one grid axis only (and are in focus) keeps
    // the other axis crisp: its lookup there the nearest cell, the pixel's own row (column) of
    // samples, and no Gaussian across the motion but the radiance's, stopped at edges
    // (smoothAcrossEdges), or where the samples carry their own light its plain one
    // (LayerOptions::crispRadiance) (-1: neither; 0: x crisp; 1: y).
    int crisp = -1;
    float sigmaX(float s) const { return crisp == 0 ? 0.f : s; }
    float sigmaY(float s) const { return crisp == 1 ? 0.f : s; }
    int timeBins = 1;
    // The grid: cell (i, j) covers the pixels [(gx0 + i) step, (gx0 + i + 1) step) x [(gy0 + j)
    // step, (gy0 + j + 1) step). (Half-pixel cells blur less but are noisier: AAF relMSE on
    // conference at 512x512 0.000625 -> 0.000842.) A cell is a pixel but in a blurred still
    // layer whose blur would take its grid more than LayerOptions::stillGridReach pixels beyond
    // its tile: there it is `step` pixels a side, the fewest that keep the grid within that many
    // cells (its sigmas are in cells, and its own blur, gridBlur, step^2 times a 1-px grid's:
    // "Blur past the grid's reach" in docs/layers.md); and in a moving layer whose grid of 1-px
    // cells would have more than LayerOptions::maxGridMargin allows, the fewest pixels that fit
    // (the motion grid's fits are in pixels all the same, inPixels; no crisp axis on such
    // cells: "Larger cells for a long motion").
    int gx0 = 0, gy0 = 0, gw = 0, gh = 0;
    int step = 1;
    float invStep = 1.f;
    // Per cell: N, the sum of the samples' slopes, then per time bin W, R, G, B (accumulated;
    // the coverage's channels first, so that each Gaussian smooths a contiguous run), or alpha,
    // then per time bin R, G, B, and last the layer's own slope there (resolved: a slanted
    // surface's slope changes across the tile, and the rays follow it). D has a grid of its own
    // (accD): every sample behind the layer adds to it, at scattered cells, and a 4-byte cell
    // keeps those writes in cache (a moving layer's accumulated cell is 136 bytes).
    std::vector<float> acc, accD, cell;
    // `cell` holds the cells of cellBox alone (row-major, cellBox's width a row): the box
    // resolveCells resolved, grown by one cell within the grid. Every other cell resolves to what
    // that ring's do (alpha 0, no light, the layer's slope), so a lookup beyond the box reads the
    // nearest cell of it (cellAt): the values of a whole grid, in the part of its memory its
    // samples reach (docs/layers.md, "Memory per thread").
    CellBox cellBox;
    // acc holds the cells of accWin alone (row-major, accWin's width a row): the cells its own
    // samples land in, grown by as far as its Gaussians carry them; accD those of dWin, grown
    // farther, by the Ds that can change its coverage (dMargin), their Gaussian and
    // resolveCells' rings, within the grid (reconstructLayers, before the splat). Beyond accWin
    // acc is zero; a D beyond dWin is not counted: it would change nothing (dMargin says why).
    CellBox accWin, dWin;
    /// The index in acc (times accStride) of the grid's cell (i, j), within accWin; in accD, within dWin.
    int accAt(int i, int j) const { return (j - accWin.y0) * (accWin.x1 - accWin.x0) + (i - accWin.x0); }
    int dAt(int i, int j) const { return (j - dWin.y0) * (dWin.x1 - dWin.x0) + (i - dWin.x0); }
    bool inAcc(int i, int j) const { return accWin.contains(i, j); }
    /// The index in `cell` of the grid's cell (i, j), or of the nearest one cellBox holds.
    size_t cellAt(int i, int j) const {
        const int w = cellBox.x1 - cellBox.x0;
        return size_t(std::clamp(j - cellBox.y0, 0, cellBox.y1 - cellBox.y0 - 1)) * size_t(w) + size_t(std::clamp(i - cellBox.x0, 0, w - 1));
    }
    // Where acc can be non-zero: its cells with N > 0, since a sample adds to every channel at
    // one cell (CellBox; set by the D passes, which count those cells anyway).
    CellBox accBox;
    /// Summed-area table of the cells with alpha > 0 ((gw + 1) x (gh + 1)): a pixel whose rays
    /// can reach only uncovered cells skips the layer (exactly: it would add nothing there).
    std::vector<int> covered;
    /// How far (pixels) a ray's lookups can land from the pixel: the largest slope (the rays
    /// follow the slope they find, never beyond the layer's extremes) and half the motion.
    float rayReach = 0;
    /// ... along each axis apart (a layer moving sideways reaches a pixel's rays from far along
    /// x, from as far as its blur along y): the slope, and each axis's largest motion and sagitta
    /// (motionExtent, sagExtent).
    Vec2f rayExtent{};
    Vec2f motionExtent{}, sagExtent{};  // the largest |x| and |y| over motionGrid, sagGrid
    // A moving layer's window (traceWindowed): the least and largest lens shear A + B |u|^2 its
    // rays can take where they follow the slope they find (over its slope table), and per block
    // of kWindowBlock x kWindowBlock cells of motionGrid the least and largest motion a ray whose
    // first lookup lands in the block can read (bilinear, or a crisp axis's nearest cell: two
    // cells beyond the block each way): x lo, x hi, y lo, y hi.
    float shearLo = 0, shearHi = 0;
    static constexpr int kWindowBlock = 8;
    int blocksX = 0, blocksY = 0;
    std::vector<float> windowBlocks;
    void buildWindow() {
        shearLo = shearHi = 0;
        if (followsSlope()) {
            shearLo = kInf, shearHi = -kInf;
            for (const Shaped& k : shearTable) shearLo = std::min({shearLo, k.a, k.a + k.b}), shearHi = std::max({shearHi, k.a, k.a + k.b});
        }
        windowBlocks.clear();
        blocksX = blocksY = 0;
        if (motionGrid.empty()) return;
        blocksX = (gw + kWindowBlock - 1) / kWindowBlock, blocksY = (gh + kWindowBlock - 1) / kWindowBlock;
        windowBlocks.assign(size_t(blocksX) * blocksY * 4, 0.f);
        for (int by = 0; by < blocksY; ++by)
            for (int bx = 0; bx < blocksX; ++bx) {
                const int i0 = std::max(0, bx * kWindowBlock - 2), i1 = std::min(gw, (bx + 1) * kWindowBlock + 2);
                const int j0 = std::max(0, by * kWindowBlock - 2), j1 = std::min(gh, (by + 1) * kWindowBlock + 2);
                Vec2f lo{kInf, kInf}, hi{-kInf, -kInf};
                for (int j = j0; j < j1; ++j)
                    for (int i = i0; i < i1; ++i) {
                        const float* m = &motionGrid[2 * (size_t(j) * gw + size_t(i))];
                        lo = vmin(lo, Vec2f{m[0], m[1]}), hi = vmax(hi, Vec2f{m[0], m[1]});
                    }
                float* w = &windowBlocks[4 * (size_t(by) * blocksX + size_t(bx))];
                w[0] = lo.x, w[1] = hi.x, w[2] = lo.y, w[3] = hi.y;
            }
    }
    int accStride() const { return 2 + 4 * timeBins; }
    int cellStride() const { return 2 + 3 * timeBins; }  // ... and last the samples' mean slope there

    Vec2f sharpPosition(const Gathered& s) const { return layerPosition(s, sharp, c, mx, my, depthRate); }
    /// The blurred layer's shear of sample s with the screen motion (motionX, motionY).
    Vec2f sharpPosition(const Gathered& s, float motionX, float motionY) const { return shearOf(s, c, motionX, motionY, depthRate); }
    int cellIndex(Vec2f p) const { return gridCell(gx0, gy0, gw, gh, p, invStep); }
    int timeBin(float t) const { return timeBinOf(timeBins, t); }

    /// The cells where a sample that sees an emitter landed (LayerOptions::emitterRays; empty
    /// where none did), and their summed-area table as `covered`'s.
    std::vector<uint8_t> emitCells;
    std::vector<int> emitting;

    void buildCovered() {
        const int cs = cellStride();
        // (Every cell beyond cellBox has alpha 0.)
        const int bw = cellBox.x1 - cellBox.x0;
        summedArea(gw, gh, covered, [&](int i, int j) {
            return cellBox.contains(i, j) &&
                   cell[(size_t(j - cellBox.y0) * size_t(bw) + size_t(i - cellBox.x0)) * size_t(cs)] > 0.f;
        });
        if (!emitCells.empty()) summedArea(gw, gh, emitting, [&](int i, int j) { return emitCells[size_t(j) * gw + i] != 0; });
    }
    /// Whether any covered cell can be read by a lookup of pixel (x, y)'s rays: bilinear lookups
    /// within rayReach of the pixel's square, a sharp layer's at the pixel's own cell.
    bool reaches(int x, int y) const { return sharp ? reaches(x, y, Vec2f{}) : reaches(x, y, Vec2f{rayReach, rayReach}); }
    /// ... within r.x of the pixel's square along x and r.y along y.
    bool reaches(int x, int y, Vec2f r) const { return reaches(covered, x, y, r); }
    /// Whether a blurred layer's rays from pixel (x, y) can read a cell where an emitter was seen.
    bool reachesEmitter(int x, int y) const { return !sharp && !emitting.empty() && reaches(emitting, x, y, rayExtent); }
    /// ... any cell counted in the summed-area table `sat`.
    bool reaches(const std::vector<int>& sat, int x, int y, Vec2f r) const {
        // (In cells: pixel x's offset from the grid's origin, gx0 step, over the cell's size.)
        const int i0 = std::max(0, int(std::floor((float(x - gx0 * step) - r.x) * invStep)) - 1);
        const int i1 = std::min(gw - 1, int(std::ceil((float(x + 1 - gx0 * step) + r.x) * invStep)) + 1);
        const int j0 = std::max(0, int(std::floor((float(y - gy0 * step) - r.y) * invStep)) - 1);
        const int j1 = std::min(gh - 1, int(std::ceil((float(y + 1 - gy0 * step) + r.y) * invStep)) + 1);
        if (i0 > i1 || j0 > j1) return false;
        const size_t s = size_t(gw + 1);
        return sat[(j1 + 1) * s + i1 + 1] - sat[j0 * s + i1 + 1] - sat[(j1 + 1) * s + i0] + sat[j0 * s + i0] > 0;
    }
};

/// The slopes of one class of a tile's samples (still, or a motion group); lo > hi where it has none.
struct SlopeRange {
    float lo = kInf, hi = -kInf;
    bool empty() const { return lo > hi; }
};

/// A tile's layers, front to back, and which layer a sample is in (splitLayers).
struct Split {
    /// Per class (still, each motion group), a histogram of slopes, nearest (largest c) first, with each
    /// bin's sums: a layer is a run of bins, so its statistics are its bins'.
    struct Histogram {
        float cHi = 0, binW = 1;
        int bins = 0, base = 0;
        std::vector<int> count, binLayer;
        std::vector<double> sumC, sumMx, sumMy, sumM2, sumMx2, sumInvDepth;
        std::vector<float> cMin, cMax, invMax, invMin;
        std::vector<Vec2f> motionMax, sagMax;
        std::vector<double> arcSag, arcMotion;
        std::vector<uint8_t> sharpRun;  // per layer of the class: a merged run of sharp layers
        float invBinW = 0;  // 1 / binW where that is exact (binW a power of two, as the least, 0.25, is), else 0
        int bin(float c) const { return std::clamp(int(invBinW > 0.f ? (cHi - c) * invBinW : (cHi - c) / binW), 0, bins - 1); }
    };
    Histogram hist[kClasses];
    std::vector<int> rank;  // front-to-back rank of the layer of a histogram's run
    std::vector<Layer> layers;
    /// The layer (index into `layers`) of sample s.
    int layerOf(const Gathered& s) const {
        const Histogram& h = hist[s.cls];
        return rank[h.base + h.binLayer[s.bin]];
    }
};

/// Adds bin b of `h` to a layer's sums.
void addBin(Layer& l, const Split::Histogram& h, int b) {
    l.count += h.count[b];
    l.sumC += h.sumC[b];
    l.sumMx += h.sumMx[b];
    l.sumMy += h.sumMy[b];
    l.sumM2 += h.sumM2[b];
    l.sumMx2 += h.sumMx2[b];
    l.sumInvDepth += h.sumInvDepth[b];
    l.cMin = std::min(l.cMin, h.cMin[b]);
    l.cMax = std::max(l.cMax, h.cMax[b]);
    l.invDepthMax = std::max(l.invDepthMax, h.invMax[b]);
    l.invDepthMin = std::min(l.invDepthMin, h.invMin[b]);
    l.motionMax = vmax(l.motionMax, h.motionMax[b]);
    l.sagMax = vmax(l.sagMax, h.sagMax[b]);
    l.arcSag += h.arcSag[b];
    l.arcMotion += h.arcMotion[b];
}

/// What a tile's samples are split into layers by (splitLayers): their defocus slope, which falls
/// with depth; or, under a pinhole, where every slope is 0, with motion in the tile, their
/// inverse depth q relative to the moving samples' mean q_m, 3.5 (q / q_m - 1), so that the
/// split's threshold of half a pixel is about 14% in depth near the moving objects. Without it a
/// pinhole's still surfaces were one layer whatever their depth, composited in front of a moving
/// object or behind it as a whole: an object moving behind a post showed through it
/// (`layers_test Layers.UnderAPinholeAnObjectMovingBehindAPostStaysBehindIt`).
struct SplitKey {
    float scale = 0;  // 0: the slope
    float invReference = 0;  // 1 / q_m
    float ofInvDepth(float q) const { return scale * (q * invReference - 1.f); }
    float of(const Gathered& s) const { return scale > 0.f ? ofInvDepth(s.invDepth) : s.c; }
};

/// Merges consecutive still layers (runs of the histogram `h`'s bins, numbered by slope) that
/// would each be sharp into one, and renumbers the bins' layers; returns the new count and marks
/// the merged layers in h.sharpRun. Exact: a sharp layer is looked up at the pixel's own cell,
/// where two consecutive ones composite to (N_A L_A + N_B L_B) / D, A's alpha N_A / D over B's
/// N_B / (D - N_A) (D the samples of both and of everything behind), which is the merged
/// layer's alpha (N_A + N_B) / D times its mean light. So they take one slot of the layer budget
/// (LayerOptions::maxLayers) instead of several, and the budget goes to the blurred layers,
/// whose visibility it resolves.
/// That holds only while no other layer lies between them in depth: a moving layer (another
/// class, split on its own) whose slopes fall within the run's would be composited behind or in
/// front of the whole merged run, not between its parts. So a run never spans a slope of
/// `moving` (the tile's motion groups' slope ranges): there it is cut. (Found on a moving bunny
/// over a floor that falls away from the focal plane, 64 spp: the floor's sharp layers in front
/// of the bunny and behind it were one layer, composited in front of the bunny, and the floor
/// showed through it: +7% over 35 x 15 pixels; docs/layers.md, "Sharp runs across a moving
/// layer".)
int mergeSharpRuns(Split::Histogram& h, int nLayers, const LayerOptions& o, const SlopeRange* moving, int movingCount, const SplitKey& key) {
    std::vector<Layer> st(static_cast<size_t>(nLayers));
    for (int b = 0; b < h.bins; ++b)
        if (h.count[b] > 0) addBin(st[size_t(h.binLayer[b])], h, b);
    std::vector<int> renumber(static_cast<size_t>(nLayers));
    std::vector<uint8_t> run;
    int merged = 0;
    bool previousSharp = false;
    float runLo = kInf, runHi = -kInf;  // the current run's slopes
    for (int k = 0; k < nLayers; ++k) {
        const Layer& s = st[size_t(k)];
        const double inv = 1.0 / std::max(1, s.count);
        const float mx = float(s.sumMx * inv), my = float(s.sumMy * inv);
        const bool sharp = isSharp(float(s.sumC * inv), s.cMax - s.cMin, std::sqrt(mx * mx + my * my), o);
        // The run's slopes (keys) extended by this layer, and whether a moving layer's fall within them.
        const float keyLo = key.scale > 0.f ? key.ofInvDepth(s.invDepthMin) : s.cMin;
        const float keyHi = key.scale > 0.f ? key.ofInvDepth(s.invDepthMax) : s.cMax;
        const float lo = std::min(runLo, keyLo), hi = std::max(runHi, keyHi);
        bool between = false;
        for (int m = 0; m < movingCount; ++m) between |= !moving[m].empty() && moving[m].lo <= hi && moving[m].hi >= lo;
        if (sharp && previousSharp && !between) {
            run.back() = 1;
            runLo = lo, runHi = hi;
        } else {
            ++merged;
            run.push_back(0);
            runLo = keyLo, runHi = keyHi;
        }
        renumber[size_t(k)] = merged - 1;
        previousSharp = sharp;
    }
    for (int b = 0; b < h.bins; ++b)
        if (h.count[b] > 0) h.binLayer[b] = renumber[size_t(h.binLayer[b])];
    h.sharpRun = run;
    return merged;
}

/// How a tile's motion group's defocus slope changes over the shutter, pixels per shutter: an
/// object moving towards or away from the camera changes its slope as it moves (a sphere moving
/// 2.2 towards a camera focused at 4, from 5 to 2.8 away: -1 -> +2.3 px). Split by the slopes its
/// samples were taken at, such an object's samples fell into layers by shutter time, each with a
/// coverage averaged over the shutter and interleaved in the tile's one order with the still
/// layers at those depths, and it came out partly transparent (docs/layers.md, "Motion longer than a tile's reach, and an object moving in depth");
/// its samples are split by their slope at mid-shutter, c - rate (t - 1/2), instead.
/// The rate is the regression of the samples' slopes on their shutter times within cells of
/// kRateCell pixels of the sharp image (where a sample lies at mid-shutter): the samples of one
/// surface point, so that surfaces of different depths passing through the tile over the
/// shutter (a camera pan over a set whose depth varies) do not count as a change. It counts
/// where it is at least the layers' slope tolerance (LayerOptions::splitMin) and three of its
/// standard errors; 0 otherwise.
constexpr int kRateCell = 8;
struct SlopeMoments {
    double n = 0, t = 0, c = 0, tt = 0, ct = 0, cc = 0;
    void add(float slope, float time) {
        n += 1;
        t += time;
        c += slope;
        tt += double(time) * time;
        ct += double(slope) * time;
        cc += double(slope) * slope;
    }
};
/// The within-cell sums of `count` cells' moments (SlopeMoments: a value y against the time t),
/// pooled: the regression of y on t with an intercept per cell.
struct PooledRegression {
    double sxx = 0, sxy = 0, syy = 0, n = 0, groups = 0, sumY = 0, sumT = 0;
    bool valid() const { return n - groups >= 3 && sxx > 1e-6; }
    /// The squared standard error of the slope beta.
    double slopeVariance(double beta) const { return std::max(0.0, syy - beta * sxy) / (n - groups - 1) / sxx; }
};
PooledRegression pooledRegression(const SlopeMoments* cells, size_t count) {
    PooledRegression r;
    for (size_t k = 0; k < count; ++k) {
        const SlopeMoments& m = cells[k];
        if (m.n < 2) continue;
        r.sxx += m.tt - m.t * m.t / m.n;
        r.sxy += m.ct - m.t * m.c / m.n;
        r.syy += m.cc - m.c * m.c / m.n;
        r.n += m.n;
        r.sumY += m.c;
        r.sumT += m.t;
        r.groups += 1;
    }
    return r;
}
/// A motion group's depth over the shutter relative to its depth at mid-shutter (Layer::depthRate,
/// alongChord): the pooled within-cell regression of its samples' depth on their time (`cells`:
/// the moments of (depth, time) per cell of the sharp image, where one cell holds one surface
/// point at its several times), over the depth at mid-shutter. 0 where the regression is not
/// three standard errors from 0 or the rate is under 2% (the rate along the chord then differs
/// from uniform by under 1%), so that scenes without motion in depth keep their images.
float depthRateOf(const SlopeMoments* cells, size_t count) {
    const PooledRegression r = pooledRegression(cells, count);
    if (!r.valid()) return 0.f;
    const double beta = r.sxy / r.sxx;  // depth per shutter
    const double depthMid = r.sumY / r.n - beta * (r.sumT / r.n - 0.5);
    if (beta * beta < 9.0 * r.slopeVariance(beta) || !(depthMid > 0)) return 0.f;
    // (|g| < 2 keeps the depth positive over the shutter; 1.5: a depth 7x at its close what it
    // is at its open.)
    const double g = std::clamp(beta / depthMid, -1.5, 1.5);
    return std::abs(g) >= 0.02 ? float(g) : 0.f;
}

/// The pooled within-cell regression of `count` cells' moments (above).
float slopeRate(const SlopeMoments* cells, size_t count, const LayerOptions& o) {
    const PooledRegression r = pooledRegression(cells, count);
    if (!r.valid()) return 0.f;
    const double beta = r.sxy / r.sxx;
    return std::abs(beta) >= o.splitMin && beta * beta >= 9.0 * r.slopeVariance(beta) ? float(beta) : 0.f;
}

/// A tile's motion groups as the connected parts of its moving samples' motion field: one
/// object moving in depth grows or shrinks on screen, its samples' motion fanning out from its
/// vanishing point, and grouped by distance to a group's first motion it was cut into many
/// groups (a sphere moving towards the camera into 9, the bunny into 13), each a layer whose
/// coverage fell off at its border with the next: seams inside the object, where what is
/// behind it showed through. Here the samples are first clustered by motion within cells of
/// kFieldCell pixels at their mid-shutter sharp positions (first-fit, within max(kFieldTolerance
/// px, kFieldToleranceRel x the cluster's first motion)); clusters of neighbouring cells whose
/// mean motions are within that of each other are one group. Another object moves otherwise
/// than its neighbour there (else nothing tells them apart), so it stays a group of its own.
/// Groups past kMotionGroups join the one whose mean motion is nearest theirs. On entry a
/// moving sample's class is nonzero; on return it is 1 + its group. Returns the groups' count.
constexpr int kFieldCell = 8;
constexpr int kCellClusters = 6;
constexpr float kFieldTolerance = 3.f, kFieldToleranceRel = 0.3f;
struct FieldScratch {
    struct Cluster {
        float n, sx, sy, fx, fy;  // count, motion summed, first motion
    };
    std::vector<Cluster> clusters;  // kCellClusters per cell
    std::vector<uint8_t> used;      // per cell
    std::vector<int> parent, group;  // per cluster (group: at its root, then resolved for every cluster)
    std::vector<uint32_t> sampleCell;  // per sample: its cell (moving samples only)
};
inline float fieldTolerance2(float mx, float my) {
    return sqr(std::max(kFieldTolerance, kFieldToleranceRel * std::sqrt(mx * mx + my * my)));
}
template <class Samples>
int groupByMotionField(Samples& g, int x0, int y0, int x1, int y1, FieldScratch& f, float (&lo)[kClasses], float (&hi)[kClasses]) {
    const int ox = x0 - 64, oy = y0 - 64;
    const int nx = (x1 - x0 + 128) / kFieldCell + 1, ny = (y1 - y0 + 128) / kFieldCell + 1;
    const size_t cells = size_t(nx) * ny;
    auto cellOf = [&](const Gathered& a) {
        const float px = a.x + a.c * a.u - a.mx * (a.t - 0.5f), py = a.y - a.c * a.v - a.my * (a.t - 0.5f);
        const int ix = std::clamp(int(std::floor((px - float(ox)) / float(kFieldCell))), 0, nx - 1);
        const int iy = std::clamp(int(std::floor((py - float(oy)) / float(kFieldCell))), 0, ny - 1);
        return size_t(iy) * nx + ix;
    };
    f.used.assign(cells, 0);
    f.clusters.resize(cells * kCellClusters);
    f.sampleCell.resize(g.size());
    bool any = false;
    for (size_t si = 0; si < g.size(); ++si) {
        auto& a = g[si];
        if (a.cls == 0) continue;
        any = true;
        const size_t cell = cellOf(a);
        f.sampleCell[si] = uint32_t(cell);
        FieldScratch::Cluster* c = &f.clusters[cell * kCellClusters];
        const int used = f.used[cell];
        int k = 0, nearest = 0;
        float best = kInf;
        for (; k < used; ++k) {
            const float d2 = sqr(a.mx - c[k].fx) + sqr(a.my - c[k].fy);
            if (d2 <= fieldTolerance2(c[k].fx, c[k].fy)) break;
            if (d2 < best) best = d2, nearest = k;
        }
        if (k == used) {
            if (used < kCellClusters) {
                c[k] = {0.f, 0.f, 0.f, a.mx, a.my};
                f.used[cell] = uint8_t(used + 1);
            } else {
                k = nearest;
            }
        }
        c[k].n += 1.f, c[k].sx += a.mx, c[k].sy += a.my;
        a.cls = uint8_t(1 + k);
    }
    if (!any) return 0;
    f.parent.resize(cells * kCellClusters);
    for (size_t i = 0; i < f.parent.size(); ++i) f.parent[i] = int(i);
    auto find = [&](int i) {
        while (f.parent[size_t(i)] != i) i = f.parent[size_t(i)] = f.parent[size_t(f.parent[size_t(i)])];
        return i;
    };
    auto mean = [&](size_t i) { return Vec2f{f.clusters[i].sx / f.clusters[i].n, f.clusters[i].sy / f.clusters[i].n}; };
    for (int iy = 0; iy < ny; ++iy)
        for (int ix = 0; ix < nx; ++ix) {
            const size_t cell = size_t(iy) * nx + ix;
            for (int ka = 0; ka < f.used[cell]; ++ka) {
                const size_t ia = cell * kCellClusters + size_t(ka);
                const Vec2f ma = mean(ia);
                const float tolA = fieldTolerance2(ma.x, ma.y);
                const int nb[5][2] = {{0, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}};
                for (const auto& d : nb) {
                    const int jx = ix + d[0], jy = iy + d[1];
                    if (jx < 0 || jx >= nx || jy >= ny) continue;
                    const size_t other = size_t(jy) * nx + jx;
                    for (int kb = other == cell ? ka + 1 : 0; kb < f.used[other]; ++kb) {
                        const size_t ib = other * kCellClusters + size_t(kb);
                        const Vec2f mb = mean(ib);
                        const float d2 = sqr(ma.x - mb.x) + sqr(ma.y - mb.y);
                        if (d2 > std::max(tolA, fieldTolerance2(mb.x, mb.y))) continue;
                        const int ra = find(int(ia)), rb = find(int(ib));
                        if (ra != rb) f.parent[size_t(std::max(ra, rb))] = std::min(ra, rb);
                    }
                }
            }
        }
    // Groups in the order of their first cluster (cell by cell), their mean motions.
    f.group.assign(cells * kCellClusters, -1);
    double gx[kMotionGroups] = {}, gy[kMotionGroups] = {}, gn[kMotionGroups] = {};
    int groups = 0;
    std::vector<int> overflow;
    for (size_t cell = 0; cell < cells; ++cell)
        for (int k = 0; k < f.used[cell]; ++k) {
            const size_t i = cell * kCellClusters + size_t(k);
            const int r = find(int(i));
            int& id = f.group[size_t(r)];
            if (id == -1) {
                if (groups < kMotionGroups) id = groups++;
                else id = -2 - int(overflow.size()), overflow.push_back(r);
            }
            if (id >= 0) gx[id] += f.clusters[i].sx, gy[id] += f.clusters[i].sy, gn[id] += f.clusters[i].n;
        }
    if (!overflow.empty()) {
        // Each overflowing group's mean motion, then the nearest kept group's.
        std::vector<Vec2f> sum(overflow.size(), Vec2f{0.f, 0.f});
        std::vector<float> n(overflow.size(), 0.f);
        for (size_t cell = 0; cell < cells; ++cell)
            for (int k = 0; k < f.used[cell]; ++k) {
                const size_t i = cell * kCellClusters + size_t(k);
                const int id = f.group[size_t(find(int(i)))];
                if (id >= 0) continue;
                const size_t o = size_t(-2 - id);
                sum[o].x += f.clusters[i].sx, sum[o].y += f.clusters[i].sy, n[o] += f.clusters[i].n;
            }
        for (size_t o = 0; o < overflow.size(); ++o) {
            const Vec2f m{sum[o].x / n[o], sum[o].y / n[o]};
            int nearest = 0;
            float best = kInf;
            for (int k = 0; k < groups; ++k) {
                const float d2 = sqr(m.x - float(gx[k] / gn[k])) + sqr(m.y - float(gy[k] / gn[k]));
                if (d2 < best) best = d2, nearest = k;
            }
            f.group[size_t(overflow[o])] = nearest;
        }
    }
    // Each cluster's group, found once (not once per sample: the samples' cells and the
    // union-find walks were a third of this function on raster-pan). In place: a root's own
    // entry is its group already and stays.
    for (size_t cell = 0; cell < cells; ++cell)
        for (int k = 0; k < f.used[cell]; ++k) {
            const size_t i = cell * kCellClusters + size_t(k);
            f.group[i] = f.group[size_t(find(int(i)))];
        }
    for (int k = 1; k < kClasses; ++k) lo[k] = kInf, hi[k] = -kInf;
    for (size_t si = 0; si < g.size(); ++si) {
        auto& a = g[si];
        if (a.cls == 0) continue;
        const size_t i = size_t(f.sampleCell[si]) * kCellClusters + size_t(a.cls - 1);
        a.cls = uint8_t(1 + f.group[i]);
        lo[a.cls] = std::min(lo[a.cls], a.c);
        hi[a.cls] = std::max(hi[a.cls], a.c);
    }
    return groups;
}

/// Splits the tile's samples into layers, front to back (see layers.h, step 1).
/// `range[cls]`: the slopes of the still samples and of each motion group's (what mergeSharpRuns
/// cuts at); `rate[cls]`: how a group's slope changes over the shutter (slopeRate), whose samples
/// are binned by their slope at mid-shutter (`splitRange[cls]`: the range of the slopes binned);
/// a layer's slopes are its samples' own. One pass over the samples,
/// both classes at once, into the histograms and their bins' sums (the tile's samples are
/// megabytes: each pass is a trip through memory; three passes, with one to set each sample's
/// layer and one to renumber it front to back, were a tenth of an MC render of
/// docs/motion.json); the splat takes each sample's layer from its bin (Split::layerOf).
template <class Samples>
void splitLayers(Samples& g, const Vec2f* sags, const SlopeRange (&range)[kClasses], const float (&rate)[kClasses],
                 const float (&depthRate)[kClasses], const SlopeRange (&splitRange)[kClasses], const LayerOptions& o, Split& split,
                 const SplitKey& splitKey) {
    auto& hist = split.hist;
    for (int cls = 0; cls < kClasses; ++cls) {
        const SlopeRange& r = splitRange[cls];
        Split::Histogram& h = hist[cls];
        h.bins = 0;
        if (r.empty()) continue;
        h.cHi = r.hi;
        h.binW = std::max(0.25f, (r.hi - r.lo) / 2048.f);
        // (A product by the reciprocal of a power of two is the quotient, exactly: the same bins
        // without the division, whose latency the samples' loop below waited on.)
        int exponent = 0;
        h.invBinW = std::frexp(h.binW, &exponent) == 0.5f ? std::ldexp(1.f, 1 - exponent) : 0.f;
        h.bins = int((r.hi - r.lo) / h.binW) + 1;
        h.count.assign(h.bins, 0);
        h.binLayer.assign(h.bins, -1);
        for (auto* v : {&h.sumC, &h.sumMx, &h.sumMy, &h.sumM2, &h.sumMx2, &h.sumInvDepth}) v->assign(h.bins, 0.0);
        h.cMin.assign(h.bins, kInf);
        h.cMax.assign(h.bins, -kInf);
        h.invMax.assign(h.bins, 0.f);
        h.invMin.assign(h.bins, kInf);
        h.motionMax.assign(h.bins, Vec2f{});
        h.sagMax.assign(h.bins, Vec2f{});
        h.arcSag.assign(h.bins, 0.0);
        h.arcMotion.assign(h.bins, 0.0);
    }
    // Consecutive samples mostly fall in one bin (a pixel's, its neighbour's: one surface), so
    // each class sums its current run of one bin in registers and adds the run to the bin when
    // the bin changes (summing into the bin sample by sample chained every add through memory).
    struct Run {
        int bin = -1, count = 0;
        double c = 0, mx = 0, my = 0, m2 = 0, mx2 = 0, invDepth = 0;
        float cMin = kInf, cMax = -kInf, invMax = 0, invMin = kInf;
        Vec2f motionMax{}, sagMax{};
        double arcSag = 0, arcMotion = 0;
    };
    Run run[kClasses];
    auto flush = [&](int cls) {
        Run& r = run[cls];
        if (r.bin < 0) return;
        Split::Histogram& h = hist[cls];
        h.count[r.bin] += r.count;
        h.sumC[r.bin] += r.c;
        h.sumMx[r.bin] += r.mx;
        h.sumMy[r.bin] += r.my;
        h.sumM2[r.bin] += r.m2;
        h.sumMx2[r.bin] += r.mx2;
        h.sumInvDepth[r.bin] += r.invDepth;
        h.cMin[r.bin] = std::min(h.cMin[r.bin], r.cMin);
        h.cMax[r.bin] = std::max(h.cMax[r.bin], r.cMax);
        h.invMax[r.bin] = std::max(h.invMax[r.bin], r.invMax);
        h.invMin[r.bin] = std::min(h.invMin[r.bin], r.invMin);
        h.motionMax[r.bin] = vmax(h.motionMax[r.bin], r.motionMax);
        h.sagMax[r.bin] = vmax(h.sagMax[r.bin], r.sagMax);
        h.arcSag[r.bin] += r.arcSag;
        h.arcMotion[r.bin] += r.arcMotion;
        r = Run{};
    };
    // (With still samples alone, as in a tile without motion, the class is 0 for every sample:
    // known at compile time, the loop indexes no histogram or run by it. The same sums.)
    auto sumRuns = [&](auto stillOnly) {
        for (Gathered& s : g) {
            const int cls = stillOnly ? 0 : s.cls;
            const int b = hist[cls].bin((cls == 0 ? splitKey.of(s) : s.c) - rate[cls] * (s.t - 0.5f));
            s.bin = uint16_t(b);
            Run& r = run[cls];
            if (b != r.bin) {
                flush(cls);
                r.bin = b;
            }
            ++r.count;
            r.c += s.c;
            r.mx += s.mx;
            r.my += s.my;
            r.m2 += s.mx * s.mx + s.my * s.my;
            r.mx2 += double(s.mx) * double(s.mx);
            r.invDepth += s.invDepth;
            r.cMin = std::min(r.cMin, s.c);
            r.cMax = std::max(r.cMax, s.c);
            r.invMax = std::max(r.invMax, s.invDepth);
            r.invMin = std::min(r.invMin, s.invDepth);
            r.motionMax = vmax(r.motionMax, Vec2f{std::abs(s.mx), std::abs(s.my)});
            const Vec2f sag = sags ? sags[&s - g.data()] : Vec2f{0.f, 0.f};
            r.sagMax = vmax(r.sagMax, Vec2f{std::abs(sag.x), std::abs(sag.y)});
            if (curved(sag)) {
                // (Its sagitta across its chord: along it a sagitta is a turn in depth's uneven
                // pace, whose ratio to the chord depends on where the point is on its circle.)
                const double m = std::sqrt(double(s.mx) * s.mx + double(s.my) * s.my);
                if (m > 1e-3) {
                    r.arcSag += std::abs(double(sag.x) * s.my - double(sag.y) * s.mx) / m;
                    r.arcMotion += m;
                }
            }
        }
    };
    bool stillOnly = true;
    for (int cls = 1; cls < kClasses; ++cls) stillOnly = stillOnly && hist[cls].bins == 0;
    if (stillOnly)
        sumRuns(std::true_type{});
    else
        sumRuns(std::false_type{});
    for (int cls = 0; cls < kClasses; ++cls) flush(cls);
    std::vector<Layer> layers;
    for (int cls = 0; cls < kClasses; ++cls) {
        Split::Histogram& h = hist[cls];
        if (h.bins == 0) continue;  // no samples of this class
        int nLayers = 0;
        for (float scale = 1.f;; scale *= 1.5f) {
            nLayers = 0;
            float cStart = 0;
            int last = -1;
            for (int b = 0; b < h.bins; ++b) {
                if (h.count[b] == 0) continue;
                const float cb = h.cHi - (float(b) + 0.5f) * h.binW;
                const float spread = std::max(o.splitMin, o.splitScale * std::abs(cStart)) * scale;
                const bool gap = last >= 0 && float(b - last - 1) * h.binW >= o.splitMin * scale;
                if (last < 0 || cStart - cb > spread || gap) {
                    ++nLayers;
                    cStart = cb;
                }
                h.binLayer[b] = nLayers - 1;
                last = b;
            }
            h.sharpRun.assign(size_t(nLayers), 0);
            if (cls == 0 && o.mergeSharp) nLayers = mergeSharpRuns(h, nLayers, o, range + 1, kClasses - 1, splitKey);
            if (int(layers.size()) + nLayers <= o.maxLayers || nLayers <= 1) break;
        }
        h.base = int(layers.size());
        layers.resize(h.base + nLayers);
        for (int k = h.base; k < h.base + nLayers; ++k) {
            layers[k].moving = cls > 0;
            layers[k].depthRate = depthRate[cls];
            layers[k].sharpRun = h.sharpRun[size_t(k - h.base)] != 0;
        }
        // A layer's statistics are those of its bins (summed bin by bin: the means can differ
        // from a sample-by-sample sum in the last bits of the double sums).
        for (int b = 0; b < h.bins; ++b)
            if (h.count[b] > 0) addBin(layers[h.base + h.binLayer[b]], h, b);
    }
    for (Layer& l : layers) {
        const double inv = 1.0 / std::max(1, l.count);
        l.c = float(l.sumC * inv);
        l.mx = float(l.sumMx * inv);
        l.my = float(l.sumMy * inv);
        l.motionRms = float(std::sqrt(l.sumM2 * inv));
        l.motionRmsX = float(std::sqrt(l.sumMx2 * inv));
        l.motionRmsY = float(std::sqrt(std::max(0.0, l.sumM2 - l.sumMx2) * inv));
        l.invDepth = float(l.sumInvDepth * inv);
        l.arc.build(l.arcMotion > 0 ? float(4.0 * std::atan(2.0 * l.arcSag / l.arcMotion)) : 0.f, std::sqrt(sqr(l.motionMax.x) + sqr(l.motionMax.y)),
                    std::sqrt(sqr(l.sagMax.x) + sqr(l.sagMax.y)));
    }
    // Front to back: by mean inverse depth (a miss is at 0), which orders layers of any slope; a
    // moving layer by its nearest sample's (below).
    std::vector<int> order(layers.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = int(i);
    // A moving layer by its nearest sample: where it and a still layer overlap in depth (an
    // object moving over the floor it stands on) it goes first, since its coverage follows the
    // shutter time (its grid moves with it, and its D counts the samples behind it) while a
    // still layer's is one over the shutter: in front, the still layer took the rays at the
    // times the moving one hid it. (layers_test
    // Layers.AMovingLayerGoesBeforeAStillOneItReachesInFrontOf: a column's mean 0.14 -> 0.005
    // off. AAF `--layers on` relMSE -7.8% on docs/bunny-motion.json, -11% / -4.2% on
    // raster-motion-defocus without and with textures, MC -1.2 to -2.6% and à-trous -2.7 to
    // -5.5% there, but +5.0% (MC +2.2%, à-trous +3.3%) on docs/conference-motion.json, where a
    // sphere moves behind the table's edge: there the still layer is in front, and first it
    // was right. Neither order is right for both; contact with the surface an object moves
    // over is the commoner. docs/layers.md, "Moving layers first".)
    auto key = [&](const Layer& l) { return l.moving ? l.invDepthMax : l.invDepth; };
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key(layers[a]) > key(layers[b]); });
    split.rank.assign(layers.size(), 0);
    split.layers.clear();
    split.layers.reserve(layers.size());
    for (size_t i = 0; i < order.size(); ++i) {
        split.rank[order[i]] = int(i);
        split.layers.push_back(std::move(layers[order[i]]));
    }
}

/// A Gaussian's taps exp(-k^2 / (2 sigma^2)), k = -r..r with r = ceil(3 sigma); the one tap 1
/// for sigma 0 (no smoothing).
std::vector<float> gaussianTaps(float sigma) {
    const int r = sigma > 0.f ? int(std::ceil(3.f * sigma)) : 0;
    std::vector<float> w(2 * r + 1, 1.f);
    for (int k = -r; k <= r && r > 0; ++k) w[k + r] = std::exp(-0.5f * float(k * k) / (sigma * sigma));
    return w;
}

/// Separable Gaussian of `sigma` cells along x and `sigmaY` along y (0: none) over channels
/// [c0, c1) of the `stride` interleaved channels of `acc` (gw x gh); c1 < 0: to the last. kChannels > 0: c1 - c0 known at compile
/// time (the common runs, a still layer's and a moving one's: the loops over channels unrolled
/// and vectorised; the same sums in the same order, so the same bytes as the general loop).
/// `box`: where those channels can be non-zero (CellBox); returns where they can be after.
template <int kChannels>
CellBox smoothRun(std::vector<float>& acc, int gw, int gh, int stride, float sigma, float sigmaY, int c0, int c1, CellBox box) {
    const int n = kChannels > 0 ? kChannels : c1 - c0;
    const std::vector<float> w = gaussianTaps(sigma), wy = gaussianTaps(sigmaY);
    const int r = int(w.size() / 2), ry = int(wy.size() / 2);
    if (box.empty()) return box;
    // The horizontal pass's output, over the box's rows and its columns grown by r (the other
    // cells' sums are of zeros).
    const CellBox out = box.grown(r, ry, gw, gh);
    const int tx0 = out.x0, tw = out.x1 - out.x0;
    std::vector<float> tmp(size_t(box.y1 - box.y0) * tw * n, 0.f);  // (row j - box.y0, column i - tx0)
    // Per row, the columns [lo, hi) the horizontal pass can make non-zero: within r of its cells
    // with a non-zero channel (empty: lo = hi). A layer's samples cover a part of its grid (an
    // object, a slat), and elsewhere the sums only add zeros: skipped, the same sums.
    // (Found from each end of the row, not by reading all of it: a row a layer covers is read
    // a few cells deep; the scan was 2% of an MC render of raster-pan.)
    std::vector<int> lo(size_t(gh), 0), hi(size_t(gh), 0);
    for (int j = box.y0; j < box.y1; ++j) {
        auto any = [&](int i) {
            const float* in = &acc[(size_t(j) * gw + i) * stride + c0];
            bool nonZero = false;
            for (int ch = 0; ch < n; ++ch) nonZero |= in[ch] != 0.f;
            return nonZero;
        };
        int first = box.x0;
        while (first < box.x1 && !any(first)) ++first;
        if (first == box.x1) continue;
        int last = box.x1 - 1;
        while (!any(last)) --last;
        lo[size_t(j)] = std::max(0, first - r), hi[size_t(j)] = std::min(gw, last + r + 1);
    }
    for (int j = box.y0; j < box.y1; ++j)
        for (int i = lo[size_t(j)]; i < hi[size_t(j)]; ++i) {
            float* o = &tmp[(size_t(j - box.y0) * tw + size_t(i - tx0)) * n];
            for (int k = std::max(-r, -i); k <= std::min(r, gw - 1 - i); ++k) {
                const float* in = &acc[(size_t(j) * gw + i + k) * stride + c0];
                const float wk = w[k + r];
                for (int ch = 0; ch < n; ++ch) o[ch] += wk * in[ch];
            }
        }
    // (Zeroed where a row can be non-zero: elsewhere it is.)
    for (int j = box.y0; j < box.y1; ++j)
        for (int i = lo[size_t(j)]; i < hi[size_t(j)]; ++i) std::fill_n(&acc[(size_t(j) * gw + i) * stride + c0], n, 0.f);
    for (int j = out.y0; j < out.y1; ++j)
        for (int k = std::max(-ry, -j); k <= std::min(ry, gh - 1 - j); ++k) {
            const int i0 = lo[size_t(j + k)], i1 = hi[size_t(j + k)];
            if (i0 >= i1) continue;
            const float wk = wy[k + ry];
            const float* in = &tmp[size_t(j + k - box.y0) * tw * n];
            float* o = &acc[size_t(j) * gw * stride + c0];
            for (int i = i0; i < i1; ++i)
                for (int ch = 0; ch < n; ++ch) o[size_t(i) * stride + ch] += wk * in[size_t(i - tx0) * n + ch];
        }
    return out;
}
CellBox smooth(std::vector<float>& acc, int gw, int gh, int stride, float sigma, float sigmaY, CellBox box, int c0 = 0, int c1 = -1) {
    if (c1 < 0) c1 = stride;
    switch (c1 - c0) {
        case 1: return smoothRun<1>(acc, gw, gh, stride, sigma, sigmaY, c0, c1, box);
        case 2: return smoothRun<2>(acc, gw, gh, stride, sigma, sigmaY, c0, c1, box);
        case 3: return smoothRun<3>(acc, gw, gh, stride, sigma, sigmaY, c0, c1, box);
        case 4: return smoothRun<4>(acc, gw, gh, stride, sigma, sigmaY, c0, c1, box);
        case 6: return smoothRun<6>(acc, gw, gh, stride, sigma, sigmaY, c0, c1, box);
        case 4 * kTimeBins: return smoothRun<4 * kTimeBins>(acc, gw, gh, stride, sigma, sigmaY, c0, c1, box);  // a moving layer's W, R, G, B per time bin
        case 2 + 4 * kTimeBins: return smoothRun<2 + 4 * kTimeBins>(acc, gw, gh, stride, sigma, sigmaY, c0, c1, box);  // ... with N and the slopes
        default: return smoothRun<0>(acc, gw, gh, stride, sigma, sigmaY, c0, c1, box);
    }
}

/// The radiance's edge-stopping Gaussian of `sigma` cells along grid axis `axis`, over channels
/// [c0, stride) (W, R, G, B per time bin): neighbour k weighs exp(-k^2 / (2 sigma^2)) exp(-d^2 /
/// 2), d the difference of the two cells' radiance (luminance over all time bins) relative to
/// their mean plus `epsilon` (relMSE's 0.01 in the light field's luminance unit), over `edge`
/// (LayerOptions::edgeStop). The weight is symmetric and scales W with
/// R, G, B, so a cell's radiance stays a weighted mean.
/// (Without it across a crisp layer's motion, a moving object's samples that carry their own
/// light were noisier inside its trail: AAF relMSE docs/motion.json +3%, many-motion +4%,
/// à-trous +11% and +3%; with the plain Gaussian a lit strip's edge blurs. docs/layers.md,
/// "Crisp across the motion".)
/// `box`: where those channels can be non-zero (CellBox); returns where they can be after (the
/// box grown by the Gaussian's reach along the axis). Beyond that reach of the box a cell and
/// all its neighbours are zero and add nothing: skipped, the same sums in the same order.
CellBox smoothAcrossEdges(std::vector<float>& acc, int gw, int gh, int stride, int c0, float sigma, int axis, float edge, float epsilon,
                          CellBox box) {
    const int n = stride - c0;
    const std::vector<float> taps = gaussianTaps(sigma);
    const int r = int(taps.size() / 2);
    if (box.empty()) return box;
    const CellBox b = box.grown(axis == 0 ? r : 0, axis == 1 ? r : 0, gw, gh);
    const int bw = b.x1 - b.x0, bh = b.y1 - b.y0;
    const size_t cells = size_t(bw) * bh;  // (within b: cell q of b is the grid's (b.x0 + q % bw, b.y0 + q / bw))
    auto gridIndex = [&](size_t q) { return (size_t(b.y0) + q / size_t(bw)) * size_t(gw) + size_t(b.x0) + q % size_t(bw); };
    std::vector<float> luminance(cells, -1.f);  // -1: no weight (the cell adds nothing)
    for (size_t q = 0; q < cells; ++q) {
        const float* a = &acc[gridIndex(q) * stride + c0];
        float w = 0, v = 0;
        for (int k = 0; k < n / 4; ++k) w += a[4 * k], v += a[4 * k + 1] + a[4 * k + 2] + a[4 * k + 3];
        if (w > 0.f) luminance[q] = v / w;
    }
    std::vector<float> out(cells * n, 0.f);
    const int len = axis == 1 ? bh : bw, step = axis == 1 ? bw : 1, gridStep = axis == 1 ? gw : 1;
    // Each pair of cells once (its weight is symmetric), from the lower one; a cell without
    // weight adds nothing and takes the plain Gaussian of its neighbours.
    for (size_t q = 0; q < cells; ++q) {
        const bool hasQ = luminance[q] >= 0.f;
        float* oq = &out[q * n];
        const float* iq = &acc[gridIndex(q) * stride + c0];
        if (hasQ)
            for (int ch = 0; ch < n; ++ch) oq[ch] += iq[ch];
        const int at = axis == 1 ? int(q / size_t(bw)) : int(q % size_t(bw));
        for (int k = 1; k <= std::min(r, len - 1 - at); ++k) {
            const size_t e = q + size_t(k) * size_t(step);
            const bool hasE = luminance[e] >= 0.f;
            if (!hasQ && !hasE) continue;
            float w = taps[size_t(r + k)];
            if (hasQ && hasE) {
                const float d = (luminance[q] - luminance[e]) / (edge * (0.5f * (luminance[q] + luminance[e]) + epsilon));
                w *= std::exp(-0.5f * d * d);
            }
            float* oe = &out[e * n];
            const float* ie = iq + size_t(k) * size_t(gridStep) * size_t(stride);
            for (int ch = 0; ch < n; ++ch) oq[ch] += w * ie[ch], oe[ch] += w * iq[ch];
        }
    }
    for (size_t q = 0; q < cells; ++q) std::copy_n(&out[q * n], n, &acc[gridIndex(q) * stride + c0]);
    return b;
}

/// How many rings of missing cells resolveCells fills from their neighbours (alpha 0 beyond).
constexpr int kFillRings = 4;

/// Per cell: alpha = N / D and, premultiplied by it, the radiance RGB / W of each time bin.
/// Holes are filled, where they matter: a time bin without samples takes the cell's other bins;
/// a cell with alpha but no radiance, or without enough weight for alpha (the layer hidden
/// there: everything of it and behind it covered by the layers in front), takes the mean of its
/// valid neighbours, ring by ring (a few rings; alpha 0 beyond them).
/// `box`: where acc and accD can be non-zero, grown by the rings (CellBox). Every cell beyond it
/// resolves to alpha 0, no light and the layer's slope, and no ring reaches it: only that is set.
void resolveCells(Layer& l, float minWeight, CellBox box) {
    const int as = l.accStride(), cs = l.cellStride(), bins = l.timeBins;
    // (Layer::cellBox: the box and a ring around it, at least one cell. Below, cells are indexed
    // within it, and a neighbour beyond it is a cell no pass sets: as one beyond the grid.)
    l.cellBox = box.empty() ? CellBox{0, 0, 1, 1} : box.grown(1, 1, l.gw, l.gh);
    const int ww = l.cellBox.x1 - l.cellBox.x0, wh = l.cellBox.y1 - l.cellBox.y0, cells = ww * wh;
    l.cell.assign(size_t(cells) * cs, 0.f);
    for (int i = 0; i < cells; ++i) l.cell[size_t(i) * cs + size_t(cs - 1)] = l.c;
    std::vector<uint8_t> alphaOk(cells, 0), radianceOk(cells, 0);
    // fn(i, x, y): i the cell's index in `cell`, (x, y) the grid's cell (the box lies in dWin;
    // beyond accWin acc is zero).
    assert(box.empty() || (box.x0 >= l.dWin.x0 && box.y0 >= l.dWin.y0 && box.x1 <= l.dWin.x1 && box.y1 <= l.dWin.y1));
    auto forEachInBox = [&](auto&& fn) {
        for (int y = box.y0; y < box.y1; ++y) {
            const int w = (y - l.cellBox.y0) * ww - l.cellBox.x0;
            for (int x = box.x0; x < box.x1; ++x) fn(w + x, x, y);
        }
    };
    static constexpr float kNoAcc[2 + 4 * kTimeBins] = {};
    forEachInBox([&](int i, int x, int y) {
        const float* a = l.inAcc(x, y) ? &l.acc[size_t(l.accAt(x, y)) * as] : kNoAcc;
        const float d = l.accD[size_t(l.dAt(x, y))];
        float* c = &l.cell[size_t(i) * cs];
        c[cs - 1] = a[0] >= minWeight ? a[1] / a[0] : l.c;
        if (d >= minWeight) {
            c[0] = std::clamp(a[0] / d, 0.f, 1.f);
            alphaOk[i] = 1;
        }
        int have = -1;
        for (int b = 0; b < bins; ++b) {
            const float* ab = a + 2 + 4 * b;
            if (ab[0] < minWeight) continue;
            const float inv = 1.f / ab[0];
            for (int ch = 0; ch < 3; ++ch) c[1 + 3 * b + ch] = ab[1 + ch] * inv;
            if (have < 0) have = b;
        }
        if (have < 0) return;
        radianceOk[i] = 1;
        // Empty time bins take the nearest bin that has samples.
        for (int b = 0; b < bins; ++b) {
            if (a[2 + 4 * b] >= minWeight) continue;
            int best = have;
            for (int k = 0; k < bins; ++k)
                if (a[2 + 4 * k] >= minWeight && std::abs(k - b) < std::abs(best - b)) best = k;
            for (int ch = 0; ch < 3; ++ch) c[1 + 3 * b + ch] = c[1 + 3 * best + ch];
        }
    });
    // Ring-by-ring fill of what is missing where it can matter (alpha everywhere, radiance where
    // the cell has alpha).
    auto isHole = [&](int i) { return !alphaOk[i] || (!radianceOk[i] && l.cell[size_t(i) * cs] > 0.f); };
    std::vector<int> holes;
    forEachInBox([&](int i, int, int) {
        if (isHole(i)) holes.push_back(i);
    });
    // Per ring, the holes that have a valid neighbour and the means they take. Most holes of a
    // layer's grid have none (far from its samples, where nothing behind them counted in D), and
    // a hole can gain one only next to a cell filled in the ring before: after the first ring
    // only those holes are looked at (the same fills as looking at every hole every ring).
    struct Fill {
        int cell;
        bool alpha, radiance;
    };
    std::vector<Fill> fills;
    std::vector<float> values;
    std::vector<int> next;
    std::vector<int8_t> seen(holes.empty() ? 0 : size_t(cells), -1);  // the ring a hole was last put in `next`
    float v[2 + 3 * kTimeBins];
    for (int ring = 0; ring < kFillRings && !holes.empty(); ++ring) {
        fills.clear();
        values.clear();
        for (const int i : holes) {
            const int x = i % ww, y = i / ww;
            std::fill_n(v, cs, 0.f);
            int nA = 0, nL = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = x + dx, yy = y + dy;
                    if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= ww || yy >= wh) continue;
                    const int q = yy * ww + xx;
                    const float* c = &l.cell[size_t(q) * cs];
                    if (!alphaOk[i] && alphaOk[q]) v[0] += c[0], ++nA;
                    if (!radianceOk[i] && radianceOk[q]) {
                        for (int k = 1; k < cs; ++k) v[k] += c[k];
                        ++nL;
                    }
                }
            if (nA == 0 && nL == 0) continue;
            if (nA > 0) v[0] /= float(nA);
            if (nL > 0)
                for (int k = 1; k < cs; ++k) v[k] /= float(nL);
            fills.push_back({i, nA > 0, nL > 0});
            values.insert(values.end(), v, v + cs);
        }
        for (size_t f = 0; f < fills.size(); ++f) {
            const int i = fills[f].cell;
            float* c = &l.cell[size_t(i) * cs];
            const float* value = &values[f * cs];
            if (fills[f].alpha) c[0] = value[0], alphaOk[i] = 1;
            if (fills[f].radiance) {
                for (int k = 1; k < cs; ++k) c[k] = value[k];
                radianceOk[i] = 1;
            }
        }
        // The holes next to a cell filled in this ring, in the order of the cells.
        next.clear();
        for (const Fill& f : fills) {
            const int x = f.cell % ww, y = f.cell / ww;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= ww || yy >= wh) continue;
                    const int q = yy * ww + xx;
                    if (seen[size_t(q)] == ring || !isHole(q)) continue;
                    seen[size_t(q)] = int8_t(ring);
                    next.push_back(q);
                }
        }
        std::sort(next.begin(), next.end());
        holes.swap(next);
    }
    // Premultiply; what is still without radiance is taken as uncovered.
    forEachInBox([&](int i, int, int) {
        float* c = &l.cell[size_t(i) * cs];
        if (!radianceOk[i]) c[0] = 0.f;
        for (int k = 1; k < cs - 1; ++k) c[k] *= c[0];
    });
}

/// Alpha and premultiplied radiance of a sharp layer at pixel (x, y) and shutter time t (see
/// lookupSharp; a blurred layer's are read by traceBlurred).
struct Lookup {
    float alpha = 0;
    Vec3f premultiplied{0.f};
};
/// What a blurred layer with a sharp band (Layer::own) mixes into its rays at one pixel: alpha
/// w alpha_grid + (1 - w) alpha_own, light likewise; `alpha`, r, g, b hold (1 - w) times the
/// pixel's own. The default is the grid alone, to the bit (x 1 + 0).
struct Blend {
    float w = 1.f, alpha = 0.f, r = 0.f, g = 0.f, b = 0.f;
};
/// The bilinear cells and weights of a blurred layer's lookup at sharp-image position p: between
/// cell centres (at +1/2); along a crisp axis (Layer::crisp) the cell that holds p (weights 0
/// and 1).
struct Bilinear {
    int cell[4];
    float w[4];
    int stored[4];  // ... the cells' indices in Layer::cell (Layer::cellAt)
};
/// std::clamp and std::min by value: the same results, and no references for the SIMD loops'
/// if-conversion to trip on (traceBlurred).
[[gnu::always_inline]] inline float clampValue(float v, float lo, float hi) { return v < lo ? lo : hi < v ? hi : v; }
[[gnu::always_inline]] inline int minValue(int a, int b) { return b < a ? b : a; }
[[gnu::always_inline]] inline int maxValue(int a, int b) { return a < b ? b : a; }
[[gnu::always_inline]] inline float minFloat(float a, float b) { return b < a ? b : a; }
[[gnu::always_inline]] inline float maxFloat(float a, float b) { return a < b ? b : a; }
[[gnu::always_inline]] inline Bilinear bilinear(const Layer& l, Vec2f p) {
    // (Both roundings computed and one selected: a floor under the condition is a masked call,
    // which kept traceBlurred's loops from vectorising.)
    const float x = p.x * l.invStep - float(l.gx0), y = p.y * l.invStep - float(l.gy0), floorX = std::floor(x), floorY = std::floor(y);
    const float fx = clampValue(l.crisp == 0 ? floorX : x - 0.5f, 0.f, float(l.gw - 1));
    const float fy = clampValue(l.crisp == 1 ? floorY : y - 0.5f, 0.f, float(l.gh - 1));
    const int i0 = minValue(int(fx), std::max(0, l.gw - 2)), j0 = minValue(int(fy), std::max(0, l.gh - 2));
    const float ax = fx - float(i0), ay = fy - float(j0);
    // A blurred layer's grid is at least 7 cells a side (its tile and a margin of at least
    // ceil(3 sigma) + 1 = 3 cells each way), so the next cell along either axis is inside it.
    const int c00 = j0 * l.gw + i0;
    // (Layer::cellAt of the four.)
    const int bx = l.cellBox.x0, by = l.cellBox.y0, bw = l.cellBox.x1 - bx, bh = l.cellBox.y1 - by;
    const int a0 = minValue(maxValue(i0 - bx, 0), bw - 1), a1 = minValue(maxValue(i0 + 1 - bx, 0), bw - 1);
    const int r0 = minValue(maxValue(j0 - by, 0), bh - 1) * bw, r1 = minValue(maxValue(j0 + 1 - by, 0), bh - 1) * bw;
    return {{c00, c00 + 1, c00 + l.gw, c00 + l.gw + 1},
            {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay},
            {r0 + a0, r0 + a1, r1 + a0, r1 + a1}};
}
/// The AffineMotion of a grid's unsmoothed sums of 2-vectors (gw x gh cells of 1 pixel; cell i's
/// count at count[i cs], its sums of x and y at sums[i ss] and sums[i ss + 1]: a motion grid's
/// count, sum of mx, sum of my, or a turning layer's sagittas beside that count), the fit's
/// positions at the cells' centres; `fallback` (with no gradient) where the samples do not span
/// two dimensions.
AffineMotion fitMotion(const float* count, int cs, const float* sums, int ss, int gw, int gh, Vec2f fallback) {
    double w = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, smx = 0, smy = 0, sxmx = 0, symx = 0, sxmy = 0, symy = 0;
    for (int j = 0; j < gh; ++j)
        for (int i = 0; i < gw; ++i) {
            const size_t c = size_t(j) * gw + i;
            const float n0 = count[c * cs], m1 = sums[c * ss], m2 = sums[c * ss + 1];
            if (!(n0 > 0.f)) continue;
            const double n = n0, x = i + 0.5, y = j + 0.5;
            w += n, sx += n * x, sy += n * y, sxx += n * x * x, sxy += n * x * y, syy += n * y * y;
            smx += m1, smy += m2, sxmx += x * m1, symx += y * m1, sxmy += x * m2, symy += y * m2;
        }
    AffineMotion fit;
    fit.mean = fallback;
    if (w < 8) return fit;
    const double cx = sx / w, cy = sy / w, mx = smx / w, my = smy / w;
    fit.mean = {float(mx), float(my)};
    fit.centre = {float(cx), float(cy)};
    // Covariances of the position (xx, xy, yy) and of the motion with it (B = C_mp C_pp^-1).
    const double cxx = sxx / w - cx * cx, cxy = sxy / w - cx * cy, cyy = syy / w - cy * cy;
    const double cxmx = sxmx / w - cx * mx, cymx = symx / w - cy * mx, cxmy = sxmy / w - cx * my, cymy = symy / w - cy * my;
    const double det = cxx * cyy - cxy * cxy;
    if (!(cxx + cyy > 1.0) || !(det > 1e-4 * sqr(cxx + cyy))) return fit;
    fit.b00 = float((cxmx * cyy - cymx * cxy) / det), fit.b01 = float((cymx * cxx - cxmx * cxy) / det);
    fit.b10 = float((cxmy * cyy - cymy * cxy) / det), fit.b11 = float((cymy * cxx - cxmy * cxy) / det);
    return fit;
}

/// fitMotion's fit of layer l's grid (its cells' positions from the grid's corner, in cells) in
/// the image's pixels, as the rays and the D pass read it (motionShift).
AffineMotion inPixels(const AffineMotion& f, const Layer& l) {
    AffineMotion p = f;
    const float step = float(l.step), inv = l.invStep;
    p.centre = {(f.centre.x + float(l.gx0)) * step, (f.centre.y + float(l.gy0)) * step};
    p.b00 = f.b00 * inv, p.b01 = f.b01 * inv, p.b10 = f.b10 * inv, p.b11 = f.b11 * inv;
    return p;
}

/// A layer's grid of mean 2-vectors (motionGrid, sagGrid: x and y per cell) from its smoothed
/// counts and sums (as fitMotion reads them): a cell's mean where its count is at least 0.05,
/// else (no samples there) `fit` at the cell, within the largest distance from the fit's mean
/// of the means seen, plus the nearest cell with samples' difference from the fit there
/// (nearest along its row, or where its row has none, along its column from the rows that have).
/// A ray or a sample behind starts where the fit puts it (motionShift) and takes one step on
/// this grid: beyond the rim of a sphere moving sideways, whose rim moves slower on screen than
/// its front (nearer) and so than the fit, the fit alone sent the rays of the pixels the rim
/// crosses late and early in the shutter past it, and counted the sky's samples beside the rim
/// in the sphere's D: the middle of docs/motion.json's trail at 1024x1024 (282 px) was 4.5% too
/// dark with layers, for every method (docs/layers.md, "The rim's motion beyond the rim").
/// `residuals`: the sums are of the differences from the (unclamped) fit at the cells' centres,
/// and a cell's mean is the fit there plus their mean (the motion grid).
void meanVectorGrid(const float* count, int cs, const float* sums, int ss, int gw, int gh, const AffineMotion& fit,
                    std::vector<float>& grid, bool residuals) {
    const size_t cells = size_t(gw) * gh;
    grid.resize(cells * 2);
    auto has = [&](size_t i) { return !(count[i * cs] < 0.05f); };
    float deviation = 0;
    bool any = false;
    for (size_t i = 0; i < cells; ++i) {
        if (!has(i)) continue;
        const float n = count[i * cs];
        grid[2 * i] = sums[i * ss] / n, grid[2 * i + 1] = sums[i * ss + 1] / n;
        if (residuals) {
            const Vec2f f = fit.at({float(i % size_t(gw)) + 0.5f, float(i / size_t(gw)) + 0.5f}, kInf);
            grid[2 * i] += f.x, grid[2 * i + 1] += f.y;
        }
        deviation = std::max(deviation, sqr(grid[2 * i] - fit.mean.x) + sqr(grid[2 * i + 1] - fit.mean.y));
        any = true;
    }
    deviation = std::sqrt(deviation);
    auto fitAt = [&](size_t i) { return fit.at({float(i % size_t(gw)) + 0.5f, float(i / size_t(gw)) + 0.5f}, deviation); };
    // The differences from the fit: per cell with samples its own, then per row the nearest
    // one's along the row (its left one's where two are as near), then in a row without any the
    // nearest such row's (the upper where two are as near).
    std::vector<Vec2f> residual(any ? cells : 0);
    std::vector<int> left(any ? size_t(gw) : 0), below(any ? size_t(gh) : 0, -1);
    std::vector<uint8_t> rowHas(any ? size_t(gh) : 0, 0);
    for (int j = 0; any && j < gh; ++j) {
        const size_t row = size_t(j) * gw;
        int last = -1;
        for (int i = 0; i < gw; ++i) {
            if (has(row + i)) {
                const Vec2f f = fitAt(row + i);
                residual[row + i] = {grid[2 * (row + i)] - f.x, grid[2 * (row + i) + 1] - f.y};
                last = i;
            }
            left[size_t(i)] = last;
        }
        if (last < 0) continue;
        rowHas[size_t(j)] = 1;
        for (int i = gw - 1, next = -1; i >= 0; --i) {
            if (has(row + i)) {
                next = i;
                continue;
            }
            const int l = left[size_t(i)];
            residual[row + i] = residual[row + size_t(l >= 0 && (next < 0 || i - l <= next - i) ? l : next)];
        }
    }
    for (int j = gh - 1, next = -1; any && j >= 0; --j) {
        if (rowHas[size_t(j)]) next = j;
        below[size_t(j)] = next;
    }
    for (int j = 0, above = -1; any && j < gh; ++j) {
        if (rowHas[size_t(j)]) {
            above = j;
            continue;
        }
        const int b = below[size_t(j)];
        const int from = above >= 0 && (b < 0 || j - above <= b - j) ? above : b;
        std::copy_n(&residual[size_t(from) * gw], gw, &residual[size_t(j) * gw]);
    }
    for (size_t i = 0; i < cells; ++i) {
        if (has(i)) continue;
        const Vec2f v = fitAt(i);
        const Vec2f r = any ? residual[i] : Vec2f{0.f, 0.f};
        grid[2 * i] = v.x + r.x, grid[2 * i + 1] = v.y + r.y;
    }
}

/// A grid of 2-vectors (a layer's motionGrid or sagGrid, x and y per cell) at a bilinear lookup.
[[gnu::always_inline]] inline Vec2f vectorAt(const float* grid, const Bilinear& b) {
    float vx = 0, vy = 0;
#pragma GCC unroll 4
    for (int k = 0; k < 4; ++k) {
        vx += b.w[k] * grid[2 * b.cell[k]];
        vy += b.w[k] * grid[2 * b.cell[k] + 1];
    }
    return {vx, vy};
}
/// A moving layer's mean motion (motionGrid) at a bilinear lookup.
[[gnu::always_inline]] inline Vec2f motionAt(const Layer& l, const Bilinear& b) { return vectorAt(l.motionGrid.data(), b); }
/// A turning layer's mean effective sagitta (sagGrid) at a bilinear lookup.
[[gnu::always_inline]] inline Vec2f sagAt(const Layer& l, const Bilinear& b) { return vectorAt(l.sagGrid.data(), b); }
/// Shutter time t between the centres of a layer's `bins` time bins: bins b0 and b1 (the same
/// for a still layer, one bin, or in the last bin's half) and the weight `at` of b1.
struct TimeLerp {
    int b0, b1;
    float at;
};
[[gnu::always_inline]] inline TimeLerp timeLerp(int bins, float t) {
    const float tb = clampValue(t * float(bins) - 0.5f, 0.f, float(bins - 1));
    const int b0 = minValue(int(tb), bins - 1);
    return {b0, minValue(b0 + 1, bins - 1), tb - float(b0)};
}
/// A sharp layer's cell of pixel (x, y) at shutter time t.
Lookup lookupSharp(const Layer& l, int x, int y, float t) {
    const TimeLerp tl = timeLerp(l.timeBins, t);
    const float* c = &l.cell[l.cellAt(x - l.gx0, y - l.gy0) * size_t(l.cellStride())];
    const float* r0 = c + 1 + 3 * tl.b0;
    if (tl.b1 == tl.b0) return {c[0], Vec3f(r0[0], r0[1], r0[2])};
    const float* r1 = c + 1 + 3 * tl.b1;
    return {c[0], Vec3f(r0[0], r0[1], r0[2]) * (1.f - tl.at) + Vec3f(r1[0], r1[1], r1[2]) * tl.at};
}

/// A pixel's reconstruction rays, a structure of arrays (a blurred layer's step is a SIMD loop
/// over them, traceBlurred): each ray's film point, lens point u (u2 = |u|^2) and shutter
/// offset dt = t - 1/2, and what the layers in front gave it so far (premultiplied light,
/// transmittance, the first layer that covered it, -1 none).
struct Rays {
    static constexpr int kMax = 1024;  // (LayerOptions::emitterRays; elsewhere at most kMaxRays)
    // Each array a cache line longer than kMax, so that ray j of the arrays does not fall in one
    // set of the L1 cache, as it would 4 KB apart. (The stage's time with it, conference MC, one
    // thread: as with 128 rays; not measured without it.)
    static constexpr int kLength = kMax + 16;
    alignas(64) float ux[kLength], uy[kLength], u2[kLength], px[kLength], py[kLength], dt[kLength], trans[kLength];
    alignas(64) float cr[kLength], cg[kLength], cb[kLength];
    alignas(64) int hit[kLength];
};

/// Ray j takes alpha and premultiplied light (r, g, b) of the `index`-th layer its pixel's rays
/// see, under what is in front, C += T alpha L, T *= 1 - alpha, unless it has stopped (T <
/// 1e-4). Returns 1 where it took part of the layer's coverage (the rays straddle layers there).
/// Selects, not branches, so that traceBlurred's loop vectorises.
[[gnu::always_inline]] inline int composite(Rays& ray, int j, int index, float alpha, float r, float g, float b) {
    const float t = ray.trans[j];
    const bool live = t >= 1e-4f, covers = live && alpha > 0.f;
    ray.cr[j] = live ? ray.cr[j] + r * t : ray.cr[j];
    ray.cg[j] = live ? ray.cg[j] + g * t : ray.cg[j];
    ray.cb[j] = live ? ray.cb[j] + b * t : ray.cb[j];
    ray.trans[j] = live ? t * (1.f - alpha) : t;
    ray.hit[j] = covers && ray.hit[j] < 0 ? index : ray.hit[j];
    return covers && alpha < 1.f - 1e-4f ? 1 : 0;
}

/// Where a ray (or a sample behind the layer, for D) meets a layer with a motion grid: the
/// point p of its sharp image with q = p + s m(p), q the ray's point sheared by the lens alone
/// and s its shutter offset along the chord (alongChord, times motionScale for a ray). Solved
/// for the affine fit of the layer's motion, (I + s B) p = q - s (m0 - B c), and returned as the
/// shift s m(p); the caller then takes one step on the grid's own motion at q minus that shift.
/// From the layer's mean motion one step missed where the motion varies across the layer (an
/// object moving in depth grows or shrinks on screen, and since groupByMotionField it is one
/// layer): AAF relMSE with the affine start -26% on docs/sphere-away.json, -8% on
/// docs/many-motion.json, the same as three fixed-point steps from the mean motion at a third
/// of their cost (docs/layers.md, "A held-out bunny moving through slats").
/// (`f` is the layer's motionFit, copied by the caller out of its SIMD loop: read through the
/// layer under the loop's condition, its loads kept the moving rays' loop from vectorising.)
/// (The solve of motionShift and curvedMotionShift: p = A^-1 r, returned as q - p.)
[[gnu::always_inline]] inline Vec2f solveShift(float a00, float a01, float a10, float a11, float rx, float ry, float qx, float qy,
                                               Vec2f fallback) {
    const float det = a00 * a11 - a01 * a10;
    const bool solvable = det > 0.2f;  // (a fit that folds the layer over itself within the shutter: the mean motion's shift)
    return {solvable ? qx - (a11 * rx - a01 * ry) / det : fallback.x, solvable ? qy - (a00 * ry - a10 * rx) / det : fallback.y};
}
[[gnu::always_inline]] inline Vec2f motionShift(const AffineMotion& f, float qx, float qy, float s, Vec2f fallback) {
    const float a00 = 1.f + s * f.b00, a01 = s * f.b01, a10 = s * f.b10, a11 = 1.f + s * f.b11;
    const float rx = qx - s * (f.mean.x - (f.b00 * f.centre.x + f.b01 * f.centre.y));
    const float ry = qy - s * (f.mean.y - (f.b10 * f.centre.x + f.b11 * f.centre.y));
    return solveShift(a00, a01, a10, a11, rx, ry, qx, qy, fallback);
}

/// motionShift on a turning layer's arcs (Layer::sagGrid): the point p of the sharp image with
/// q = p + s m(p) - k e(p), e the affine fit of the effective sagittas (Layer::sagFit) and k =
/// 4 tau^2 (curvedShift), solved as (I + s B - k E) p = q - s (m0 - B c) + k (e0 - E c_e);
/// returns s m(p) - k e(p).
[[gnu::always_inline]] inline Vec2f curvedMotionShift(const AffineMotion& f, const AffineMotion& e, float qx, float qy, float s, float k,
                                                      Vec2f fallback) {
    const float a00 = 1.f + s * f.b00 - k * e.b00, a01 = s * f.b01 - k * e.b01, a10 = s * f.b10 - k * e.b10, a11 = 1.f + s * f.b11 - k * e.b11;
    const float rx = qx - s * (f.mean.x - (f.b00 * f.centre.x + f.b01 * f.centre.y)) + k * (e.mean.x - (e.b00 * e.centre.x + e.b01 * e.centre.y));
    const float ry = qy - s * (f.mean.y - (f.b10 * f.centre.x + f.b11 * f.centre.y)) + k * (e.mean.y - (e.b10 * e.centre.x + e.b11 * e.centre.y));
    return solveShift(a00, a01, a10, a11, rx, ry, qx, qy, fallback);
}

/// What rays [j0, j1) find on one layer: per ray its alpha and premultiplied light there,
/// before they are composited (compositeTaken).
struct Taken {
    alignas(64) float alpha[Rays::kLength], r[Rays::kLength], g[Rays::kLength], b[Rays::kLength];
};

/// Rays [j0, j1) composited under layer `index`'s alpha and light as `taken` holds them
/// (composite, ray by ray). Returns whether a ray took part of the layer's coverage.
bool compositeTaken(Rays& ray, int index, const Taken& taken, int j0, int j1) {
    int partial = 0;
#pragma omp simd reduction(| : partial)
    for (int j = j0; j < j1; ++j) partial |= composite(ray, j, index, taken.alpha[j], taken.r[j], taken.g[j], taken.b[j]);
    return partial != 0;
}

/// Rays [j0, j1) through a blurred layer: the layer's lens and shutter shear, then (kFollow)
/// the slope of the surface found there, shaped by the grid's blur, and the layer's alpha and
/// premultiplied light there (kMoving: between its two nearest time bins), into `taken`, for
/// compositeTaken to put under what is in front. Per ray the arithmetic of the scalar loop it
/// replaced, in the same order, as one SIMD loop (its images the same to float rounding,
/// docs/layers.md): every lane is computed, a stopped ray's too.
/// (Apart from compositing, since rays whose layers change order over the shutter are
/// composited per order bin, a few rays each: traced there a bin at a time, the loop ran its
/// scalar remainder, and on 400 small spheres moving every way the stage took 11x the
/// sampling's time; docs/layers.md, "Rays traced once per layer where the order changes".)
/// (kGrid: the layer has a motion grid, followed as above; a template parameter, since a
/// runtime condition in the loop left its lookups masked, and GCC kept such loops scalar.)
template <bool kFollow, bool kMoving, bool kGrid, bool kCurved, bool kArc = false>
void traceBlurredRays(const Layer& l, const Rays& ray, int j0, int j1, const Blend& own, Taken& taken) {
    const int cs = l.cellStride(), bins = l.timeBins;
    const float ownW = own.w, ownA = own.alpha, ownR = own.r, ownG = own.g, ownB = own.b;
    const float* cell = l.cell.data();
    constexpr bool followMotion = kMoving && kGrid;
    // (The grids' and the shear table's bases in locals: gathers through the layer were not
    // supported, and kept the loop scalar.)
    const float* motionGrid = l.motionGrid.data();
    const float* sagGrid = l.sagGrid.data();
    float shearA[Layer::kShearSteps + 1], shearB[Layer::kShearSteps + 1];
    for (int i = 0; i <= Layer::kShearSteps; ++i) shearA[i] = l.shearTable[i].a, shearB[i] = l.shearTable[i].b;
    const AffineMotion fit = l.motionFit, sagFit = l.sagFit;
    // (kArc: a turning layer's arcs where they are not its parabolas, ArcPace. That loop is not
    // vectorised: with the arcs' pace GCC's if-conversion gives up on it, "control flow in loop",
    // whether the pace is computed in it, read from a table or from a loop of its own; a lead.
    // Where motionScale is 0 the chord's pace is scaled by it wherever it is used: 0 as well.)
    const ArcPace arc = l.arc;
    const float invMotionScale = l.motionScale > 0.f ? 1.f / l.motionScale : 0.f;
    // The chord's middle, as an offset from the mid-shutter point (chords; chordMiddle), and the
    // layer's mean motion times it: the rays' segment is shaped about it (below). -0 where the
    // depth rate is 0.
    const float middle = chordMiddle(l.depthRate), middleX = l.mx * middle, middleY = l.my * middle;
    const float depthRate = l.depthRate, rayT2 = l.rayT2;
    float* takenAlpha = taken.alpha;
    float* takenR = taken.r;
    float* takenG = taken.g;
    float* takenB = taken.b;
#pragma omp simd
    for (int j = j0; j < j1; ++j) {
        const float dt = ray.dt[j];
        // Where along its chord the point the ray finds is at its time (alongChord), from the
        // chord's middle, and that offset shaped for the grid's blur (shapeRays), about the
        // chord's middle, so that both ends of the segment are drawn in as far. (Before, the time
        // was shaped, about the mid-shutter point: where the depth changes fast that point lies
        // near one end of the chord, and the other end was drawn in the farthest. The same where
        // the depth rate is 0. docs/layers.md, "An object rushing towards the camera".)
        const float along = alongChord(dt, depthRate) - middle;
        const float shaped = along * (1.f + rayT2 * 4.f * along * along);
        // st: that offset over the chord, as the layer's rays scale it (rayMx = motionScale mx),
        // from the chord's middle; sPos = motionScale st + middle, from the mid-shutter point.
        // (kCurved: 4 tau^2, tau the ray's shutter offset as its motion is scaled: curvedShift;
        // kArc: on its arc, ArcPace. Written with the middle added last, outside the product:
        // added to st, GCC left the loop scalar where the layer has a motion grid.)
        const float tau = l.motionScale * shaped;
        const float st = kArc ? arc.chord(tau) * invMotionScale : shaped;
        const float sPos = (kArc ? arc.chord(tau) : tau) + middle;
        const float arcKj = kArc ? arc.arc(tau) : 4.f * tau * tau;
        float mox = l.rayMx * st + middleX, moy = l.rayMy * st + middleY;
        float cRay = l.rayC + l.rayC2 * ray.u2[j];
        if constexpr (followMotion) {
            // (One expression: a Vec2f declared here and assigned in the branches became a
            // per-lane array with masked stores, and the moving variants' loops did not vectorise.)
            const float qx = ray.px[j] + cRay * ray.ux[j], qy = ray.py[j] - cRay * ray.uy[j];
            const Vec2f shift = kCurved ? curvedMotionShift(fit, sagFit, qx, qy, sPos, arcKj, {mox, moy})
                                        : motionShift(fit, qx, qy, sPos, {mox, moy});
            mox = shift.x, moy = shift.y;
        }
        if constexpr (kFollow || followMotion) {
            // One fixed-point step: the slope and the motion of the surface found at the
            // layer's shear.
            const Bilinear b = bilinear(l, {ray.px[j] + cRay * ray.ux[j] - mox, ray.py[j] - cRay * ray.uy[j] - moy});
            if constexpr (kFollow) {
                float slope = 0;
#pragma GCC unroll 4
                for (int k = 0; k < 4; ++k) slope += b.w[k] * cell[b.stored[k] * cs + cs - 1];
                // (Linear in the table's copy, written out: a Shaped returned by a helper kept the
                // loop scalar.)
                const float at = clampValue((slope - l.shearFrom) * l.shearScale, 0.f, float(Layer::kShearSteps) - 1e-3f);
                const int i = int(at);
                const float f = at - float(i);
                const float a = shearA[i] + f * (shearA[i + 1] - shearA[i]), bb = shearB[i] + f * (shearB[i + 1] - shearB[i]);
                cRay = a + bb * ray.u2[j];
            }
            if constexpr (kMoving) {
                if constexpr (followMotion) {
                    const Vec2f m = vectorAt(motionGrid, b);
                    mox = l.motionScale * m.x * st + m.x * middle;
                    moy = l.motionScale * m.y * st + m.y * middle;
                    if constexpr (kCurved) {
                        // On its arc (curvedShift): the point it finds there is 4 e tau^2 back
                        // towards its mid-shutter place; then a second step, the motion and the
                        // sagitta where the first put it (the sagitta moves the lookup by up to
                        // its length).
                        const float k = arcKj;
                        const Vec2f e = vectorAt(sagGrid, b);
                        mox -= k * e.x;
                        moy -= k * e.y;
                        const Bilinear b2 = bilinear(l, {ray.px[j] + cRay * ray.ux[j] - mox, ray.py[j] - cRay * ray.uy[j] - moy});
                        const Vec2f m2 = vectorAt(motionGrid, b2), e2 = vectorAt(sagGrid, b2);
                        mox = l.motionScale * m2.x * st + m2.x * middle - k * e2.x;
                        moy = l.motionScale * m2.y * st + m2.y * middle - k * e2.y;
                    }
                }
            }
        }
        const Bilinear b = bilinear(l, {ray.px[j] + cRay * ray.ux[j] - mox, ray.py[j] - cRay * ray.uy[j] - moy});
        const TimeLerp tl = kMoving ? timeLerp(bins, dt + 0.5f) : TimeLerp{0, 0, 0.f};
        const int b0 = tl.b0, b1 = tl.b1;
        const float at = tl.at;
        float alpha = 0, r = 0, g = 0, bl = 0;
#pragma GCC unroll 4  // (an inner loop would keep the outer one from vectorising)
        for (int k = 0; k < 4; ++k) {
            const int c = b.stored[k] * cs;  // indices from one base: gathers
            const float w = b.w[k];
            alpha += w * cell[c];
            const int c0 = c + 1 + 3 * b0;
            if constexpr (kMoving) {
                // (Both bins' light read whatever `one` is: loads under the condition were masked
                // gathers, and kept the loop scalar.)
                const int c1 = c + 1 + 3 * b1;
                const bool one = b1 == b0;
                const float r0 = cell[c0], g0 = cell[c0 + 1], bl0 = cell[c0 + 2], r1 = cell[c1], g1 = cell[c1 + 1], bl1 = cell[c1 + 2];
                r = one ? r + r0 * w : r + (r0 * (w * (1.f - at)) + r1 * (w * at));
                g = one ? g + g0 * w : g + (g0 * (w * (1.f - at)) + g1 * (w * at));
                bl = one ? bl + bl0 * w : bl + (bl0 * (w * (1.f - at)) + bl1 * (w * at));
            } else {
                r += cell[c0] * w;
                g += cell[c0 + 1] * w;
                bl += cell[c0 + 2] * w;
            }
        }
        takenAlpha[j] = alpha * ownW + ownA;
        takenR[j] = r * ownW + ownR;
        takenG[j] = g * ownW + ownG;
        takenB[j] = bl * ownW + ownB;
    }
}
/// A moving layer's rays [j0, j1) traced only where they can read a covered cell; the others
/// find alpha and light 0 there and take the pixel's own share, `own`, alone, which is exactly
/// what the whole loop gives them. A small object's trail is covered at a pixel for a short
/// part of the shutter: on docs/snow.json (400 small spheres moving every way) 95% of the rays
/// a moving layer was traced for found nothing there, on bunny-slats, crossing and many-motion
/// 55-82% (docs/layers.md, "A moving layer's rays where they can find it"). Per ray, a bound of
/// where its final lookup lands: its film point; its lens point times its own lens shear, or
/// (kFollow) any its layer's slope table gives (Layer::shearLo, shearHi); less its motion
/// shift m s at its time, s its offset along the chord as traceBlurredRays computes it and m
/// within the motion of the grid's block where its first lookup lands (Layer::windowBlocks; a
/// layer without a grid: its rays' own shift); two cells to spare.
/// Where no cell within that bound is covered (Layer::covered) the ray is left out. The others
/// are copied into a scratch set and traced by the same loop: the same alpha and light per ray,
/// the same image to the byte. Returns false (nothing done) where three quarters of the rays
/// or more pass: the plain loop is cheaper there.
/// (Not for a turning layer's arcs: their sagitta moves the lookup too.)
// (Not inlined: scripts/check_vectorised.py finds its loop by its name.)
template <bool kFollow, bool kGrid>
[[gnu::noinline]] bool traceWindowed(const Layer& l, const Rays& ray, int j0, int j1, const Blend& own, Taken& taken) {
    const int n = j1 - j0;
    if (n < 8) return false;
    alignas(64) static thread_local int in[Rays::kLength];
    const float depthRate = l.depthRate, rayT2 = l.rayT2, middle = chordMiddle(depthRate);
    const float rayC = l.rayC, rayC2 = l.rayC2, rayMx = l.rayMx, rayMy = l.rayMy, shearLo = l.shearLo, shearHi = l.shearHi;
    const float middleX = l.mx * middle, middleY = l.my * middle, scale = l.motionScale;
    const AffineMotion f = l.motionFit;
    const float invStep = l.invStep, gx0 = float(l.gx0), gy0 = float(l.gy0), lastX = float(l.gw - 1), lastY = float(l.gh - 1);
    const int gw = l.gw, blocksX = std::max(l.blocksX, 1), blocksY = std::max(l.blocksY, 1);
    static const float kNoBlock[4] = {0.f, 0.f, 0.f, 0.f};  // (read, and not used, without a grid)
    const float* blocks = kGrid ? l.windowBlocks.data() : kNoBlock;
    const int* sat = l.covered.data();
    int count = 0;
#pragma omp simd reduction(+ : count)
    for (int j = j0; j < j1; ++j) {
        const float along = alongChord(ray.dt[j], depthRate) - middle;
        const float shaped = along * (1.f + rayT2 * 4.f * along * along);
        const float cRay = rayC + rayC2 * ray.u2[j];
        const float qx = ray.px[j] + cRay * ray.ux[j], qy = ray.py[j] - cRay * ray.uy[j];
        // The first lookup, q less its shift: on a grid, motionShift's (as traceBlurredRays
        // takes it); without one, and where the fit folds, the rays' own. (One expression each,
        // as in traceBlurredRays: values assigned in branches kept the loop scalar.)
        const float ownX = rayMx * shaped + middleX, ownY = rayMy * shaped + middleY;
        const float sigma = scale * shaped + middle;
        const Vec2f shift = kGrid ? motionShift(f, qx, qy, sigma, {ownX, ownY}) : Vec2f{ownX, ownY};
        const float pX = qx - shift.x, pY = qy - shift.y;
        // The final lookup's lens shear: the ray's own, or (kFollow) within the slope table's
        // range (its x term c u_x, its y term -c u_y).
        const float cLo = kFollow ? shearLo : cRay, cHi = kFollow ? shearHi : cRay;
        const float ux = ray.ux[j], uy = ray.uy[j];
        const float lx0 = minFloat(cLo * ux, cHi * ux), lx1 = maxFloat(cLo * ux, cHi * ux);
        const float ly0 = minFloat(-cLo * uy, -cHi * uy), ly1 = maxFloat(-cLo * uy, -cHi * uy);
        // ... and its motion shift, m s: m within the range of the grid's block where the first
        // lookup lands (without a grid, the rays' own shift).
        const int bx = minValue(int(clampValue(pX * invStep - gx0 - 0.5f, 0.f, lastX)) / Layer::kWindowBlock, blocksX - 1);
        const int by = minValue(int(clampValue(pY * invStep - gy0 - 0.5f, 0.f, lastY)) / Layer::kWindowBlock, blocksY - 1);
        const int bi = kGrid ? 4 * (by * blocksX + bx) : 0;
        const float lox = blocks[bi] * sigma, hix = blocks[bi + 1] * sigma, loy = blocks[bi + 2] * sigma, hiy = blocks[bi + 3] * sigma;
        const float sx0 = kGrid ? minFloat(lox, hix) : ownX, sx1 = kGrid ? maxFloat(lox, hix) : ownX;
        const float sy0 = kGrid ? minFloat(loy, hiy) : ownY, sy1 = kGrid ? maxFloat(loy, hiy) : ownY;
        const float cx0 = ray.px[j] + lx0, cx1 = ray.px[j] + lx1, cy0 = ray.py[j] + ly0, cy1 = ray.py[j] + ly1;
        // The cells the final lookup can read (two more each way: rounding, a crisp axis's
        // nearest cell), clamped to the grid as the lookup is, and whether one is covered.
        const int i0 = int(clampValue((cx0 - sx1) * invStep - gx0 - 2.f, 0.f, lastX));
        const int i1 = int(clampValue((cx1 - sx0) * invStep - gx0 + 2.f, 0.f, lastX));
        const int k0 = int(clampValue((cy0 - sy1) * invStep - gy0 - 2.f, 0.f, lastY));
        const int k1 = int(clampValue((cy1 - sy0) * invStep - gy0 + 2.f, 0.f, lastY));
        const int s = gw + 1;
        const bool reads = sat[(k1 + 1) * s + i1 + 1] - sat[k0 * s + i1 + 1] - sat[(k1 + 1) * s + i0] + sat[k0 * s + i0] > 0;
        in[j] = reads ? 1 : 0;
        count += reads ? 1 : 0;
    }
    if (4 * count > 3 * n) return false;
    for (int j = j0; j < j1; ++j) taken.alpha[j] = own.alpha, taken.r[j] = own.r, taken.g[j] = own.g, taken.b[j] = own.b;
    if (count == 0) return true;
    alignas(64) static thread_local Rays sub;
    alignas(64) static thread_local Taken subTaken;
    alignas(64) static thread_local int index[Rays::kLength];
    int k = 0;
    for (int j = j0; j < j1; ++j) {
        if (!in[j]) continue;
        sub.ux[k] = ray.ux[j], sub.uy[k] = ray.uy[j], sub.u2[k] = ray.u2[j];
        sub.px[k] = ray.px[j], sub.py[k] = ray.py[j], sub.dt[k] = ray.dt[j];
        index[k++] = j;
    }
    traceBlurredRays<kFollow, true, kGrid, false>(l, sub, 0, k, own, subTaken);
    for (int i = 0; i < k; ++i) {
        const int j = index[i];
        taken.alpha[j] = subTaken.alpha[i], taken.r[j] = subTaken.r[i], taken.g[j] = subTaken.g[i], taken.b[j] = subTaken.b[i];
    }
    return true;
}

/// (`window`: traceWindowed where it can; false, every ray through the layer's whole loop,
/// LayerOptions::everyCell.)
template <bool kFollow, bool kMoving, bool kCurved = false>
void traceBlurred(const Layer& l, const Rays& ray, int j0, int j1, const Blend& own, Taken& taken, bool window) {
    if constexpr (kMoving) {
        if (!l.motionGrid.empty()) {
            if constexpr (kCurved) {
                if (l.arc.theta2 > 0.f) return traceBlurredRays<kFollow, true, true, true, true>(l, ray, j0, j1, own, taken);
                return traceBlurredRays<kFollow, true, true, true>(l, ray, j0, j1, own, taken);
            }
            if (window && traceWindowed<kFollow, true>(l, ray, j0, j1, own, taken)) return;
            return traceBlurredRays<kFollow, true, true, false>(l, ray, j0, j1, own, taken);
        }
        if (window && traceWindowed<kFollow, false>(l, ray, j0, j1, own, taken)) return;
    }
    traceBlurredRays<kFollow, kMoving, false, false>(l, ray, j0, j1, own, taken);
}

/// Samples behind a layer with a motion grid, for its D (the D pass of reconstructLayers): each
/// one's point q sheared by the layer's lens slope, and its shutter time t (motionCells takes its
/// offset along the chord, alongChord).
struct MotionBatch {
    static constexpr int kMax = 256;
    alignas(64) float qx[kMax], qy[kMax], t[kMax];
    alignas(64) int cell[kMax];
    int n = 0;
};
/// The cells of layer l the batch's samples count in D (its accD's index; -1: none), as one SIMD loop: the
/// point p of the sharp image with q = p + dt m(p) (motionShift, then one step on the grid's
/// motion), and -1 where no cell within `margin` of p's has samples of the layer (`occupied`:
/// their count summed over rectangles of its accWin, where they lie: (aw + 1) x (ah + 1)), since such a D changes nothing the
/// layer's coverage reads (reconstructLayers). p lies within |dt| maxMotion of q (|m| <=
/// maxMotion, a bilinear mean of the grid's motions), so that test needs no solve; a cell to
/// spare for rounding.
/// (kCurved: the layer's points on their arcs, Layer::sagGrid, as a ray's.)
template <bool kCurved>
void motionCells(const Layer& l, const int* occupied, int margin, MotionBatch& b) {
    const int n = b.n;
    const int wx0 = l.dWin.x0, wy0 = l.dWin.y0, ww = l.dWin.x1 - wx0, wh = l.dWin.y1 - wy0;
    const int ax0 = l.accWin.x0, ay0 = l.accWin.y0, aw = l.accWin.x1 - ax0, ah = l.accWin.y1 - ay0, ow = aw + 1;
    const float inv = l.invStep;  // (pixels to cells)
    const AffineMotion fit = l.motionFit, sagFit = l.sagFit;
    const ArcPace pace = l.arc;  // (a copy out of the loop, as the fits)
#pragma omp simd
    for (int j = 0; j < n; ++j) {
        const float qx = b.qx[j], qy = b.qy[j], chordPace = alongChord(b.t[j] - 0.5f, l.depthRate);
        const float dt = kCurved ? pace.chord(chordPace) : chordPace;
        const float r = std::abs(dt) * l.maxMotion + (kCurved ? l.maxSag : 0.f) + 1.f;
        const float d = b.t[j] - 0.5f, k = kCurved ? pace.arc(d) : 4.f * d * d;  // (kCurved)
        const int i0 = int(std::floor((qx - r) * inv)) - l.gx0 - margin, i1 = int(std::floor((qx + r) * inv)) - l.gx0 + margin;
        const int j0 = int(std::floor((qy - r) * inv)) - l.gy0 - margin, j1 = int(std::floor((qy + r) * inv)) - l.gy0 + margin;
        // The rectangle clamped to accWin (empty where it misses it: no cell beyond has samples).
        const int a0 = minValue(aw, maxValue(0, i0 - ax0)), a1 = minValue(aw, maxValue(0, i1 + 1 - ax0));
        const int c0 = minValue(ah, maxValue(0, j0 - ay0)), c1 = minValue(ah, maxValue(0, j1 + 1 - ay0));
        const int samples = occupied[c1 * ow + a1] - occupied[c1 * ow + a0] - occupied[c0 * ow + a1] + occupied[c0 * ow + a0];
        const Vec2f shift = kCurved ? curvedMotionShift(fit, sagFit, qx, qy, dt, k, Vec2f{l.mx * dt, l.my * dt})
                                    : motionShift(fit, qx, qy, dt, Vec2f{l.mx * dt, l.my * dt});
        const Bilinear at = bilinear(l, {qx - shift.x, qy - shift.y});
        const Vec2f m = motionAt(l, at);
        float px = qx - m.x * dt, py = qy - m.y * dt;
        if constexpr (kCurved) {  // (and a second step, as a ray's: traceBlurred)
            const Vec2f e = sagAt(l, at);
            const Bilinear at2 = bilinear(l, {px + k * e.x, py + k * e.y});
            const Vec2f m2 = motionAt(l, at2), e2 = sagAt(l, at2);
            px = qx - m2.x * dt + k * e2.x;
            py = qy - m2.y * dt + k * e2.y;
        }
        // (gridCell's cell, with its tests as one mask for the SIMD loop.)
        const int ci = int(std::floor(px * inv)) - l.gx0, cj = int(std::floor(py * inv)) - l.gy0;
        // (Within the layer's dWin, beyond which a D changes nothing: Layer::dWin.)
        const int ai = ci - wx0, aj = cj - wy0;
        const int counts = int(unsigned(ai) < unsigned(ww)) & int(unsigned(aj) < unsigned(wh)) & int(samples > 0);
        b.cell[j] = counts ? aj * ww + ai : -1;
    }
}

}  // namespace

void orderLayers(const uint8_t* before, int n, int* order) {
    // Each layer in splitLayers' order is placed just before the first placed layer it must go
    // before, unless a placed layer it must follow comes later; without such a layer, or where
    // the two disagree, last. A layer jumps the layers it has no rule with: the slats of
    // docs/bunny-slats.json, which go before the bunny where they cross its head, are after a
    // moving box in splitLayers' order with no rule against it, and an insertion that stopped at
    // the first pair without a rule left them behind the bunny (AAF relMSE with layers -11% with
    // the bunny's old order rule alone; docs/layers.md, "Two moving layers ordered where they
    // meet").
    for (int i = 0; i < n; ++i) {
        int after = 0, first = -1;
        for (int p = 0; p < i; ++p) {
            const int k = order[p];
            if (before[size_t(k) * n + size_t(i)]) after = p + 1;
            if (first < 0 && before[size_t(i) * n + size_t(k)]) first = p;
        }
        const int at = first >= after ? first : i;
        for (int p = i; p > at; --p) order[p] = order[p - 1];
        order[at] = i;
    }
}

bool samplesSharpAndStill(const LightFieldSamples& lf, size_t p, const ViewGeometry& view, const LayerOptions& o, int surface) {
    bool sharp = true;
    lf.forEach(p, [&](const LightFieldSample& s) {
        if (surface < 0 || s.surface() == surface)
            sharp = sharp && !movesOnScreen(s.motion()) && trueBlurOf(slopeOf(s, view), 0.f) < sharpThreshold(o);  // (the threshold, not the band's foot)
    });
    return sharp;
}

Image<uint8_t> pixelsAwayFromSilhouettes(const Image<uint8_t>& mixed, int reach) {
    Image<uint8_t> out = dilateBox(mixed, reach);
    for (size_t i = 0; i < out.size(); ++i) out[i] = !out[i];
    return out;
}

namespace {
/// What a tile's margin adds to the trajectories' reach for its grids' Gaussians, pixels.
float gridPad(const LayerOptions& o) { return std::ceil(3.f * o.sigmaMax) + 2.f; }
/// A gathered sample and its scratch: its sagitta where the light field keeps them (counted
/// always), its layer (sampleLayer) and its cell (ownCell).
constexpr uint64_t kGatheredBytes = sizeof(Gathered) + sizeof(Vec2f) + sizeof(uint16_t) + sizeof(uint32_t);
/// The pixels of the largest region a tile gathers.
uint64_t largestRegion(int width, int height, const LayerOptions& o) {
    // (A tile's margin is its trajectories' reach, at most maxReach, and the pad: reconstructLayers.)
    const int margin = int(std::ceil(float(o.maxReach) + gridPad(o)));
    return uint64_t(std::min(width, o.tile + 2 * margin)) * uint64_t(std::min(height, o.tile + 2 * margin));
}

/// The memory the tiles' grids may hold at once, over every thread (LayerOptions::memoryHeld):
/// a tile reserves a bound of its grids before it allocates them (all of it at once, so that no
/// thread waits while it holds a part) and releases it when they are freed. A tile that does not
/// fit beside what the other threads' tiles hold waits for them; one that needs more than the
/// whole budget is an error. Waiting changes no image: a tile's work is the same whenever it runs.
class GridBudget {
public:
    GridBudget(uint64_t budget, uint64_t held, uint64_t gathered, int threads)
        : m_budget(budget), m_held0(held), m_gathered(gathered), m_threads(threads) {}
    uint64_t budget() const { return m_budget; }
    /// Reserves `bytes` for the tile whose pixels start at (x, y), waiting while other tiles hold
    /// too much; throws wedge::Error where `bytes` exceed the whole budget.
    void reserve(uint64_t bytes, int x, int y) {
        if (bytes > m_budget)
            throw Error("--layers", overMemoryLimit("the layers' tile at (" + std::to_string(x) + ", " + std::to_string(y) + "), with its grids (" +
                                                        formatBytes(double(bytes)) + ") beside the render's " + formatBytes(double(m_held0)) +
                                                        " and " + (m_threads == 1 ? std::string("1 thread's") : std::to_string(m_threads) + " threads'") + " gathered samples (" +
                                                        formatBytes(double(m_gathered)) + "),",
                                                    m_held0 + m_gathered + bytes) +
                                        (m_threads > 1 ? "; fewer --threads, or --layers off, need less" : "; --layers off needs less"));
        std::unique_lock<std::mutex> lock(m_mutex);
        if (m_held > 0 && m_held + bytes > m_budget) {
            ++m_waited;
            m_freed.wait(lock, [&] { return m_held == 0 || m_held + bytes <= m_budget; });
        }
        m_held += bytes;
        m_most = std::max(m_most, bytes);
    }
    void release(uint64_t bytes) {
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            m_held -= bytes;
        }
        m_freed.notify_all();
    }
    uint64_t waited() const { return m_waited; }
    uint64_t most() const { return m_most; }

private:
    const uint64_t m_budget, m_held0, m_gathered;
    const int m_threads;
    std::mutex m_mutex;
    std::condition_variable m_freed;
    uint64_t m_held = 0, m_waited = 0, m_most = 0;
};
}  // namespace

uint64_t gatheredSamplesPerThread(int width, int height, double samplesPerPixel, const LayerOptions& o) {
    return uint64_t(std::ceil(double(largestRegion(width, height, o)) * samplesPerPixel));
}

uint64_t gatheredBytesPerThread(int width, int height, double samplesPerPixel, const LayerOptions& o) {
    return gatheredSamplesPerThread(width, height, samplesPerPixel, o) * kGatheredBytes +
           (largestRegion(width, height, o) + 1) * sizeof(uint32_t);  // (and pixelStart)
}

Image3f reconstructLayers(const LayerInput& in, const LayerOptions& o, LayerStats* stats, Image<uint8_t>* own) {
    const LightFieldSamples& lf = in.samples;
    const int W = lf.width(), H = lf.height();
    // The samples' radiance is stored times radianceScale (LightFieldSamples); its inverse is also
    // the luminance in which the edge-stopping's and rayTolerance's epsilon, relMSE's 0.01, is
    // measured (1 where the brightest emitter is at most 64, a power of two above: a scene in
    // brighter units is treated as with its lights scaled to 32-64; docs/reliability.md,
    // "Linearity in the lights' radiance"; MethodContext::luminanceUnit).
    const float invRadianceScale = 1.f / lf.radianceScale();
    // How far from all of a layer's cells with samples a D can still change its coverage, in
    // cells (both D passes skip the Ds beyond it): N / D is 0 wherever the smoothed N is (its
    // Gaussian reaches rs cells), D's own Gaussian carries a change rs cells, and resolveCells'
    // fill carries alpha kFillRings cells, so a D beyond them changes D only where alpha stays 0
    // and no fill that reaches a covered cell reads it (two cells to spare). With
    // LayerOptions::countEveryD, the whole grid.
    const bool countEveryD = o.countEveryD;
    auto dMargin = [countEveryD](const Layer& l) {
        return countEveryD ? l.gw + l.gh : 2 * int(std::ceil(3.f * l.sigmaCoverage)) + 2 * kFillRings + 2;
    };
    Image3f out(W, H);
    if (own) *own = Image<uint8_t>(W, H);
    const ViewGeometry& view = in.view;

    // How far each pixel's samples' trajectories reach from where they were taken, per axis: 2 |c|
    // + |m_x| across, 2 |c| + |m_y| down. (A ray at film x_r, lens u_r and time t_r reads a
    // layer's grid where a sample at x_s, u_s, t_s lands when x_s - x_r = c (u_r - u_s) - m (t_r -
    // t_s), each axis apart. As one radius, 2 |c| + |m|, a camera pan's tiles gathered as far
    // above and below as sideways: docs/layers.md, "A tile's margin per axis".)
    std::vector<Vec2f> reach(size_t(W) * H, Vec2f{});
    // Whether a pixel's samples saw several surfaces (what the sample carries: radianceOf below).
    std::vector<uint8_t> mixed(size_t(W) * H, 0);
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            const size_t p = size_t(y) * W + x;
            Vec2f r{};
            lf.forEachWithSag(p, [&](const LightFieldSample& s, Vec2f sag) {  // (on its arc a sample lands up to |sag| off its chord: curvedShift)
                if (s.surface() != 0) mixed[p] = 1;
                const Vec2f m = s.motion();
                const float c = 2.f * std::abs(view.defocusSlope(s.hit() ? s.depth : kInf));
                r = vmax(r, Vec2f{c + std::abs(m.x) + std::abs(sag.x), c + std::abs(m.y) + std::abs(sag.y)});
            });
            reach[p] = vmin(r, Vec2f{float(o.maxReach), float(o.maxReach)});
        }
    });
    const int T = o.tile, tilesX = (W + T - 1) / T, tilesY = (H + T - 1) / T;
    std::vector<Vec2f> tileReach(size_t(tilesX) * tilesY, Vec2f{});
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            Vec2f& r = tileReach[size_t(y / T) * tilesX + x / T];
            r = vmax(r, reach[size_t(y) * W + x]);
        }

    // The mean slope and inverse depth of the samples of each kSharpTextured pixel: where its
    // rays straddle only layers at its own depth (one surface split between two layers inside
    // it) or behind it, it still shows one surface.
    Image<Vec2f> ownDepth;
    if (own && in.textured) {
        ownDepth = Image<Vec2f>(W, H);
        parallelRows(H, [&](int y) {
            for (int x = 0; x < W; ++x) {
                const size_t p = size_t(y) * W + x;
                double c = 0, inv = 0;
                int n = 0;
                if ((*in.textured)[p] & kSharpTextured)
                    in.samples.forEach(p, [&](const LightFieldSample& s) {
                        c += slopeOf(s, view), inv += s.hit() ? 1.0 / std::max(s.depth, 1e-6f) : 0.0, ++n;
                    });
                ownDepth[p] = n > 0 ? Vec2f{float(c / n), float(inv / n)} : Vec2f{kInf, 0.f};
            }
        });
    }
    std::atomic<uint64_t> gatheredTotal{0}, layerTotal{0}, blurredTotal{0}, straddlingTotal{0}, leftTotal{0}, multiRayTotal{0}, rayTotal{0};
    std::atomic<uint64_t> largestTileBytes{0}, gridFloats{0}, wholeGridFloats{0};  // (LayerStats)
    const int apronTiles = (o.maxReach + T - 1) / T;
    const float pad = gridPad(o);
    // Each tile's margin per axis: the reach of the trajectories that can touch it, and a pad
    // for the grids' Gaussians.
    std::vector<std::array<int, 2>> tileMargin(size_t(tilesX) * tilesY, {0, 0});
    for (int ty = 0; ty < tilesY; ++ty)
        for (int tx = 0; tx < tilesX; ++tx) {
            const int X0 = tx * T, Y0 = ty * T, X1 = std::min(W, X0 + T), Y1 = std::min(H, Y0 + T);
            Vec2f reachT{};
            for (int sy = std::max(0, ty - apronTiles); sy <= std::min(tilesY - 1, ty + apronTiles); ++sy)
                for (int sx = std::max(0, tx - apronTiles); sx <= std::min(tilesX - 1, tx + apronTiles); ++sx) {
                    const Vec2f r = tileReach[size_t(sy) * tilesX + sx];
                    const int gapX = std::max({0, sx * T - X1, X0 - std::min(W, (sx + 1) * T)});
                    const int gapY = std::max({0, sy * T - Y1, Y0 - std::min(H, (sy + 1) * T)});
                    if (float(gapX) <= r.x && float(gapY) <= r.y) reachT = vmax(reachT, r);
                }
            tileMargin[size_t(ty) * tilesX + tx] = {int(std::ceil(reachT.x + pad)), int(std::ceil(reachT.y + pad))};
        }
    // The samples each tile gathers (its pixels and its margin), from sums of the counts over
    // rectangles; a thread's array is made as large as the largest tile's before its first tile.
    // (Grown tile by tile, each larger tile mapped a new array whose pages the kernel cleared:
    // on docs/bunny-slats.json, one thread, 193 MB for a largest tile of 52 MB, 4% of the
    // process in clear_page_erms under the gather.)
    std::vector<uint64_t> countSum(size_t(W + 1) * (H + 1), 0);
    for (int y = 0; y < H; ++y) {
        uint64_t row = 0;
        for (int x = 0; x < W; ++x) {
            row += lf.count(size_t(y) * W + x);
            countSum[size_t(y + 1) * (W + 1) + x + 1] = countSum[size_t(y) * (W + 1) + x + 1] + row;
        }
    }
    auto tileBox = [&](int tx, int ty) {
        return std::array<int, 4>{tx * T, ty * T, std::min(W, tx * T + T), std::min(H, ty * T + T)};
    };
    // The samples a tile reads for the pixels of `box` (within the tile): the box and the tile's
    // margins.
    auto tileRegion = [&](int tx, int ty, const std::array<int, 4>& box) {
        const auto [mx, my] = tileMargin[size_t(ty) * tilesX + tx];
        return std::array<int, 4>{std::max(0, box[0] - mx), std::max(0, box[1] - my), std::min(W, box[2] + mx), std::min(H, box[3] + my)};
    };
    auto regionCount = [&](const std::array<int, 4>& r) {
        const auto at = [&](int x, int y) { return countSum[size_t(y) * (W + 1) + x]; };
        return size_t(at(r[2], r[3]) - at(r[0], r[3]) - at(r[2], r[1]) + at(r[0], r[1]));
    };
    size_t largestTile = 0;
    for (int ty = 0; ty < tilesY; ++ty)
        for (int tx = 0; tx < tilesX; ++tx) largestTile = std::max(largestTile, regionCount(tileRegion(tx, ty, tileBox(tx, ty))));
    // Each thread's gathered samples and split, kept across its tiles: a tile's array is tens of
    // megabytes, and allocated per tile (the tasks are single tiles) its pages were fresh every
    // time, cleared by the kernel (conference MC 512x512: 2.3% of the process in page clearing
    // under this stage, `perf record`). Written whole before they are read, tile by tile.
    struct Scratch {
        // Left unwritten when it grows; huge pages for its megabytes (LargeAllocator).
        std::vector<Gathered, UnwrittenAllocator<Gathered>> g;
        std::vector<Vec2f, UnwrittenAllocator<Vec2f>> sag;  // per gathered sample, where the light field keeps sagittas (Gathered)
        Split split;
        std::vector<SlopeMoments> moments;  // per motion group and cell (slopeRate)
        std::vector<SlopeMoments> depthMoments;  // ... of the depth (depthRateOf)
        FieldScratch field;                      // groupByMotionField
        std::vector<float> binKey;          // per layer and kOrderBins bin: its nearest sample
        std::vector<int> binOrder, binRank;  // per bin: the layers front to back, each layer's place
        std::vector<uint8_t> before;        // per order bin and pair of layers: the first goes before the second
        std::vector<uint8_t> reordered;     // per layer: its order against another changes over the shutter
        std::vector<std::array<float, 4>> box;  // per moving layer and order bin: where its samples were seen
        std::vector<Vec2f> depthCells;      // per still layer and kOrderCell cell: inverse depth summed, count
        std::vector<float> nearCells;       // per moving layer, order bin and kOrderCell cell: its nearest sample's inverse depth
        std::vector<int> movingSlot;        // per layer: its place among the tile's moving layers (-1: still)
        std::vector<float> farthest;        // per layer: its farthest sample's inverse depth (the D passes)
        // The D pass of the layers with a motion grid (withGrid): per layer, its cells with
        // samples summed over rectangles, its margin, and the samples behind it, a batch at a time.
        std::vector<int> withGrid, margin;
        std::vector<std::array<float, 4>> reachBox, ownBox;
        std::vector<std::vector<int>> occupied;
        std::vector<MotionBatch> batch;
        std::vector<uint16_t> sampleLayer;  // per gathered sample: its layer (Split::layerOf)
        std::vector<uint32_t> ownCell;      // ... and the cell of its layer's grid it is splatted in (j << 16 | i, a grid at most
                                            // tile + 2 maxGridMargin cells a side; kOffGrid: none)
        std::vector<uint32_t> pixelStart;   // per pixel of the tile's region (row-major), and one past: its first sample in g
        std::vector<int> occupiedStill;     // the D pass of the other layers: a layer's cells with samples summed over rectangles,
        std::vector<uint8_t> near;          // ... and its cells within the margin of one
    };
    // The grids' budget: the memory limit less what the caller holds and every thread's gathered
    // samples (GridBudget).
    const int threads = std::max(1, ThreadLimit::current());
    const uint64_t gatheredHeld = uint64_t(threads) * (uint64_t(largestTile) * kGatheredBytes + (largestRegion(W, H, o) + 1) * sizeof(uint32_t));
    const uint64_t limit = memoryLimit(), outside = o.memoryHeld + gatheredHeld;
    GridBudget budget(limit > outside ? limit - outside : 0, o.memoryHeld, gatheredHeld, threads);
    std::atomic<uint64_t> overReserve{0};
    tbb::enumerable_thread_specific<Scratch> scratch;
    parallelTiles(tilesX, tilesY, 1, [&](int tx0, int tx1, int ty0, int ty1) {
        Scratch& local = scratch.local();
        auto& g = local.g;
        Split& split = local.split;
        for (int ty = ty0; ty < ty1; ++ty)
            for (int tx = tx0; tx < tx1; ++tx) {
                // The tile's reservation from the grids' budget (GridBudget), given back once its
                // layers' grids are freed: at the end of the tile, or where it throws.
                struct Reservation {
                    GridBudget& budget;
                    std::vector<Layer>& layers;
                    uint64_t bytes = 0;
                    void reserve(uint64_t b, int x, int y) {
                        budget.reserve(b, x, y);
                        bytes = b;
                    }
                    ~Reservation() {
                        if (bytes == 0) return;
                        layers.clear();
                        budget.release(bytes);
                    }
                } reserved{budget, split.layers};
                // The pixels left to the method (LayerInput::methodPixels): own, and no ray. The
                // tile's work is the box of the others (its grids, and the samples it gathers:
                // a silhouette through one corner of the tile needs that corner); a tile of them
                // alone is not gathered either. (docs/layers.md, "A tile's margin per axis".)
                std::array<int, 4> box = tileBox(tx, ty);
                const Image<uint8_t>* left = own ? in.methodPixels : nullptr;
                if (left) {
                    std::array<int, 4> rays{box[2], box[3], box[0], box[1]};
                    for (int y = box[1]; y < box[3]; ++y)
                        for (int x = box[0]; x < box[2]; ++x)
                            if ((*left)(x, y))
                                out(x, y) = Vec3f(0.f), (*own)(x, y) = 1;
                            else
                                rays = {std::min(rays[0], x), std::min(rays[1], y), std::max(rays[2], x + 1), std::max(rays[3], y + 1)};
                    if (rays[0] >= rays[2]) {
                        ++leftTotal;
                        continue;
                    }
                    box = rays;
                }
                const int X0 = box[0], Y0 = box[1], X1 = box[2], Y1 = box[3];
                const std::array<int, 4> region = tileRegion(tx, ty, box);
                const int rx0 = region[0], ry0 = region[1], rx1 = region[2], ry1 = region[3];
                g.clear();
                if (g.capacity() < largestTile) g.reserve(largestTile);
                g.resize(regionCount(region));
                Gathered* next = g.data();
                // (Their sagittas where the light field keeps them; sags[i] is g[i]'s.)
                std::vector<Vec2f, UnwrittenAllocator<Vec2f>>& sagOf = local.sag;
                if (lf.curved()) {
                    if (sagOf.capacity() < largestTile) sagOf.reserve(largestTile);
                    sagOf.resize(g.size());
                }
                Vec2f* const sags = lf.curved() ? sagOf.data() : nullptr;
                // The slopes of each class, kept in registers while the samples are read (as
                // range[cls].add(c) they went through memory, a store and a load per sample on
                // the gather's critical path). A moving sample's class is 1 until the tile's
                // motion groups are known (groupByMotionField).
                float lo[kClasses], hi[kClasses];
                std::fill(lo, lo + kClasses, kInf);
                std::fill(hi, hi + kClasses, -kInf);
                bool anyMoving = false;
                bool anyEmitting = false;  // a sample carries an emitter's light (LayerOptions::emitterRays)
                const float invFocus = 1.f / view.focusDistance;  // (out of the loop: slopeAt)
                const int rw = rx1 - rx0;
                std::vector<uint32_t>& pixelStart = local.pixelStart;
                pixelStart.resize(size_t(rw) * (ry1 - ry0) + 1);
                for (int y = ry0; y < ry1; ++y)
                    for (int x = rx0; x < rx1; ++x) {
                        const size_t q = size_t(y) * W + x;
                        pixelStart[size_t(y - ry0) * rw + (x - rx0)] = uint32_t(next - g.data());
                        lf.forEachWithSag(q, [&](const LightFieldSample& s, Vec2f sag) {
                            Gathered a;
                            const Vec2f f = s.film(), l = s.lens(), m = s.motion();
                            a.x = float(x) + f.x;
                            a.y = float(y) + f.y;
                            a.u = l.x;
                            a.v = l.y;
                            a.t = s.time();
                            a.mx = m.x;
                            a.my = m.y;
                            if (sags) sags[next - g.data()] = sag;
                            a.cls = uint8_t(movesOnScreen(m) ? 1 : 0);
                            anyMoving |= a.cls != 0;
                            // slopeOf and the inverse depth from one division (the same values).
                            const float inv = 1.f / std::max(s.hit() ? s.depth : kInf, 1e-6f);
                            a.c = slopeAt(inv, view, invFocus);
                            a.invDepth = s.hit() ? inv : 0.f;
                            a.albedo = s.albedo;
                            a.radiance = s.radiance;
                            anyEmitting |= s.carriesEmission();
                            a.pixel = uint32_t(q);
                            a.surface = int8_t(s.surface());
                            const float c = a.c;
                            lo[a.cls] = std::min(lo[a.cls], c);
                            hi[a.cls] = std::max(hi[a.cls], c);
                            *next++ = a;
                        });
                    }
                assert(next == g.data() + g.size());  // every sample counted was read
                pixelStart.back() = uint32_t(g.size());
                gatheredTotal += g.size();
                const int groups = anyMoving ? groupByMotionField(g, rx0, ry0, rx1, ry1, local.field, lo, hi) : 0;
                SlopeRange range[kClasses];
                for (int k = 0; k < kClasses; ++k) range[k] = {lo[k], hi[k]};
                // Under a pinhole, with motion in the tile, the still samples are split by their
                // inverse depth (SplitKey), and a run of sharp still layers is cut where the
                // moving classes' inverse depths fall (keyRange); the moving classes are split
                // as before (by slope: all 0), since an object cut into slices of depth
                // composites with seams (AAF +28% on docs/sphere-away.json).
                SplitKey key;
                SlopeRange keyRange[kClasses];
                std::copy(range, range + kClasses, keyRange);
                if (view.apertureRadius <= 0.f && groups > 0) {
                    double sum = 0, n = 0;
                    for (const Gathered& a : g)
                        if (a.cls != 0 && a.invDepth > 0.f) sum += a.invDepth, n += 1;
                    if (n > 0 && sum > 0) {
                        key.scale = 3.5f;
                        key.invReference = float(n / sum);
                        for (SlopeRange& r : keyRange) r = SlopeRange{};
                        for (const Gathered& a : g) {
                            const float k = key.ofInvDepth(a.invDepth);
                            keyRange[a.cls].lo = std::min(keyRange[a.cls].lo, k);
                            keyRange[a.cls].hi = std::max(keyRange[a.cls].hi, k);
                        }
                        range[0] = keyRange[0];
                    }
                }
                if (g.empty()) {
                    for (int y = Y0; y < Y1; ++y)
                        for (int x = X0; x < X1; ++x) out(x, y) = Vec3f(0.f);
                    continue;
                }
                // What a sample carries: its surface's filtered light times its albedo, or its own.
                // (Taking instead each layer's radiance from the pixel's own samples on it, where
                // it has any, and only the coverage from the layers, measured worse: AAF relMSE
                // at 512x512 cornell 0.0000699 -> 0.0000882, sponza 0.000668 -> 0.000889,
                // docs/motion.json 0.0000931 -> 0.000142, conference 0.000625 -> 0.000719.)
                // In a blurred still layer a sample carries its own light where its filtered
                // light is another point's or would blur twice:
                // - on another surface than its pixel's primary one (that surface's filtered
                //   light is a film-space neighbour's, FrameBuffers::surfaceLight);
                // - on the primary surface of a pixel that saw several, where the slope is at
                //   least kOwnLightSlope (the pixel's filtered light is a mean over its circle of
                //   confusion and over filter neighbours on both sides of the silhouette);
                // - anywhere the slope is at least kOwnLightAll (the pixel's filtered light,
                //   already a mean over its circle of confusion, would be blurred again).
                // The layer's grid and the rays' disc average the own light over many samples.
                // In a blurred moving layer only the first. On another surface than its pixel's
                // primary one, the neighbour whose filtered light a sample would carry is as far
                // away as the motion: AAF relMSE -21% on a moving bunny over a floor (384x384),
                // -11.5% / -8.5% on raster-cornell without and with its textures, -3.6% on
                // docs/motion.json, -3.7% / -0.3% on raster-pan, +7.5% / +2.7% on
                // raster-motion-defocus (its moving sphere's smooth light). On the primary
                // surface it keeps the filtered light: its radiance is split over 8 time bins,
                // and there the own light (the two slope rules as for a still layer) gained
                // nothing on the bunny and cost +10% on raster-motion-defocus without textures
                // (docs/layers.md, "Own light on a moving layer's other surfaces").
                // Measured, AAF at 512x512, 16 spp, relMSE with layers before -> after: conference
                // 0.000588 -> 0.000485, sponza 0.000656 -> 0.000586, bunny 0.000112 -> 0.000103,
                // cornell-sphere 0.000129 -> 0.000124, cornell 0.0000709 -> 0.0000712; the held-out
                // docs/bunny-near.json (384x384) 0.000289 -> 0.0000961. The thresholds and the
                // variants tried (other slopes, moving layers, the pixel's unfiltered light) are
                // in docs/layers.md, "Own light where the filtered light is another point's" and
                // "Every sample its own light where the blur is large".
                auto radianceOf = [&](const Gathered& s, const auto& l) {  // l: a Layer, or its SplatTarget
                    const float c = std::abs(l.c);
                    const bool own = !l.sharp && (s.surface > 0 || (!l.moving && s.surface == 0 &&
                                                                    (c >= kOwnLightAll || (mixed[s.pixel] && c >= kOwnLightSlope))));
                    // (A sample with no albedo carries its own: an emitter's, its emission.)
                    const Image3f* light = s.surface >= 0 && !own && s.albedo != 0u ? in.surfaceLight[s.surface] : nullptr;
                    return light ? unpackRgb9e5(s.albedo) * (*light)[s.pixel] : unpackRgb9e5(s.radiance) * invRadianceScale;
                };
                // A motion group's slope and depth over the shutter (slopeRate, depthRateOf), and
                // the range of its samples' slopes at mid-shutter.
                float rate[kClasses] = {}, depthRate[kClasses] = {};
                SlopeRange splitRange[kClasses];
                std::copy(range, range + kClasses, splitRange);
                if (groups > 0) {
                    // Moments per motion group and kRateCell cell of the sharp image, over the
                    // apron and a margin of 64 px (beyond it, the border cells).
                    const int ox = rx0 - 64, oy = ry0 - 64;
                    const int nx = (rx1 - rx0 + 128) / kRateCell + 1, ny = (ry1 - ry0 + 128) / kRateCell + 1;
                    const size_t cells = size_t(nx) * ny;
                    auto& moments = local.moments;
                    auto& depthMoments = local.depthMoments;
                    moments.assign(size_t(groups) * cells, SlopeMoments{});
                    depthMoments.assign(size_t(groups) * cells, SlopeMoments{});
                    for (const Gathered& a : g) {
                        if (a.cls == 0) continue;
                        const Vec2f p = shearOf(a, a.c, a.mx, a.my, 0.f);
                        const int ix = std::clamp(int(std::floor((p.x - float(ox)) / float(kRateCell))), 0, nx - 1);
                        const int iy = std::clamp(int(std::floor((p.y - float(oy)) / float(kRateCell))), 0, ny - 1);
                        const size_t cell = size_t(a.cls - 1) * cells + size_t(iy) * nx + ix;
                        moments[cell].add(a.c, a.t);
                        if (a.invDepth > 0.f) depthMoments[cell].add(1.f / a.invDepth, a.t);
                    }
                    for (int k = 1; k <= groups; ++k) depthRate[k] = depthRateOf(&depthMoments[size_t(k - 1) * cells], cells);
                    bool any = false;
                    for (int k = 1; k <= groups; ++k) any |= (rate[k] = slopeRate(&moments[size_t(k - 1) * cells], cells, o)) != 0.f;
                    if (any) {
                        for (int k = 1; k < kClasses; ++k)
                            if (rate[k] != 0.f) splitRange[k] = SlopeRange{};
                        for (const Gathered& a : g) {
                            if (rate[a.cls] == 0.f) continue;
                            const float c = a.c - rate[a.cls] * (a.t - 0.5f);
                            splitRange[a.cls].lo = std::min(splitRange[a.cls].lo, c);
                            splitRange[a.cls].hi = std::max(splitRange[a.cls].hi, c);
                        }
                    }
                }
                splitLayers(g, sags, keyRange, rate, depthRate, splitRange, o, split, key);
                std::vector<Layer>& layers = split.layers;
                layerTotal += layers.size();
                if (groups > 0) {
                    // Each moving layer's tileNeed: per sample of it, its path's ends (alongChord)
                    // and the lens's disc around them against the tile's box. Only where the
                    // sample's motion group changes in depth (Layer::depthRate), whose image grows
                    // or shrinks over the shutter: where it moves at one depth its motion varies
                    // little across it, and the root mean square reaches as far. Not the samples
                    // of a pixel with bent paths (LightFieldSamples::bentReach: a surface turning
                    // in depth past the arcs' limit), which lie off their chords: with them, the
                    // box of docs/turning-room.json turning 120 degrees about its diagonal took
                    // grids reaching farther, whose far cells held less of it than the clamped
                    // edge did (MC relMSE +2%, seeds 3 and 4).
                    const float bx0 = float(X0), by0 = float(Y0), bx1 = float(X1), by1 = float(Y1);
                    // (Per motion group, where its chords end: every layer of the group has its
                    // depth rate, splitLayers.)
                    Vec2f chordEnds[kClasses];
                    for (int k = 1; k <= groups; ++k) chordEnds[k] = {alongChord(-0.5f, depthRate[k]), alongChord(0.5f, depthRate[k])};
                    for (const Gathered& a : g) {
                        if (a.cls == 0 || depthRate[a.cls] == 0.f || lf.bentReach(a.pixel) > 0.f) continue;
                        Layer& l = layers[size_t(split.layerOf(a))];  // (a moving layer: its class is a motion group)
                        const Vec2f q = shearOf(a, l.c, a.mx, a.my, l.depthRate);
                        const float a0 = chordEnds[a.cls].x, a1 = chordEnds[a.cls].y, lens = std::abs(l.c);
                        const float ex0 = q.x + a.mx * a0, ex1 = q.x + a.mx * a1, ey0 = q.y + a.my * a0, ey1 = q.y + a.my * a1;
                        if (std::max(ex0, ex1) + lens < bx0 || std::min(ex0, ex1) - lens > bx1 || std::max(ey0, ey1) + lens < by0 ||
                            std::min(ey0, ey1) - lens > by1)
                            continue;
                        // (Beyond the lens's reach, which reachAxes adds.)
                        l.tileNeed = vmax(l.tileNeed, Vec2f{std::max({0.f, bx0 - lens - q.x, q.x - bx1 - lens}), std::max({0.f, by0 - lens - q.y, q.y - by1 - lens})});
                    }
                }
                // Front to back at each time: where a moving layer passes in depth behind or in
                // front of another layer over the shutter, the two are ordered in each of
                // kOrderBins bins of shutter time (the rule per pair below); every other pair
                // keeps splitLayers' order, one over the shutter. Twelve spheres moving twelve
                // ways, some in depth (docs/many-motion.json): with one order a sphere moving
                // away stayed in front of one it passed behind, its colour over the other's
                // trail (AAF relMSE with layers 0.000165 -> 0.000126); a sphere rolling behind
                // the table's edge (docs/conference-motion.json) 0.000720 -> 0.000628.
                // `binOrder` holds each bin's layers front to back and `binRank` each layer's
                // place in them, only where some bin's order is not splitLayers' (the tile's
                // `timeOrder`); elsewhere the layers' own order, the same images.
                const int nLayers = int(layers.size());
                bool timeOrder = false;
                // (timeOrder) Per layer: its place changes from bin to bin against another one.
                // Only pairs of such layers change their order: the other layers' D and rays
                // take splitLayers' order.
                std::vector<uint8_t>& reordered = local.reordered;
                std::vector<int>& binOrder = local.binOrder;
                std::vector<int>& binRank = local.binRank;
                std::vector<float>& binKey = local.binKey;
                // (Only where some moving layer and another one are not apart in depth over the
                // whole shutter: one's farthest sample clearly nearer than the other's nearest.)
                auto clearly = [](float nearer, float farther) { return nearer > farther * (1.f + kOrderMargin); };
                bool overlapping = false;
                for (int i = 0; i < int(layers.size()) && !overlapping; ++i)
                    for (int j = i + 1; j < int(layers.size()) && !overlapping; ++j) {
                        const Layer &li = layers[size_t(i)], &lj = layers[size_t(j)];
                        overlapping = (li.moving || lj.moving) && !clearly(li.invDepthMin, lj.invDepthMax) &&
                                      !clearly(lj.invDepthMin, li.invDepthMax);
                    }
                if (overlapping) {
                    // Per bin, a moving layer's nearest sample (-1 in a bin without samples: no
                    // say there) and the box its samples of that bin were seen in; a still layer's
                    // inverse depth summed over cells of kOrderCell pixels.
                    binKey.assign(size_t(nLayers) * kOrderBins, -1.f);
                    std::vector<std::array<float, 4>>& box = local.box;
                    box.assign(size_t(nLayers) * kOrderBins, {kInf, kInf, -kInf, -kInf});
                    const int cx = (rx1 - rx0 + kOrderCell - 1) / kOrderCell + 1, cyN = (ry1 - ry0 + kOrderCell - 1) / kOrderCell + 1;
                    const size_t cells = size_t(cx) * cyN;
                    std::vector<Vec2f>& depthCells = local.depthCells;  // per still layer and cell: sum of inverse depth, count
                    depthCells.assign(size_t(nLayers) * cells, Vec2f{0.f, 0.f});
                    auto cellOf = [&](float x, float y) {
                        const int ix = std::clamp(int((x - float(rx0)) / float(kOrderCell)), 0, cx - 1);
                        const int iy = std::clamp(int((y - float(ry0)) / float(kOrderCell)), 0, cyN - 1);
                        return size_t(iy) * cx + size_t(ix);
                    };
                    // Per moving layer, bin and cell, its nearest sample's inverse depth (-1: none),
                    // carried to the bin's centre along the layer's depth rate (within one bin of
                    // docs/fast-motion.json's sphere its depth changes by 6%).
                    std::vector<float>& nearCells = local.nearCells;
                    std::vector<int>& movingSlot = local.movingSlot;
                    movingSlot.assign(size_t(nLayers), -1);
                    int nMoving = 0;
                    for (int k = 0; k < nLayers; ++k)
                        if (layers[size_t(k)].moving) movingSlot[size_t(k)] = nMoving++;
                    // (Only two moving layers are ordered by them.)
                    const bool byCells = nMoving >= 2;
                    if (byCells) nearCells.assign(size_t(nMoving) * kOrderBins * cells, -1.f);
                    // (A still layer's depth from every kOrderStride-th sample: a mean over cells
                    // of 8 x 8 pixels needs no more, and the still samples are most of a tile's.)
                    for (size_t i = 0; i < g.size(); ++i) {
                        const Gathered& a = g[i];
                        if (a.cls == 0) {
                            if (i % kOrderStride) continue;
                            Vec2f& d = depthCells[size_t(split.layerOf(a)) * cells + cellOf(a.x, a.y)];
                            d.x += a.invDepth, d.y += 1.f;
                            continue;
                        }
                        const int k = split.layerOf(a), bin = timeBinOf(kOrderBins, a.t);
                        const size_t kb = size_t(k) * kOrderBins + size_t(bin);
                        binKey[kb] = std::max(binKey[kb], a.invDepth);
                        if (byCells) {
                            const float g = layers[size_t(k)].depthRate, centre = (float(bin) + 0.5f) / float(kOrderBins);
                            float& near = nearCells[(size_t(movingSlot[size_t(k)]) * kOrderBins + size_t(bin)) * cells + cellOf(a.x, a.y)];
                            near = std::max(near, a.invDepth * (1.f + g * (a.t - 0.5f)) / (1.f + g * (centre - 0.5f)));
                        }
                        std::array<float, 4>& bx = box[kb];
                        bx[0] = std::min(bx[0], a.x), bx[1] = std::min(bx[1], a.y), bx[2] = std::max(bx[2], a.x), bx[3] = std::max(bx[3], a.y);
                    }
                    // A still layer's mean inverse depth where moving layer m's samples of bin b
                    // were seen (-1: none of its samples there).
                    auto localDepth = [&](int still, int m, int b) {
                        const std::array<float, 4>& bx = box[size_t(m) * kOrderBins + size_t(b)];
                        const size_t c0 = cellOf(bx[0], bx[1]), c1 = cellOf(bx[2], bx[3]);
                        const size_t ix0 = c0 % cx, iy0 = c0 / cx, ix1 = c1 % cx, iy1 = c1 / cx;
                        Vec2f sum{0.f, 0.f};
                        const Vec2f* d = &depthCells[size_t(still) * cells];
                        for (size_t iy = iy0; iy <= iy1; ++iy)
                            for (size_t ix = ix0; ix <= ix1; ++ix) sum.x += d[iy * cx + ix].x, sum.y += d[iy * cx + ix].y;
                        return sum.y > 0.f ? sum.x / sum.y : -1.f;
                    };
                    // Per pair and bin, whether layer i goes before layer j in that bin though it
                    // does not in splitLayers' order (and so the other way round):
                    // - two moving layers seen in the same cells in a bin: by their depths there
                    //   (kOrderVotes). A layer's nearest sample over the whole tile is not where
                    //   it meets the other: the bunny of docs/bunny-slats.json coming forward
                    //   through the slats' depth was nearer than a slat by its chest, and went
                    //   before the slats in the shutter's second half, where they cross its head
                    //   behind them (AAF relMSE with layers -24%, MC -12%; docs/layers.md, "Two
                    //   moving layers ordered where they meet");
                    // - where no bin has a say that way, two moving layers that cross: one
                    //   clearly in front of the other in some bin and clearly behind it in
                    //   another, by their nearest samples, ordered by
                    //   those in each bin (not every pair: the parts of one object in several
                    //   motion groups, a sphere moving towards the camera, have nearly one nearest
                    //   depth, and swapped from bin to bin by a hair their pooled coverages, N / D
                    //   over the shutter, no longer add up where they meet: docs/fast-motion.json
                    //   MC relMSE +9%);
                    // - a moving layer and a still one: the moving one behind where its nearest
                    //   sample in the bin is clearly behind the still layer's mean depth where
                    //   those samples were seen, otherwise in front (a still layer spans depths:
                    //   an object moving over the floor it stands on is nearer than the floor's
                    //   mean over the tile at one time and farther at another, but in front of
                    //   the floor under it all along: layers_test
                    //   Layers.AMovingLayerGoesBeforeAStillOneItReachesInFrontOf).
                    std::vector<uint8_t>& before = local.before;  // [(b * n + i) * n + j]
                    before.assign(size_t(kOrderBins) * nLayers * nLayers, 0);
                    bool any = false;
                    for (int i = 0; i < nLayers; ++i)
                        for (int j = i + 1; j < nLayers; ++j) {
                            const Layer &li = layers[size_t(i)], &lj = layers[size_t(j)];
                            if (!li.moving && !lj.moving) continue;
                            auto key = [&](int k, int b) { return binKey[size_t(k) * kOrderBins + size_t(b)]; };
                            auto set = [&](int b, bool jFirst) {
                                before[(size_t(b) * nLayers + size_t(jFirst ? j : i)) * nLayers + size_t(jFirst ? i : j)] = 1;
                                any |= jFirst;  // (i is before j in splitLayers' order)
                            };
                            if (li.moving && lj.moving) {
                                int say[kOrderBins] = {};  // 1: i first, -1: j first, 0: no say
                                bool anySay = false;
                                for (int b = 0; b < kOrderBins; ++b) {
                                    const float* ni = &nearCells[(size_t(movingSlot[size_t(i)]) * kOrderBins + size_t(b)) * cells];
                                    const float* nj = &nearCells[(size_t(movingSlot[size_t(j)]) * kOrderBins + size_t(b)) * cells];
                                    int iNearer = 0, jNearer = 0;
                                    for (size_t c = 0; c < cells; ++c) {
                                        if (ni[c] < 0.f || nj[c] < 0.f) continue;
                                        iNearer += clearly(ni[c], nj[c]);
                                        jNearer += clearly(nj[c], ni[c]);
                                    }
                                    // (Parts of one object in two motion groups are nearer by turns.)
                                    say[b] = iNearer > kOrderVotes * jNearer ? 1 : jNearer > kOrderVotes * iNearer ? -1 : 0;
                                    anySay |= say[b] != 0;
                                }
                                if (anySay) {
                                    for (int b = 0; b < kOrderBins; ++b)
                                        if (say[b] != 0) set(b, say[b] < 0);
                                    continue;
                                }
                                bool ahead = false, behind = false;
                                for (int b = 0; b < kOrderBins; ++b) {
                                    if (key(i, b) < 0.f || key(j, b) < 0.f) continue;
                                    ahead |= clearly(key(i, b), key(j, b));
                                    behind |= clearly(key(j, b), key(i, b));
                                }
                                if (!(ahead && behind)) continue;
                                for (int b = 0; b < kOrderBins; ++b)
                                    if (key(i, b) >= 0.f && key(j, b) >= 0.f) set(b, key(j, b) > key(i, b));
                            } else {
                                const int m = li.moving ? i : j, still = li.moving ? j : i;
                                for (int b = 0; b < kOrderBins; ++b) {
                                    if (key(m, b) < 0.f) continue;
                                    const float d = localDepth(still, m, b);
                                    if (d < 0.f) continue;
                                    const bool movingBehind = clearly(d, key(m, b));
                                    set(b, (m == j) != movingBehind);  // j first: j moving and in front, or j still and the moving i behind
                                }
                            }
                        }
                    if (any) {
                        binOrder.resize(size_t(nLayers) * kOrderBins);
                        binRank.resize(size_t(nLayers) * kOrderBins);
                        for (int b = 0; b < kOrderBins; ++b) {
                            int* order = &binOrder[size_t(b) * nLayers];
                            orderLayers(&before[size_t(b) * nLayers * nLayers], nLayers, order);
                            for (int i = 0; i < nLayers; ++i) {
                                binRank[size_t(b) * nLayers + size_t(order[i])] = i;
                                timeOrder |= order[i] != i;
                            }
                        }
                        // A layer is reordered where its order against another one is not
                        // splitLayers' in some bin: also a layer that another one jumped
                        // (orderLayers), though no rule of its own changed.
                        reordered.assign(size_t(nLayers), 0);
                        for (int b = 0; b < kOrderBins; ++b) {
                            const int* rank = &binRank[size_t(b) * nLayers];
                            for (int i = 0; i < nLayers; ++i)
                                for (int j = i + 1; j < nLayers; ++j)
                                    if (rank[j] < rank[i]) reordered[size_t(i)] = reordered[size_t(j)] = 1;
                        }
                    }
                }
                // (timeOrder) Whether layer k lies in front of layer l at shutter time t.
                auto inFront = [&](int k, int l, float t) {
                    const int* rank = &binRank[size_t(timeBinOf(kOrderBins, t)) * nLayers];
                    return rank[k] < rank[l];
                };
                bool anyBlurred = false;
                // The sharp twins of the layers in the sharp band (below), and each layer's (-1: none).
                std::vector<Layer> twins;
                std::vector<int> twinOf(layers.size(), -1);
                // A blurred layer's grid reaches |c| + |m| / 2 + 3 sigma beyond its tile (below),
                // in cells of `step` pixels (Layer::step), its sigmas in cells.
                auto sigmaIn = [&](const Layer& l, int step) {
                    return std::clamp(o.sigmaScale * std::abs(l.c) / float(step), o.sigmaMin, o.sigmaMax);
                };
                auto reachIn = [&](const Layer& l, int step) {
                    return (std::abs(l.c) + chordReach(l.depthRate) * l.motionRms) / float(step) + 3.f * sigmaIn(l, step);
                };
                // ... along x and along y apart: the lens's disc and the Gaussian both ways, the
                // motion as far as it goes along each (a still layer's, whose samples move less
                // than a pixel, within reachIn both ways).
                auto reachAxes = [&](const Layer& l, int step) {
                    const float k = chordReach(l.depthRate), s3 = 3.f * sigmaIn(l, step);
                    // (A turning layer's as far as its farthest-moving samples: Layer::motionMax.)
                    const bool turning = l.sagMax.x > 0.f || l.sagMax.y > 0.f;
                    const float rx = turning ? k * l.motionMax.x + l.sagMax.x : std::max(k * l.motionRmsX, l.tileNeed.x);
                    const float ry = turning ? k * l.motionMax.y + l.sagMax.y : std::max(k * l.motionRmsY, l.tileNeed.y);
                    return Vec2f{(std::abs(l.c) + rx) / float(step) + s3, (std::abs(l.c) + ry) / float(step) + s3};
                };
                // A grid's margin beyond its tile (cells) for a reach of r cells.
                auto marginOf = [](float r) { return int(std::ceil(r)) + 1; };
                // The most cells a grid may have: a still layer's (or a moving one's) that reaches
                // maxGridMargin beyond its tile both ways.
                const float maxCells = sqr(float(o.tile + 2 * o.maxGridMargin));
                // The cell size that keeps a layer's grid within LayerOptions::stillGridReach
                // cells of its tile (a still layer) or within maxCells (a moving one): 1 pixel,
                // or past that the fewest pixels that do (a moving layer's at most
                // kMaxMovingStep); 0 where none will.
                auto stepOf = [&](const Layer& l) {
                    if (l.moving) {
                        // A moving layer's grid reaches along each axis as far as its motion
                        // there (a streak across the image, far along x and no farther than its
                        // blur along y); it fits where it has no more cells than a grid reaching
                        // maxGridMargin both ways. (Before, its reach in both axes was the
                        // motion's length, bounded by maxGridMargin: a sphere moving 264 px kept
                        // its pixels' own samples, and so did motion of 282 px, docs/motion.json
                        // rendered at 1024x1024; docs/layers.md, "A moving layer's grid per axis".)
                        // Past that its cells are larger, as a still layer's: a motion along a
                        // diagonal, a dolly's near walls, blurs along itself far more than a cell.
                        // (Before, a motion of more than about 250 px along each axis fitted in
                        // no grid: on docs/sponza-dolly.json a quarter of the image kept its
                        // pixels' own samples; docs/layers.md, "Larger cells for a long motion".)
                        for (int step = 1; step <= kMaxMovingStep; ++step) {
                            const Vec2f r = reachAxes(l, step);
                            // (A tile's cells: with cells of `step` pixels that do not divide
                            // it, one more.)
                            const int tileCells = step == 1 ? o.tile : (o.tile + step - 1) / step + 1;
                            if (float(tileCells + 2 * marginOf(r.x)) * float(tileCells + 2 * marginOf(r.y)) <= maxCells) return step;
                        }
                        return 0;
                    }
                    const float bound = float(std::min(o.maxGridMargin, o.stillGridReach)) - 1.f;
                    if (reachIn(l, 1) <= bound) return 1;
                    if (bound <= 3.f * o.sigmaMax) return 0;
                    const float first = std::ceil(std::abs(l.c) / (bound - 3.f * o.sigmaMax));
                    if (!(first < float(1 << 20))) return 0;
                    int step = std::max(2, int(first));
                    while (reachIn(l, step) > bound) ++step;  // (at most once or twice: the sigma is at most sigmaMax)
                    return step;
                };
                // A layer that fits in no grid cannot be reprojected, and then no layer of the
                // tile is: every one keeps its pixels' own samples, as without layers. A layer
                // that keeps its own samples has its coverage averaged over the lens and the
                // shutter, a blurred one behind it its coverage per lens point and time:
                // composited, the two do not add up where they are parts of one surface (a near
                // column's slices, nearest first, over the light behind it), and the light
                // behind showed through. So it was for still layers too before their cells grew
                // with their blur: on a held-out view of Sponza with a column 4 units from a lens
                // of radius 3 (slopes to 173 px at 256x256) MC's relMSE was 0.0132 with the
                // column's nearest slices kept sharp, 0.0124 without layers, with bright 64-px
                // tiles where the column should have hidden the light; now 0.0013
                // (docs/layers.md, "Blur past the grid's reach").
                bool tileBeyondGrid = false;
                for (const Layer& l : layers)
                    if (!l.sharpRun && stepOf(l) == 0) tileBeyondGrid = true;
                for (Layer& l : layers) {
                    const float spread = l.cMax - l.cMin;
                    const float motion = l.motionRms;
                    // The grid blurs by its own kernel too: the cells a sample is splatted into
                    // (variance 1/12 per axis), the Gaussian (sigma^2) and the bilinear lookup
                    // (1/6). The rays' lens and shutter shear is shaped (Shaped) so that with
                    // it they give the true blur, a disc of radius |c| (c^2 / 4 per axis) and a
                    // segment of length |m| (m^2 / 12); a layer whose true blur is below the
                    // grid's own with the smallest sigma is sharp.
                    // A blurred layer's grid reaches |c| + |m| / 2 + 3 sigma beyond its tile
                    // (a moving one's along each axis with that axis's motion: reachAxes),
                    // wherever the rays read it, also past the trajectories a tile gathers
                    // (LayerOptions::maxReach): there it holds only the samples gathered, but N
                    // and D alike (the samples of the same source pixels), so its coverage stays
                    // right for the rays of this tile, whose own pixels are among them. (Capped at
                    // maxReach, a fast box's 220-px trail lost its ends: the rays read the
                    // clamped edge of the grid; docs/layers.md, "Motion longer than a tile's reach, and an object moving in depth".)
                    // Past LayerOptions::stillGridReach a still layer's cells are larger (stepOf);
                    // with more cells than one reaching maxGridMargin both ways a moving layer fits
                    // in no grid, and then no layer of the tile is reprojected (tileBeyondGrid, above).
                    const bool forcedSharp = l.sharpRun || tileBeyondGrid;
                    l.sharp = forcedSharp || isSharp(l.c, spread, motion, o);
                    l.rayC = l.c, l.rayMx = l.mx, l.rayMy = l.my;
                    int lmx = 0, lmy = 0;  // the grid's margins beyond the tile, in cells
                    l.step = l.sharp ? 1 : stepOf(l);
                    l.invStep = 1.f / float(l.step);
                    const float sigma = sigmaIn(l, l.step);
                    const Vec2f gridReach = reachAxes(l, l.step);  // beyond the tile, the rays' cells
                    if (!l.sharp) {
                        // (Not widened by the slopes' spread: the rays follow the slope they find. Half the
                        // spread, as it was, over-blurred the layers a tile's budget had widened: AAF
                        // relMSE on docs/conference-wide.json with a budget of 8 layers 0.000927 -> 0.000667.)
                        l.sigma = sigma;
                        // The coverage's Gaussian may be narrower than the radiance's: a Gaussian
                        // of 0.5 px sampled at 1-px cells is aliased, and the edge it gives a
                        // layer just past the sharp threshold depends on where the edge falls
                        // in its cell (a half-plane at c = 1.49 px: 0.067 of the edge's
                        // contrast too sharp on a cell boundary, 0.010 on a cell centre;
                        // scripts/layer_edge_sim.py). With a narrower one the rays' lens shear,
                        // continuous, carries more of the blur (docs/layers.md, "What the mixed
                        // pixels' error is made of").
                        l.sigmaCoverage = std::clamp(o.sigmaScale * std::abs(l.c) / float(l.step), std::min(o.sigmaCoverageMin, o.sigmaMin), l.sigma);
                        const float gridBlur = sqr(float(l.step)) * (kCellBlur + sqr(l.sigmaCoverage));  // (pixels^2)
                        l.gridBlur = l.lensBlur = gridBlur;
                        l.shapeRays(motion);
                        lmx = marginOf(gridReach.x);  // (within stepOf's bound: above)
                        lmy = marginOf(gridReach.y);
                        anyBlurred = true;
                    }
                    // (In cells; with a step of 1, X0 - lmx to X1 + lmx.)
                    l.gx0 = X0 / l.step - lmx;
                    l.gy0 = Y0 / l.step - lmy;
                    l.gw = (X1 + l.step - 1) / l.step + lmx - l.gx0;
                    l.gh = (Y1 + l.step - 1) / l.step + lmy - l.gy0;
                    // (A sharp layer's pixels take one ray where the whole tile is sharp: its
                    // radiance is its pixel's samples over the whole shutter, not one bin's.)
                    l.timeBins = l.moving && !l.sharp ? kTimeBins : 1;
                    // (acc and accD: below, where the splat's cells are known.)
                    // The sharp band (LayerOptions::sharpBand): a blurred layer whose slope nearest
                    // focus lies below the threshold also keeps its pixels' own samples, as a
                    // sharp layer of the tile would (its twin), and each pixel blends the two by
                    // its own slope (sharpWeight): a surface crossing the threshold turns from its
                    // own samples to its grid gradually, not at a tile's or a layer's edge.
                    const size_t k = size_t(&l - layers.data());
                    if (!l.sharp && !forcedSharp && o.sharpBand < 1.f) {
                        const float nearest = l.cMin <= 0.f && l.cMax >= 0.f ? 0.f : std::min(std::abs(l.cMin), std::abs(l.cMax));
                        if (sharpWeight(nearest, motion, o) < 1.f) {
                            twinOf[k] = int(twins.size());
                            Layer& t = twins.emplace_back();
                            t.c = l.c, t.moving = l.moving;  // (radianceOf's and resolveCells' reads)
                            t.sharp = true, t.timeBins = 1;
                            t.gx0 = X0, t.gy0 = Y0, t.gw = X1 - X0, t.gh = Y1 - Y0;
                            t.accWin = t.dWin = {0, 0, t.gw, t.gh};  // (acc and accD: below, with the layers')
                        }
                    }
                }
                blurredTotal += anyBlurred ? 1 : 0;
                // Splat: N and D at the layer's shear, W and the radiance at the sample's own.
                // (Per layer, whether it has a motion grid: its sums are allocated with the
                // accumulations, below.)
                bool anyMotionGrid = false;
                std::vector<std::vector<float>> motionAcc(layers.size());
                std::vector<std::vector<float>> sagAcc(layers.size());  // per cell: the sums of the effective sagittas (Layer::sagGrid)
                std::vector<uint8_t> hasMotionGrid(layers.size(), 0);
                for (size_t k = 0; k < layers.size(); ++k)
                    if (layers[k].moving && !layers[k].sharp && layers[k].motionScale > 0.f) hasMotionGrid[k] = 1, anyMotionGrid = true;
                // What the splat reads of each layer, packed (the Layer is hundreds of bytes, and
                // every sample visits every layer in front of its own); a moving layer with a
                // motion grid (`motion`) takes its D in the pass below.
                struct SplatTarget {
                    float c, mx, my, depthRate, invDepthMax;
                    int gx0, gy0, gw, gh, accStride, timeBins;
                    bool sharp, moving;
                    float *acc, *d, *motion;
                    int step;
                    float invStep;
                    int ax0, ay0, aw, dx0, dy0, dw;  // (Layer::accWin and dWin: their origins and widths)
                    int accIndex(int i, int j) const { return (j - ay0) * aw + (i - ax0); }
                    int dIndex(int i, int j) const { return (j - dy0) * dw + (i - dx0); }
                    bool inFrontOfAll(float q, float t) const { return moving && inFrontOfMoving(invDepthMax, depthRate, q, t); }
                };
                if (o.crispAcrossMotion && anyMotionGrid) {
                    // Which axis each blurred moving layer in focus keeps crisp (Layer::crisp): the
                    // largest motion of its samples along each axis.
                    std::vector<std::array<float, 2>> most(layers.size(), {-1.f, -1.f});
                    for (size_t k = 0; k < layers.size(); ++k) {
                        const Layer& l = layers[k];
                        if (hasMotionGrid[k] && l.step == 1 && std::max(std::abs(l.cMin), std::abs(l.cMax)) <= kCrispSlope) most[k] = {0.f, 0.f};
                    }
                    for (const Gathered& s : g) {
                        std::array<float, 2>& m = most[size_t(split.layerOf(s))];
                        if (m[0] < 0.f) continue;
                        m[0] = std::max(m[0], std::abs(s.mx));
                        m[1] = std::max(m[1], std::abs(s.my));
                    }
                    for (size_t k = 0; k < layers.size(); ++k) {
                        Layer& l = layers[k];
                        const std::array<float, 2>& m = most[k];
                        if (m[0] < 0.f) continue;
                        l.crisp = m[1] <= kCrispMotion ? 1 : m[0] <= kCrispMotion ? 0 : -1;
                        if (l.crisp < 0) continue;
                        // Across the motion the grid blurs by its cells alone (1/12 per axis), so
                        // the rays carry the lens's disc but for that; along it the grid's whole
                        // blur, which the motion's shaping counts.
                        l.lensBlur = kCellOnly;
                        l.shapeRays(l.motionRms);
                    }
                }
                // Each sample's layer and the cell of its layer's grid it is splatted in (below), and
                // per layer the box of those cells: its acc and accD hold that box grown by as far
                // as the passes after carry what can change its cells (Layer::accWin, dWin): a moving
                // layer's grid reaches as far as its motion, and its samples fill a part of it (a
                // snowflake's trail). (Over the whole grid, with up to 29 layers a tile, the
                // tile's accumulations were 120 MB a thread on docs/snow.json; docs/layers.md,
                // "Memory per thread".)
                constexpr uint32_t kOffGrid = ~0u;
                std::vector<uint16_t>& sampleLayer = local.sampleLayer;
                sampleLayer.resize(g.size());
                // Its own layer's N, D, W and radiance at its own trajectory's point. (A turning
                // object's sample on its arc: only in a layer with a motion grid, whose rays and
                // D follow the grid's sagittas.)
                // (Of sample g[i], in layer sl.)
                auto ownCellOf = [&](size_t i, int sl) __attribute__((always_inline)) {  // (called in the splat: a call per sample cost 1% of conference AAF)
                    const Gathered& s = g[i];
                    const Layer& l = layers[size_t(sl)];
                    Vec2f own = layerPosition(s, l.sharp, s.c, s.mx, s.my, l.depthRate);
                    if (const Vec2f sag = sags ? sags[i] : Vec2f{0.f, 0.f}; hasMotionGrid[size_t(sl)] && curved(sag)) {
                        const Vec2f shift = curvedShift(l.arc, {s.mx, s.my}, effectiveSag(s, sag, l.depthRate), alongChord(s.t - 0.5f, l.depthRate), s.t);
                        own = {own.x + shift.x, own.y + shift.y};
                    }
                    int ci, cj;
                    return gridCellAt(l.gx0, l.gy0, l.gw, l.gh, own, l.invStep, ci, cj) ? uint32_t(cj) << 16 | uint32_t(ci) : kOffGrid;
                };
                // Only in a tile with a blurred moving layer: a still layer's grid reaches at most
                // stillGridReach cells beyond its tile, and on docs/bunny-near.json and conference
                // (lens blur alone) the pass over the samples it needs made the stage 10% slower.
                const bool windows = !o.everyCell && !countEveryD &&
                                     std::any_of(layers.begin(), layers.end(), [](const Layer& l) { return l.moving && !l.sharp; });
                std::vector<uint32_t>& ownCell = local.ownCell;
                std::vector<CellBox> splatBox(layers.size(), CellBox{INT_MAX, INT_MAX, INT_MIN, INT_MIN});
                if (windows) {
                    ownCell.resize(g.size());
                    for (size_t i = 0; i < g.size(); ++i) {
                        const Gathered& s = g[i];
                        const int sl = split.layerOf(s);
                        sampleLayer[i] = uint16_t(sl);
                        const uint32_t c = ownCell[i] = ownCellOf(i, sl);
                        if (c == kOffGrid) continue;
                        const int ci = int(c & 0xffffu), cj = int(c >> 16);
                        CellBox& b = splatBox[size_t(sl)];
                        b = {std::min(b.x0, ci), std::min(b.y0, cj), std::max(b.x1, ci + 1), std::max(b.y1, cj + 1)};
                    }
                }
                for (size_t k = 0; k < layers.size(); ++k) {
                    Layer& l = layers[k];
                    const CellBox& b = splatBox[k];
                    if (!windows) {
                        l.accWin = l.dWin = {0, 0, l.gw, l.gh};
                    } else if (b.empty()) {
                        l.accWin = l.dWin = {};
                    } else {
                        // The radiance's Gaussians (sigma, then the edge-stopping one along each
                        // axis) or the coverage's (sigmaCoverage); for D, the Ds dMargin counts
                        // and their Gaussian, and resolveCells' rings beyond (whose box lies
                        // within dWin).
                        const int coverage = l.sharp ? 0 : int(std::ceil(3.f * l.sigmaCoverage));
                        const float width = l.moving ? o.movingEdgeWidth : o.stillEdgeWidth;
                        const int radiance = l.sharp ? 0 : int(std::ceil(3.f * l.sigma)) + (width > 0.f ? int(std::ceil(3.f * width * l.sigma)) : 0);
                        const int ra = std::max(coverage, radiance), rd = std::max(dMargin(l) + coverage, ra) + kFillRings;
                        l.accWin = b.grown(ra, ra, l.gw, l.gh);
                        l.dWin = b.grown(rd, rd, l.gw, l.gh);
                    }
                }
                // The grids' bound, reserved from the budget before they are allocated, and the
                // grids allocated.
                auto cellsOf = [](const CellBox& w) { return w.empty() ? uint64_t(0) : uint64_t(w.x1 - w.x0) * uint64_t(w.y1 - w.y0); };
                {
                    // Per layer: its accumulations; its resolved cells (within dWin and a ring:
                    // resolveCells); a moving layer's motion sums, motion grid and window, and a
                    // turning one's sagittas (where the light field keeps them); the summed-area
                    // tables of its covered cells and, where the tile's samples see an emitter,
                    // its emitters' cells; and the scratch the D passes fill for it. Per twin, its
                    // grids and the blend its layer keeps (own).
                    constexpr uint64_t F = sizeof(float), I = sizeof(int);
                    uint64_t bound = uint64_t(layers.capacity() + twins.capacity()) * sizeof(Layer), scratchD = 0;
                    for (size_t k = 0; k < layers.size(); ++k) {
                        const Layer& l = layers[k];
                        const uint64_t cells = uint64_t(l.gw) * uint64_t(l.gh), sat = uint64_t(l.gw + 1) * uint64_t(l.gh + 1);
                        bound += (cellsOf(l.accWin) * uint64_t(l.accStride()) + cellsOf(l.dWin)) * F;
                        bound += std::max<uint64_t>(1, cellsOf(l.dWin.empty() ? l.dWin : l.dWin.grown(1, 1, l.gw, l.gh))) * uint64_t(l.cellStride()) * F;
                        bound += sat * I;
                        if (anyEmitting && !l.sharp) bound += sat * I + cells;
                        if (hasMotionGrid[k]) {
                            bound += cells * 5 * F + uint64_t((l.gw + Layer::kWindowBlock - 1) / Layer::kWindowBlock) *
                                                      uint64_t((l.gh + Layer::kWindowBlock - 1) / Layer::kWindowBlock) * 4 * F;
                            bound += uint64_t(l.accWin.x1 - l.accWin.x0 + 1) * uint64_t(l.accWin.y1 - l.accWin.y0 + 1) * I;  // (occupied)
                            if (sags) bound += cells * 4 * F;
                        } else {
                            scratchD = std::max(scratchD, sat * I + cells);  // (occupiedStill, near)
                        }
                    }
                    for (const Layer& t : twins) bound += uint64_t(t.gw) * uint64_t(t.gh) * uint64_t(t.accStride() + 1 + t.cellStride() + 5) * F;
                    reserved.reserve(bound + scratchD, X0, Y0);
                }
                for (size_t k = 0; k < layers.size(); ++k) {
                    Layer& l = layers[k];
                    l.acc.assign(size_t(cellsOf(l.accWin)) * size_t(l.accStride()), 0.f);
                    l.accD.assign(size_t(cellsOf(l.dWin)), 0.f);
                    if (hasMotionGrid[k]) motionAcc[k].assign(size_t(l.gw) * l.gh * 3, 0.f);
                }
                for (Layer& t : twins) {
                    t.acc.assign(size_t(t.gw) * t.gh * t.accStride(), 0.f);
                    t.accD.assign(size_t(t.gw) * t.gh, 0.f);
                }
                std::vector<SplatTarget> target(layers.size());
                for (size_t k = 0; k < layers.size(); ++k) {
                    Layer& l = layers[k];
                    target[k] = {l.c,        l.mx,         l.my,  l.depthRate, l.invDepthMax,   l.gx0,     l.gy0,       l.gw,
                                 l.gh,       l.accStride(), l.timeBins, l.sharp,  l.moving,    l.acc.data(),
                                 l.accD.data(), motionAcc[k].empty() ? nullptr : motionAcc[k].data(), l.step, l.invStep,
                                 l.accWin.x0, l.accWin.y0, l.accWin.x1 - l.accWin.x0, l.dWin.x0, l.dWin.y0, l.dWin.x1 - l.dWin.x0};
                }
                // The layer of each of the tile's textured pixels' surfaces, where all of its
                // samples there are in one (-2: in several): there a sample in a sharp layer
                // carries its pixel's mean albedo (LayerInput::surfaceAlbedo). (Without that
                // test a surface split between two layers inside a pixel gave each part the
                // whole pixel's albedo: docs/textured.json's floor dark along a checker edge.)
                const int tw = X1 - X0, th = Y1 - Y0;
                constexpr int kSurfaces = 1 + FrameBuffers::kOtherSurfaces;
                std::vector<int16_t> surfaceLayer;
                auto tilePixel = [&](const Gathered& s) -> int {
                    const int px = int(s.pixel % uint32_t(W)), py = int(s.pixel / uint32_t(W));
                    return px >= X0 && px < X1 && py >= Y0 && py < Y1 ? (py - Y0) * tw + (px - X0) : -1;
                };
                if (in.textured && in.surfaceAlbedo[0]) {
                    surfaceLayer.assign(size_t(tw) * th * kSurfaces, -1);
                    for (const Gathered& s : g) {
                        const int tp = s.surface >= 0 ? tilePixel(s) : -1;
                        if (tp < 0 || !((*in.textured)[s.pixel] & kTextureSurface)) continue;
                        int16_t& k = surfaceLayer[size_t(tp) * kSurfaces + size_t(s.surface)];
                        const int sl = split.layerOf(s);
                        k = k == -1 ? int16_t(sl) : k == sl ? k : int16_t(-2);
                    }
                }
                // What sample s of layer sl carries into layer l (its SplatTarget, or a sharp twin):
                // radianceOf, and in a sharp layer, on a surface of a textured pixel whose samples
                // there are all in sl, that pixel's mean albedo x its light.
                auto splatRadiance = [&](const Gathered& s, int sl, const auto& l) {
                    if (l.sharp && !surfaceLayer.empty() && s.surface >= 0 && s.albedo != 0u && in.surfaceLight[s.surface] && in.surfaceAlbedo[s.surface]) {
                        const int tp = tilePixel(s);
                        if (tp >= 0 && surfaceLayer[size_t(tp) * kSurfaces + size_t(s.surface)] == sl)
                            return (*in.surfaceAlbedo[s.surface])[s.pixel] * (*in.surfaceLight[s.surface])[s.pixel];
                    }
                    return radianceOf(s, l);
                };
                // (The samples' layers, sampleLayer, are kept for the D passes.)
                for (size_t i = 0; i < g.size(); ++i) {
                    const Gathered& s = g[i];
                    const int sl = windows ? int(sampleLayer[i]) : split.layerOf(s);
                    const uint32_t own = windows ? ownCell[i] : ownCellOf(i, sl);
                    if (!windows) sampleLayer[i] = uint16_t(sl);
                    if (own == kOffGrid) continue;
                    const SplatTarget& l = target[size_t(sl)];
                    const int cx = int(own & 0xffffu), cy = int(own >> 16);
                    const int ci = cy * l.gw + cx, ai = l.accIndex(cx, cy), di = l.dIndex(cx, cy);  // (its index in the grid, in acc and in accD)
                    if (const Vec2f sag = sags ? sags[i] : Vec2f{0.f, 0.f}; l.motion && curved(sag)) {
                        const Vec2f e = effectiveSag(s, sag, l.depthRate);
                        std::vector<float>& sa = sagAcc[size_t(sl)];
                        if (sa.empty()) sa.assign(size_t(l.gw) * l.gh * 2, 0.f);
                        sa[size_t(ci) * 2] += e.x;
                        sa[size_t(ci) * 2 + 1] += e.y;
                    }
                    if (l.motion) {
                        float* m = l.motion + size_t(ci) * 3;
                        m[0] += 1.f, m[1] += s.mx, m[2] += s.my;
                    }
                    splatCell(l.acc + size_t(ai) * l.accStride, l.d[di], s.c, timeBinOf(l.timeBins, s.t), splatRadiance(s, sl, l));
                    if (LightFieldSample::carriesEmission(s.albedo, s.radiance) && !l.sharp) {  // (LayerOptions::emitterRays)
                        std::vector<uint8_t>& e = layers[size_t(sl)].emitCells;
                        if (e.empty()) e.assign(size_t(l.gw) * l.gh, 0);
                        e[size_t(ci)] = 1;
                    }
                    if (const int tk = twinOf[size_t(sl)]; tk >= 0) {
                        // Its layer's twin: as a sharp layer takes it, at its own position.
                        Layer& t = twins[size_t(tk)];
                        const int tc = t.cellIndex({s.x, s.y});
                        if (tc >= 0) splatCell(&t.acc[size_t(tc) * size_t(t.accStride())], t.accD[size_t(tc)], s.c, 0, splatRadiance(s, sl, t));
                    }
                }
                // D of the layers in front of a sample, at their shear (as Layer::sharpPosition):
                // where it shows that they do not cover. Not that of a moving layer it lies in
                // front of then (a still post a moving object passes behind, in a tile that keeps
                // one order over the shutter since the object is not seen where the post hides
                // it): it tells nothing of whether the layer covers there, and counted, it took
                // the object's coverage away over the whole shutter (docs/crossing.json AAF relMSE
                // -16%: docs/layers.md, "A post a moving object passes behind"). The layers with
                // a motion grid take theirs in the pass below.
                // A layer at a time, over the samples that can land on its grid: those of the
                // pixels within its shear's reach of it (a sharp layer's grid is its tile, and a
                // sample lands at its own position). Sample by sample over every layer in front,
                // this was 58% of the splat on docs/bunny-slats.json (one thread). D counts whole
                // samples: the order of the sums does not change it.
                // As in the D pass of the layers with a motion grid (below), a D farther than
                // dMargin from all of the layer's cells with samples (N > 0, splatted above)
                // changes nothing: such Ds are not counted (`near`), and the samples are read only
                // within the shear's reach of the box of the cells that count. (Tried when the
                // splat counted D sample by sample, it needed a pass of its own and cost what it
                // saved: docs/layers.md.)
                // fn(s) for each sample of the region's pixels [wx0, wx1) x [wy0, wy1) that lies
                // behind layer k: in a layer after it, or where the two change order over the
                // shutter, behind it at the sample's time.
                // A sample nearer than every point of a moving layer k in front of its own (Layer::
                // inFrontOfAll) says nothing of k's coverage where its layer lies wholly in front
                // of k (a post the object passes behind), and is not counted in k's D; where its
                // layer reaches as far as k it is (the far end of a box's face, a motion group of
                // its own, sinks on screen behind the nearer part of a floor that spans its
                // depths: counted, the floor is no longer hidden under the face's coverage of 1,
                // docs/moving-boxes.json MC relMSE -11%, AAF -5%; docs/layers.md, "A sliver of a
                // moving box in front of the floor beside it").
                std::vector<float>& farthest = local.farthest;  // per layer: its farthest sample's inverse depth
                farthest.resize(size_t(nLayers));
                for (int k = 0; k < nLayers; ++k) farthest[size_t(k)] = layers[size_t(k)].invDepthMin;
                // (`band(y, x0, x1)` may narrow row y's pixels [x0, x1) to those whose samples
                // can count.)
                auto forEachBehindIn = [&](int k, int wx0, int wx1, int wy0, int wy1, auto&& band, auto&& fn) {
                    for (int y = wy0; y < wy1 && wx0 < wx1; ++y) {
                        int x0 = wx0, x1 = wx1;
                        band(y, x0, x1);
                        if (x0 >= x1) continue;
                        const uint32_t i0 = pixelStart[size_t(y - ry0) * rw + (x0 - rx0)];
                        const uint32_t i1 = pixelStart[size_t(y - ry0) * rw + (x1 - rx0)];
                        for (uint32_t i = i0; i < i1; ++i) {
                            const int sl = sampleLayer[i];
                            const Gathered& s = g[i];
                            if (timeOrder && reordered[size_t(sl)] ? !inFront(k, sl, s.t) : k >= sl) continue;
                            fn(s, sl);
                        }
                    }
                };
                auto forEachBehind = [&](int k, int wx0, int wx1, int wy0, int wy1, auto&& fn) {
                    forEachBehindIn(k, wx0, wx1, wy0, wy1, [](int, int&, int&) {}, fn);
                };
                std::vector<int>& occupiedStill = local.occupiedStill;
                std::vector<uint8_t>& near = local.near;
                for (int k = 0; k < nLayers; ++k) {
                    const SplatTarget& l = target[size_t(k)];
                    if (l.motion) continue;
                    const int gw = l.gw, gh = l.gh;
                    const Layer& layer = layers[size_t(k)];
                    summedArea(gw, gh, occupiedStill, [&](int i, int j) { return layer.inAcc(i, j) && l.acc[size_t(l.accIndex(i, j)) * l.accStride] > 0.f; });
                    layers[size_t(k)].accBox = summedBox(occupiedStill, gw, gh);
                    if (occupiedStill.back() == 0) continue;  // no samples of its own: alpha 0 whatever D is
                    const int m = dMargin(layers[size_t(k)]);
                    near.resize(size_t(gw) * gh);
                    int cx0 = gw, cy0 = gh, cx1 = -1, cy1 = -1;  // the box of the cells that count
                    const int ow = gw + 1;
                    const int* o = occupiedStill.data();
                    for (int j = 0; j < gh; ++j) {
                        const int c0 = std::max(0, j - m), c1 = std::min(gh, j + m + 1);
                        for (int i = 0; i < gw; ++i) {
                            const int a0 = std::max(0, i - m), a1 = std::min(gw, i + m + 1);
                            const bool counts = o[c1 * ow + a1] - o[c1 * ow + a0] - o[c0 * ow + a1] + o[c0 * ow + a0] > 0;
                            near[size_t(j) * gw + i] = counts;
                            if (counts) cx0 = std::min(cx0, i), cx1 = std::max(cx1, i), cy0 = std::min(cy0, j), cy1 = std::max(cy1, j);
                        }
                    }
                    const float shear = l.sharp ? 0.f : std::abs(l.c) + chordReach(l.depthRate) * std::sqrt(l.mx * l.mx + l.my * l.my);
                    const int r = int(std::ceil(shear)) + 1;
                    // (The box's cells in pixels.)
                    const int wx0 = std::max(rx0, (l.gx0 + cx0) * l.step - r), wx1 = std::min(rx1, (l.gx0 + cx1 + 1) * l.step + r);
                    const int wy0 = std::max(ry0, (l.gy0 + cy0) * l.step - r), wy1 = std::min(ry1, (l.gy0 + cy1 + 1) * l.step + r);
                    const float nearest = layers[size_t(k)].invDepthMax;
                    forEachBehind(k, wx0, wx1, wy0, wy1, [&](const Gathered& s, int sl) {
                        if (farthest[size_t(sl)] >= nearest && l.inFrontOfAll(s.invDepth, s.t)) return;
                        const Vec2f p = layerPosition(s, l.sharp, l.c, l.mx, l.my, l.depthRate);
                        int ci, cj;
                        if (!gridCellAt(l.gx0, l.gy0, gw, gh, p, l.invStep, ci, cj) || !near[size_t(cj) * gw + size_t(ci)]) return;
                        l.d[l.dIndex(ci, cj)] += 1.f;  // (a cell `near` counts lies within dWin)
                    });
                }
                if (anyMotionGrid) {
                    for (size_t k = 0; k < layers.size(); ++k) {
                        if (motionAcc[k].empty()) continue;
                        Layer& l = layers[k];
                        const float* sums = motionAcc[k].data();  // (per cell: count, sum of mx, sum of my)
                        const AffineMotion fit = fitMotion(sums, 3, sums + 1, 3, l.gw, l.gh, Vec2f{l.mx, l.my});
                        l.motionFit = inPixels(fit, l);
                        // (A turning layer's effective sagittas fitted likewise, over the same count,
                        // before the sums are smoothed.)
                        const bool turning = !sagAcc[k].empty();
                        const AffineMotion sagFit = turning ? fitMotion(sums, 3, sagAcc[k].data(), 2, l.gw, l.gh, Vec2f{0.f, 0.f}) : AffineMotion{};
                        l.sagFit = inPixels(sagFit, l);
                        // The mean motion per cell, and where the layer turns the mean effective
                        // sagitta, the sums smoothed alike and over the same (smoothed) count.
                        const CellBox counted = o.everyCell ? CellBox{0, 0, l.gw, l.gh} : nonZeroBox(motionAcc[k], l.gw, l.gh, 3);  // (its N's cells)
                        // The motion is smoothed as its differences from the affine fit (the
                        // sums less the count times the fit at the cell), which meanVectorGrid adds
                        // back: a Gaussian mean of the motion itself is pulled towards the inside
                        // at a layer's rim, where the neighbours are all on one side, and an
                        // object moving in depth, whose motion grows from its middle to its rim,
                        // had its rim's motion short by about a cell times that growth in the
                        // cells its Gaussian's tail reaches, and past them: the rays of the
                        // pixels its rim reaches late missed it (an approaching plate's rim 15%
                        // dark; docs/layers.md, "An object rushing towards the camera"). The fit
                        // is an affine field's own mean, at the rim too. Only where the layer's
                        // motion is within the tiles' gathering reach (LayerOptions::maxReach):
                        // a longer one's tiles hold only the part of its samples near them, and
                        // there the fit predicted the rim worse (a sphere rushing towards the
                        // camera and sideways, a chord of 150 px: AAF relMSE +39%).
                        float* sumsM = motionAcc[k].data();
                        const bool fromFit = std::max(l.motionMax.x, l.motionMax.y) <= float(o.maxReach);
                        for (int j = 0; fromFit && j < l.gh; ++j)
                            for (int i = 0; i < l.gw; ++i) {
                                const size_t c = size_t(j) * l.gw + size_t(i);
                                const float n = sumsM[c * 3];
                                if (!(n > 0.f)) continue;
                                const Vec2f at = fit.at({float(i) + 0.5f, float(j) + 0.5f}, kInf);
                                sumsM[c * 3 + 1] -= n * at.x, sumsM[c * 3 + 2] -= n * at.y;
                            }
                        smooth(motionAcc[k], l.gw, l.gh, 3, l.sigmaX(l.sigma), l.sigmaY(l.sigma), counted);
                        const float* count = motionAcc[k].data();  // (smoothed)
                        meanVectorGrid(count, 3, count + 1, 3, l.gw, l.gh, fit, l.motionGrid, fromFit);
                        float reach = 0, spread = 0;
                        l.motionExtent = {};
                        for (size_t i = 0; i < l.motionGrid.size(); i += 2) {
                            const float mx = l.motionGrid[i], my = l.motionGrid[i + 1];
                            reach = std::max(reach, mx * mx + my * my);
                            spread = std::max(spread, sqr(mx - fit.mean.x) + sqr(my - fit.mean.y));
                            l.motionExtent = vmax(l.motionExtent, Vec2f{std::abs(mx), std::abs(my)});
                        }
                        l.maxMotion = std::sqrt(reach);
                        l.motionSpread = std::sqrt(spread);
                        l.sagGrid.clear();
                        l.maxSag = 0;
                        l.sagExtent = {};
                        if (turning) {
                            smooth(sagAcc[k], l.gw, l.gh, 2, l.sigmaX(l.sigma), l.sigmaY(l.sigma), counted);
                            meanVectorGrid(count, 3, sagAcc[k].data(), 2, l.gw, l.gh, sagFit, l.sagGrid, false);
                            float most = 0;
                            for (size_t i = 0; i < l.sagGrid.size(); i += 2) {
                                most = std::max(most, sqr(l.sagGrid[i]) + sqr(l.sagGrid[i + 1]));
                                l.sagExtent = vmax(l.sagExtent, Vec2f{std::abs(l.sagGrid[i]), std::abs(l.sagGrid[i + 1])});
                            }
                            l.maxSag = std::sqrt(most);
                        }
                        // (The sums are done with: their grids are built. The layers with a motion
                        // grid are those with motionGrid from here.)
                        motionAcc[k] = std::vector<float>();
                        sagAcc[k] = std::vector<float>();
                    }
                    // Each sample's point on the layers in front of it goes into that layer's
                    // batch, and a full batch's cells are found by one SIMD loop (motionCells):
                    // one pass over the tile's samples (tens of megabytes). Sample by sample, with
                    // the solve for each, this pass was a third of the stage on
                    // docs/bunny-slats.json (about 45 ns a sample and layer); a layer at a time,
                    // it read the samples once per layer from memory. D counts whole samples: the
                    // order of the sums does not change it.
                    // A D farther than dMargin from all of the layer's cells with samples
                    // (N > 0) changes nothing (dMargin says why).
                    std::vector<int>& withGrid = local.withGrid;  // the layers with a motion grid, front to back
                    withGrid.clear();
                    for (int k = 0; k < nLayers; ++k)
                        if (!layers[size_t(k)].motionGrid.empty()) withGrid.push_back(k);
                    std::vector<std::vector<int>>& occupied = local.occupied;
                    std::vector<MotionBatch>& batch = local.batch;
                    if (occupied.size() < size_t(nLayers)) occupied.resize(size_t(nLayers));
                    if (batch.size() < size_t(nLayers)) batch.resize(size_t(nLayers));
                    std::vector<int>& margin = local.margin;
                    margin.assign(size_t(nLayers), 0);
                    // Per layer, the points q that can count (motionCells): within the margin
                    // and the largest motion's reach of the box of its cells with samples.
                    std::vector<std::array<float, 4>>& reachBox = local.reachBox;
                    reachBox.assign(size_t(nLayers), {kInf, kInf, -kInf, -kInf});
                    // ... and the box of its cells with samples widened by the margin, where the
                    // point p of its sharp image must lie (below).
                    std::vector<std::array<float, 4>>& ownBox = local.ownBox;
                    ownBox.assign(size_t(nLayers), {kInf, kInf, -kInf, -kInf});
                    for (const int k : withGrid) {
                        const Layer& l = layers[size_t(k)];
                        const int aw = l.accWin.x1 - l.accWin.x0, ah = l.accWin.y1 - l.accWin.y0, as = l.accStride();
                        std::vector<int>& o = occupied[size_t(k)];  // (over accWin: no cell beyond has samples)
                        summedArea(aw, ah, o, [&](int i, int j) { return l.acc[(size_t(j) * aw + i) * as] > 0.f; });
                        // The box of those cells.
                        const CellBox inWin = summedBox(o, aw, ah);
                        const CellBox cellsBox = inWin.empty() ? CellBox{} : inWin.shifted(l.accWin.x0, l.accWin.y0);
                        layers[size_t(k)].accBox = cellsBox;
                        const int bx0 = cellsBox.x0, by0 = cellsBox.y0, bx1 = cellsBox.x1 - 1, by1 = cellsBox.y1 - 1;
                        const int m = dMargin(l);
                        margin[size_t(k)] = m;
                        // (motionCells' r is at most |dt| maxMotion + 1, |dt| at most chordReach; a cell to spare.)
                        // (In pixels: the cells' edges are multiples of the layer's step.)
                        const float step = float(l.step);
                        const float reach = float(m) * step + chordReach(l.depthRate) * l.maxMotion + l.maxSag + 2.f;
                        if (bx1 >= 0) {
                            reachBox[size_t(k)] = {float(l.gx0 + bx0) * step - reach, float(l.gy0 + by0) * step - reach,
                                                   float(l.gx0 + bx1 + 1) * step + reach, float(l.gy0 + by1 + 1) * step + reach};
                            ownBox[size_t(k)] = {float(l.gx0 + bx0 - m) * step, float(l.gy0 + by0 - m) * step, float(l.gx0 + bx1 + 1 + m) * step,
                                                 float(l.gy0 + by1 + 1 + m) * step};
                        }
                        batch[size_t(k)].n = 0;
                    }
                    auto flush = [&](int k) {
                        MotionBatch& b = batch[size_t(k)];
                        if (layers[size_t(k)].sagGrid.empty())
                            motionCells<false>(layers[size_t(k)], occupied[size_t(k)].data(), margin[size_t(k)], b);
                        else
                            motionCells<true>(layers[size_t(k)], occupied[size_t(k)].data(), margin[size_t(k)], b);
                        float* accD = layers[size_t(k)].accD.data();
                        for (int j = 0; j < b.n; ++j)
                            if (b.cell[j] >= 0) accD[b.cell[j]] += 1.f;
                        b.n = 0;
                    };
                    // A layer at a time, over the samples of the pixels within its shear's reach
                    // of the box its points can count in (reachBox): one pass over all of the
                    // tile's samples for every layer read them from memory each time.
                    for (const int k : withGrid) {
                        const Layer& l = layers[size_t(k)];
                        const std::array<float, 4>& box = reachBox[size_t(k)];
                        if (!(box[0] < box[2])) continue;  // (no cell with samples)
                        const float reachC = std::abs(l.c) + 1.f;
                        const int wx0 = int(std::max(float(rx0), std::floor(box[0] - reachC)));
                        const int wx1 = int(std::min(float(rx1), std::ceil(box[2] + reachC)));
                        const int wy0 = int(std::max(float(ry0), std::floor(box[1] - reachC)));
                        const int wy1 = int(std::min(float(ry1), std::ceil(box[3] + reachC)));
                        MotionBatch& b = batch[size_t(k)];
                        // p = q - dt m, m a bilinear mean of the grid's motions, each within
                        // motionSpread of the fit's mean: p lies within |dt| motionSpread of q - dt
                        // mean (two cells to spare for rounding), and where that is outside ownBox no
                        // cell within the margin of p's has samples (on a bunny moving over a floor
                        // most of its trail's samples behind it; their D changes nothing).
                        const std::array<float, 4>& own = ownBox[size_t(k)];
                        const Vec2f mean = l.motionFit.mean;
                        const float spread = l.motionSpread, nearest = l.invDepthMax;
                        // Per row, the pixels whose samples can pass that test: their q within
                        // |c| of the pixel, their dt between the chord's ends (alongChord is
                        // monotone for |depthRate| < 2), r at most its value at the larger end;
                        // the dts row y's q can take, then the q along x those dts allow. A
                        // diagonal trail's samples lie in a band of its reach box (docs/snow.json:
                        // this pass read every sample of the box for every moving layer).
                        const float dtA = alongChord(-0.5f, l.depthRate), dtB = alongChord(0.5f, l.depthRate);
                        const float rMax = std::max(std::abs(dtA), std::abs(dtB)) * spread + l.maxSag + 2.f, cAbs = std::abs(l.c);
                        const bool banded = !countEveryD && std::abs(l.depthRate) < 1.9f;
                        auto band = [&](int y, int& x0, int& x1) {
                            if (!banded) return;
                            // dt my within [lo, hi] for some q_y of the row (a pixel to spare).
                            const float lo = float(y) - cAbs - own[3] - rMax - 1.f, hi = float(y) + 2.f + cAbs - own[1] + rMax;
                            float d0 = dtA, d1 = dtB;
                            if (mean.y > 1e-6f) d0 = std::max(d0, lo / mean.y), d1 = std::min(d1, hi / mean.y);
                            else if (mean.y < -1e-6f) d0 = std::max(d0, hi / mean.y), d1 = std::min(d1, lo / mean.y);
                            else if (lo > 0.f || hi < 0.f) d1 = d0 - 1.f;
                            if (d0 > d1) {
                                x1 = x0;
                                return;
                            }
                            const float m0 = std::min(d0 * mean.x, d1 * mean.x), m1 = std::max(d0 * mean.x, d1 * mean.x);
                            x0 = std::max(x0, int(std::floor(own[0] - rMax + m0 - cAbs)) - 1);
                            x1 = std::min(x1, int(std::ceil(own[2] + rMax + m1 + cAbs)) + 1);
                        };
                        forEachBehindIn(k, wx0, wx1, wy0, wy1, band, [&](const Gathered& s, int sl) {
                            const float qx = s.x + l.c * s.u, qy = s.y - l.c * s.v;
                            if (qx < box[0] || qy < box[1] || qx >= box[2] || qy >= box[3]) return;
                            if (!countEveryD) {
                                const float dt = alongChord(s.t - 0.5f, l.depthRate), r = std::abs(dt) * spread + l.maxSag + 2.f;
                                const float px = qx - dt * mean.x, py = qy - dt * mean.y;
                                if (px < own[0] - r || py < own[1] - r || px >= own[2] + r || py >= own[3] + r) return;
                            }
                            if (farthest[size_t(sl)] >= nearest && l.inFrontOfAll(s.invDepth, s.t)) return;
                            b.qx[b.n] = qx;
                            b.qy[b.n] = qy;
                            b.t[b.n] = s.t;
                            if (++b.n == MotionBatch::kMax) flush(k);
                        });
                        flush(k);
                    }
                }
                // The twins' D: the samples behind their layers at their own positions, as a
                // sharp layer's (the pass of the still layers above).
                for (int k = 0; k < nLayers; ++k) {
                    if (twinOf[size_t(k)] < 0) continue;
                    Layer& t = twins[size_t(twinOf[size_t(k)])];
                    const Layer& l = layers[size_t(k)];
                    forEachBehind(k, X0, X1, Y0, Y1, [&](const Gathered& s, int sl) {
                        if (farthest[size_t(sl)] >= l.invDepthMax && l.inFrontOfAll(s.invDepth, s.t)) return;
                        const int ci = t.cellIndex({s.x, s.y});
                        if (ci >= 0) t.accD[size_t(ci)] += 1.f;
                    });
                }
                // (LayerStats::largestTileBytes, gridShare.)
                uint64_t tileBytes = uint64_t(g.size()) * sizeof(Gathered), tileFloats = 0, tileWhole = 0;
                for (Layer& l : layers) {
                    tileFloats += l.acc.size() + l.accD.size();
                    tileWhole += uint64_t(l.gw) * uint64_t(l.gh) * uint64_t(l.accStride() + 1 + l.cellStride());
                    tileBytes += (l.acc.size() + l.accD.size()) * sizeof(float);
                }
                for (Layer& l : layers) {
                    // Each pass within the cells it can change (CellBox): the same sums. (acc's in
                    // the cells of accWin, whose width is a row of it, accD's in dWin's, until
                    // resolveCells; with everyCell both are the grid.)
                    const int aw = l.accWin.x1 - l.accWin.x0, ah = l.accWin.y1 - l.accWin.y0;
                    const int dw = l.dWin.x1 - l.dWin.x0, dh = l.dWin.y1 - l.dWin.y0;
                    CellBox box = o.everyCell ? CellBox{0, 0, aw, ah} : l.accBox.shifted(-l.accWin.x0, -l.accWin.y0);
                    CellBox boxD = o.everyCell ? CellBox{0, 0, dw, dh} : nonZeroBox(l.accD, dw, dh);
                    if (!l.sharp) {
                        const float sc = l.sigmaCoverage, sr = l.sigma;
                        CellBox radiance;  // (of W, R, G, B)
                        const bool plainRadiance = l.crisp >= 0 && !o.crispRadiance;
                        if (sc == sr && !plainRadiance) {
                            radiance = smooth(l.acc, aw, ah, l.accStride(), l.sigmaX(sr), l.sigmaY(sr), box);
                        } else {
                            const CellBox coverage = smooth(l.acc, aw, ah, l.accStride(), l.sigmaX(sc), l.sigmaY(sc), box, 0, 2);  // N, the slopes
                            radiance = smooth(l.acc, aw, ah, l.accStride(), plainRadiance ? sr : l.sigmaX(sr), plainRadiance ? sr : l.sigmaY(sr), box,
                                              2);  // W, R, G, B
                            box = coverage;
                        }
                        boxD = smooth(l.accD, dw, dh, 1, l.sigmaX(sc), l.sigmaY(sc), boxD);
                        // The radiance, edge-stopped along both axes (across a crisp layer's motion
                        // its only Gaussian; LayerOptions::movingEdgeWidth, stillEdgeWidth).
                        if (const float width = l.moving ? o.movingEdgeWidth : o.stillEdgeWidth; width > 0.f)
                            for (int axis = 0; axis < 2; ++axis)
                                radiance = smoothAcrossEdges(l.acc, aw, ah, l.accStride(), 2, width * sr, axis, o.edgeStop,
                                                             0.01f * invRadianceScale, radiance);
                        box = box.united(radiance);
                    }
                    // (In dWin's cells: accWin lies within it.)
                    box = box.shifted(l.accWin.x0 - l.dWin.x0, l.accWin.y0 - l.dWin.y0);
                    resolveCells(l, l.sharp ? 0.5f : 0.05f, box.united(boxD).grown(kFillRings, kFillRings, dw, dh).shifted(l.dWin.x0, l.dWin.y0));
                    l.acc = std::vector<float>();
                    l.accD = std::vector<float>();
                    if (const int tk = twinOf[size_t(&l - layers.data())]; tk >= 0) {
                        // The pixels' own samples resolved as a sharp layer's, and per pixel
                        // the grid's share by the slope of the layer's samples there (Blend).
                        Layer& t = twins[size_t(tk)];
                        resolveCells(t, 0.5f, CellBox{0, 0, t.gw, t.gh});
                        const int tcs = t.cellStride();
                        l.own.resize(size_t(t.gw) * t.gh * 5);
                        for (size_t i = 0; i < size_t(t.gw) * t.gh; ++i) {
                            const float* c = &t.cell[t.cellAt(int(i % size_t(t.gw)), int(i / size_t(t.gw))) * size_t(tcs)];
                            const float w = sharpWeight(c[tcs - 1], l.motionRms, o), keep = 1.f - w;
                            float* b = &l.own[i * 5];
                            b[0] = w, b[1] = keep * c[0], b[2] = keep * c[1], b[3] = keep * c[2], b[4] = keep * c[3];
                        }
                    }
                    l.buildCovered();
                    tileFloats += l.cell.size();
                    tileBytes += (l.cell.size() + l.motionGrid.size() + l.sagGrid.size()) * sizeof(float) +
                                 (l.covered.size() + l.emitting.size()) * sizeof(int) + l.emitCells.size();
                    const float slopeReach = std::max({std::abs(l.cMin), std::abs(l.cMax), std::abs(l.rayC), std::abs(l.rayC + l.rayC2)});
                    if (l.moving && !l.sharp) l.buildWindow();  // (a sharp layer's rays read its pixel's cell)
                    const float chord = chordReach(l.depthRate);
                    // (The rays' segment is shaped about the chord's middle, which lies off the
                    // mid-shutter point where the depth changes: where motionScale < 1 its ends
                    // reach that much farther than chord times motionScale, as a share of the motion.)
                    const float beyond = std::max(0.f, std::abs(chordMiddle(l.depthRate)) * (1.f - l.motionScale));
                    const Vec2f mean{std::abs(l.mx), std::abs(l.my)};
                    l.rayReach = slopeReach + chord * std::max(std::sqrt(l.rayMx * l.rayMx + l.rayMy * l.rayMy), l.motionScale * l.maxMotion) +
                                 beyond * std::max(std::sqrt(l.mx * l.mx + l.my * l.my), l.maxMotion) + l.maxSag;
                    l.rayExtent = {slopeReach + chord * std::max(std::abs(l.rayMx), l.motionScale * l.motionExtent.x) +
                                       beyond * std::max(mean.x, l.motionExtent.x) + l.sagExtent.x,
                                   slopeReach + chord * std::max(std::abs(l.rayMy), l.motionScale * l.motionExtent.y) +
                                       beyond * std::max(mean.y, l.motionExtent.y) + l.sagExtent.y};
                }
                // A layer a pixel's rays can see; a sharp still layer is the same for every ray
                // (its pixel's cell), looked up once.
                gridFloats += tileFloats, wholeGridFloats += tileWhole;
                {
                    // (LayerStats::tilesOverReserve: what the grids came to against their bound,
                    // but the D passes' scratch.)
                    uint64_t grids = tileBytes - uint64_t(g.size()) * sizeof(Gathered) + uint64_t(layers.capacity() + twins.capacity()) * sizeof(Layer);
                    for (const Layer& l : layers) grids += (l.windowBlocks.size() + l.own.size()) * sizeof(float);
                    for (const Layer& t : twins) grids += (t.acc.capacity() + t.accD.capacity() + t.cell.size()) * sizeof(float);
                    if (grids > reserved.bytes) ++overReserve;
                }
                for (uint64_t most = largestTileBytes.load(); tileBytes > most && !largestTileBytes.compare_exchange_weak(most, tileBytes);) {
                }
                struct Active {
                    const Layer* layer;
                    bool fixed;
                    Lookup value;
                    // No ray of the pixel can read a covered cell of it along both axes apart
                    // (Layer::rayExtent): the rays skip it, which changes nothing they find. (It
                    // stays in the pixel's list, whose layers decide how many rays it takes.)
                    bool skip;
                    Blend blend;  // a blurred layer's pixel in the sharp band (Layer::own)
                };
                std::vector<Active> active;
                std::vector<int> binActive;  // (timeOrder) per order bin, `active` in its order
                Rays ray, sorted;
                // The alpha and light each of a pixel's active layers gives its rays (traceBlurred),
                // and whether they are there yet (where its layers change order over the shutter).
                std::vector<Taken> taken(1);
                std::vector<uint8_t> isTaken;
                // The rays' sequence before each pixel's shift: (j + 1) k_d modulo 1.
                alignas(64) float kron[5][Rays::kLength];  // (by dimension: the rays' SIMD loop below reads them as vectors)
                const int rays = anyBlurred ? std::clamp(o.rays, 1, kMaxRays) : 1;
                // Where a layer moves, the rays that straddle integrate over the shutter as well,
                // and their own noise is a larger part of the error: movingRays there
                // (docs/layers.md, "More rays where a layer moves"; 128 for every straddling
                // pixel measured AAF -0.3% to -4% on the five lens scenes, a wash for the time,
                // as 128 on conference before).
                const bool tileMoves = std::any_of(layers.begin(), layers.end(), [](const Layer& l) { return l.moving; });
                const int mixedRays = anyBlurred ? std::clamp(tileMoves ? o.movingRays : o.mixedRays, rays, kMaxRays) : 1;
                // Where the tile's samples see an emitter, up to emitterRays (LayerOptions).
                const int emitterRays = anyBlurred && anyEmitting ? std::clamp(o.emitterRays, mixedRays, Rays::kMax) : mixedRays;
                for (int j = 0; j < emitterRays; ++j)
                    for (int d = 0; d < 5; ++d) {
                        const double v = double(j + 1) * kKronecker[d];
                        kron[d][j] = float(v - std::floor(v));
                    }

                // Reconstruction rays, composited front to back.
                uint64_t straddling = 0, multiRay = 0, raysTraced = 0;
                for (int y = Y0; y < Y1; ++y)
                    for (int x = X0; x < X1; ++x) {
                        if (left && (*left)(x, y)) {
                            out(x, y) = Vec3f(0.f), (*own)(x, y) = 1;
                            continue;
                        }
                        // The rays: a 5D Kronecker sequence (the generalised golden ratio's powers,
                        // Roberts 2018) shifted by a random point per pixel, so that (x, y, u, v,
                        // t) are stratified jointly: a moving edge is a step in x - m t, a
                        // defocused one in x + c u, and marginally stratified pairs would integrate
                        // them no better than random points.
                        const PixelSampler rng(o.seed ^ 0x6c8e9cf5u, uint32_t(y) * uint32_t(W) + uint32_t(x));
                        float shift[5];
                        {
                            Vec2f a, b;
                            rng.get4D(0, 0, a, b);
                            shift[0] = a.x, shift[1] = a.y, shift[2] = b.x, shift[3] = b.y, shift[4] = rng.get1D(0, 2);
                        }
                        // The layers this pixel's rays can see (the others add nothing: the same
                        // image; the stage 1.0-1.7x faster with the per-tile sequence and the
                        // slope-only lookups, docs/layers.md).
                        active.clear();
                        for (const Layer& l : layers) {
                            if (!l.own.empty()) {
                                // In the sharp band: where the grid has no share the pixel's own
                                // samples alone, as a sharp layer's, else both (Blend).
                                const float* b = &l.own[(size_t(y - Y0) * size_t(X1 - X0) + size_t(x - X0)) * 5];
                                const Blend blend{b[0], b[1], b[2], b[3], b[4]};
                                if (blend.w == 0.f) {
                                    if (blend.alpha > 0.f) active.push_back({&l, true, {blend.alpha, Vec3f(blend.r, blend.g, blend.b)}, false, blend});
                                } else if (blend.alpha > 0.f || l.reaches(x, y)) {
                                    active.push_back({&l, false, Lookup{}, !o.everyCell && !(blend.alpha > 0.f) && !l.reaches(x, y, l.rayExtent), blend});
                                }
                                continue;
                            }
                            if (!l.reaches(x, y)) continue;
                            const bool fixed = l.sharp && l.timeBins == 1;
                            active.push_back({&l, fixed, fixed ? lookupSharp(l, x, y, 0.5f) : Lookup{}, !o.everyCell && !l.sharp && !l.reaches(x, y, l.rayExtent), Blend{}});
                        }
                        // (timeOrder) The order of those layers in each order bin, and whether it
                        // is one for every bin.
                        bool sameOrder = true;
                        int reorderedActive = 0;
                        if (timeOrder)
                            for (const Active& a : active) reorderedActive += reordered[size_t(a.layer - layers.data())];
                        if (reorderedActive >= 2) {
                            const size_t na = active.size();
                            binActive.resize(na * kOrderBins);
                            for (int b = 0; b < kOrderBins; ++b) {
                                int* order = &binActive[size_t(b) * na];
                                const int* rank = &binRank[size_t(b) * nLayers];
                                for (size_t i = 0; i < na; ++i) order[i] = int(i);
                                std::sort(order, order + na, [&](int p, int q) {
                                    return rank[active[size_t(p)].layer - layers.data()] < rank[active[size_t(q)].layer - layers.data()];
                                });
                                if (b > 0) sameOrder = sameOrder && std::equal(order, order + na, &binActive[0]);
                            }
                        }
                        // Where every layer a ray can reach before it ends (its transmittance
                        // below 1e-4) is sharp and still, every ray finds the same values (its
                        // pixel's cells): one ray is all of them. (Stopping at 8 or 16 rays where
                        // every one ended whole on one layer cost AAF relMSE +12% / +2% on
                        // cornell, +21% / +6% on conference at 512x512.)
                        bool sameForEveryRay = true;
                        {
                            float trans = 1.f;
                            for (const Active& a : active) {
                                if (!a.fixed) {
                                    sameForEveryRay = false;
                                    break;
                                }
                                trans *= 1.f - a.value.alpha;
                                if (trans < 1e-4f) break;
                            }
                        }
                        int pixelRays = sameForEveryRay ? 1 : rays;
                        // The rays are traced a layer at a time, each layer over all the rays it
                        // has not yet stopped (transmittance below 1e-4): per ray the same
                        // front-to-back steps as ray after ray, with the layer's branches and
                        // constants taken once per layer and a blurred layer's step one SIMD loop
                        // over the rays (traceBlurred).
                        // Whether the rays straddle layers: one ended on another layer than the
                        // first ray, or took part of a layer's coverage.
                        bool partial = false;
                        // A blurred layer's alpha and light for rays [j0, j1): its shear, then the
                        // slope of the surface it finds there (one fixed-point step), shaped by
                        // the grid's blur.
                        auto traceLayer = [&](const Active& a, int j0, int j1, Taken& t) {
                            const Layer& l = *a.layer;
                            const bool follow = l.followsSlope(), moving = l.timeBins > 1;
                            const bool arcs = moving && !l.sagGrid.empty() && !l.motionGrid.empty();
                            const Blend& bl = a.blend;
                            const bool w = !o.everyCell;
                            if (arcs)
                                follow ? traceBlurred<true, true, true>(l, ray, j0, j1, bl, t, w) : traceBlurred<false, true, true>(l, ray, j0, j1, bl, t, w);
                            else if (follow)
                                moving ? traceBlurred<true, true>(l, ray, j0, j1, bl, t, w) : traceBlurred<true, false>(l, ray, j0, j1, bl, t, w);
                            else
                                moving ? traceBlurred<false, true>(l, ray, j0, j1, bl, t, w) : traceBlurred<false, false>(l, ray, j0, j1, bl, t, w);
                        };
                        // Rays [j0, j1) through the layers they can see, front to back: in the
                        // tile's order, or (activeOrder) in that of an order bin. With `all`,
                        // rays all[0] to all[1] of which [j0, j1) are one bin's: a blurred
                        // layer is traced for all of them the first time one bin's rays reach
                        // it (a bin's few rays would run the SIMD loop's scalar remainder), its
                        // alpha and light kept in taken[its index in active] for the others.
                        auto traceLayers = [&](int j0, int j1, const int* activeOrder, const int* all) {
                            for (size_t i = 0; i < active.size(); ++i) {
                                const size_t index = activeOrder ? size_t(activeOrder[i]) : i;
                                const Active& a = active[index];
                                // Once every ray has stopped (T < 1e-4) the layers behind add
                                // nothing (composite stores nothing for a stopped ray): the
                                // same image, without their lookups.
                                bool live = false;
                                for (int j = j0; j < j1; ++j) live |= ray.trans[j] >= 1e-4f;
                                if (!live) break;
                                if (a.skip) continue;
                                const Layer& l = *a.layer;
                                auto take = [&](int j, const Lookup& v) {
                                    partial |= composite(ray, j, int(index), v.alpha, v.premultiplied.x, v.premultiplied.y, v.premultiplied.z) != 0;
                                };
                                if (a.fixed) {
                                    for (int j = j0; j < j1; ++j) take(j, a.value);
                                } else if (l.sharp) {  // a sharp layer is its pixels' own samples: the ray's pixel
                                    for (int j = j0; j < j1; ++j)
                                        if (ray.trans[j] >= 1e-4f) take(j, lookupSharp(l, x, y, ray.dt[j] + 0.5f));
                                } else if (!all) {
                                    traceLayer(a, j0, j1, taken[0]);
                                    partial |= compositeTaken(ray, int(index), taken[0], j0, j1);
                                } else {
                                    if (!isTaken[index]) traceLayer(a, all[0], all[1], taken[index]), isTaken[index] = 1;
                                    partial |= compositeTaken(ray, int(index), taken[index], j0, j1);
                                }
                            }
                        };
                        auto trace = [&](int j0, int j1) {
                            // (Locals, not the lambda's references, and one loop for each value of
                            // anyBlurred, so that the loop vectorises.)
                            const float fx = float(x), fy = float(y);
                            const float s0 = shift[0], s1 = shift[1], s2 = shift[2], s3 = shift[3], s4 = shift[4];
                            Rays& r = ray;
                            auto wrap = [](float v) { return v >= 1.f ? v - 1.f : v; };
                            if (anyBlurred) {
#pragma omp simd
                                for (int j = j0; j < j1; ++j) {
                                    const Vec2f u = concentricDisc(wrap(s2 + kron[2][j]), wrap(s3 + kron[3][j]));
                                    r.ux[j] = u.x;
                                    r.uy[j] = u.y;
                                    r.u2[j] = u.x * u.x + u.y * u.y;
                                    r.px[j] = fx + wrap(s0 + kron[0][j]);
                                    r.py[j] = fy + wrap(s1 + kron[1][j]);
                                    r.dt[j] = wrap(s4 + kron[4][j]) - 0.5f;
                                    r.cr[j] = r.cg[j] = r.cb[j] = 0.f;
                                    r.trans[j] = 1.f;
                                    r.hit[j] = -1;
                                }
                            } else {
                                for (int j = j0; j < j1; ++j) {
                                    r.ux[j] = r.uy[j] = r.u2[j] = 0.f;
                                    r.px[j] = fx + 0.5f;
                                    r.py[j] = fy + 0.5f;
                                    r.dt[j] = 0.f;
                                    r.cr[j] = r.cg[j] = r.cb[j] = 0.f;
                                    r.trans[j] = 1.f;
                                    r.hit[j] = -1;
                                }
                            }
                            if (reorderedActive < 2 || sameOrder) return traceLayers(j0, j1, reorderedActive >= 2 ? binActive.data() : nullptr, nullptr);
                            // Where the order of the layers the pixel's rays see changes over the
                            // shutter, the rays are grouped by their time's bin (a stable counting
                            // sort: which ray is where does not change their mean), each group
                            // through its bin's order (consecutive bins of one order together).
                            int first[kOrderBins + 1] = {};
                            for (int j = j0; j < j1; ++j) ++first[timeBinOf(kOrderBins, ray.dt[j] + 0.5f) + 1];
                            for (int b = 0; b < kOrderBins; ++b) first[b + 1] += first[b];
                            int next[kOrderBins];
                            std::copy(first, first + kOrderBins, next);
                            for (int j = j0; j < j1; ++j) {
                                const int to = j0 + next[timeBinOf(kOrderBins, ray.dt[j] + 0.5f)]++;
                                sorted.ux[to] = ray.ux[j], sorted.uy[to] = ray.uy[j], sorted.u2[to] = ray.u2[j];
                                sorted.px[to] = ray.px[j], sorted.py[to] = ray.py[j], sorted.dt[to] = ray.dt[j];
                            }
                            for (int j = j0; j < j1; ++j) {
                                ray.ux[j] = sorted.ux[j], ray.uy[j] = sorted.uy[j], ray.u2[j] = sorted.u2[j];
                                ray.px[j] = sorted.px[j], ray.py[j] = sorted.py[j], ray.dt[j] = sorted.dt[j];
                            }
                            // Each blurred layer traced for all of them at once, then composited
                            // bin by bin: the same arithmetic per ray.
                            const size_t na = active.size();
                            if (taken.size() < na) taken.resize(na);
                            isTaken.assign(na, 0);
                            const int all[2] = {j0, j1};
                            for (int b = 0; b < kOrderBins;) {
                                int e = b + 1;
                                while (e < kOrderBins && std::equal(&binActive[size_t(e) * na], &binActive[size_t(e) * na] + na, &binActive[size_t(b) * na])) ++e;
                                if (first[e] > first[b]) traceLayers(j0 + first[b], j0 + first[e], &binActive[size_t(b) * na], all);
                                b = e;
                            }
                        };
                        trace(0, pixelRays);
                        bool straddles = partial;
                        for (int j = 1; j < pixelRays && !straddles; ++j) straddles = ray.hit[j] != ray.hit[0];
                        if (own) {
                            // Rays that all end whole on one still layer show one surface
                            // (docs/layers.md, "A sharp textured pixel on a blurred layer").
                            bool oneSurface = false;
                            if (in.textured && ((*in.textured)(x, y) & kSharpTextured)) {
                                oneSurface = !straddles && ray.hit[0] >= 0 && !active[size_t(ray.hit[0])].layer->moving;
                                // Or no layer it can see moves or lies in front of its own depth.
                                // (Measured, with layers: AAF textured.json 0.000107 -> 0.000102,
                                // posts -2.5%, raster and textured-motion -1%; docs/layers.md.)
                                const Vec2f d = ownDepth(x, y);
                                if (!oneSurface && std::isfinite(d.x)) {
                                    oneSurface = true;
                                    for (const Active& a : active) {
                                        const Layer& l = *a.layer;
                                        const float gap = std::max({0.f, l.cMin - d.x, d.x - l.cMax});  // slope, px
                                        if (l.moving || (gap >= 1.f && l.invDepth > d.y)) oneSurface = false;
                                    }
                                }
                            }
                            (*own)(x, y) = sameForEveryRay || oneSurface ? 1 : 0;
                        }
                        // A pixel whose rays straddle layers (a defocused or moving silhouette)
                        // takes the rest of the sequence: there the rays' own noise is what
                        // remains (docs/layers.md). Not where the first rays agree (two layers of
                        // one colour, a dim trail): there the rest would change the pixel by less
                        // than the noise the pixel keeps (LayerOptions::rayTolerance). On a camera
                        // pan through Sponza (docs/sponza-pan.json) 74% of the pixels straddle,
                        // and the tolerance takes AAF from 99 to 67 rays a pixel (docs/layers.md,
                        // "Extra rays only where the first ones disagree").
                        // Ray j's light: light the layers leave uncovered (a hole no sample saw) is
                        // taken as the mean of what they cover.
                        auto rayLight = [&](int j) {
                            const Vec3f c(ray.cr[j], ray.cg[j], ray.cb[j]);
                            const float t = ray.trans[j];
                            return t > 1e-4f && t < 1.f ? c / (1.f - t) : c;
                        };
                        // The variance of the luminance of rays [0, n) and their mean's square
                        // plus relMSE's 0.01 (in the stored radiance's unit), whose ratio over n is
                        // the relative variance of the mean.
                        struct Spread {
                            double variance, scale;
                        };
                        auto spreadOf = [&](int n) {
                            double sum = 0, sum2 = 0;
                            for (int j = 0; j < n; ++j) {
                                const Vec3f l = rayLight(j);
                                const double v = double(l.x + l.y + l.z) / 3.0;
                                sum += v, sum2 += v * v;
                            }
                            const double mean = sum / n, variance = std::max(0.0, sum2 / n - mean * mean);
                            const double unit = invRadianceScale;
                            return Spread{variance, mean * mean + 0.01 * unit * unit};
                        };
                        if (pixelRays == rays && mixedRays > rays) {
                            if (straddles && o.rayTolerance > 0.f) {
                                const Spread v = spreadOf(rays);
                                straddles = v.variance >= double(o.rayTolerance) * double(rays) * v.scale;
                            }
                            if (straddles) {
                                trace(rays, mixedRays);
                                pixelRays = mixedRays;
                                ++straddling;
                            }
                        }
                        if (emitterRays > pixelRays && std::any_of(active.begin(), active.end(), [&](const Active& a) { return a.layer->reachesEmitter(x, y); })) {
                            // (LayerOptions::emitterRays) The rays it would take for its mean's
                            // relative variance to fall to emitterTolerance, by the first ones'.
                            const Spread v = spreadOf(pixelRays);
                            const double n = pixelRays, need = v.variance / (double(o.emitterTolerance) * v.scale);
                            // (At least a quarter of emitterRays: a small emitter in a wide
                            // blur can be missed by all of the first rays.)
                            if (need > n || pixelRays < emitterRays / 4) {
                                const int more = int(std::clamp(std::ceil(need / 32.0) * 32.0, double(emitterRays / 4), double(emitterRays)));
                                trace(pixelRays, more);
                                pixelRays = more;
                            }
                        }
                        Vec3f sum(0.f);
                        for (int j = 0; j < pixelRays; ++j) sum += rayLight(j);
                        out(x, y) = sum / float(pixelRays);
                        multiRay += pixelRays > 1;
                        raysTraced += uint64_t(pixelRays);
                    }
                straddlingTotal += straddling;
                multiRayTotal += multiRay;
                rayTotal += raysTraced;
            }
    });
    if (stats) {
        const double pixels = double(std::max<size_t>(1, size_t(W) * H)), tiles = double(size_t(tilesX) * tilesY);
        stats->gatheredPerPixel = double(gatheredTotal) / pixels;
        stats->layersPerTile = double(layerTotal) / tiles;
        stats->blurredTiles = double(blurredTotal) / tiles;
        stats->straddlingPixels = double(straddlingTotal) / pixels;
        stats->multiRayPixels = double(multiRayTotal) / pixels;
        stats->raysPerPixel = double(rayTotal) / pixels;
        stats->methodTiles = double(leftTotal) / tiles;
        stats->largestTileBytes = double(largestTileBytes);
        stats->gridShare = wholeGridFloats > 0 ? double(gridFloats) / double(wholeGridFloats) : 0.0;
        stats->largestTileSamples = double(largestTile);
        stats->largestTileReserve = double(budget.most());
        stats->tilesOverReserve = double(overReserve);
        stats->tilesWaited = double(budget.waited());
        stats->gridBudget = double(budget.budget());
    }
    return out;
}

}  // namespace wedge::filter
