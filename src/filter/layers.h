// Layered reconstruction of the camera's light field across pixels, lens and shutter: defocus and
// motion blur, with visibility resolved by depth. After Munkberg, Vaidyanathan, Hasselgren,
// Clarberg and Akenine-Möller 2014 ("Layered Reconstruction for Defocus and Motion Blur": per
// tile depth layers, samples reprojected to the lens centre at one shutter time, a screen-space
// filter per layer, layers composited front to back) and Lehtinen, Aila, Chen, Laine and Durand
// 2011 (samples reprojected along their trajectories; the nearest surface that covers a
// reconstruction ray is the one it sees).
//
// A sample taken at film position x, lens point u and shutter time t on a surface whose
// defocus slope is c (pixels per unit lens coordinate, ViewGeometry::defocusSlope) and whose
// screen motion over the shutter is m sees the point that, through the lens centre at mid-shutter,
// lies at y = x + c u - m (t - 1/2): its position in the layer's "sharp" image (film x along the
// lens's u, film y downward against its v: y_y = y - c v - m_y (t - 1/2)). Samples of one
// surface collapse there onto a sharp image, so samples of many pixels can be reused. (For a
// surface moving in depth, t - 1/2 is replaced by the share of its chord m a point moving at
// constant velocity in space covers by then, which is not proportional to the time under
// perspective: layers.cpp, alongChord. A point of an object turning by at most half a turn,
// and in depth by at most 60 degrees, moves along the parabola through its chord's ends and its
// place at mid-shutter, which its sample records as the sagitta s: its y gains 4 e (t - 1/2)^2,
// e = s less what alongChord gives; a moving layer's motion grid holds the mean e beside the
// motion: layers.cpp, curvedShift.)
//
// Per screen tile (64 pixels, with an apron as wide as the trajectories that reach it, at most
// LayerOptions::maxReach):
// 1. The samples are split into depth layers: still samples and up to sixteen groups of moving
//    ones apart, a group per connected part of the motion field (layers.cpp, groupByMotionField,
//    kMotionGroups), each sorted by defocus slope (which
//    falls with depth; a moving group whose slope changes over the shutter, an object moving in
//    depth, by its slope at mid-shutter: layers.cpp, slopeRate); a new layer starts where the slopes spread more than
//    max(0.5, 0.15 |c|) pixels or jump by half a pixel; consecutive still layers that are each
//    sharp (below) are one, which composites exactly as they would (at most 16 layers, the
//    thresholds widened until they fit). Layers are composited in the order of their mean
//    inverse depth (a moving one's nearest sample's); two that cross in depth over the shutter,
//    one of them moving, in the order of each of 8 bins of shutter time (layers.cpp,
//    kOrderBins; two moving layers by their depths in the cells where both were seen,
//    kOrderVotes; orderLayers), and a sample counts in the D of the layers in front of its own at
//    its time (not a sample nearer than all of a moving layer whose own layer lies wholly in front).
// 2. Per layer, on a grid of 1-pixel cells in its sharp image (of larger cells in a still layer
//    blurred so far that its grid would reach more than LayerOptions::stillGridReach pixels
//    beyond its tile): N, the layer's samples at their own y; D,
//    those and the samples of every layer behind it at the layer's shear y = x + c_l u - m_l (t -
//    1/2) (c_l, m_l its means); W, R, G, B, its samples' radiance at their own y, in 8 bins of
//    shutter time for a moving layer (a moving surface's shading changes as it moves); and the
//    sum of its samples' slopes. A sample in front of the layer tells nothing about it, so it is
//    left out of D: alpha = N / D is the layer's coverage where it is not hidden. The grids are
//    smoothed with a Gaussian of sigma = clamp(0.15 |c_l|, 0.5, 2) pixels, the coverage's (N, D)
//    and the slopes' with one of clamp(0.15 |c_l|, 0.25, 2); cells without weight (the layer
//    hidden there) are filled from their neighbours. A layer's true blur (a disc of radius |c|,
//    a segment of length |m|) is set against the grid's own with the radiance's Gaussian (the
//    sharp threshold; for samples that carry their own radiance, half of it at 16 samples per
//    pixel: LayerOptions::sharpShare): a pixel whose samples of the layer lie at or above it
//    takes the grid; below the band's foot (LayerOptions::sharpBand) its own samples of the
//    layer, not reprojected; between, both, the grid's share rising linearly with their blur
//    radius. A layer none of whose pixels takes its grid is "sharp": its grid is its pixels'
//    own samples.
//    A moving layer in focus whose samples move along one axis of the grid keeps the other axis
//    crisp: the nearest cell there, and across the motion no Gaussian for the coverage; for the
//    radiance, where the samples carry filtered light none but one stopped at edges, where they
//    carry their own the plain one (LayerOptions::crispAcrossMotion, crispRadiance).
//    Every blurred moving layer's radiance is smoothed to its edges along both axes, and for
//    samples with their own radiance every blurred still layer's (LayerOptions::movingEdgeWidth).
// 3. Each pixel is the mean of 32 reconstruction rays (x, y, u, v, t), a 5D Kronecker sequence
//    shifted per pixel, so that pixel, lens and shutter are stratified jointly. Front to back, a
//    ray takes each layer's alpha and premultiplied radiance at its shear, with the slope and
//    the screen motion of the surface it finds there (one fixed-point step: a slanted floor's
//    slope changes across the tile, and a sphere's front moves faster on screen than its
//    silhouette; a moving layer keeps its samples' mean motion per cell, where it has none the
//    affine fit of their motion to their position, and its D counts the samples behind it at
//    that motion too), shaped so that the grid's own blur (cells,
//    Gaussian, bilinear lookup) over the rays' disc (segment) gives the true disc's (segment's)
//    edge profile as nearly as a near-Gaussian allows (rays drawn towards the rim: layers.cpp,
//    Shaped): C += T alpha L, T *= 1 - alpha. (A moving layer is traced only for the rays
//    whose lookups can land on a cell it covers: layers.cpp, traceWindowed.)
//    Light the layers leave uncovered (a hole no sample saw) is the mean of what they cover.
//    Where every layer of the tile is sharp, one ray at the pixel gives the same: the pixel's
//    own samples composited by surface, as without layers. A pixel whose 32 rays straddle
//    layers (ended on different ones, or on a layer's partial coverage: a defocused or moving
//    silhouette) takes the sequence on to 64 rays: there the rays' own noise was a tenth of
//    the error (MC 16 spp on bunny at 512x512: the mixed pixels' relMSE 0.00136 -> 0.00121);
//    to LayerOptions::movingRays in a tile where a layer moves, whose rays integrate over the
//    shutter as well (the renderer: 128 where the samples carry filtered light, AAF relMSE
//    3-19% lower on eight scenes with motion; docs/layers.md, "More rays where a layer moves"),
//    unless its first rays agree (LayerOptions::rayTolerance).
//
// The radiance a sample carries is its surface's light as the method filtered it (AAF's or
// MAAF's filtered direct and indirect light of the sample's surface in its pixel, times the
// sample's own albedo) or, without filtered light, its own. In a blurred layer it carries its
// own light also where the filtered light is another point's: on a surface other than its
// pixel's primary one (whose filtered light is a neighbour pixel's; still or moving), and, in a
// still layer, on the primary surface of a pixel that saw several, where the layer's slope is
// at least 2 px, and wherever the slope is at least 8 px, where the filtered light would blur
// twice (layers.cpp, radianceOf).
// Emitted light is not reconstructed here but where a moving light is spread thin over its blur
// (a small light's streak: LightFieldSamples::wideBlur): there a sample that sees it carries its emission with
// its own radiance (and no albedo, so that it keeps its own under the filters' light), and the
// pixels within its reach take more rays (LayerOptions::emitterRays). The caller adds the rest
// of each pixel's own emission (densely sampled at emitter edges).
#pragma once

#include <array>
#include <cstdint>

#include "core/buffers.h"
#include "core/light_field.h"

namespace wedge::filter {

struct LayerOptions {
    int tile = 64;             // pixels
    int maxReach = 48;         // pixels: a tile gathers the samples whose trajectories reach it from at most this far (the cost bound)
    // cells: a blurred layer's grid has at most the cells of one reaching this far beyond its
    // tile both ways (its memory: (64 + 2 x 128)^2 cells). A moving layer's grid reaches along
    // each axis as far as its blur there, |c| + |m_x| / 2 + 3 sigma across and |c| + |m_y| / 2
    // + 3 sigma down, on cells of 1 px where that fits (an in-focus streak along x of up to
    // 1400 px, a diagonal one of about 250 px along each axis) and past it on larger cells, up
    // to 8 px (Layer::step: a diagonal motion of about 2400 px along each axis); a tile with a
    // moving layer that fits on none reconstructs no layer (each keeps its pixels' own samples,
    // as without layers: layers.cpp, tileBeyondGrid).
    int maxGridMargin = 128;
    // cells: a blurred still layer's grid reaches at most this far beyond its tile: where its
    // blur would take a grid of 1-px cells farther, its cells are larger (Layer::step), so that
    // a blur of any size is reconstructed at a bounded cost. (Of the built-in and docs/ scenes
    // only sponza at 512x512 and docs/sponza-motion.json have such a layer, their relMSE the
    // same to five digits. Beyond 128 px, before, a layer kept its pixels' own samples, and
    // composited with the blurred layers behind it the light behind a near column showed
    // through it: docs/layers.md, "Blur past the grid's reach".)
    int stillGridReach = 32;
    float sigmaScale = 0.15f;  // the sharp image's Gaussian: sigmaScale |c_l|, clamped to [sigmaMin, sigmaMax]
    float sigmaMin = 0.5f, sigmaMax = 2.f;
    // ... and the coverage's (N, D) and the slopes': sigmaScale |c_l| clamped to [sigmaCoverageMin,
    // the radiance's]. The rays' shear is shaped for it; the sharp threshold stays sigmaMin's.
    // (0.5, as the radiance's, measured MC relMSE higher at 512x512 on conference by 9%, cornell
    // by 5%, cornell-sphere by 4%; docs/layers.md, "What the mixed pixels' error is made of".)
    float sigmaCoverageMin = 0.25f;
    float splitMin = 0.5f, splitScale = 0.15f;  // a layer's slopes spread at most max(splitMin, splitScale |c|)
    // The sharp threshold: sharpShare times the grid's own blur with the smallest Gaussian
    // (kCellBlur + sigmaMin^2). From it on a pixel takes the layer's grid alone: at 1 the grid
    // never blurs beyond the true blur's variance. Below 1 the grid is taken from a smaller
    // blur, at the price of up to 1 / sharpShare times its true blur's variance: for samples
    // that carry their own (noisy) radiance the renderer sets clamp(sqrt(samples per pixel /
    // 64), 0.5, 1) (reconstructFromLayers; docs/layers.md, "Near-focus layers share their
    // samples").
    float sharpShare = 1.f;
    // The sharp band: a pixel takes its own samples of a layer alone (as a sharp layer's) only
    // while the blur radius of the layer's samples there (the square root of their true blur) is
    // below sharpBand times the threshold's; from there to the threshold it blends them with the
    // layer's grid, the grid's share rising linearly with that radius, and from the threshold on
    // it takes the grid alone. A layer is sharp where all of its pixels take their own samples.
    // At 1, no band: a layer's sharpness, and with it its noise, stepped at the threshold, tile
    // by tile and layer by layer (a seam across a ceiling where MC's samples carry their own
    // noise: docs/layers.md, "A seam where a tile's layer turns sharp"). At 0.5, for filtered
    // light, relMSE against 1: AAF 0.88-1.006 on nineteen scenes with motion, à-trous 0.84-0.97
    // on five with a lens (0 cost AAF 10% on docs/posts.json's checkered floor near focus);
    // where the samples carry their own radiance the renderer sets 0 (MC 0.59-0.91 on the five
    // lens scenes at 16 and 64 spp; docs/layers.md, "The sharp band").
    float sharpBand = 0.5f;
    // At most this many layers a tile: past it the split's thresholds widen (x 1.5 until they
    // fit), which merges layers whose visibility then goes unresolved. Consecutive still layers
    // that are each sharp count as one (they composite exactly as one: mergeSharp).
    // (8 measured AAF relMSE 2.1x higher on docs/conference-wide.json; docs/layers.md, "The
    // layer budget".)
    int maxLayers = 16;
    bool mergeSharp = true;
    int rays = 32;      // reconstruction rays per pixel where a tile has a blurred layer (at most 128)
    int mixedRays = 64; // ... where the first `rays` straddle layers (at most 128)
    int movingRays = 128;  // ... and a layer of the tile moves (at most 128; the renderer keeps mixedRays for MC)
    // ... but only where the first rays leave their mean uncertain: the variance of their
    // luminance over the rays, divided by the number of rays and by the mean's square plus 0.01
    // (relMSE's epsilon), at least this (0: every straddling pixel; docs/layers.md, "Extra rays
    // only where the first ones disagree").
    float rayTolerance = 1e-4f;
    // Where a pixel's rays can reach a cell where a sample that carries an emitter's light landed
    // (one with emission carries no albedo: render/sampling.h), it takes at least a quarter of
    // emitterRays, and more, up to emitterRays, until the same measure of its rays falls to
    // emitterTolerance: an emitter is hundreds of times brighter than what it lights, and a
    // small one moving far is found by few of a pixel's 32-128 rays (docs/layers.md, "Emitters
    // through the layers").
    int emitterRays = 1024;  // (at most Rays::kMax, 1024)
    float emitterTolerance = 0.01f;
    uint32_t seed = 0;  // of the reconstruction rays
    // Count every sample's D on the grid of each layer in front of it, also where it lies farther
    // from all of that layer's own samples than can change the layer's coverage (the stage skips
    // those Ds; for the test that the skip changes no image, layers_test
    // Layers.TheDsSkippedFarFromALayersOwnSamplesChangeNoImage).
    bool countEveryD = false;
    // Smooth and resolve every cell of each layer's grids, also beyond the cells its
    // accumulations can reach (the stage works within those, CellBox in layers.cpp), and trace a
    // pixel's rays through every layer within its reach as one radius (the stage skips those
    // its rays cannot read along each axis apart, Layer::rayExtent), and every one of those rays
    // through a moving layer (the stage traces only those that can read a covered cell of it,
    // traceWindowed). For the test that none of these changes an image, layers_test
    // Layers.TheCellsBeyondALayersAccumulationsChangeNoImage and
    // Layers.RaysOutsideAMovingLayersWindowFindNothingThere.
    bool everyCell = false;
    // Bytes the caller holds beside the stage while it runs (the render's buffers and the kept
    // samples). With each thread's gathered samples (the largest tile's) they are taken from the
    // memory limit (core/memory_limit.h); what is left is the grids' budget: a tile reserves a
    // bound of its grids before it allocates them and gives it back when they are freed, waits
    // while the other threads' tiles hold too much of it, and is an error (wedge::Error, "--layers")
    // where it needs more than all of it (docs/layers.md, "The grids' budget").
    uint64_t memoryHeld = 0;
    // A blurred moving layer whose samples move along one axis of the grid, in focus (slopes
    // within 0.75 px), keeps the other axis crisp: the rays' lookup there the nearest cell, the
    // pixel's own row (column) of samples, no Gaussian across the motion for the coverage, the
    // radiance's stopped at edges, and the rays carrying the lens's disc but for the cells'
    // blur. The grid's blur across a motion, about 0.7 px (sigma) with its cells, Gaussian and
    // bilinear lookup, spread a moving box's lit top face, a strip 1-2 px tall, into the wall
    // above it and the box below (docs/moving-boxes.json). Off by default; the renderer sets it.
    bool crispAcrossMotion = false;
    // ... and the radiance too (true), or only the coverage, the slopes and the motion grid, the
    // radiance keeping its plain Gaussian across the motion (false: samples with their own
    // radiance, whose noise that Gaussian averages: with the radiance crisp too MC's relMSE on
    // raster-pan was 12% higher than with no crisp axis, with the coverage alone 7.5% lower;
    // docs/layers.md, "A crisp coverage for Monte Carlo's samples").
    bool crispRadiance = true;
    // A blurred moving layer's radiance is also smoothed along both grid axes by a Gaussian of
    // movingEdgeWidth times its radiance's sigma that stops at edges: a neighbour's weight falls
    // by e^(-1/2) where the two cells' luminance differs by edgeStop of their mean (across a
    // crisp layer's motion it is the only Gaussian; 0: none); a blurred still layer's by one of
    // stillEdgeWidth times. Along the motion the rays average a trail's samples; across it only
    // the grid does, and at the radiance's own sigma (about 0.5 px) the rows' noise showed as
    // streaks along the motion. The range is the samples' noise: the defaults are for filtered
    // light, where a still layer's measured no better with it (à-trous conference +0.9%), and
    // where the samples carry their own radiance the renderer sets 4, 4 and 0.2. Against the
    // crisp axis's alone (2x, at 0.2), on 19 scenes with motion: AAF relMSE +0.8% to -8.4%,
    // à-trous +0.1% to -12.5%, MC -0% to -59% (the camera pans); MC on the five lens scenes -15% to
    // -27% (docs/layers.md, "Moving layers' radiance, smoothed to its edges", "... and MC's
    // defocused layers").
    float movingEdgeWidth = 2.f, stillEdgeWidth = 0.f, edgeStop = 0.15f;
};

struct LayerInput {
    const LightFieldSamples& samples;
    ViewGeometry view;
    /// The filtered demodulated light of each FrameBuffers surface (0: the primary, 1 + k:
    /// other[k]); a sample on surface k of pixel p carries albedo x (*surfaceLight[k])[p] (but
    /// where that is another point's light, above). Null: the samples on that surface carry
    /// their own radiance.
    std::array<const Image3f*, 1 + FrameBuffers::kOtherSurfaces> surfaceLight{};
    /// Per pixel, kTextureSurface and kSharpTextured (null: none), and the mean albedo of each
    /// FrameBuffers surface in its pixel, its texture samples' included. A sample in a sharp
    /// layer, on a surface of a kTextureSurface pixel whose samples there all lie in that layer,
    /// carries that mean albedo x its light instead of its own albedo: the same expectation over
    /// the pixel, from the texture samples' camera rays too (where a defocused occluder in front
    /// covers part of the pixel, those that pass it are as the path samples that pass it).
    const Image<uint8_t>* textured = nullptr;
    std::array<const Image3f*, 1 + FrameBuffers::kOtherSurfaces> surfaceAlbedo{};
    /// Per pixel, 1 where the pixel is left to the method's own composition
    /// (pixelsAwayFromSilhouettes): with `own`, own = 1 there and no ray is traced, and a tile
    /// of such pixels alone is not gathered or split either. Null: none is.
    const Image<uint8_t>* methodPixels = nullptr;
};

/// How far from a silhouette (a pixel whose samples saw several surfaces) the renderer leaves a
/// pixel to aaf's and maaf's own composition (pixelsAwayFromSilhouettes). Per pixel at 1 px
/// measured better than 32-px blocks at 2 px on nine of eleven scenes with motion (raster-pan
/// -7%, conference-motion and fast-motion +2-3%) and worse on the lens scenes with `--layers on`
/// (cornell +5%, whose defocused walls gain from the layers away from silhouettes too;
/// docs/layers.md, "Pixels away from a silhouette left to the filters").
constexpr int kSilhouetteReach = 1;
/// Per pixel, 1 where no pixel within `reach` pixels (a square) is set in `mixed` (its samples
/// saw several surfaces: a silhouette). There aaf's and maaf's own composition, their
/// per-surface filters' light with the defocus filter, measured better than the layers'
/// (LayerInput::methodPixels).
Image<uint8_t> pixelsAwayFromSilhouettes(const Image<uint8_t>& mixed, int reach);

/// LayerInput::textured's bits: the pixel took texture samples for a surface whose samples there
/// are sharp and still (kTextureSurface); every sample it holds is sharp and still, and it or a
/// pixel within kTextureReach of it took texture samples with every sample sharp and still
/// (kSharpTextured: a texture's edge the layer's grid would blur more than the lens does).
constexpr uint8_t kTextureSurface = 1, kSharpTextured = 2;
/// How far (pixels) kSharpTextured reaches from a pixel with texture samples: the grid's blur
/// (its smallest Gaussian, sigma 0.5 px, and its cells) carries a texel's edge about that far.
constexpr int kTextureReach = 2;

struct LayerStats {
    double gatheredPerPixel = 0;  // samples a tile read, per pixel of the image
    double layersPerTile = 0;
    double blurredTiles = 0;      // fraction of tiles with a reprojected (blurred) layer
    double straddlingPixels = 0;  // fraction of pixels whose first rays straddled layers and disagreed (and took mixedRays)
    double multiRayPixels = 0;    // fraction of pixels that traced more than one reconstruction ray
    double raysPerPixel = 0;      // reconstruction rays traced, per pixel of the image
    double methodTiles = 0;       // fraction of tiles left whole to the method's own composition (LayerInput::methodPixels)
    // What a thread holds for one tile: the largest tile's gathered samples and its layers' grids
    // (accumulations, resolved cells, motion grids and summed-area tables, each counted whole,
    // though a layer's accumulations are freed as its cells are resolved), bytes.
    double largestTileBytes = 0;
    // The layers' accumulations and resolved cells as stored (around the cells their samples
    // reach: Layer::accWin, dWin, cellBox), over what they would be across their whole grids.
    double gridShare = 0;
    // The samples the largest tile gathered (its pixels and its margins), which each thread
    // reserves once (gatheredBytesPerThread bounds it).
    double largestTileSamples = 0;
    // The largest bound a tile reserved for its grids (LayerOptions::memoryHeld), bytes; the
    // tiles whose grids came to more than their bound (none: layers_test checks it); the tiles
    // that waited for the budget; and the budget.
    double largestTileReserve = 0;
    double tilesOverReserve = 0;
    double tilesWaited = 0;
    double gridBudget = 0;
};

/// The most samples one tile of reconstructLayers gathers: a tile and its widest margins
/// (LayerOptions::maxReach and the Gaussians' pad) within the image, at samplesPerPixel samples a
/// pixel.
uint64_t gatheredSamplesPerThread(int width, int height, double samplesPerPixel, const LayerOptions& options = {});
/// ... what a thread holds for them, bytes, with each sample's scratch. (The tile's grids come on
/// top and depend on the scene: the stage reserves them from what the memory limit leaves,
/// LayerOptions::memoryHeld; LayerStats::largestTileBytes.)
uint64_t gatheredBytesPerThread(int width, int height, double samplesPerPixel, const LayerOptions& options = {});

/// Whether every sample pixel `p` holds is sharp and still: its defocus blur, a disc of radius
/// |c|, and its screen motion below the grid's own blur with the smallest Gaussian (the sharp
/// threshold of a layer whose samples carry filtered light). Where such a pixel's layers in
/// front are sharp too, or its rays all end whole on one still layer, the reconstruction can be
/// its own (reconstructLayers' `own`).
/// With `surface` >= 0, only the samples on that surface (LightFieldSample::surface()).
bool samplesSharpAndStill(const LightFieldSamples& samples, size_t p, const ViewGeometry& view, const LayerOptions& options = {},
                          int surface = -1);

/// The front-to-back order of a tile's n layers in one order bin (reconstructLayers): from
/// splitLayers' order 0 .. n - 1, with before[i * n + j] = 1 where layer i must go before layer j
/// (set for pairs whose order changes over the shutter, either way). A layer goes just before the
/// first layer it must precede, past layers it has no rule with, unless one it must follow comes
/// later; the others keep splitLayers' order. `order` receives the n layers front to back.
void orderLayers(const uint8_t* before, int n, int* order);

/// The radiance of every pixel, reconstructed from the light field.
/// `own`, where given, is set to 1 in the pixels whose rays all end in sharp still layers (every
/// ray finds the same values there: the pixel's own samples, composited) and, among the pixels
/// input.textured marks kSharpTextured, in those whose first rays all end whole (no ray taking
/// part of a layer's coverage) on one still layer, blurred or not, or touch no layer but still
/// ones at the pixel's own depth (within 1 px of its samples' mean slope) or behind it: such a
/// pixel shows one surface (perhaps split between two layers inside it), sharper than the
/// layer's grid can reconstruct it, and a caller with its own estimate of the pixel (its texture
/// samples' mean albedo) takes it there. 0 elsewhere.
Image3f reconstructLayers(const LayerInput& input, const LayerOptions& options = {}, LayerStats* stats = nullptr,
                          Image<uint8_t>* own = nullptr);

}  // namespace wedge::filter
