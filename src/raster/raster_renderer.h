// `wedge raster`: the stochastic rasterization pipeline with decoupled shading, measured the way
// Vaidyanathan et al. 2012 (Sec. 4, Fig. 8) measure it: shaded 2x2 quads and shading-cache
// behaviour under motion and defocus blur, for decoupled sampling (DS, Ragan-Kelley et al. 2011:
// pixel-aligned shading grid at the canonical pose) and adaptive anisotropic shading (AAS: the
// per-primitive motion-aligned grid of eqs. 8-9 and Sec. 3.4), against a reference that shades
// every visibility sample at its own surface point.
//
// Pipeline: (0) tessellation (raster_geometry.h) splits blurred triangles longer than 32 pixels,
// so that AAS bounds small patches; DS ignores the split (it keys on the scene's triangles).
// (1) Visibility (visibility.h) resolves every sample's nearest triangle, as a depth pre-pass
// would. (2) Each visible sample maps to (shading primitive, cell) of its triangle's shading grid
// at the canonical pose. (3) Traversal order: shading primitives in scene order (meshes, then
// tessellated spheres, each in file order; a scene triangle's pieces in split order), and for each
// its visible samples in screen traversal order (8x8 tiles row-major, 2x2 leaf blocks row-major,
// pixels row-major, samples by index): the order a sort-last pipeline with a hierarchical
// rasterizer meets a primitive's samples. (4) Each key is looked up in the LRU cache of
// `cacheEntries` cells (shading_cache.h); a miss shades the 2x2 quad of cells holding the cell
// (four shader invocations; cell centres clamped into the triangle) and inserts its four cells.
// (5) The shaded quads are evaluated (in parallel: the shader is a pure function of the key), and
// every pixel averages its samples' values (box filter; background black).
//
// Because the shader is a pure function of (primitive, cell), the image does not depend on the
// cache size: the cache decides only how often a cell is shaded. Triangles that cross the near
// plane during the shutter have no canonical pose; their samples are shaded one by one, each
// counted as a miss and one shaded quad.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/timer.h"
#include "raster/shading_space.h"
#include "scene/scene_desc.h"

namespace wedge::raster {

enum class ShadingMode { Reference, Decoupled, Adaptive };

/// "reference", "ds", "aas".
std::string shadingModeName(ShadingMode mode);
/// Parses a mode name; throws wedge::Error naming `where` on anything else.
ShadingMode parseShadingMode(const std::string& name, const std::string& where);

struct RasterOptions {
    ShadingMode shading = ShadingMode::Adaptive;
    size_t cacheEntries = 64;
    int spp = 16;
    uint32_t seed = 0;
    FrequencyCutoffs cutoffs;
    float maxTriangleEdge = kDefaultMaxEdge;  // pixels on the canonical image; 0: no splitting
    bool alignGrid = true;  // AAS: start a sub-pixel-rate lattice at its triangle's corner
    int truthSpp = 0;       // > 0: also render a converged reference at this many spp (rel_mse_vs_truth)
    bool computeReference = true;  // also shade every sample, to report the image error
    bool progress = false;
};

struct CacheCounts {
    uint64_t lookups = 0, hits = 0, misses = 0, evictions = 0;
    uint64_t shadedQuads = 0, shaderInvocations = 0;
    std::vector<uint64_t> shadedQuadsPerObject;  // by scene object (mesh, then sphere) index
};

struct RasterStats {
    ShadingMode shading = ShadingMode::Adaptive;
    size_t cacheEntries = 0;
    int width = 0, height = 0, spp = 0;
    size_t triangles = 0, culledTriangles = 0, fallbackTriangles = 0;
    bool splitBudgetReached = false;  // RasterScene::splitBudgetReached
    float maxTriangleEdge = 0;
    uint64_t samples = 0, visibleSamples = 0, sampleTests = 0, boundRejects = 0, fallbackSamples = 0;
    CacheCounts cache;
    uint64_t quadsUnboundedCache = 0;  // distinct (primitive, quad) keys: the shaded quads of an infinite cache
    double meanSpacingMu = 1, meanSpacingPerp = 1;  // pixels; grid spacing averaged over visible samples
    double relMse = -1;     // against the reference (shading every sample); -1 when not computed
    double psnr = 0;        // dB, against the same reference
    double relMseTruth = -1;  // against the converged reference (truthSpp); -1 when not computed
    double truthSeconds = 0;
    double seconds = 0;     // the render, without the reference
    double referenceSeconds = 0;
    StageTimes stages;
};

struct RasterResult {
    Image3f image;
    Image3f reference;  // empty unless computed
    Image3f truth;      // empty unless options.truthSpp > 0
    RasterStats stats;
};

RasterResult renderRaster(const scene::SceneDesc& desc, const RasterOptions& options);

struct SweepRow {
    size_t cacheEntries = 0;
    CacheCounts ds, aas;
};

struct SweepResult {
    std::vector<SweepRow> rows;
    RasterStats ds, aas;  // full stats of each mode at the largest cache size
    Image3f dsImage, aasImage, reference, truth;
    double aasVsDsRelMse = 0, aasVsDsPsnr = 0;
    double referenceRelMseTruth = -1;
    double seconds = 0;
};

/// DS and AAS over several cache sizes, sharing one visibility pass (the images do not depend on
/// the cache size; they come from the largest).
SweepResult sweepCache(const scene::SceneDesc& desc, const RasterOptions& options, const std::vector<size_t>& cacheSizes);

/// Every sample shaded at its own point, averaged over options.truthSpp samples per pixel (seeds
/// derived from options.seed): the converged image DS, AAS and the reference approach.
Image3f renderTruth(const scene::SceneDesc& desc, const RasterOptions& options);

/// mean over pixels and channels of (x - r)^2 / (r^2 + 0.01) (NOTES.md, no factor 0.5).
double relMse(const Image3f& x, const Image3f& reference);
/// PSNR in dB of the images clamped to [0, 1] (linear radiance, exposure 1; NOTES.md).
double psnr(const Image3f& x, const Image3f& reference);

}  // namespace wedge::raster
