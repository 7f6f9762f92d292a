// Internal: the per-method entry points behind render(). Each receives a ready PathSampler and
// fills a RenderResult (colour, buffers, stage times, sample and ray counts).
#pragma once

#include <array>
#include <string>

#include "core/light_field.h"
#include "core/progress.h"
#include "render/path_sampler.h"
#include "render/pixel_stats.h"
#include "render/renderer.h"
#include "render/sampling.h"

namespace wedge::render {

struct MethodContext {
    const scene::Scene& scene;
    const RenderOptions& options;
    const PathSampler& sampler;
    ViewGeometry view;
    int spp;  // the method's base sample count
    /// Every sample, for the layered reconstruction (RenderOptions::layers); null when off or
    /// when the camera has no lens and nothing moves (nothing to reconstruct across pixels).
    LightFieldSamples* lightField = nullptr;
    /// The luminance in which relMSE's epsilon 0.01 is measured where a method compares a
    /// pixel's noise with its mean (the mixed pixels' top-ups, the layers' edge-stopping and extra
    /// rays): 1 / LightFieldSamples::radianceScale, 1 where the brightest emitter is at most 64.
    /// Above, a scene in brighter units samples and reconstructs as it would with its lights
    /// scaled to 32-64, by a power of two (docs/reliability.md, "Linearity in the lights' radiance").
    float luminanceUnit = 1.f;
};

void renderMc(const MethodContext& ctx, RenderResult& result);
void renderAaf(const MethodContext& ctx, RenderResult& result);
void renderMaaf(const MethodContext& ctx, RenderResult& result);
void renderAtrous(const MethodContext& ctx, RenderResult& result);

/// Samples per pixel at emitter edges (PixelStats::emitterTopUp), for every method. Their emitted
/// light comes from denseEmission's kEmitterEdgeRays camera rays; these path samples are for the
/// rest of the pixel (the surfaces beside the emitter and their light). 256 was measured before
/// the dense emission (cornell 512x512, aaf relMSE 0.000225 / 0.000191 / 0.000184 at 64 / 256 /
/// 1024); with it, 64 measured the same relMSE (-1% to +2%: cornell, conference, sponza,
/// cornell-sphere, docs/bokeh.json, docs/lights.json; MC and AAF, seeds 3 and 4) in 0.54-0.73x the
/// time on the two held-out views of small lights out of focus (1.4-1.8x the efficiency) and
/// 0.90-0.94x on cornell (docs/layers.md, "Fewer path samples at emitter edges").
constexpr uint32_t kEmitterEdgeSpp = 64;

/// Extra samples at the edges of visible emitters, for every method: up to `target` samples for
/// each pixel whose samples partly saw an emitter (PixelStats::emitterTopUp) and for each pixel
/// within an emitter-seeing pixel's circle of confusion plus one pixel whose samples did not all
/// see an emitter. Its 16 samples miss the few percent of a (defocused) emitter's light that
/// reach such a rim pixel, and that light is many times the dark surface's own. With the
/// layers' samples `lf` (every rank's emissions gathered first: shareEmissions), only where the
/// pixel's samples saw an emitter they do not carry into the layers (LightFieldSamples::
/// wideBlur: a moving light spread thin over its blur).
Image<uint32_t> emitterTopUps(const PixelStatsImage& stats, uint32_t target, const LightFieldSamples* lf = nullptr);
/// Gives every rank the per-pixel emission sums of the others' rows (LightFieldSamples::
/// emissionData, wideEmissionData), which emitterTopUps reads across them (and, called at the end
/// of denseEmission, the layers' composition); nothing without `lf`.
void shareEmissions(LightFieldSamples* lf, const Distribution* distribution);

/// The light-field stage of aaf's and maaf's adaptive samples (`extra` per pixel): a pixel's are
/// kept only where its initial samples (`stats`, before the adaptive ones) saw more than one
/// surface, or a surface and nothing (PixelStats::mixed), where the pixel takes emitter-edge
/// samples (`emitterExtra`), and where they saw a surface's albedo vary (kTextureVariance: each
/// sample carries its own albedo). Elsewhere a pixel's initial samples saw one untextured
/// surface, and the samples the filters add there for their rates carry filtered light the
/// stage already has from them (LayerInput::surfaceLight: the light of the sample's surface in
/// its pixel), so they would only cost the stage's time and memory. Measured on twelve scenes
/// with motion (AAF, 512x512 or their own size, relMSE against 1024-spp MC): docs/layers.md,
/// "The samples the stage keeps". Without ctx.lightField, a stage that records nothing.
LightFieldStage adaptiveLightFieldStage(const MethodContext& ctx, const PixelStatsImage& stats, const Image<uint32_t>& emitterExtra,
                                        const Image<uint32_t>& extra);

/// Camera rays per pixel for the emitted light where emitterTopUps applies.
constexpr uint32_t kEmitterEdgeRays = 1024;
/// Where `topUp` is non-zero, replaces the pixel's emitted light (the emission plane and its
/// share of the colour) by PathSampler::meanEmission over kEmitterEdgeRays camera rays. What an
/// emitter's edge or rim pixel emits depends only on what its camera rays hit, and a path
/// sample costs several camera rays; at 256 samples a rim pixel still sees the emitter only 0-2
/// times. The methods pass emitterTopUps(stats, kEmitterEdgeRays): every edge and rim pixel with
/// fewer path samples than these rays, also those that take no path samples more (256 or more
/// already; before, those kept their own, and MC at 256 spp had noisier emitter edges than at
/// 64). Returns the rays traced.
uint64_t denseEmission(const MethodContext& ctx, const Image<uint32_t>& topUp, FrameBuffers& fb);

/// Mixed pixels (PixelStats::mixedTopUp) in aaf and maaf: 71-87% of either filter's relMSE sits
/// in pixels that mix surfaces (384x384, conference, sponza). Measured at tau 0.02 / 0.005 (384x384,
/// 1 / (relMSE x seconds) against no top-up): aaf conference +19% / +39%, sponza +25% / +23%,
/// grids +30% / +25%, cornell +4% / +5%; maaf conference +28% / +39%, sponza -3% / -15%,
/// cornell +20% / +25%, grids +3% / +1%.
constexpr float kMixedTau = 0.01f;
constexpr uint32_t kMixedSpp = 64;
/// With a light field, a mixed pixel whose every surface sample moves on screen by at least m
/// pixels is reconstructed by the layers from samples pooled along the motion, its neighbours'
/// along the trail as well as its own: there tau is multiplied by kMotionPooling x m x the share
/// of the trail's pixels (m / 2 either way) whose surface samples all move (when that is above
/// 1), as if each pixel the motion crosses gave half a pixel's worth of samples. On a pan,
/// where nearly every pixel mixes surfaces, the top-ups to 64 had made AAF's samples 3x MC's.
/// AAF on nineteen scenes with motion, 1 / (relMSE x seconds) against tau alone: sponza-pan
/// 1.28x, sponza-campan 1.24x, sponza-turn 1.16x, moving-boxes 1.08x, bunny-slats 0.96x (the
/// one loss), 1.05x on the geometric mean of those that changed; 0.25 and 1 in place of 0.5
/// measured 1.08x and 1.09x against 1.125x on eight of them (docs/layers.md, "Fewer top-ups
/// where every surface moves").
constexpr float kMotionPooling = 0.5f;
/// The circle of confusion (radius, pixels) from which the layers reconstruct a surface from its
/// neighbours' samples as well as its own: a layer blurred by less, below the layers' sharp
/// threshold of 1.41 px, keeps its pixels' own samples. Where the mixed pixels' top-ups pool
/// (blurPooling) and what settleLayers counts.
constexpr float kLayerBlurFrom = 1.5f;
/// Likewise a mixed pixel whose every surface sample is defocused, by a circle of confusion of
/// radius c pixels (|defocus slope|) at least kLayerBlurFrom: the layers reconstruct it from the
/// samples of the pixels its circle covers, and tau is multiplied by kDefocusPooling x c^2 (the
/// circle's area over 2 pi, as the motion's half a pixel per pixel crossed). AAF with layers,
/// against the same without this (docs/layers.md, "Fewer top-ups where every surface is
/// defocused"): sponza-motion 42.4 -> 35.9 samples a pixel for relMSE +0.9%, sponza (--layers
/// on) 41.9 -> 35.4 for +0.9%; fence, bunny-slats 5-6% fewer for +0.4%; elsewhere within 2% of
/// the samples (fast-motion 1% fewer for +1.7%, the one loss).
constexpr float kDefocusPooling = 0.5f;
/// Per pixel, the factor kMotionPooling or kDefocusPooling gives its top-up's tau (the larger; 1
/// where neither gives any), from the light field's initial samples: not in the pixels `bent`
/// marks (bentPixels; may be empty), which aaf and maaf compose themselves (`distribution`:
/// every rank reads the other ranks' rows of the trail). Empty without a light field.
Image<float> blurPooling(const LightFieldSamples* lightField, const ViewGeometry& view, const Image<uint8_t>& bent,
                         const Distribution* distribution = nullptr);
/// aaf and maaf, after their initial samples (stats, every rank's): where the layers wait for
/// them (RenderOptions::layeredIfMixed) and fewer than kLayersMixedShare of the pixels saw
/// several surfaces, one of them defocused by at least kLayerBlurFrom, the light field is let
/// go and ctx.lightField set to null: the render is the one `--layers off` gives, to the bit.
/// Adds `layers_defocused_mixed_share` to the result's figures where it decided.
void settleLayers(MethodContext& ctx, const PixelStatsImage& stats, RenderResult& result);
/// The mixed pixels' top-ups of aaf and maaf: PixelStats::mixedTopUp at kMixedTau times the
/// pixel's `pooling` (blurPooling; empty: 1), up to kMixedSpp, with relMSE's epsilon in
/// MethodContext::luminanceUnit.
Image<uint32_t> mixedTopUps(const PixelStatsImage& stats, const Image<float>& pooling, float luminanceUnit);
/// The pixels within reach of a sample whose path bends on a surface turning towards or away
/// from the camera (LightFieldSamples::bentReach, every rank's rows), where aaf and maaf keep
/// their own composition (result.methodPixels); empty where there are none or no light field.
Image<uint8_t> bentPixels(const MethodContext& ctx);


/// Texture samples, in every method that multiplies filtered light by albedo (aaf, maaf, atrous)
/// where it composes per pixel (with a light field: only in the pixels whose samples on a
/// textured surface are sharp and still, filter::samplesSharpAndStill, whose sharp layers then
/// carry the pixel's mean albedo and which can keep their own composition there;
/// result.texturePixels marks them for reconstructFromLayers): where a
/// pixel's path samples saw the albedo of a surface vary by more than kTextureVariance
/// (PixelStats::albedoVariance), options.textureSpp primary hits more (PathSampler::primaryHits:
/// a camera ray each, no light, no bounce), whose albedo joins that of the surface they land on
/// and whose hits refine the surfaces' shares of the pixel (PixelStats::addPrimary). No filter
/// reaches a texture's noise: a pixel's colour is its surface's filtered light times the mean
/// albedo its camera rays saw, and 16-32 of them leave a checker's pixels noisy
/// (docs/textures.md). Takes the pixels' sample indices on from their path samples' (the same
/// seed, the same image on any number of threads or ranks). Adds the rays to result.rays and the
/// pixels' count to result.extra ("texture_pixels"). First, for aaf and maaf with a light field,
/// marks result.methodPixels (filter::pixelsAwayFromSilhouettes), where texture samples are taken
/// as without layers.
void textureSamples(const MethodContext& ctx, PixelStatsImage& stats, RenderResult& result);
/// The relative variance of a surface's albedo luminance above which a pixel takes texture samples.
constexpr float kTextureVariance = 1e-4f;

/// Monte Carlo sampling as `mc` does it: ctx.spp samples per pixel, then the emitter-edge
/// top-up, into pixel statistics of its own. Adds the rays to result.rays, fills result.buffers,
/// and times "sampling" (the statistics' allocation included).
/// With `texture`, texture samples (textureSamples) before the statistics are stored.
void sampleUniform(const MethodContext& ctx, const std::string& label, RenderResult& result, bool texture = false);

/// Stores every pixel's statistics into `fb`, with the closed-form unoccluded direct light.
void storeStats(const PixelStatsImage& stats, const MethodContext& ctx, FrameBuffers& fb);
/// Average samples per pixel of `fb.spp`.
double averageSpp(const FrameBuffers& fb);

/// The samples' surfaces in ctx.lightField (PixelStats slots as they were taken) become
/// FrameBuffers surfaces (0 the primary, 1 + k other[k]), once the statistics are final.
void finishLightField(const MethodContext& ctx, const PixelStatsImage& stats);
/// The image of a method whose samples carry `surfaceLight` (null entries: their own radiance;
/// filter/layers.h): each pixel's emission plus the layered reconstruction of the reflected light
/// from ctx.lightField; with `perPixel` (the method's own composition of each pixel, emission
/// included), that composition where the reconstruction is the pixel's own samples on sharp
/// still layers (filter::reconstructLayers' `own`) and in the pixels result.methodPixels leaves to
/// it. Times the "layers" stage and adds its figures to result.extra.
Image3f reconstructFromLayers(const MethodContext& ctx, const std::array<const Image3f*, 1 + FrameBuffers::kOtherSurfaces>& surfaceLight,
                              RenderResult& result, const Image3f* perPixel = nullptr);

/// The primary surface's visibility as rgb, the input of the direct-light filters.
Image3f visibilityImage(const FrameBuffers& fb);
/// The last step of aaf and maaf: direct light as the closed-form unoccluded irradiance times
/// the filtered visibility (AAF report eq. 3.2), composed with the filtered indirect light
/// (FrameBuffers::composeFiltered), then, where the camera has a lens, the defocus filter of the
/// composited radiance (filter/defocus.h).
/// With ctx.lightField, the layered reconstruction (reconstructFromLayers) takes the place of that
/// image near silhouettes (result.methodPixels: filter::pixelsAwayFromSilhouettes).
Image3f composeFilteredLight(const MethodContext& ctx, const Image3f& filteredVisibility, const Image3f& filteredIndirect,
                             RenderResult& result);

}  // namespace wedge::render
