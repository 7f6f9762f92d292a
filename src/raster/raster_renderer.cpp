// The pipeline of raster_renderer.h: shared visibility, per-mode keys (DS pixel grid or AAS grid of
// eqs. 8-9), the LRU cache simulation in traversal order, quad shading, resolve, reference, truth
// and the cache-size sweep.
#include "raster/raster_renderer.h"

#include <unordered_set>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/memory_limit.h"
#include "core/parallel.h"
#include "core/sampler.h"
#include "raster/diffuse_shader.h"
#include "raster/shading_cache.h"
#include "raster/visibility.h"

namespace wedge::raster {

namespace {

constexpr float kCanonicalTime = 0.5f;  // shutter centre; the lens centre is the other half of the pose
constexpr uint32_t kNoRef = 0xffffffffu;

struct QuadRecord {
    uint32_t prim;
    int32_t qx, qy;
};

void validate(const scene::SceneDesc& desc, const RasterOptions& opt) {
    if (opt.spp <= 0 || opt.spp > 1024) throw Error("--spp " + std::to_string(opt.spp), "expected 1 to 1024 samples per pixel");
    if (opt.cacheEntries == 0 || opt.cacheEntries > (size_t(1) << 30))
        throw Error("--cache-entries " + std::to_string(opt.cacheEntries), "expected 1 to 2^30 entries");
    uint64_t samples = uint64_t(desc.camera.width) * desc.camera.height * opt.spp;
    if (samples >= (uint64_t(1) << 31))
        throw Error(desc.file, "resolution x spp = " + std::to_string(samples) + " samples; at most 2^31 are supported");
    if (!(opt.maxTriangleEdge >= 0)) throw Error("--split-edge", "expected a non-negative number of pixels");
    if (!(opt.cutoffs.lens > 0 && opt.cutoffs.shutter > 0 && opt.cutoffs.pixel > 0))
        throw Error("frequency cutoffs", "expected positive lens, shutter and pixel cutoffs");
    if (opt.truthSpp < 0 || opt.truthSpp > 65536)
        throw Error("--truth-spp " + std::to_string(opt.truthSpp), "expected 0 to 65536 samples per pixel");
    // The rasterizer's camera is still (its triangles' screen motion is their own velocity's);
    // a moving camera is `wedge render`'s.
    if (desc.camera.velocity != Vec3f(0.f) || desc.camera.lookAtVelocity != Vec3f(0.f))
        throw Error(desc.file + (desc.camera.velocity != Vec3f(0.f) ? ": camera.velocity" : ": camera.look_at_velocity"),
                    "wedge raster renders a still camera; a moving one is rendered by wedge render");
    // Likewise its triangles translate and do not turn.
    for (const scene::TriangleMesh& m : desc.meshes)
        if (m.turnDegrees != 0)
            throw Error(desc.file + ": " + m.name + ": angular_velocity",
                        "wedge raster moves objects by translation alone; a turning one is rendered by wedge render");
}

/// The rasterizer's memory per visibility sample: the sample (16 bytes), its place in the
/// traversal order and in the visible list (4 + 4), its shading key and sort position (12 + 4),
/// its reference to a shaded value (4), and the shaded quads and their values. Measured
/// (/usr/bin/time, cornell at 512x512, aas: 193 MB at 16 spp, 699 MB at 64 spp): 42 bytes a
/// sample; rounded up for grids finer than the pixel's, which shade more quads.
constexpr uint64_t kRasterBytesPerSample = 64;
/// The per-pixel images (the render, the reference, the truth and its sum: 12 bytes each).
constexpr uint64_t kRasterBytesPerPixel = 64;
/// A shading-cache entry (shading_cache.h): its node (24 bytes), its hash bucket and map node.
constexpr uint64_t kCacheBytesPerEntry = 64;
/// The spp of one --truth-spp pass (renderTruth): memory stays that of one pass.
constexpr int kTruthPassSpp = 64;

/// What renderRaster or sweepCache will hold at its peak against the memory limit, before the
/// scene is rasterized: the samples of the render, a --truth-spp pass's beside them, the cache.
void checkRasterMemory(const scene::SceneDesc& desc, const RasterOptions& opt, size_t cacheEntries) {
    const uint64_t pixels = uint64_t(desc.camera.width) * uint64_t(desc.camera.height);
    const uint64_t samples = pixels * uint64_t(opt.spp);
    const uint64_t truthSamples = opt.truthSpp > 0 ? pixels * uint64_t(std::min(kTruthPassSpp, opt.truthSpp)) : 0;
    const uint64_t cache = opt.shading == ShadingMode::Reference ? 0 : uint64_t(cacheEntries);
    std::string what = "a " + std::to_string(desc.camera.width) + "x" + std::to_string(desc.camera.height) + " raster at " +
                       std::to_string(opt.spp) + " spp (" + std::to_string(samples) + " samples";
    if (truthSamples) what += ", and " + std::to_string(truthSamples) + " of a --truth-spp pass";
    what += ", at " + std::to_string(kRasterBytesPerSample) + " bytes)";
    if (cache) what += " with a shading cache of " + std::to_string(cache) + " entries (--cache-entries)";
    checkMemory(desc.file, what,
                (samples + truthSamples) * kRasterBytesPerSample + pixels * kRasterBytesPerPixel + cache * kCacheBytesPerEntry);
}

SplitPolicy splitPolicy(const RasterOptions& opt) {
    SplitPolicy p;
    p.maxEdge = opt.maxTriangleEdge;
    p.minCoc = opt.cutoffs.lens / opt.cutoffs.pixel;
    p.minSpeed = opt.cutoffs.shutter / opt.cutoffs.pixel;
    return p;
}

/// The keys of one shading mode: per visible sample (in screen traversal order) its
/// (shading primitive, cell), and the order the cache meets them in.
struct ModeKeys {
    std::vector<ShadingGrid> grids;  // per shading primitive
    std::vector<CellKey> keys;       // aligned with Pipeline::m_screen
    std::vector<uint32_t> order;     // positions into keys, in traversal order
    double meanSpacingMu = 1, meanSpacingPerp = 1;
};

/// One scene's visibility, shared by every shading mode and cache size.
///
/// Shading primitives: the rasterized triangles (ids [0, n)) and the scene's unsplit triangles
/// (ids n + parent). DS keys every sample on its scene triangle, so splitting (which serves AAS's
/// bounds) changes neither its grid, nor its clamping, nor its traversal. AAS keys a sample on its
/// split triangle and that triangle's grid, except where that grid is the pixel grid: there it
/// shades exactly as DS does. A triangle whose scene triangle crosses the near plane keys on itself.
class Pipeline {
public:
    Pipeline(const scene::SceneDesc& desc, const RasterOptions& opt) : m_scene(desc, splitPolicy(opt)), m_opt(opt) {
        Timer timer;
        {
            int tiles = ((m_scene.camera.width() + kTileSize - 1) / kTileSize) *
                        ((m_scene.camera.height() + kTileSize - 1) / kTileSize);
            Progress progress("rasterize", uint64_t(tiles), opt.progress);
            m_vis = rasterize(m_scene, opt.spp, opt.seed, &progress);
        }
        m_stages.add("visibility", timer.seconds());
        timer.reset();
        m_screen.clear();
        for (uint32_t idx : screenTraversalOrder(m_vis.width, m_vis.height, m_vis.spp))
            if (m_vis.samples[idx].prim != kNoPrim) m_screen.push_back(idx);
        m_visibleOf.assign(m_scene.triangles.size(), 0);
        for (uint32_t idx : m_screen) ++m_visibleOf[m_vis.samples[idx].prim];
        // Traversal rank of a shading primitive: a scene triangle just before its first split
        // child, children in scene order, so shading primitives are met in submission order.
        size_t n = m_scene.triangles.size();
        m_rank.assign(n + m_scene.parents.size(), 0);
        std::vector<bool> seen(m_scene.parents.size(), false);
        for (size_t c = 0; c < n; ++c) {
            m_rank[c] = uint32_t(2 * c + 1);
            uint32_t p = m_scene.triangles[c].parent;
            if (!seen[p]) {
                seen[p] = true;
                m_rank[n + p] = uint32_t(2 * c);
            }
        }
        m_stages.add("traversal", timer.seconds());
        m_objects = desc.meshes.size() + desc.spheres.size();
    }

    size_t rasterCount() const { return m_scene.triangles.size(); }
    const RasterTriangle& shadingTriangle(uint32_t id) const {
        return id < rasterCount() ? m_scene.triangles[id] : m_scene.parents[id - rasterCount()];
    }
    /// A sample of a triangle without a canonical pose: shaded on its own.
    bool isFallback(uint32_t id) const { return id < rasterCount() && !m_scene.triangles[id].nearSafe; }

    ModeKeys mapSamples(ShadingMode mode) const {
        ModeKeys mk;
        size_t n = rasterCount();
        mk.grids.assign(n + m_scene.parents.size(), ShadingGrid::pixel());
        std::vector<bool> ownKey(n, false);  // keyed on the split triangle itself
        double sumMu = 0, sumPerp = 0, weight = 0;
        for (size_t i = 0; i < n; ++i) {
            const RasterTriangle& tri = m_scene.triangles[i];
            bool parentSafe = m_scene.parents[tri.parent].nearSafe;
            ownKey[i] = !parentSafe;
            double mu = 1, perp = 1;
            if (mode == ShadingMode::Adaptive && tri.nearSafe) {
                AasBounds b = aasBounds(tri, m_scene.camera, m_opt.cutoffs);
                bool pixelRate = !b.anisotropic && b.dPerp >= 1.f;
                if (!pixelRate) {
                    ownKey[i] = true;
                    mk.grids[i] = ShadingGrid::fromBounds(b);
                    // Below the pixel rate the lattice is free: start it at the triangle's corner
                    // so that a small triangle touches as few quads as it can.
                    if (m_opt.alignGrid) mk.grids[i].alignTo(tri);
                    Vec2f a = mk.grids[i].stepA(), c = mk.grids[i].stepB();
                    mu = std::hypot(a.x, a.y);
                    perp = std::hypot(c.x, c.y);
                }
            }
            if (!tri.nearSafe) continue;
            sumMu += mu * double(m_visibleOf[i]);
            sumPerp += perp * double(m_visibleOf[i]);
            weight += double(m_visibleOf[i]);
        }
        mk.meanSpacingMu = weight > 0 ? sumMu / weight : 1;
        mk.meanSpacingPerp = weight > 0 ? sumPerp / weight : 1;

        mk.keys.resize(m_screen.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, m_screen.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i) {
                const VisibilitySample& vs = m_vis.samples[m_screen[i]];
                const RasterTriangle& tri = m_scene.triangles[vs.prim];
                if (!tri.nearSafe) {
                    mk.keys[i] = {vs.prim, 0, 0};
                    continue;
                }
                uint32_t id = ownKey[vs.prim] ? vs.prim : uint32_t(n + tri.parent);
                Vec2f g = mk.grids[id].toGrid(tri.canonicalScreen(vs.bary()));
                mk.keys[i] = {id, floorToInt(g.x), floorToInt(g.y)};
            }
        });

        // Counting sort by the rank of the shading primitive; stable, so screen order within.
        std::vector<uint64_t> offset(m_rank.size() * 2 + 2, 0);
        for (const CellKey& k : mk.keys) ++offset[m_rank[k.prim] + 1];
        for (size_t i = 1; i < offset.size(); ++i) offset[i] += offset[i - 1];
        mk.order.resize(mk.keys.size());
        for (size_t i = 0; i < mk.keys.size(); ++i) mk.order[offset[m_rank[mk.keys[i].prim]]++] = uint32_t(i);
        return mk;
    }

    /// Runs the cache over the keys in traversal order. With `quads` and `refs` it records the
    /// shaded quads and, per sample index, the quad lane (4 quad + lane) holding its value.
    CacheCounts simulate(const ModeKeys& mk, size_t entries, std::vector<QuadRecord>* quads,
                         std::vector<uint32_t>* refs) const {
        CacheCounts c;
        c.shadedQuadsPerObject.assign(m_objects, 0);
        LruShadingCache cache(entries);
        if (refs) refs->assign(m_vis.samples.size(), kNoRef);
        for (uint32_t pos : mk.order) {
            const CellKey& key = mk.keys[pos];
            uint32_t sample = m_screen[pos];
            ++c.lookups;
            const RasterTriangle& tri = shadingTriangle(key.prim);
            if (isFallback(key.prim)) {  // no shading space: shaded on its own
                ++c.misses;
                ++c.shadedQuads;
                ++c.shadedQuadsPerObject[tri.mesh];
                continue;
            }
            if (const uint32_t* payload = cache.lookup(key)) {
                ++c.hits;
                if (refs) (*refs)[sample] = *payload;
                continue;
            }
            ++c.misses;
            ++c.shadedQuadsPerObject[tri.mesh];
            uint32_t quad = uint32_t(c.shadedQuads++);
            int32_t qx = floorDiv2(key.x), qy = floorDiv2(key.y);
            if (quads) quads->push_back({key.prim, qx, qy});
            int missLane = (key.x - 2 * qx) + 2 * (key.y - 2 * qy);
            for (int lane = 0; lane < 4; ++lane)
                if (lane != missLane)
                    cache.insert({key.prim, 2 * qx + (lane & 1), 2 * qy + (lane >> 1)}, 4 * quad + uint32_t(lane));
            cache.insert(key, 4 * quad + uint32_t(missLane));
            if (refs) (*refs)[sample] = 4 * quad + uint32_t(missLane);
        }
        c.shaderInvocations = 4 * c.shadedQuads;
        c.evictions = cache.evictions();
        return c;
    }

    uint64_t distinctQuads(const ModeKeys& mk) const {
        std::unordered_set<CellKey, CellKeyHash> seen;
        seen.reserve(mk.keys.size() / 4 + 16);
        uint64_t fallback = 0;
        for (const CellKey& k : mk.keys) {
            if (isFallback(k.prim)) {
                ++fallback;
                continue;
            }
            seen.insert({k.prim, floorDiv2(k.x), floorDiv2(k.y)});
        }
        return seen.size() + fallback;
    }

    std::vector<Vec3f> shadeQuads(const std::vector<QuadRecord>& quads, const std::vector<ShadingGrid>& grids) const {
        // A quad's four cell centres, clamped into its shading primitive, shaded at the canonical
        // pose with the texture filtered over the grid's cell.
        std::vector<Vec3f> values(quads.size() * 4);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, quads.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t q = r.begin(); q < r.end(); ++q) {
                const QuadRecord& rec = quads[q];
                const RasterTriangle& tri = shadingTriangle(rec.prim);
                for (int lane = 0; lane < 4; ++lane) {
                    ShadingPoint sp = cellShadingPoint(tri, grids[rec.prim], 2 * rec.qx + (lane & 1), 2 * rec.qy + (lane >> 1));
                    Vec3f footA, footB;
                    worldFootprint(tri, m_scene.camera, kCanonicalTime, sp.screen, sp.stepA, sp.stepB, footA, footB);
                    values[4 * q + lane] = shadeSurface(m_scene, tri, sp.bary, kCanonicalTime, footA, footB);
                }
            }
        });
        return values;
    }

    /// Shades a sample at its own surface point (the reference), textures filtered over one pixel
    /// of the canonical pose like DS; a triangle without a canonical pose is shaded at the sample's
    /// own time.
    Vec3f shadeOwnSample(uint32_t idx) const {
        const VisibilitySample& vs = m_vis.samples[idx];
        const RasterTriangle& tri = m_scene.triangles[vs.prim];
        Vec3f bary = vs.bary(), footA, footB;
        if (tri.nearSafe) {
            worldFootprint(tri, m_scene.camera, kCanonicalTime, tri.canonicalScreen(bary), {1, 0}, {0, 1}, footA, footB);
            return shadeSurface(m_scene, tri, bary, kCanonicalTime, footA, footB);
        }
        int pixel = int(idx / uint32_t(m_vis.spp)), s = int(idx % uint32_t(m_vis.spp));
        SamplePoint sp = samplePoint(m_vis.seed, m_vis.width, pixel % m_vis.width, pixel / m_vis.width, uint32_t(s));
        worldFootprint(tri, m_scene.camera, sp.tau, {sp.px, sp.py}, {1, 0}, {0, 1}, footA, footB);
        return shadeSurface(m_scene, tri, bary, sp.tau, footA, footB);
    }

    /// Box-filters the samples of each pixel; `value(idx)` gives a visible sample's radiance.
    template <class Value>
    Image3f resolve(Value&& value) const {
        Image3f img(m_vis.width, m_vis.height, Vec3f(0.f));
        parallelRows(m_vis.height, [&](int y) {
            for (int x = 0; x < m_vis.width; ++x) {
                Vec3f sum(0.f);
                for (int s = 0; s < m_vis.spp; ++s) {
                    uint32_t idx = uint32_t(m_vis.index(x, y, s));
                    if (m_vis.samples[idx].prim != kNoPrim) sum += value(idx);
                }
                img(x, y) = sum / float(m_vis.spp);
            }
        });
        return img;
    }

    Image3f referenceImage() const {
        return resolve([&](uint32_t idx) { return shadeOwnSample(idx); });
    }

    /// A decoupled mode at one cache size: counts, image and stats.
    RasterResult renderDecoupled(ShadingMode mode, size_t entries) const {
        RasterResult r;
        StageTimes stages;
        Timer timer;
        ModeKeys mk = mapSamples(mode);
        stages.add("mapping", timer.seconds());
        timer.reset();
        std::vector<QuadRecord> quads;
        std::vector<uint32_t> refs;
        CacheCounts counts = simulate(mk, entries, &quads, &refs);
        stages.add("cache", timer.seconds());
        timer.reset();
        std::vector<Vec3f> values = shadeQuads(quads, mk.grids);
        stages.add("shading", timer.seconds());
        timer.reset();
        r.image = resolve([&](uint32_t idx) {
            return refs[idx] != kNoRef ? values[refs[idx]] : shadeOwnSample(idx);  // kNoRef: near-plane fallback
        });
        stages.add("resolve", timer.seconds());
        r.stats = baseStats(mode, entries);
        r.stats.cache = counts;
        r.stats.meanSpacingMu = mk.meanSpacingMu;
        r.stats.meanSpacingPerp = mk.meanSpacingPerp;
        r.stats.quadsUnboundedCache = distinctQuads(mk);
        for (auto& [name, s] : stages.stages()) r.stats.stages.add(name, s);
        r.stats.seconds = 0;
        for (auto& [name, s] : r.stats.stages.stages()) r.stats.seconds += s;
        return r;
    }

    RasterResult renderReference() const {
        RasterResult r;
        Timer timer;
        r.image = referenceImage();
        r.stats = baseStats(ShadingMode::Reference, 0);
        r.stats.stages.add("shading", timer.seconds());
        r.stats.cache.lookups = m_screen.size();
        r.stats.cache.shaderInvocations = m_screen.size();
        r.stats.cache.shadedQuads = (m_screen.size() + 3) / 4;  // lanes packed four to a quad
        r.stats.quadsUnboundedCache = r.stats.cache.shadedQuads;
        r.stats.relMse = 0;
        for (auto& [name, s] : r.stats.stages.stages()) r.stats.seconds += s;
        return r;
    }

    RasterStats baseStats(ShadingMode mode, size_t entries) const {
        RasterStats s;
        s.shading = mode;
        s.cacheEntries = entries;
        s.width = m_vis.width;
        s.height = m_vis.height;
        s.spp = m_vis.spp;
        s.triangles = m_scene.triangles.size();
        s.culledTriangles = m_scene.culledTriangles;
        s.splitBudgetReached = m_scene.splitBudgetReached;
        s.maxTriangleEdge = m_opt.maxTriangleEdge;
        for (size_t i = 0; i < m_scene.triangles.size(); ++i)
            if (!m_scene.triangles[i].nearSafe) {
                ++s.fallbackTriangles;
                s.fallbackSamples += m_visibleOf[i];
            }
        s.samples = m_vis.samples.size();
        s.visibleSamples = m_vis.visibleSamples;
        s.sampleTests = m_vis.sampleTests;
        s.boundRejects = m_vis.boundRejects;
        for (auto& [name, sec] : m_stages.stages()) s.stages.add(name, sec);
        return s;
    }

private:
    RasterScene m_scene;
    RasterOptions m_opt;
    VisibilityBuffer m_vis;
    std::vector<uint32_t> m_screen;      // visible sample indices in screen traversal order
    std::vector<uint32_t> m_rank;        // traversal rank per shading primitive
    std::vector<uint64_t> m_visibleOf;   // visible samples per rasterized triangle
    StageTimes m_stages;                 // visibility and traversal, shared by every mode
    size_t m_objects = 0;
};

}  // namespace

std::string shadingModeName(ShadingMode mode) {
    switch (mode) {
        case ShadingMode::Reference: return "reference";
        case ShadingMode::Decoupled: return "ds";
        case ShadingMode::Adaptive: return "aas";
    }
    return "?";
}

ShadingMode parseShadingMode(const std::string& name, const std::string& where) {
    if (name == "ds") return ShadingMode::Decoupled;
    if (name == "aas") return ShadingMode::Adaptive;
    if (name == "reference") return ShadingMode::Reference;
    throw Error(where, "unknown shading mode '" + name + "' (expected ds, aas or reference)");
}

double relMse(const Image3f& x, const Image3f& reference) {
    if (!x.sameSize(reference) || x.empty()) throw Error("relMSE", "image size mismatch");
    double sum = 0;  // sequential: the same value for any thread count
    for (size_t i = 0; i < x.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            double d = double(x[i][c]) - double(reference[i][c]);
            sum += d * d / (double(reference[i][c]) * reference[i][c] + 0.01);
        }
    return sum / (3.0 * double(x.size()));
}

double psnr(const Image3f& x, const Image3f& reference) {
    if (!x.sameSize(reference) || x.empty()) throw Error("PSNR", "image size mismatch");
    double sum = 0;
    for (size_t i = 0; i < x.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            double d = std::clamp(double(x[i][c]), 0.0, 1.0) - std::clamp(double(reference[i][c]), 0.0, 1.0);
            sum += d * d;
        }
    double mse = sum / (3.0 * double(x.size()));
    return mse > 0 ? 10.0 * std::log10(1.0 / mse) : 99.0;
}

RasterResult renderRaster(const scene::SceneDesc& desc, const RasterOptions& options) {
    validate(desc, options);
    checkRasterMemory(desc, options, options.cacheEntries);
    Timer total;
    Pipeline pipeline(desc, options);
    RasterResult r = options.shading == ShadingMode::Reference
                         ? pipeline.renderReference()
                         : pipeline.renderDecoupled(options.shading, options.cacheEntries);
    r.stats.seconds = total.seconds();
    if (options.computeReference && options.shading != ShadingMode::Reference) {
        Timer t;
        r.reference = pipeline.referenceImage();
        r.stats.relMse = relMse(r.image, r.reference);
        r.stats.psnr = psnr(r.image, r.reference);
        r.stats.referenceSeconds = t.seconds();
    }
    if (options.truthSpp > 0) {
        Timer t;
        r.truth = renderTruth(desc, options);
        r.stats.relMseTruth = relMse(r.image, r.truth);
        r.stats.truthSeconds = t.seconds();
    }
    return r;
}

Image3f renderTruth(const scene::SceneDesc& desc, const RasterOptions& options) {
    // Passes of at most 64 spp with their own seeds, averaged: memory stays that of one pass.
    constexpr int kPassSpp = 64;
    Image3f sum(desc.camera.width, desc.camera.height, Vec3f(0.f));
    int done = 0;
    for (int pass = 0; done < options.truthSpp; ++pass) {
        RasterOptions o = options;
        o.spp = std::min(kPassSpp, options.truthSpp - done);
        o.seed = hashCombine(options.seed, 0x7275u + uint32_t(pass));
        o.progress = false;
        validate(desc, o);
        Pipeline p(desc, o);
        Image3f img = p.referenceImage();
        for (size_t i = 0; i < sum.size(); ++i) sum[i] += img[i] * float(o.spp);
        done += o.spp;
    }
    for (size_t i = 0; i < sum.size(); ++i) sum[i] = sum[i] / float(done);
    return sum;
}

SweepResult sweepCache(const scene::SceneDesc& desc, const RasterOptions& options, const std::vector<size_t>& cacheSizes) {
    if (cacheSizes.empty()) throw Error("--sweep-cache", "expected at least one cache size");
    size_t largest = 0;
    for (size_t k : cacheSizes) {
        RasterOptions o = options;
        o.cacheEntries = k;
        validate(desc, o);
        largest = std::max(largest, k);
    }
    {
        RasterOptions o = options;
        o.shading = ShadingMode::Decoupled;  // the sweep runs both decoupled modes
        checkRasterMemory(desc, o, largest);
    }
    Timer total;
    Pipeline pipeline(desc, options);
    SweepResult sweep;
    sweep.rows.resize(cacheSizes.size());
    for (size_t i = 0; i < cacheSizes.size(); ++i) sweep.rows[i].cacheEntries = cacheSizes[i];
    for (ShadingMode mode : {ShadingMode::Decoupled, ShadingMode::Adaptive}) {
        RasterResult full = pipeline.renderDecoupled(mode, largest);
        ModeKeys mk = pipeline.mapSamples(mode);
        for (size_t i = 0; i < cacheSizes.size(); ++i) {
            CacheCounts c = cacheSizes[i] == largest ? full.stats.cache : pipeline.simulate(mk, cacheSizes[i], nullptr, nullptr);
            (mode == ShadingMode::Decoupled ? sweep.rows[i].ds : sweep.rows[i].aas) = c;
        }
        (mode == ShadingMode::Decoupled ? sweep.dsImage : sweep.aasImage) = std::move(full.image);
        (mode == ShadingMode::Decoupled ? sweep.ds : sweep.aas) = full.stats;
    }
    sweep.reference = pipeline.referenceImage();
    sweep.ds.relMse = relMse(sweep.dsImage, sweep.reference);
    sweep.aas.relMse = relMse(sweep.aasImage, sweep.reference);
    sweep.ds.psnr = psnr(sweep.dsImage, sweep.reference);
    sweep.aas.psnr = psnr(sweep.aasImage, sweep.reference);
    sweep.aasVsDsRelMse = relMse(sweep.aasImage, sweep.dsImage);
    sweep.aasVsDsPsnr = psnr(sweep.aasImage, sweep.dsImage);
    if (options.truthSpp > 0) {
        sweep.truth = renderTruth(desc, options);
        sweep.ds.relMseTruth = relMse(sweep.dsImage, sweep.truth);
        sweep.aas.relMseTruth = relMse(sweep.aasImage, sweep.truth);
        sweep.referenceRelMseTruth = relMse(sweep.reference, sweep.truth);
    }
    sweep.seconds = total.seconds();
    return sweep;
}

}  // namespace wedge::raster
