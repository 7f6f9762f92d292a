// Raster module: the stochastic rasterizer with decoupled (DS) and adaptive anisotropic (AAS)
// shading. Properties from the issue: a static in-focus scene gives the same image with DS and
// AAS; AAS shading cost falls as blur grows; cache counts match a hand-counted case; the
// reference (every sample shaded) agrees with DS within the texture-filtering tolerance. Plus the
// pieces: the LRU cache, the frequency bounds of eqs. 8-9, the clamp, the filtered checker, the
// polygon irradiance, determinism, and the command line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/parallel.h"
#include "raster/checker_texture.h"
#include "raster/diffuse_shader.h"
#include "raster/raster_renderer.h"
#include "raster/shading_cache.h"
#include "test_util.h"

using namespace wedge;
using namespace wedge::raster;

namespace {

/// A checkered quad facing the camera at depth `depth` in front of a checkered back wall, lit from
/// the camera side. The quad moves by `velocity` over the shutter; the lens has radius `aperture`
/// and focuses at `focus`.
scene::SceneDesc testScene(int size, Vec3f velocity, float aperture, float focus, bool withWall = true) {
    const float depth = 3.f;
    scene::SceneDesc d;
    d.file = "test";
    d.camera.position = {0, 0, 0};
    d.camera.lookAt = {0, 0, -1};
    d.camera.up = {0, 1, 0};
    d.camera.fovY = 40;
    d.camera.width = d.camera.height = size;
    d.camera.apertureRadius = aperture;
    d.camera.focusDistance = focus;
    scene::Material quad{"quad", Vec3f(0.8f, 0.6f, 0.4f), Vec3f(0.f), "checker", 6.f, nullptr};
    scene::Material wall{"wall", Vec3f(0.5f, 0.6f, 0.8f), Vec3f(0.f), "checker", 3.f, nullptr};
    d.materials = {quad, wall};
    d.lights.push_back({{-2, 2, 1}, {0, 0, -1}, {4, 0, 0}, Vec3f(4.f)});  // faces -y, above the camera
    d.lights.push_back({{-2, -2, 0.5f}, {4, 0, 0}, {0, 4, 0}, Vec3f(1.f)});  // faces +z, towards the scene
    scene::TriangleMesh m;
    scene::appendQuad(m, {-0.6f, -0.6f, -depth}, {1.2f, 0, 0}, {0, 1.2f, 0}, 0);
    m.velocity = velocity;
    d.meshes.push_back(m);
    if (withWall) {
        scene::TriangleMesh w;
        scene::appendQuad(w, {-6, -6, -8}, {12, 0, 0}, {0, 12, 0}, 1);
        d.meshes.push_back(w);
    }
    return d;
}

RasterOptions opts(ShadingMode mode, size_t entries, int spp = 4) {
    RasterOptions o;
    o.shading = mode;
    o.cacheEntries = entries;
    o.spp = spp;
    o.seed = 3;
    return o;
}

double maxAbsDiff(const Image3f& a, const Image3f& b) {
    double m = 0;
    for (size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) m = std::max(m, double(std::abs(a[i][c] - b[i][c])));
    return m;
}

/// A small motion + defocus scene file for the command-line tests.
std::string writeTinySceneFile() {
    std::string dir = test::tempDir();
    std::string path = dir + "/tiny.json";
    test::writeFile(path, R"({
  "camera": {"position": [0, 0.5, 3], "look_at": [0, 0.3, 0], "up": [0, 1, 0], "fov_y": 45,
             "resolution": [32, 24], "aperture_radius": 0.05, "focus_distance": 3},
  "materials": {"c": {"albedo": [0.8, 0.7, 0.6], "texture": "checker", "texture_scale": 4}},
  "lights": [{"type": "parallelogram", "corner": [-1, 3, -1], "edge1": [2, 0, 0], "edge2": [0, 0, 2],
              "radiance": [5, 5, 5]}],
  "objects": [
    {"type": "quad", "corner": [-3, 0, 2], "edge1": [6, 0, 0], "edge2": [0, 0, -5], "material": "c"},
    {"type": "box", "min": [-0.4, 0, -0.4], "max": [0.4, 0.8, 0.4], "material": "c", "velocity": [0.3, 0, 0]}
  ]
})");
    return path;
}

}  // namespace

// --- The issue's four properties --------------------------------------------------------------

TEST(Raster, StaticInFocusSceneGivesTheSameImageWithDsAndAas) {
    scene::SceneDesc d = testScene(48, Vec3f(0.f), 0.f, 3.f);
    RasterResult ds = renderRaster(d, opts(ShadingMode::Decoupled, 256));
    RasterResult aas = renderRaster(d, opts(ShadingMode::Adaptive, 256));
    EXPECT_EQ(maxAbsDiff(ds.image, aas.image), 0.0);
    EXPECT_EQ(ds.stats.cache.shadedQuads, aas.stats.cache.shadedQuads);
    EXPECT_EQ(ds.stats.cache.hits, aas.stats.cache.hits);
    EXPECT_DOUBLE_EQ(aas.stats.meanSpacingMu, 1.0);
    EXPECT_DOUBLE_EQ(aas.stats.meanSpacingPerp, 1.0);
}

TEST(Raster, AasShadingCostFallsAsBlurGrows) {
    // Motion: the quad (alone) moves sideways, more and more; a cache big enough to hold
    // everything, so that the counts measure the shading rate alone.
    std::vector<uint64_t> aasQuads, dsQuads;
    for (float v : {0.f, 0.3f, 0.6f, 1.2f}) {
        scene::SceneDesc d = testScene(48, {v, 0, 0}, 0.f, 3.f, false);
        aasQuads.push_back(renderRaster(d, opts(ShadingMode::Adaptive, 1 << 16)).stats.cache.shadedQuads);
        dsQuads.push_back(renderRaster(d, opts(ShadingMode::Decoupled, 1 << 16)).stats.cache.shadedQuads);
    }
    for (size_t i = 1; i < aasQuads.size(); ++i) EXPECT_LT(aasQuads[i], aasQuads[i - 1]) << "motion step " << i;
    EXPECT_LT(double(aasQuads.back()), 0.5 * double(dsQuads.back()));
    EXPECT_GT(double(dsQuads.back()), 0.8 * double(dsQuads.front())) << "DS shades at the pixel rate whatever the blur";

    // Defocus: the quad stays at depth 3, the focus moves away from it.
    std::vector<uint64_t> defocus;
    for (float aperture : {0.f, 0.1f, 0.2f, 0.4f}) {
        scene::SceneDesc d = testScene(48, Vec3f(0.f), aperture, 8.f, false);
        defocus.push_back(renderRaster(d, opts(ShadingMode::Adaptive, 1 << 16)).stats.cache.shadedQuads);
    }
    for (size_t i = 1; i < defocus.size(); ++i) EXPECT_LT(defocus[i], defocus[i - 1]) << "aperture step " << i;
}

TEST(Raster, CacheCountsMatchAHandCountedTinyCase) {
    // One triangle covers the whole 4x4 image (static, pinhole), so each of a pixel's 4 samples
    // maps to the cell of its pixel and each 2x2 leaf block of the traversal is one shading quad.
    // Per leaf (pixels = lanes 0..3, in order): a miss inserts the quad's other cells, then the
    // missed one.
    //   K = 1: only the missed cell stays: every pixel misses once      -> 16 misses, 48 hits.
    //   K = 2: lane 0 misses, keeps {0, 3}; lane 1 misses, keeps {1, 3}; lane 2 misses, keeps
    //          {2, 3}; lane 3 hits                                       -> 12 misses, 52 hits.
    //   K = 3: lane 0 misses, keeps {0, 3, 2}; lane 1 misses, keeps {1, 3, 2}; lanes 2, 3 hit
    //                                                                    ->  8 misses, 56 hits.
    //   K = 4: one miss per leaf                                         ->  4 misses, 60 hits.
    scene::SceneDesc d;
    d.file = "tiny";
    d.camera.position = {0, 0, 1};
    d.camera.lookAt = {0, 0, 0};
    d.camera.up = {0, 1, 0};
    d.camera.fovY = 90;
    d.camera.width = d.camera.height = 4;
    d.materials.push_back({"white", Vec3f(0.5f), Vec3f(0.f), "", 1.f, nullptr});
    d.lights.push_back({{-1, -1, 3}, {2, 0, 0}, {0, -2, 0}, Vec3f(1.f)});
    scene::TriangleMesh m;
    m.positions = {{-1.5f, -1.5f, 0}, {4, -1.5f, 0}, {-1.5f, 4, 0}};
    m.indices = {0, 1, 2};
    m.materialIds = {0};
    d.meshes.push_back(m);
    struct Expect {
        size_t k;
        uint64_t misses, hits;
    };
    for (Expect e : {Expect{1, 16, 48}, Expect{2, 12, 52}, Expect{3, 8, 56}, Expect{4, 4, 60}, Expect{64, 4, 60}}) {
        RasterOptions o = opts(ShadingMode::Decoupled, e.k, 4);
        o.maxTriangleEdge = 0;
        RasterResult r = renderRaster(d, o);
        EXPECT_EQ(r.stats.visibleSamples, 64u);
        EXPECT_EQ(r.stats.cache.misses, e.misses) << "K = " << e.k;
        EXPECT_EQ(r.stats.cache.hits, e.hits) << "K = " << e.k;
        EXPECT_EQ(r.stats.cache.shadedQuads, e.misses) << "K = " << e.k;
        EXPECT_EQ(r.stats.cache.shaderInvocations, 4 * e.misses) << "K = " << e.k;
        EXPECT_EQ(r.stats.quadsUnboundedCache, 4u);
    }
}

TEST(Raster, ReferenceAgreesWithDsWithinTextureFilteringTolerance) {
    // Motion and defocus. DS shades each cell at its (clamped) centre; the reference shades each
    // sample at its own point with the same one-pixel texture filter. They differ only where a
    // pixel-sized step of the filtered checker lands, which the blur averages out.
    scene::SceneDesc d = testScene(48, {0.3f, 0.1f, 0}, 0.06f, 5.f);
    RasterResult ds = renderRaster(d, opts(ShadingMode::Decoupled, 1024, 8));
    ASSERT_FALSE(ds.reference.empty());
    EXPECT_LT(ds.stats.relMse, 2e-3);
    EXPECT_GT(ds.stats.relMse, 0.0);
    RasterResult ref = renderRaster(d, opts(ShadingMode::Reference, 1, 8));
    EXPECT_EQ(maxAbsDiff(ref.image, ds.reference), 0.0);
    // AAS band-limits the texture to its coarser grid: further from the reference, still close.
    RasterResult aas = renderRaster(d, opts(ShadingMode::Adaptive, 1024, 8));
    EXPECT_LT(aas.stats.relMse, 3e-3);
    EXPECT_LT(aas.stats.cache.shadedQuads, ds.stats.cache.shadedQuads);
}

// --- Determinism ------------------------------------------------------------------------------

TEST(Raster, ImageDoesNotDependOnCacheSizeOrThreadCount) {
    scene::SceneDesc d = testScene(40, {0.4f, 0, 0}, 0.05f, 5.f);
    RasterOptions small = opts(ShadingMode::Adaptive, 16), big = opts(ShadingMode::Adaptive, 4096);
    small.computeReference = big.computeReference = false;
    RasterResult a = renderRaster(d, small), b = renderRaster(d, big);
    EXPECT_EQ(maxAbsDiff(a.image, b.image), 0.0);
    EXPECT_GE(a.stats.cache.shadedQuads, b.stats.cache.shadedQuads);
    RasterResult c;
    {
        ThreadLimit one(1);
        c = renderRaster(d, small);
    }
    EXPECT_EQ(maxAbsDiff(a.image, c.image), 0.0);
    EXPECT_EQ(a.stats.cache.shadedQuads, c.stats.cache.shadedQuads);
    EXPECT_EQ(a.stats.sampleTests, c.stats.sampleTests);
}

TEST(Raster, VelocityIsPerUnitOfShutterTime) {
    // An object moves by velocity x (close - open) over the shutter (scene_desc.h), as in the
    // ray tracer: half the shutter at the full velocity is the whole shutter at half of it, and
    // a shutter that opens later is the same shutter.
    scene::SceneDesc full = testScene(32, {0.6f, 0, 0}, 0.f, 3.f), half = full, later = full, slow = testScene(32, {0.3f, 0, 0}, 0.f, 3.f);
    half.camera.shutterClose = 0.5f;
    later.camera.shutterOpen = 2.f;
    later.camera.shutterClose = 3.f;
    RasterOptions o = opts(ShadingMode::Adaptive, 256);
    o.computeReference = false;
    const Image3f a = renderRaster(full, o).image;
    EXPECT_EQ(maxAbsDiff(renderRaster(half, o).image, renderRaster(slow, o).image), 0.0);
    EXPECT_EQ(maxAbsDiff(renderRaster(later, o).image, a), 0.0);
    EXPECT_GT(maxAbsDiff(renderRaster(half, o).image, a), 0.02) << "the shutter's length was ignored before";
}

TEST(Raster, DsDoesNotDependOnTheTessellationAasUses) {
    // Splitting serves AAS's per-primitive bounds; DS keys every sample on the scene's triangle, so
    // its counts and image stay those of the unsplit scene (up to float rounding at cell borders).
    scene::SceneDesc d = testScene(48, {0.4f, 0.1f, 0}, 0.08f, 5.f);
    RasterOptions whole = opts(ShadingMode::Decoupled, 256), split = whole;
    whole.maxTriangleEdge = 0;
    split.maxTriangleEdge = 6;
    RasterResult a = renderRaster(d, whole), b = renderRaster(d, split);
    EXPECT_GT(b.stats.triangles, 4 * a.stats.triangles);
    EXPECT_NEAR(double(b.stats.cache.shadedQuads), double(a.stats.cache.shadedQuads), 0.01 * double(a.stats.cache.shadedQuads));
    EXPECT_LT(relMse(b.image, a.image), 1e-4);
}

TEST(Raster, TheSplitStopsAtItsBudget) {
    // A quad with an edge in depth that sweeps 400 units sideways over the shutter: at
    // mid-shutter (the canonical image) it is far off screen, where its depth edge projects
    // thousands of pixels long, so every child splits to the level limit (the scene's triangle
    // 4^8 times). The budget stops the split (it was 979K triangles and 2.9 GB on
    // motion_defocus); the same quad moving slowly splits as before, within the budget.
    auto sweeping = [](float speed) {
        scene::SceneDesc d = testScene(64, Vec3f(0.f), 0.f, 3.f, false);
        d.meshes.clear();
        for (int i = 0; i < 32; ++i) {
            scene::TriangleMesh m;
            scene::appendQuad(m, {-0.6f + 0.03f * float(i), -0.6f, -3}, {1.2f, 0, 0}, {0, 0.3f, -1.2f}, 0);
            m.velocity = {speed, 0, 0};
            d.meshes.push_back(m);
        }
        return d;
    };
    SplitPolicy policy;
    RasterScene fast(sweeping(400.f), policy), slow(sweeping(0.5f), policy);
    EXPECT_TRUE(fast.splitBudgetReached);
    EXPECT_GE(fast.triangles.size(), kMaxSplitTriangles);
    const size_t subtree = size_t(1) << (2 * kMaxSplits);  // one scene triangle split to the limit
    EXPECT_LE(fast.triangles.size(), kMaxSplitTriangles + subtree);
    EXPECT_FALSE(slow.splitBudgetReached);
    EXPECT_GT(slow.triangles.size(), slow.parents.size());  // split, as blurred and 35 px long
    EXPECT_LT(slow.triangles.size(), 16 * slow.parents.size());
}

TEST(Raster, NearPlaneCrossingGeometryKeepsItsSamples) {
    // A floor that runs behind the camera crosses the near plane; the same floor cut just in front
    // of the camera does not. The clipped bounds must not lose a sample, and the reference shading
    // does not depend on how the floor was split.
    auto floorScene = [](float zNear) {
        scene::SceneDesc d = testScene(32, Vec3f(0.f), 0.f, 3.f, false);
        d.meshes.clear();
        scene::TriangleMesh m;
        scene::appendQuad(m, {-4, -1, zNear}, {0, 0, -20 - zNear}, {8, 0, 0}, 0);
        d.meshes.push_back(m);
        return d;
    };
    RasterOptions o = opts(ShadingMode::Reference, 1, 4);
    RasterResult crossing = renderRaster(floorScene(5.f), o), cut = renderRaster(floorScene(-0.01f), o);
    EXPECT_GT(crossing.stats.visibleSamples, 1000u);
    EXPECT_EQ(crossing.stats.visibleSamples, cut.stats.visibleSamples);
    EXPECT_LT(maxAbsDiff(crossing.image, cut.image), 1e-4);
    EXPECT_LT(crossing.stats.sampleTests, 4 * crossing.stats.samples) << "bounds of the clipped floor stay tight";
}

// --- Pieces -----------------------------------------------------------------------------------

TEST(RasterCamera, LensShearMatchesTheThinLensRay) {
    // A point seen from lens point (lu, lv) lands at (x0 + phi lu, y0 - phi lv): the ray from that
    // lens point through the film position must pass through the point.
    scene::CameraDesc cd;
    cd.position = {0.3f, 0.2f, 4};
    cd.lookAt = {0, 0, 0};
    cd.width = 64;
    cd.height = 48;
    cd.apertureRadius = 0.2f;
    cd.focusDistance = 3.f;
    RasterCamera cam(cd);
    Vec3f p = cam.toCamera({0.4f, -0.3f, 0.5f});
    for (Vec2f lens : {Vec2f{0.5f, -0.25f}, Vec2f{-0.8f, 0.1f}}) {
        Vec2f s0 = cam.project(p);
        float phi = cam.circleOfConfusion(p.z);
        Vec3f origin, dir;
        cam.ray(s0.x + phi * lens.x, s0.y - phi * lens.y, lens.x, lens.y, origin, dir);
        float t = (p.z - origin.z) / dir.z;
        Vec3f q = origin + dir * t;
        EXPECT_NEAR(q.x, p.x, 1e-4f);
        EXPECT_NEAR(q.y, p.y, 1e-4f);
    }
}

TEST(RasterCache, EvictsLeastRecentlyUsed) {
    LruShadingCache cache(2);
    CellKey a{0, 0, 0}, b{0, 1, 0}, c{1, 0, 0};
    EXPECT_EQ(cache.lookup(a), nullptr);
    cache.insert(a, 10);
    cache.insert(b, 11);
    ASSERT_NE(cache.lookup(a), nullptr);  // a is now the most recently used
    cache.insert(c, 12);                  // evicts b
    EXPECT_EQ(cache.lookup(b), nullptr);
    ASSERT_NE(cache.lookup(a), nullptr);
    EXPECT_EQ(*cache.lookup(a), 10u);
    EXPECT_EQ(*cache.lookup(c), 12u);
    cache.insert(a, 20);  // refresh, no eviction
    EXPECT_EQ(*cache.lookup(a), 20u);
    EXPECT_EQ(cache.size(), 2u);
    EXPECT_EQ(cache.evictions(), 1u);
}

TEST(RasterAas, BoundsFollowEquations8And9) {
    FrequencyCutoffs cut;
    // Static, pinhole: the square box 2r = 2 Omega_R = 1, i.e. the pixel grid.
    {
        RasterScene s(testScene(64, Vec3f(0.f), 0.f, 3.f), SplitPolicy{0.f, 0.f, 0.f});
        AasBounds b = aasBounds(s.triangles[0], s.camera, cut);
        EXPECT_FLOAT_EQ(b.dMu, 1.f);
        EXPECT_FLOAT_EQ(b.dPerp, 1.f);
        EXPECT_FALSE(b.anisotropic);
    }
    // Pure sideways motion at constant depth: every vertex moves by the same mu, theta-hat = 0,
    // so d_mu = 2 Omega_S' = 2 Omega_S / ||mu|| (eq. 7), d_perp = 2r = 1, e_mu along x.
    {
        RasterScene s(testScene(64, {0.5f, 0, 0}, 0.f, 3.f), SplitPolicy{0.f, 0.f, 0.f});
        const RasterTriangle& t = s.triangles[0];
        float mu = s.camera.project(t.p[0] + t.motion).x - s.camera.project(t.p[0]).x;
        AasBounds b = aasBounds(t, s.camera, cut);
        EXPECT_NEAR(b.speedMin, mu, 1e-3f);
        EXPECT_NEAR(b.halfSpan, 0.f, 1e-5f);
        EXPECT_NEAR(b.dMu, 2.f * cut.shutter / mu, 1e-5f);
        EXPECT_FLOAT_EQ(b.dPerp, 1.f);
        EXPECT_NEAR(std::abs(b.eMu.x), 1.f, 1e-6f);
        EXPECT_TRUE(b.anisotropic);
        ShadingGrid g = ShadingGrid::fromBounds(b);
        EXPECT_NEAR(std::hypot(g.stepA().x, g.stepA().y), mu / (2.f * cut.shutter), 1e-3f);
    }
    // Defocus only, all of the quad behind the focus plane: r = Omega_A / phi_min.
    {
        RasterScene s(testScene(64, Vec3f(0.f), 0.1f, 1.f), SplitPolicy{0.f, 0.f, 0.f});
        const RasterTriangle& t = s.triangles[0];
        float phi = std::abs(s.camera.circleOfConfusion(3.f));
        AasBounds b = aasBounds(t, s.camera, cut);
        EXPECT_NEAR(b.phiMin, phi, 1e-3f);
        EXPECT_NEAR(b.dPerp, 2.f * cut.lens / phi, 1e-4f);
        EXPECT_FLOAT_EQ(b.dMu, b.dPerp);
    }
    // A quad straddling the focus plane cannot bound A'.
    {
        scene::SceneDesc d = testScene(64, Vec3f(0.f), 0.1f, 3.f);
        d.meshes[0].positions[1].z = -2.f;  // the first triangle spans depths 2..3 around the focus at 2.5
        d.meshes[0].positions[2].z = -2.f;
        d.camera.focusDistance = 2.5f;
        RasterScene s(d, SplitPolicy{0.f, 0.f, 0.f});
        EXPECT_EQ(aasBounds(s.triangles[0], s.camera, cut).phiMin, 0.f);
    }
}

TEST(RasterAas, DirectionSpanWidensTheBoxAlongMotion) {
    // Vertex velocities that fan out (motion towards the camera) give theta-hat > 0: eq. 8 as
    // constructed in the text, d_mu = 2 (Omega_S' cos(theta) + sqrt(r^2 - Omega_S'^2) sin(theta)),
    // wider than the single-direction 2 Omega_S', at most the square 2r.
    RasterScene s(testScene(64, {0.5f, 0, 0}, 0.f, 3.f), SplitPolicy{0.f, 0.f, 0.f});
    RasterTriangle t = s.triangles[0];
    t.motion = {0.5f, 0, 1.0f};
    AasBounds b = aasBounds(t, s.camera, FrequencyCutoffs{});
    ASSERT_TRUE(b.anisotropic);
    EXPECT_GT(b.halfSpan, 0.05f);
    float os = b.omegaShutter, r = b.r;
    EXPECT_NEAR(b.dMu, 2.f * (os * std::cos(b.halfSpan) + std::sqrt(r * r - os * os) * std::sin(b.halfSpan)), 1e-5f);
    EXPECT_GT(b.dMu, 2.f * os);
    EXPECT_LE(b.dMu, b.dPerp);
}

TEST(RasterShadingSpace, ClampKeepsShadingPointsInsideTheTriangle) {
    Vec2f a{0, 0}, b{4, 0}, c{0, 4};
    Vec3f in = closestPointBarycentrics({1, 1}, a, b, c);
    EXPECT_NEAR(in.x, 0.5f, 1e-6f);
    EXPECT_NEAR(in.y, 0.25f, 1e-6f);
    EXPECT_NEAR(in.z, 0.25f, 1e-6f);
    Vec3f edge = closestPointBarycentrics({3, 3}, a, b, c);  // beyond the hypotenuse: its midpoint
    EXPECT_NEAR(edge.y, 0.5f, 1e-6f);
    EXPECT_NEAR(edge.z, 0.5f, 1e-6f);
    Vec3f corner = closestPointBarycentrics({-1, -2}, a, b, c);
    EXPECT_FLOAT_EQ(corner.x, 1.f);
    Vec3f degenerate = closestPointBarycentrics({1, 1}, a, b, {2, 0});
    EXPECT_NEAR(degenerate.x + degenerate.y + degenerate.z, 1.f, 1e-6f);
    for (float v : {degenerate.x, degenerate.y, degenerate.z}) EXPECT_GE(v, 0.f);
}

TEST(RasterTexture, BoxFilteredCheckerIsExact) {
    EXPECT_FLOAT_EQ(filteredChecker({0.25f, 0.25f}, {0, 0}, {0, 0}), 1.f);
    EXPECT_FLOAT_EQ(filteredChecker({1.25f, 0.25f}, {0, 0}, {0, 0}), 0.f);
    // A footprint of one whole period along both axes averages to one half.
    EXPECT_NEAR(filteredChecker({0.3f, 0.7f}, {2, 0}, {0, 2}), 0.5f, 1e-5f);
    // Half a cell around a cell boundary along x: half light, half dark.
    EXPECT_NEAR(boxFilteredSquareWave(1.f, 0.25f), 0.f, 1e-6f);
    EXPECT_NEAR(boxFilteredSquareWave(0.5f, 0.25f), 1.f, 1e-6f);
    // The tent of half-width 1 around a cell centre: 3/4 of its weight on the cell, 1/4 outside.
    EXPECT_NEAR(tentFilteredSquareWave(0.5f, 1.f), 0.5f, 1e-6f);
    EXPECT_NEAR(tentFilteredSquareWave(1000.5f, 1.f), 0.5f, 1e-5f) << "exact far from the origin";
    EXPECT_NEAR(tentFilteredSquareWave(0.5f, 1e-5f), 1.f, 1e-6f);
    // Huge footprints go grey, never outside [0, 1].
    float g = filteredChecker({0.1f, 0.2f}, {100, 3}, {-2, 50});
    EXPECT_NEAR(g, 0.5f, 0.05f);
}

TEST(RasterTexture, UnfilteredItIsTheRayTracersChecker) {
    // With no footprint the rasterizer's filtered checker is scene::albedoAt, which the ray
    // tracer samples: both renderers texture a scene alike.
    scene::Material m{"c", Vec3f(0.8f, 0.6f, 0.4f), Vec3f(0.f), "checker", 3.f, nullptr};
    uint32_t state = 12345;
    auto next = [&] { return float((state = state * 1664525u + 1013904223u) >> 8) / float(1 << 24); };
    int dark = 0;
    for (int i = 0; i < 500; ++i) {
        const Vec3f p(8 * next() - 4, 8 * next() - 4, 8 * next() - 4), n(next() - 0.5f, next() - 0.5f, next() - 0.5f);
        const Vec3f a = scene::albedoAt(m, p, n);
        EXPECT_EQ(texturedAlbedo(m, p, n, Vec3f(0.f), Vec3f(0.f)), a) << i;
        const bool isDark = a == m.albedo * scene::kCheckerDark;
        EXPECT_TRUE(isDark || a == m.albedo) << i;
        dark += isDark;
    }
    EXPECT_GT(dark, 200);
    EXPECT_LT(dark, 300);
}

// --- Command line -----------------------------------------------------------------------------

TEST(RasterCli, WritesImageAndStats) {
    std::string scene = writeTinySceneFile(), dir = test::tempDir();
    std::string err;
    ASSERT_EQ(test::runWedge("raster " + scene + " --shading aas --cache-entries 64 --spp 2 -o " + dir +
                                 "/aas.png --stats " + dir + "/s.json --quiet",
                             nullptr, &err),
              0)
        << err;
    EXPECT_TRUE(std::filesystem::exists(dir + "/aas.png"));
    auto j = nlohmann::json::parse(test::readFile(dir + "/s.json"));
    for (const char* key : {"shaded_quads", "shader_invocations", "hits", "misses", "samples_tested", "seconds",
                            "rel_mse_vs_reference"})
        EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_EQ(j["hits"].get<uint64_t>() + j["misses"].get<uint64_t>(), j["visible_samples"].get<uint64_t>());
    EXPECT_EQ(j["shading"], "aas");
}

TEST(RasterCli, SweepWritesCsvAndPlot) {
    std::string scene = writeTinySceneFile(), dir = test::tempDir() + "/sweep";
    std::string err;
    ASSERT_EQ(test::runWedge("raster " + scene + " --spp 2 --sweep-cache 16,64,256 --out " + dir + " -q", nullptr, &err), 0)
        << err;
    std::string csv = test::readFile(dir + "/sweep.csv");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);
    EXPECT_EQ(csv.rfind("cache_entries,ds_shaded_quads", 0), 0u);
    for (const char* f : {"sweep.png", "sweep.json", "ds.png", "aas.png", "reference.png"})
        EXPECT_TRUE(std::filesystem::exists(dir + "/" + f)) << f;
}

TEST(RasterCli, BadInputExitsWithCode2) {
    std::string scene = writeTinySceneFile(), dir = test::tempDir();
    std::string err;
    EXPECT_EQ(test::runWedge("raster " + scene + " --shading fast -q", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge("raster " + scene + " --cache-entries 0 -q", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge("raster " + dir + "/missing.json -q", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge("raster " + scene + " -o " + dir + "/out.txt -q", nullptr, &err), 2);
    EXPECT_NE(err.find("out.txt"), std::string::npos) << err;
    EXPECT_EQ(test::runWedge("raster " + scene + " --sweep-cache 16,64 -q", nullptr, &err), 2);
    EXPECT_NE(err.find("--out"), std::string::npos) << err;
    EXPECT_EQ(test::runWedge("raster " + scene + " --sweep-cache 16,x --out " + dir + " -q", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge("raster " + scene + " --spp 0 -q", nullptr, &err), 2);
    std::string bad = dir + "/bad.json";
    test::writeFile(bad, R"({"camera": {"position": [0, 0, 1], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40,
      "resolution": [8, 8]}, "objects": [{"type": "quad", "corner": [0, 0, 0], "edge1": [1, 0, 0],
      "edge2": [0, 1, 0], "material": "nope"}], "lights": []})");
    EXPECT_EQ(test::runWedge("raster " + bad + " -q", nullptr, &err), 2);
}
