#include "render/renderer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>

#include "core/error.h"
#include "core/parallel.h"
#include "filter/defocus.h"
#include "filter/layers.h"
#include "filter/maaf.h"
#include "render/distribution.h"
#include "render/memory_estimate.h"
#include "render/methods.h"
#include "render/sampling.h"

namespace wedge::render {

std::vector<std::string> methods() { return {"mc", "aaf", "maaf", "atrous"}; }

void storeStats(const PixelStatsImage& stats, const MethodContext& ctx, FrameBuffers& fb) {
    parallelRows(stats.height(), [&](int y) {
        for (int x = 0; x < stats.width(); ++x) {
            stats(x, y).store(fb, x, y, ctx.view);
            size_t p = size_t(y) * fb.width + x;
            fb.directUnoccluded[p] =
                fb.object[p] < 0 ? Vec3f(0.f) : ctx.sampler.unoccludedIrradiance(fb.position[p], fb.normal[p]) * kInvPi;
        }
    });
}

void shareEmissions(LightFieldSamples* lf, const Distribution* distribution) {
    if (!lf) return;
    exchangeImageRows(distribution, lf->emissionData(), lf->width(), lf->height());
    exchangeImageRows(distribution, lf->wideEmissionData(), lf->width(), lf->height());
}

Image<uint32_t> emitterTopUps(const PixelStatsImage& stats, uint32_t target, const LightFieldSamples* lf) {
    const int W = stats.width(), H = stats.height();
    Image<uint32_t> extra(W, H);
    // With layers, the pixels whose samples saw emitters only through a wide blur take none: the
    // layers reconstruct that emission from the samples of the whole blur
    // (LightFieldSamples::wideBlur). (Every rank's rows, shareEmissions: the rims reach across them.)
    auto seesEmitter = [&](const PixelStats& s, size_t p) { return s.nEmitter > 0 && (!lf || lf->ownEmissionShare(p) > 0.f); };
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            const size_t p = size_t(y) * W + x;
            extra[p] = seesEmitter(stats[p], p) ? stats[p].emitterTopUp(target) : 0;
        }
    });
    // Emitter-seeing pixels are few (an emitter's image): scatter their rims serially. Measured
    // (512x512, relMSE against 1024-spp references, without -> with the rims): cornell aaf
    // 0.000198 -> 0.000133, maaf 0.000251 -> 0.000182, mc (64 spp) 0.000729 -> 0.000690;
    // conference aaf -8%, maaf -7%; sponza -3%; +0.4-0.8 spp on average.
    constexpr int kMaxRim = 32;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const PixelStats& s = stats(x, y);
            if (!seesEmitter(s, size_t(y) * W + x)) continue;
            const float coc = s.suLo <= s.suHi ? std::max(std::abs(s.suLo), std::abs(s.suHi)) : 0.f;
            const int r = std::min(kMaxRim, int(std::ceil(coc)) + 1);
            for (int yy = std::max(0, y - r); yy <= std::min(H - 1, y + r); ++yy)
                for (int xx = std::max(0, x - r); xx <= std::min(W - 1, x + r); ++xx) {
                    const PixelStats& q = stats(xx, yy);
                    if (q.nEmitter < q.n && q.n < target) extra(xx, yy) = target - q.n;
                }
        }
    return extra;
}

namespace {

/// The pixels within reach[p] (pixels, a square) of a pixel p with reach[p] > 0; empty where
/// there is none. Through a difference table: +1 and -1 at the squares' corners, then sums along
/// the rows and the columns.
Image<uint8_t> squaresAround(const float* reach, int W, int H) {
    std::vector<int32_t> cover;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float r0 = reach[size_t(y) * W + x];
            if (!(r0 > 0.f)) continue;
            if (cover.empty()) cover.assign(size_t(W + 1) * (H + 1), 0);
            const int r = int(std::ceil(std::min(r0, float(W + H))));
            const int x0 = std::max(0, x - r), x1 = std::min(W, x + r + 1), y0 = std::max(0, y - r), y1 = std::min(H, y + r + 1);
            cover[size_t(y0) * (W + 1) + x0] += 1, cover[size_t(y0) * (W + 1) + x1] -= 1;
            cover[size_t(y1) * (W + 1) + x0] -= 1, cover[size_t(y1) * (W + 1) + x1] += 1;
        }
    if (cover.empty()) return {};
    for (int y = 0; y <= H; ++y)
        for (int x = 1; x <= W; ++x) cover[size_t(y) * (W + 1) + x] += cover[size_t(y) * (W + 1) + x - 1];
    for (int y = 1; y <= H; ++y)
        for (int x = 0; x <= W; ++x) cover[size_t(y) * (W + 1) + x] += cover[size_t(y - 1) * (W + 1) + x];
    Image<uint8_t> in(W, H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) in(x, y) = cover[size_t(y) * (W + 1) + x] > 0;
    return in;
}

}  // namespace

Image<uint8_t> bentPixels(const MethodContext& ctx) {
    if (!ctx.lightField) return {};
    LightFieldSamples& lf = *ctx.lightField;
    const int W = lf.width(), H = lf.height();
    // The squares around the bent samples' pixels.
    exchangeImageRows(ctx.sampler.distribution(), lf.bentReachData(), W, H);
    return squaresAround(lf.bentReachData(), W, H);
}

Image<float> blurPooling(const LightFieldSamples* lightField, const ViewGeometry& view, const Image<uint8_t>& bent,
                         const Distribution* distribution) {
    if (!lightField) return {};
    const int W = lightField->width(), H = lightField->height();
    // Each pixel's slowest surface sample's screen motion (pixels; 0 where none hit a
    // surface), every rank's rows; its surface samples' least circle of confusion (pixels).
    Image<Vec2f> slowest(W, H);
    Image1f sharpest(W, H);
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            int64_t least = -1;
            Vec2f m{0.f, 0.f};
            float c = kInf;
            lightField->forEach(size_t(y) * W + x, [&](const LightFieldSample& l) {
                if (!(l.depth < kInf)) return;
                c = std::min(c, std::abs(view.defocusSlope(l.depth)));
                const int64_t m2 = int64_t(l.motionX) * l.motionX + int64_t(l.motionY) * l.motionY;
                if (least >= 0 && m2 >= least) return;
                least = m2;
                m = {float(l.motionX) / 8.f, float(l.motionY) / 8.f};
            });
            slowest(x, y) = m;
            sharpest(x, y) = c < kInf ? c : 0.f;
        }
    });
    exchangeImageRows(distribution, slowest.data(), W, H);
    exchangeImageRows(distribution, sharpest.data(), W, H);
    Image<float> pooling(W, H);
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            const Vec2f m = slowest(x, y);
            const float length = std::sqrt(m.x * m.x + m.y * m.y);
            float pooled = 1.f;
            if (kMotionPooling * length > 1.f && (bent.empty() || !bent(x, y))) {
                // The pixels along the trail, half its length either way: the share of them
                // whose samples all move (they pool too, where nothing still hides the trail).
                const int reach = int(std::ceil(0.5f * length));
                int moving = 0;
                for (int k = -reach; k <= reach; ++k) {
                    const int qx = int(std::lround(float(x) + float(k) * m.x / length));
                    const int qy = int(std::lround(float(y) + float(k) * m.y / length));
                    if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
                    const Vec2f q = slowest(qx, qy);
                    if (q.x * q.x + q.y * q.y >= 1.f) ++moving;
                }
                pooled = std::max(1.f, kMotionPooling * length * float(moving) / float(2 * reach + 1));
            }
            const float c = sharpest(x, y);
            if (c >= kLayerBlurFrom && (bent.empty() || !bent(x, y))) pooled = std::max(pooled, kDefocusPooling * c * c);
            pooling(x, y) = pooled;
        }
    });
    return pooling;
}

void settleLayers(MethodContext& ctx, const PixelStatsImage& stats, RenderResult& result) {
    if (!ctx.lightField || !ctx.options.layeredIfMixed(ctx.spp, ctx.scene.desc().hasMotion())) return;
    // The mixed pixels with a surface sample blurred by at least kLayerBlurFrom: those the
    // layers reconstruct from their neighbours' samples (an in-focus edge's keep their own).
    const LightFieldSamples& lf = *ctx.lightField;
    const int W = stats.width(), H = stats.height();
    std::vector<uint32_t> rows(size_t(H), 0);
    parallelRows(H, [&](int y) {
        if (!ctx.sampler.tracesRow(y)) return;  // (another rank's: below)
        for (size_t p = size_t(y) * W; p < size_t(y + 1) * W; ++p) {
            if (!stats[p].mixed()) continue;
            bool blurred = false;
            lf.forEach(p, [&](const LightFieldSample& l) {
                blurred |= l.depth < kInf && std::abs(ctx.view.defocusSlope(l.depth)) >= kLayerBlurFrom;
            });
            rows[size_t(y)] += blurred;
        }
    });
    // Every rank's rows (each rank holds the samples of its own rows only).
    exchangeImageRows(ctx.sampler.distribution(), rows.data(), 1, H);
    const size_t pixels = size_t(W) * H;
    const double share = double(std::accumulate(rows.begin(), rows.end(), uint64_t{0})) / double(std::max<size_t>(1, pixels));
    result.extra.emplace_back("layers_defocused_mixed_share", share);
    if (share >= RenderOptions::kLayersMixedShare) return;
    *ctx.lightField = LightFieldSamples();
    ctx.lightField = nullptr;
}

Image<uint32_t> mixedTopUps(const PixelStatsImage& stats, const Image<float>& pooling, float luminanceUnit) {
    const int W = stats.width(), H = stats.height();
    Image<uint32_t> extra(W, H);
    const float epsilon = 0.01f * luminanceUnit * luminanceUnit;
    parallelRows(H, [&](int y) {
        for (int x = 0; x < W; ++x)
            extra(x, y) = stats(x, y).mixedTopUp(kMixedTau * (pooling.empty() ? 1.f : pooling(x, y)), kMixedSpp, epsilon);
    });
    return extra;
}

LightFieldStage adaptiveLightFieldStage(const MethodContext& ctx, const PixelStatsImage& stats, const Image<uint32_t>& emitterExtra,
                                        const Image<uint32_t>& extra) {
    if (!ctx.lightField) return LightFieldStage(nullptr, [](size_t) { return 0u; });
    Image<uint8_t> keep(stats.width(), stats.height());
    parallelRows(stats.height(), [&](int y) {
        for (size_t p = size_t(y) * stats.width(); p < size_t(y + 1) * stats.width(); ++p)
            keep[p] = stats[p].mixed() || emitterExtra[p] > 0 || stats[p].albedoVariance() > kTextureVariance;
    });
    return LightFieldStage(ctx.lightField, [&](size_t p) { return keep[p] ? extra[p] : 0u; });
}

uint64_t denseEmission(const MethodContext& ctx, const Image<uint32_t>& topUp, FrameBuffers& fb) {
    std::atomic<uint64_t> rays{0};
    parallelRows(fb.height, [&](int y) {
        if (!ctx.sampler.tracesRow(y)) return;
        uint64_t local = 0;
        for (int x = 0; x < fb.width; ++x) {
            const size_t p = size_t(y) * fb.width + x;
            if (topUp[p] == 0) continue;
            // (The part that the layers take, where they do: the rays' hits that a sample would
            // carry into them, LightFieldSamples::wideBlur. A rim pixel whose own samples saw no
            // emitter is topped up too.)
            Vec3f wide(0.f);
            const Vec3f e = ctx.sampler.meanEmission(x, y, kEmitterEdgeRays, ctx.lightField, ctx.lightField ? &wide : nullptr);
            if (ctx.lightField) ctx.lightField->setEmission(p, LightFieldSamples::emissionLevel(e), LightFieldSamples::emissionLevel(wide));
            fb.color[p] += e - fb.emission[p];
            fb.emission[p] = e;
            local += kEmitterEdgeRays;
        }
        rays += local;
    });
    exchangeImageRows(ctx.sampler.distribution(), fb.color.data(), fb.width, fb.height);
    exchangeImageRows(ctx.sampler.distribution(), fb.emission.data(), fb.width, fb.height);
    shareEmissions(ctx.lightField, ctx.sampler.distribution());
    return rays;
}

namespace {

/// result.methodPixels for aaf and maaf with a light field: the pixels left to their own
/// composition. Each rank marks its own rows' pixels, and every rank gets the whole mask.
/// - The pixels with none within filter::kSilhouetteReach whose samples saw several surfaces (a
///   miss counts as another surface, as in the stage). (docs/layers.md, "Blocks without a
///   silhouette left to the filters" and "Pixels away from a silhouette left to the filters".)
/// - Every pixel within reach of a sample whose path bends on a surface turning towards or away
///   from the camera (LightFieldSamples::bentReach: a turning object). The layers follow chords
///   and hold one sharp image per layer at mid-shutter, and there, in filtered light with little
///   noise of its own to hide their error, measured worse than the filters' own composition.
///   mc and atrous keep the layers there: their own composition of a moving pixel is noisier
///   (16 samples, no top-up), and measured worse (docs/layers.md, "Arcs").
void leavePixelsToTheMethod(const MethodContext& ctx, const PixelStatsImage& stats, RenderResult& result) {
    if (!ctx.lightField || (ctx.options.method != "aaf" && ctx.options.method != "maaf")) return;
    LightFieldSamples& lf = *ctx.lightField;
    const int W = stats.width(), H = stats.height();
    Image<uint8_t> mixed(W, H);
    parallelRows(H, [&](int y) {
        if (!ctx.sampler.tracesRow(y)) return;
        for (int x = 0; x < W; ++x) {
            const int primary = stats(x, y).primary();
            const size_t p = size_t(y) * W + x;
            lf.forEach(p, [&](const LightFieldSample& s) {
                if (s.surface() != primary) mixed[p] = 1;
            });
        }
    });
    exchangeImageRows(ctx.sampler.distribution(), mixed.data(), W, H);
    result.methodPixels = filter::pixelsAwayFromSilhouettes(mixed, filter::kSilhouetteReach);

    const Image<uint8_t> bent = bentPixels(ctx);
    for (size_t p = 0; p < bent.size(); ++p)
        if (bent[p]) result.methodPixels[p] = 1;

    // And none within reach of a sample that carries an emitter's light into the layers
    // (LightFieldSamples::wideBlur), which no pixel tops up: the method's own image has that
    // light only in the pixels whose few samples saw it. Its reach: its blur's (the lens's
    // disc and half its motion) twice, from its sharp position to the pixel and to the blur's
    // far side.
    Image1f reach(W, H);
    parallelRows(H, [&](int y) {
        if (!ctx.sampler.tracesRow(y)) return;
        for (size_t p = size_t(y) * W; p < size_t(y + 1) * W; ++p) {
            if (!(lf.wideEmissionData()[p] > 0.f)) continue;
            lf.forEach(p, [&](const LightFieldSample& s) {
                if (!s.carriesEmission()) return;
                const Vec2f m = s.motion();
                reach[p] = std::max(reach[p], 2.f * (std::abs(ctx.view.defocusSlope(s.depth)) + 0.5f * std::sqrt(m.x * m.x + m.y * m.y)) + 1.f);
            });
        }
    });
    exchangeImageRows(ctx.sampler.distribution(), reach.data(), W, H);
    const Image<uint8_t> lit = squaresAround(reach.data(), W, H);
    for (size_t p = 0; p < lit.size(); ++p)
        if (lit[p]) result.methodPixels[p] = 0;
}

}  // namespace

void textureSamples(const MethodContext& ctx, PixelStatsImage& stats, RenderResult& result) {
    leavePixelsToTheMethod(ctx, stats, result);
    const uint32_t count = uint32_t(std::max(ctx.options.textureSpp, 0));
    if (count == 0) {
        result.extra.emplace_back("texture_pixels", 0.0);
        return;
    }
    std::atomic<uint64_t> rays{0}, textured{0};
    if (ctx.lightField) result.texturePixels = Image<uint8_t>(stats.width(), stats.height());
    parallelRows(stats.height(), [&](int y) {
        if (!ctx.sampler.tracesRow(y)) return;
        std::vector<TracedSample> hits(count);
        uint64_t localRays = 0, localPixels = 0;
        for (int x = 0; x < stats.width(); ++x) {
            PixelStats& ps = stats(x, y);
            if (ps.albedoVariance() <= kTextureVariance) continue;
            // With the layered reconstruction a pixel keeps its own composition only where its
            // samples are sharp and still (reconstructFromLayers), and a sharp layer's samples
            // carry their pixel's mean albedo: the pixel takes texture samples where its samples
            // on a textured surface are sharp and still. Elsewhere its colour is a mean over many
            // pixels' samples, which averages the texture's noise already.
            const size_t p = size_t(y) * stats.width() + x;
            // (A pixel left to the method takes them as without layers.)
            if (ctx.lightField && (result.methodPixels.empty() || !result.methodPixels[p])) {
                const bool whole = filter::samplesSharpAndStill(*ctx.lightField, p, ctx.view);
                bool surface = whole;
                for (int k = 0; k < PixelStats::kSlots && !surface; ++k)
                    surface = ps.slot(k).n > 0 && ps.slot(k).albedoVariance() > kTextureVariance &&
                              filter::samplesSharpAndStill(*ctx.lightField, p, ctx.view, {}, k);
                if (!surface) continue;
                result.texturePixels(x, y) = filter::kTextureSurface | (whole ? filter::kSharpTextured : 0);
            }
            localRays += ctx.sampler.primaryHits(x, y, ps.n, count, hits.data());
            for (const TracedSample& h : hits) ps.addPrimary(h);
            ++localPixels;
        }
        rays += localRays;
        textured += localPixels;
    });
    exchangeStats(ctx.sampler.distribution(), stats);
    if (!result.texturePixels.empty()) {
        exchangeImageRows(ctx.sampler.distribution(), result.texturePixels.data(), stats.width(), stats.height());
        // None taken (an untextured scene): no mask, and reconstructFromLayers does no texture work.
        const Image<uint8_t>& m = result.texturePixels;
        if (std::all_of(m.data(), m.data() + m.size(), [](uint8_t v) { return v == 0; })) result.texturePixels = Image<uint8_t>();
    }
    result.rays += rays;
    result.extra.emplace_back("texture_pixels", double(textured));
}

Image3f visibilityImage(const FrameBuffers& fb) {
    Image3f v(fb.width, fb.height);
    for (size_t i = 0; i < v.size(); ++i) v[i] = Vec3f(fb.visibility[i]);
    return v;
}

void finishLightField(const MethodContext& ctx, const PixelStatsImage& stats) {
    if (!ctx.lightField) return;
    LightFieldSamples& lf = *ctx.lightField;
    // Each rank recorded its own rows' samples. (Their per-pixel emissions are exchanged by
    // denseEmission, which every method calls next and which replaces some of them first.)
    exchangeLightField(ctx.sampler.distribution(), lf);
    parallelRows(lf.height(), [&](int y) {
        for (int x = 0; x < lf.width(); ++x) {
            const size_t p = size_t(y) * lf.width() + x;
            const int primary = stats(x, y).primary();
            // PixelStats::store's order: the primary slot, then the others in slot order.
            lf.forEachMutable(p, [&](LightFieldSample& s) {
                const int k = s.surface();
                if (k >= 0) s.setSurface(k == primary ? 0 : 1 + (k < primary ? k : k - 1));
            });
        }
    });
}

Image3f reconstructFromLayers(const MethodContext& ctx,
                              const std::array<const Image3f*, 1 + FrameBuffers::kOtherSurfaces>& surfaceLight,
                              RenderResult& result, const Image3f* perPixel) {
    Timer t;
    const FrameBuffers& fb = result.buffers;
    filter::LayerOptions lo;
    lo.seed = ctx.sampler.seed();
    // What the render holds beside the stage: its buffers and the samples it keeps (the grids'
    // budget is the memory limit less these and the threads' gathered samples).
    lo.memoryHeld = bufferBytes(fb.width, fb.height) + ctx.lightField->bytes();
    // Samples that carry their own radiance (mc) are as noisy as a pixel's few samples: there a
    // near-focus layer (true blur at least half the grid's own at 16 samples per pixel, all of
    // it from 64) is reconstructed from the samples of its neighbourhood rather than its
    // pixels' own. Measured at 16 spp, 512x512, MC relMSE 9-29% lower on the five lens scenes
    // and up to 23% on the held-out ones with a lens (docs/bunny-near.json +1%); filtered light
    // (aaf, maaf, atrous) measured worse with it (docs/layers.md, "Near-focus layers share their
    // samples").
    // Their noise is also most of a straddling pixel's error where a layer moves, and the rays'
    // own the smaller part: there they keep 64 rays, filtered light takes 128
    // (LayerOptions::movingRays; on eight scenes with motion, 128 against 64: AAF's efficiency
    // 0.94-1.19x, 1.06x on their geometric mean, à-trous's 0.93-1.07x, MC's 0.90-1.02x, 0.96x;
    // docs/layers.md, "More rays where a layer moves").
    const bool ownRadiance = std::all_of(surfaceLight.begin(), surfaceLight.end(), [](const Image3f* l) { return l == nullptr; });
    // Across a layer's motion, where it moves along one axis, its grid's coverage is crisp, and
    // where the samples carry filtered light its radiance too: there the grid's blur trades
    // sharpness for noise the filters have mostly removed, while a sample's own light keeps
    // the plain Gaussian across the motion (LayerOptions::crispAcrossMotion, crispRadiance;
    // docs/layers.md, "Crisp across the motion", "A crisp coverage for Monte Carlo's samples").
    lo.crispAcrossMotion = true;
    lo.crispRadiance = !ownRadiance;
    if (ownRadiance) {
        const double perPixel = double(ctx.lightField->samples()) / double(std::max<size_t>(1, size_t(fb.width) * fb.height));
        lo.sharpShare = float(std::clamp(std::sqrt(perPixel / 64.0), 0.5, 1.0));
        // ... and below that threshold a pixel blends its own samples with the layer's grid from
        // focus on, the grid's share rising with the blur radius (LayerOptions::sharpBand 0:
        // MC relMSE against no band 0.59-0.91 on the lens scenes at 16 and 64 spp, 0.47-1.00 on
        // nineteen with motion; docs/layers.md, "The sharp band").
        lo.sharpBand = 0.f;
        lo.movingRays = lo.mixedRays;
        // Their moving layers' radiance smoothed wider, and over larger differences (their
        // noise): MC relMSE on eight scenes with motion against no such Gaussian, geometric
        // means, at width 2 and edges 0.05 / 0.1 / 0.2 / 0.3: 0.965 / 0.945 / 0.928 / 0.928; at
        // 0.2 and width 3 / 4 / 6: 0.909 / 0.902 / 0.903 (docs/layers.md, "Moving layers'
        // radiance, smoothed to its edges").
        // Their defocused still layers too: MC relMSE at 512x512, 16 spp, conference -19%,
        // sponza -17%, cornell -15% (width 2: -12% and -9% on the first two; width 6 or edges at
        // 0.3 measured lower still on sponza, not chosen on two scenes).
        lo.movingEdgeWidth = lo.stillEdgeWidth = 4.f;
        lo.edgeStop = 0.2f;
    }
    filter::LayerStats stats;
    // Where every ray of a pixel ends in sharp still layers the reconstruction is the pixel's own
    // samples, composited; the method's own composition of the pixel (`perPixel`) is the same
    // estimate with its texture samples' mean albedo (textureSamples) and is taken there.
    // (docs/layers.md, "A pixel's own composition where its layers are sharp".) So it is in a
    // pixel with texture samples (sharp and still) whose rays all end whole on one still layer,
    // blurred or not: the layer's grid blurs its texture by at least its smallest Gaussian,
    // more than the lens does. (docs/layers.md, "A sharp textured pixel on a blurred layer":
    // taken also in blurred pixels, with texture samples there, it measured worse on a wall 2 px
    // out of focus, where the grid's blur is the lens's and averages more samples.)
    Image<uint8_t> own;
    filter::LayerInput input{*ctx.lightField, ctx.view, surfaceLight};
    Image<uint8_t> textured;
    if (!result.texturePixels.empty()) {
        // kSharpTextured also in the sharp still pixels within kTextureReach of one: a pixel
        // inside a texel beside its edge took no texture samples (its albedo did not vary), but
        // the grid's blur carries the edge into it. (Measured, with layers: AAF textured.json
        // 0.000102 -> 0.0000913, a-trous 0.000177 -> 0.000167; docs/layers.md.)
        textured = result.texturePixels;
        Image<uint8_t> sharp(fb.width, fb.height);
        for (size_t i = 0; i < sharp.size(); ++i) sharp[i] = (textured[i] & filter::kSharpTextured) != 0;
        const Image<uint8_t> near = filter::dilateBox(sharp, filter::kTextureReach);
        parallelRows(fb.height, [&](int y) {
            for (size_t p = size_t(y) * fb.width; p < size_t(y + 1) * fb.width; ++p)
                if (near[p] && !sharp[p] && filter::samplesSharpAndStill(*ctx.lightField, p, ctx.view)) textured[p] |= filter::kSharpTextured;
        });
        input.textured = &textured;
        input.surfaceAlbedo[0] = &fb.albedo;
        for (int k = 0; k < FrameBuffers::kOtherSurfaces; ++k) input.surfaceAlbedo[1 + k] = &fb.other[k].albedo;
    }
    if (perPixel && !result.methodPixels.empty()) {
        input.methodPixels = &result.methodPixels;
        // Where aaf and maaf keep their own image in the pixels away from silhouettes
        // (result.methodPixels), few of the pixels that trace rays do not straddle layers: there a
        // pixel's first rays are mixedRays (64), not 32. On twelve scenes with motion (AAF, three
        // rounds, docs/layers.md "First rays where the filters keep their own image") relMSE 0-4.5%
        // lower (raster-motion-defocus -4.5%, bunny-motion -3.7%, conference-motion -2.3%), the
        // stage's time unchanged at one thread (bunny-motion 1.35 s both, conference-motion 1.18 /
        // 1.19 s); à-trous, which traces rays in every pixel of a tile with a blurred layer, paid
        // 3-17% more stage time for it (efficiency 0.94-1.09x, 1.006x on the geometric mean).
        lo.rays = lo.mixedRays;
    }
    Image3f color = filter::reconstructLayers(input, lo, &stats, perPixel ? &own : nullptr);
    const size_t ownPixels = size_t(std::count(own.data(), own.data() + own.size(), uint8_t(1)));  // (empty without perPixel)
    // The samples that see an emitter through a wide blur carry its emission into the
    // reconstruction; each pixel adds the rest of its own (LightFieldSamples::wideBlur).
    const LightFieldSamples& lf = *ctx.lightField;
    parallelRows(fb.height, [&](int y) {
        for (size_t p = size_t(y) * fb.width; p < size_t(y + 1) * fb.width; ++p)
            color[p] = perPixel && own[p] ? (*perPixel)[p] : color[p] + fb.emission[p] * lf.ownEmissionShare(p);
    });
    result.seconds.add("layers", t.seconds());
    result.extra.emplace_back("layers_sample_bytes", double(ctx.lightField->bytes()));
    result.extra.emplace_back("layers_gathered_per_pixel", stats.gatheredPerPixel);
    result.extra.emplace_back("layers_per_tile", stats.layersPerTile);
    result.extra.emplace_back("layers_blurred_tiles", stats.blurredTiles);
    result.extra.emplace_back("layers_straddling_pixels", stats.straddlingPixels);
    result.extra.emplace_back("layers_multi_ray_pixels", stats.multiRayPixels);
    result.extra.emplace_back("layers_rays_per_pixel", stats.raysPerPixel);
    result.extra.emplace_back("layers_largest_tile_bytes", stats.largestTileBytes);
    result.extra.emplace_back("layers_grid_share", stats.gridShare);
    result.extra.emplace_back("layers_largest_tile_reserve", stats.largestTileReserve);
    result.extra.emplace_back("layers_tiles_over_reserve", stats.tilesOverReserve);
    result.extra.emplace_back("layers_tiles_waited", stats.tilesWaited);
    result.extra.emplace_back("layers_grid_budget", stats.gridBudget);
    if (input.methodPixels) result.extra.emplace_back("layers_method_tiles", stats.methodTiles);
    if (perPixel)
        result.extra.emplace_back("layers_own_pixels", double(ownPixels) / double(std::max<size_t>(1, size_t(fb.width) * fb.height)));
    return color;
}

Image3f composeFilteredLight(const MethodContext& ctx, const Image3f& filteredVisibility, const Image3f& filteredIndirect,
                             RenderResult& result) {
    const FrameBuffers& fb = result.buffers;
    Image3f direct(fb.width, fb.height);
    for (size_t i = 0; i < direct.size(); ++i) direct[i] = fb.directUnoccluded[i] * filteredVisibility[i].x;
    Image3f color = fb.composeFiltered(direct, filteredIndirect);
    if (ctx.view.apertureRadius > 0) color = filter::defocusFilter(color, fb);
    if (ctx.lightField) {
        // The layers where a silhouette is near; elsewhere (result.methodPixels), and in the
        // pixels whose layers are sharp, this composition.
        const std::array<Image3f, 1 + FrameBuffers::kOtherSurfaces> light = fb.surfaceLight(direct, filteredIndirect);
        return reconstructFromLayers(ctx, {&light[0], &light[1], &light[2]}, result, &color);
    }
    return color;
}

double averageSpp(const FrameBuffers& fb) {
    double s = 0;
    for (size_t i = 0; i < fb.spp.size(); ++i) s += fb.spp[i];
    return fb.spp.empty() ? 0 : s / double(fb.spp.size());
}

void sampleUniform(const MethodContext& ctx, const std::string& label, RenderResult& result, bool texture) {
    const ViewGeometry& view = ctx.view;
    Timer t;  // from the pixel statistics' allocation: first touching them is part of the stage
    PixelStatsImage stats(view.width, view.height);
    Progress progress(label, uint64_t(view.width) * view.height * ctx.spp, !ctx.options.quiet);
    LightFieldStage initial(ctx.lightField, [&](size_t) { return uint32_t(ctx.spp); });
    result.rays += samplePixels(
        ctx.sampler, stats, view, [&](int, int) { return SampleRange{0, uint32_t(ctx.spp)}; }, false, true,
        [&](int x, int y, const TracedSample& s, int slot) { initial.record(x, y, s, slot); }, &progress);
    progress.done();
    // Pixels at the edge of a visible emitter get topped up, as in every method.
    shareEmissions(ctx.lightField, ctx.sampler.distribution());
    const Image<uint32_t> topUp = emitterTopUps(stats, kEmitterEdgeSpp, ctx.lightField);
    const Image<uint32_t> edges = emitterTopUps(stats, kEmitterEdgeRays, ctx.lightField);  // (denseEmission)
    LightFieldStage more(ctx.lightField, [&](size_t p) { return topUp[p]; });
    result.rays += samplePixels(
        ctx.sampler, stats, view,
        [&](int x, int y) { return SampleRange{uint32_t(ctx.spp), topUp(x, y)}; }, false,
        false, [&](int x, int y, const TracedSample& s, int slot) { more.record(x, y, s, slot); }, nullptr);
    if (texture) textureSamples(ctx, stats, result);
    storeStats(stats, ctx, result.buffers);
    finishLightField(ctx, stats);
    result.rays += denseEmission(ctx, edges, result.buffers);
    stats = PixelStatsImage();
    result.seconds.add("sampling", t.seconds());
}

void renderMc(const MethodContext& ctx, RenderResult& result) {
    sampleUniform(ctx, "mc sampling", result);
    result.color = ctx.lightField ? reconstructFromLayers(ctx, {}, result) : result.buffers.color;
}

int renderSpp(const scene::SceneDesc& desc, const RenderOptions& options) {
    return options.spp.value_or(options.method == "mc" ? desc.render.spp : 16);
}

bool keepsSags(const scene::SceneDesc& desc) {
    return std::any_of(desc.meshes.begin(), desc.meshes.end(), [](const scene::TriangleMesh& m) { return m.turnDegrees != 0.f; });
}

float brightestEmitter(const scene::SceneDesc& desc) {
    float brightest = 0.f;
    for (const auto& l : desc.lights) brightest = std::max(brightest, maxComponent(l.radiance));
    for (const auto& m : desc.materials) brightest = std::max(brightest, maxComponent(m.emission));
    return brightest;
}

bool keepsLightField(const scene::SceneDesc& desc, const RenderOptions& options, int spp) {
    return options.layered(spp) && (desc.camera.apertureRadius > 0 || desc.hasMotion());
}

RenderResult render(const scene::Scene& scene, const RenderOptions& options) {
    const auto known = methods();
    if (std::find(known.begin(), known.end(), options.method) == known.end()) {
        std::string list;
        for (auto& m : known) list += (list.empty() ? "" : ", ") + m;
        throw Error("--method", "unknown method '" + options.method + "' (expected one of " + list + ")");
    }
    const scene::SceneDesc& desc = scene.desc();
    uint32_t seed = options.seed.value_or(desc.render.seed);
    const int spp = renderSpp(desc, options);
    if (spp <= 0) throw Error("--spp", "expected a positive number of samples per pixel");

    Timer total;
    Camera camera(desc.camera);
    PathSampler sampler(scene, camera, desc.render.indirect, seed);
    if (options.sampler != "sobol" && options.sampler != "independent")
        throw Error("--sampler", "expected sobol or independent, got '" + options.sampler + "'");
    sampler.setIndependentSamples(options.sampler == "independent");
    if (const Distribution* d = options.distribution; d && d->ranks() > 1) sampler.distribute(d, d->rank(), d->ranks());
    LightFieldSamples lightField;
    if (options.layers != "auto" && options.layers != "on" && options.layers != "off")
        throw Error("--layers", "expected auto, on or off, got '" + options.layers + "'");
    const bool layered = keepsLightField(desc, options, spp);
    const float radianceScale = LightFieldSamples::radianceScaleFor(brightestEmitter(desc));
    if (layered) {
        lightField = LightFieldSamples(desc.camera.width, desc.camera.height, keepsSags(desc), radianceScale);
        const ViewGeometry& v = sampler.view();
        const auto along = [](Vec3f h, Vec3f axis) { return std::abs(h.x * axis.x) + std::abs(h.y * axis.y) + std::abs(h.z * axis.z); };
        std::vector<Vec2f> image;
        for (const Vec3f& h : scene.objectHalfExtents()) image.push_back({along(h, v.right), along(h, v.up)});
        lightField.setView(v.focalPixels, v.apertureRadius * v.focalPixels, 1.f / v.focusDistance, std::move(image));
    }
    MethodContext ctx{scene, options, sampler, sampler.view(), spp, layered ? &lightField : nullptr, 1.f / radianceScale};

    RenderResult result;
    result.method = options.method;
    result.threads = ThreadLimit::current();
    result.buffers = FrameBuffers(desc.camera.width, desc.camera.height);
    if (options.method == "mc") renderMc(ctx, result);
    else if (options.method == "aaf") renderAaf(ctx, result);
    else if (options.method == "maaf") renderMaaf(ctx, result);
    else renderAtrous(ctx, result);
    result.sppAverage = averageSpp(result.buffers);
    // Each rank counted the rays it traced.
    result.raysPerRank = gatherCounts(sampler.distribution(), result.rays);
    result.rays = 0;
    for (uint64_t r : result.raysPerRank) result.rays += r;
    // And, over every rank, the samples whose light is not finite (--stats nonfinite_samples) and
    // those a light sample reached with light (lit_samples).
    auto overRanks = [&](uint64_t mine) {
        const std::vector<uint64_t> all = gatherCounts(sampler.distribution(), mine);
        return double(std::accumulate(all.begin(), all.end(), uint64_t{0}));
    };
    result.extra.emplace_back("nonfinite_samples", overRanks(sampler.nonFiniteSamples()));
    result.extra.emplace_back("lit_samples", overRanks(sampler.litSamples()));
    result.seconds.add("total", total.seconds());
    shareRootTimes(sampler.distribution(), result.seconds);  // every rank returns the same result
    return result;
}

}  // namespace wedge::render
