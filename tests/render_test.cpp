// Render module: the path sampler against closed forms (direct light from a parallelogram and a triangle,
// one-bounce indirect in a sphere, the thin-lens circle of confusion, the motion blur of a
// moving emitter) and determinism across thread counts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "core/parallel.h"
#include "filter/layers.h"
#include "metrics/metrics.h"
#include "render/camera.h"
#include "render/pixel_stats.h"
#include "render/methods.h"
#include "render/output.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"
#include "test_util.h"

using namespace wedge;

namespace {

/// Lambert's formula: irradiance at x (normal n) from a uniform polygon of radiance 1, vertices in order.
double polygonIrradiance(const Vec3f& x, const Vec3f& n, const std::vector<Vec3f>& poly) {
    // In double precision: the edge angles of a small, distant polygon are tiny.
    struct D3 {
        double x, y, z;
    };
    auto sub = [](const Vec3f& p, const Vec3f& q) { return D3{double(p.x) - q.x, double(p.y) - q.y, double(p.z) - q.z}; };
    auto dotd = [](const D3& a, const D3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; };
    auto crossd = [](const D3& a, const D3& b) { return D3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; };
    D3 nd{n.x, n.y, n.z};
    double sum = 0;
    for (size_t i = 0; i < poly.size(); ++i) {
        D3 a = sub(poly[i], x), b = sub(poly[(i + 1) % poly.size()], x);
        D3 c = crossd(a, b);
        double cl = std::sqrt(dotd(c, c));
        double theta = std::atan2(cl, dotd(a, b));
        sum += theta * dotd(nd, c) / cl;
    }
    return 0.5 * std::abs(sum);
}

scene::SceneDesc parse(const std::string& json) { return scene::parseScene(json, "test.json", "."); }

render::RenderResult renderJson(const std::string& json, const render::RenderOptions& o) {
    scene::Scene s(parse(json));
    return render::render(s, o);
}

const char* kPlaneScene = R"({
  "camera": {"position": [0, 0.8, 0.001], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov_y": 90, "resolution": [24, 24]},
  "materials": {"grey": {"albedo": [0.5, 0.6, 0.7]}},
  "lights": [{"type": "parallelogram", "corner": [-0.3, 1, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [10, 10, 10]}],
  "objects": [{"type": "quad", "corner": [-4, 0, 4], "edge1": [8, 0, 0], "edge2": [0, 0, -8], "material": "grey"}],
  "render": {"spp": 256, "seed": 3, "indirect": false}
})";
/// A plank over a floor under a thin lens: defocused silhouettes give pixels two surfaces.
const char* kPlankUnderLens = R"({
  "camera": {"position": [0, 1.2, 2.2], "look_at": [0, 0.3, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [32, 32],
             "aperture_radius": 0.12, "focus_distance": 1.2},
  "materials": {"grey": {"albedo": [0.6, 0.6, 0.6]}, "red": {"albedo": [0.7, 0.2, 0.1]}},
  "lights": [{"type": "parallelogram", "corner": [-0.4, 2, -0.4], "edge1": [0.8, 0, 0], "edge2": [0, 0, 0.8], "radiance": [20, 20, 20]}],
  "objects": [{"type": "quad", "corner": [-3, 0, 3], "edge1": [6, 0, 0], "edge2": [0, 0, -6], "material": "grey"},
              {"type": "box", "min": [-0.5, 0.4, -0.1], "max": [0.5, 0.45, 0.1], "material": "red"}],
  "render": {"spp": 16, "seed": 5, "indirect": true}
})";
/// The corners of kPlaneScene's light (it faces down: cross(edge1, edge2) = -y).
const std::vector<Vec3f> kPlaneLight = {{-0.3f, 1, -0.5f}, {0.7f, 1, -0.5f}, {0.7f, 1, 0.5f}, {-0.3f, 1, 0.5f}};

/// kPlaneScene with its light replaced by `light` (a JSON light object), rendered at 256 spp and
/// checked pixel by pixel against `irradiance`(point), the light's closed form: the closed-form
/// buffer the filters multiply their visibility by (light_irradiance.h) to 1e-4, the image's
/// green channel (albedo 0.6) to a mean relative error under 1% and a worst pixel under 8%.
template <class Irradiance>
void expectPlaneMatches(const std::string& light, Irradiance irradiance) {
    std::string json = kPlaneScene;
    const size_t from = json.find(R"({"type": "parallelogram")"), to = json.find("}]", from) + 1;
    json.replace(from, to - from, light);
    render::RenderOptions o;
    o.quiet = true;
    render::RenderResult r = renderJson(json, o);
    double sumRel = 0, maxRel = 0;
    int n = 0;
    for (int y = 0; y < r.color.height(); ++y)
        for (int x = 0; x < r.color.width(); ++x) {
            const double e = irradiance(r.buffers.position(x, y));
            const double expected = 0.6 * kInvPi * e;
            EXPECT_NEAR(r.buffers.directUnoccluded(x, y).y, e * kInvPi, 1e-4 * e * kInvPi);
            const double rel = std::abs(r.color(x, y).y - expected) / expected;
            sumRel += rel;
            maxRel = std::max(maxRel, rel);
            ++n;
        }
    EXPECT_LT(sumRel / n, 0.01) << "mean relative error over the image";
    EXPECT_LT(maxRel, 0.08) << "worst pixel (256 stratified samples)";
}

}  // namespace

TEST(Render, SamplesWhoseLightIsNotFiniteAreCounted) {
    // A radiance within float range (3e38) over a 10 x 10 light overflows the irradiance of the
    // samples that see it to infinity: counted per sample (--stats nonfinite_samples), beside
    // the pixels they reach (nonfinite_pixels, which `wedge render` warns of). A scene file
    // takes radiance up to 1e15 (scene_loader.cpp, kMaxRadiance), so it is set here in the
    // scene's description.
    scene::SceneDesc d = parse(R"({
      "camera": {"position": [0, 1, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [8, 8]},
      "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}},
      "lights": [{"type": "parallelogram", "corner": [-0.5, 2, -0.5], "edge1": [10, 0, 0], "edge2": [0, 0, 10], "radiance": [5, 5, 5]}],
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "white"}],
      "render": {"spp": 2, "seed": 1, "indirect": true}
    })");
    for (auto& l : d.lights) l.radiance = Vec3f(3e38f);
    for (auto& m : d.materials)
        if (maxComponent(m.emission) > 0) m.emission = Vec3f(3e38f);
    scene::Scene s(std::move(d));
    render::RenderOptions o;
    o.method = "mc";
    o.quiet = true;
    const render::RenderResult r = render::render(s, o);
    const double samples = r.figure("nonfinite_samples").value_or(-1.0);
    EXPECT_GT(samples, 0);
    EXPECT_LE(samples, 8 * 8 * 2) << "at most every sample of the 8x8 render at 2 spp";
    EXPECT_GT(render::nonFinitePixels(r), 0u);
}

TEST(Render, LambertFormulaSanity) {
    // A tiny light far above: E ~ L A / h^2.
    std::vector<Vec3f> poly = {{-0.01f, 10, -0.01f}, {0.01f, 10, -0.01f}, {0.01f, 10, 0.01f}, {-0.01f, 10, 0.01f}};
    EXPECT_NEAR(polygonIrradiance({0, 0, 0}, {0, 1, 0}, poly), 4e-4 / 100.0, 1e-8);
}

TEST(Render, PlaneUnderParallelogramMatchesClosedForm) {
    render::RenderOptions o;
    o.quiet = true;
    render::RenderResult r = renderJson(kPlaneScene, o);
    const Vec3f albedo(0.5f, 0.6f, 0.7f);
    double sumRel = 0, maxRel = 0;
    int n = 0;
    for (int y = 0; y < r.color.height(); ++y)
        for (int x = 0; x < r.color.width(); ++x) {
            Vec3f p = r.buffers.position(x, y);
            double e = 10.0 * polygonIrradiance(p, {0, 1, 0}, kPlaneLight);
            for (int c = 0; c < 3; ++c) {
                double expected = albedo[c] * kInvPi * e;
                double rel = std::abs(r.color(x, y)[c] - expected) / expected;
                sumRel += rel;
                maxRel = std::max(maxRel, rel);
                ++n;
            }
            // The demodulated direct buffer is E / pi.
            EXPECT_NEAR(r.buffers.direct(x, y).x, e * kInvPi, 0.08 * e * kInvPi);
        }
    EXPECT_LT(sumRel / n, 0.01) << "mean relative error over the image";
    EXPECT_LT(maxRel, 0.08) << "worst pixel (256 stratified samples)";
}

TEST(Render, IndependentSamplesAreUnbiasedAndNoisierThanSobol) {
    // --sampler independent: the plane under its light against Lambert's formula. The mean
    // over the image is right either way (within 2%: 576 pixels of 16 samples, the independent
    // samples' standard error 0.5%), and the stratified Sobol points' error is far below the
    // independent samples' on this smooth integral (measured 84x lower relative squared error;
    // at least 10x asserted).
    auto squaredError = [&](const std::string& sampler, double* meanRatio) {
        render::RenderOptions o;
        o.quiet = true;
        o.spp = 16;
        o.sampler = sampler;
        const render::RenderResult r = renderJson(kPlaneScene, o);
        double se = 0, sum = 0, sumExpected = 0;
        for (int y = 0; y < r.color.height(); ++y)
            for (int x = 0; x < r.color.width(); ++x) {
                const double expected = 0.5 * kInvPi * 10.0 * polygonIrradiance(r.buffers.position(x, y), {0, 1, 0}, kPlaneLight);
                se += sqr(r.color(x, y).x - expected) / sqr(expected);
                sum += r.color(x, y).x;
                sumExpected += expected;
            }
        *meanRatio = sum / sumExpected;
        return se;
    };
    double sobolMean = 0, independentMean = 0;
    const double sobol = squaredError("sobol", &sobolMean), independent = squaredError("independent", &independentMean);
    EXPECT_NEAR(sobolMean, 1.0, 0.02);
    EXPECT_NEAR(independentMean, 1.0, 0.02);
    EXPECT_GT(independent, 10 * sobol);
    render::RenderOptions bad;
    bad.quiet = true;
    bad.sampler = "halton";
    EXPECT_THROW(renderJson(kPlaneScene, bad), Error);
}

TEST(Render, PlaneUnderTriangleMatchesClosedForm) {
    // kPlaneScene's light as a triangle, half of it: each render pixel against Lambert's formula
    // over the triangle (uniform sampling by folding the unit square, pdf 1 / its area).
    const std::vector<Vec3f> triangle = {kPlaneLight[0], kPlaneLight[1], kPlaneLight[3]};
    expectPlaneMatches(
        R"({"type": "triangle", "corner": [-0.3, 1, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [10, 10, 10]})",
        [&](const Vec3f& p) { return 10.0 * polygonIrradiance(p, {0, 1, 0}, triangle); });
}

TEST(Render, PlaneUnderSphereMatchesClosedForm) {
    // kPlaneScene's light as a sphere of radius 0.3 about (0.2, 1.6, 0) (above the camera), which
    // every point of the plane sees whole above its horizon: E = pi L sin^2 alpha cos theta (sin alpha = r / d,
    // theta from the normal to the centre). Sampled uniformly in the cone the sphere fills.
    expectPlaneMatches(R"({"type": "sphere", "center": [0.2, 1.6, 0], "radius": 0.3, "radiance": [10, 10, 10]})",
                       [](const Vec3f& p) {
                           const Vec3f w = Vec3f(0.2f, 1.6f, 0) - p;
                           const double d2 = dot(w, w), cosTheta = w.y / std::sqrt(d2);
                           return 10.0 * kPi * (0.09 / d2) * cosTheta;
                       });
}

TEST(Render, ShadingNormalsOfAnObjSetTheLightCosine) {
    // The plane of kPlaneScene as an OBJ whose `vn` all lean 30 degrees towards +x: the direct
    // light follows Lambert's formula for the leaning normal, not the facet's.
    const std::string dir = test::tempDir();
    test::writeFile(dir + "/lean.obj",
                    "v -4 0 4\nv 4 0 4\nv 4 0 -4\nv -4 0 -4\nvn 0.5 0.8660254 0\nf 1//1 2//1 3//1 4//1\n");
    std::string json = kPlaneScene;
    const std::string quad = R"({"type": "quad", "corner": [-4, 0, 4], "edge1": [8, 0, 0], "edge2": [0, 0, -8], "material": "grey"})";
    json.replace(json.find(quad), quad.size(), R"({"type": "mesh", "file": ")" + dir + R"(/lean.obj", "material": "grey"})");
    render::RenderOptions o;
    o.quiet = true;
    render::RenderResult r = renderJson(json, o);
    const Vec3f lean(0.5f, 0.8660254f, 0.f);
    double sumRel = 0, sumFlat = 0;
    int n = 0;
    for (int y = 0; y < r.color.height(); ++y)
        for (int x = 0; x < r.color.width(); ++x) {
            Vec3f p = r.buffers.position(x, y);
            // The whole light stays above the leaning normal's horizon over the visible plane.
            double e = 10.0 * polygonIrradiance(p, lean, kPlaneLight) * kInvPi;
            double flat = 10.0 * polygonIrradiance(p, {0, 1, 0}, kPlaneLight) * kInvPi;
            sumRel += std::abs(r.buffers.direct(x, y).x - e) / e;
            sumFlat += std::abs(flat - e) / e;
            EXPECT_NEAR(r.buffers.normal(x, y).x, lean.x, 1e-4f);
            ++n;
        }
    EXPECT_LT(sumRel / n, 0.01) << "mean relative error against the leaning normal's closed form";
    EXPECT_GT(sumFlat / n, 0.1) << "the test must tell the two normals apart";
}

TEST(Render, OneBounceInsideSphereMatchesFormFactorClosedForm) {
    // Inside a sphere every pair of wall points has form factor dA / (4 pi R^2), so the first
    // bounce of a light's whole flux Phi = pi L A gives the same irradiance everywhere:
    // E = rho Phi / (4 pi R^2); the demodulated indirect buffer holds E / pi.
    const double R = 2.0, L = 20.0, A = 0.2 * 0.2, rho = 0.8;
    const char* json = R"({
      "camera": {"position": [0, 0, 1.0], "look_at": [0, -1, -1], "up": [0, 1, 0], "fov_y": 60, "resolution": [16, 16]},
      "materials": {"wall": {"albedo": [0.8, 0.8, 0.8]}},
      "lights": [{"type": "parallelogram", "corner": [-0.1, 0.5, -0.1], "edge1": [0.2, 0, 0], "edge2": [0, 0, 0.2], "radiance": [20, 20, 20]}],
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 2.0, "material": "wall"}],
      "render": {"spp": 256, "seed": 5, "indirect": true}
    })";
    render::RenderOptions o;
    o.quiet = true;
    render::RenderResult r = renderJson(json, o);
    double expected = rho * (kPi * L * A) / (4 * kPi * R * R) / kPi;
    double mean = 0;
    for (size_t i = 0; i < r.buffers.indirect.size(); ++i) mean += r.buffers.indirect[i].y;
    mean /= double(r.buffers.indirect.size());
    // Bounce rays that hit the (dark) light quad lose at most its solid angle, far below 1%.
    EXPECT_NEAR(mean, expected, 0.02 * expected);
    // Inside a closed sphere every bounce ray hits a wall (the MAAF prefilter's ownBounceHit).
    for (size_t i = 0; i < r.buffers.bounced.size(); ++i) ASSERT_EQ(r.buffers.bounced[i], 1.f) << i;
}

TEST(Render, ThinLensDiscMatchesCircleOfConfusion) {
    // A small emissive sphere at depth z, focus at F: its image is a disc of diameter
    // 2 A f_px |1/z - 1/F| pixels (thin lens), measured from the second moment of the image.
    const char* json = R"({
      "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": 40, "resolution": [64, 64],
                 "aperture_radius": 0.3, "focus_distance": 2.0},
      "materials": {"glow": {"albedo": [0, 0, 0], "emission": [1, 1, 1]}, "black": {"albedo": [0, 0, 0]}},
      "lights": [{"type": "parallelogram", "corner": [100, 100, 100], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [1, 1, 1]}],
      "objects": [{"type": "sphere", "center": [0, 0, -4], "radius": 0.02, "material": "glow"}],
      "render": {"spp": 256, "seed": 7, "indirect": false}
    })";
    render::RenderOptions o;
    o.quiet = true;
    render::RenderResult r = renderJson(json, o);
    render::Camera cam(parse(json).camera);
    double coc = 2.0 * 0.3 * cam.focalPixels() * std::abs(1.0 / 4.0 - 1.0 / 2.0);
    // The measured disc is the CoC convolved with the sphere's own image (radius rs) and the
    // pixel box; second moments add: r_measured^2 = r_coc^2 + rs^2 + 2 * (1/12) * 2.
    double rs = 0.02 * cam.focalPixels() / 4.0;
    double w = 0, cx = 0, cy = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            double v = r.color(x, y).x;
            w += v;
            cx += v * (x + 0.5);
            cy += v * (y + 0.5);
        }
    ASSERT_GT(w, 0);
    cx /= w;
    cy /= w;
    double m2 = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) m2 += r.color(x, y).x * (sqr(x + 0.5 - cx) + sqr(y + 0.5 - cy));
    // Uniform disc: E[rho^2] = r^2 / 2; remove the sphere image and the pixel box.
    double diameter = 2.0 * std::sqrt(std::max(0.0, 2.0 * m2 / w - rs * rs - 1.0 / 3.0));
    EXPECT_NEAR(cx, 32.0, 0.5);
    EXPECT_NEAR(cy, 32.0, 0.5);
    EXPECT_NEAR(diameter, coc, 0.04 * coc) << "CoC " << coc << " px";
}

TEST(Render, MotionBlurIsTheShutterAverage) {
    // An emissive strip 0.2 wide at depth 4 moves at 0.6 to the right (moving emitters are seen,
    // not sampled as lights). It is where the scene puts it when the shutter opens and moves by
    // 0.6 x (close - open) while it is open, so a point of the plane is covered for the share of
    // the shutter the strip spends over it. Shutter [0, 1]: a trapezoid 0.8 wide with ramps 0.2
    // wide and a top of 1/3; [2, 3], the same; [0, 0.5]: half the displacement, 0.5 wide, top 2/3.
    // (The shutter's times were parsed and ignored before: every shutter rendered as [0, 1].)
    for (auto [open, close] : {std::pair{0.0, 1.0}, std::pair{2.0, 3.0}, std::pair{0.0, 0.5}}) {
        std::string json = R"({
          "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": 10, "resolution": [64, 16],
                     "shutter": [OPEN, CLOSE]},
          "materials": {"glow": {"albedo": [0, 0, 0], "emission": [1, 1, 1]}},
          "lights": [{"type": "parallelogram", "corner": [100, 100, 100], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [1, 1, 1]}],
          "objects": [{"type": "quad", "corner": [-0.4, -1, -4], "edge1": [0.2, 0, 0], "edge2": [0, 2, 0], "material": "glow",
                       "velocity": [0.6, 0, 0]}],
          "render": {"spp": 256, "seed": 11, "indirect": false}
        })";
        json.replace(json.find("OPEN"), 4, std::to_string(open));
        json.replace(json.find("CLOSE"), 5, std::to_string(close));
        render::RenderOptions o;
        o.quiet = true;
        render::RenderResult r = renderJson(json, o);
        render::Camera cam(parse(json).camera);
        // A lambda may not capture structured bindings before C++20's P1091 (clang 14 refuses).
        const double d = 0.6 * (close - open);
        auto covered = [&](double x) {  // the share of the shutter during which the strip covers x
            const double x0 = -0.4, w = 0.2;
            const double s0 = std::max(0.0, (x - x0 - w) / d), s1 = std::min(1.0, (x - x0) / d);
            return std::max(0.0, s1 - s0);
        };
        auto planeX = [&](float px, float py) {  // where the pixel position's ray meets z = -4
            render::Ray ray = cam.generate(px, py, {0, 0});
            return double(ray.origin.x) + double(ray.direction.x) * (-4.0 - ray.origin.z) / ray.direction.z;
        };
        double worst = 0, sumMeasured = 0, sumExpected = 0;
        for (int x = 0; x < 64; ++x) {
            double measured = 0, expected = 0;
            for (int y = 0; y < 16; ++y) {
                measured += r.color(x, y).x / 16;
                for (int k = 0; k < 16; ++k) expected += covered(planeX(x + (k + 0.5f) / 16, y + 0.5f)) / (16 * 16);
            }
            // 4096 samples per column: the standard error of a share is at most 0.008.
            worst = std::max(worst, std::abs(measured - expected));
            sumMeasured += measured;
            sumExpected += expected;
        }
        EXPECT_LT(worst, 0.04) << "shutter [" << open << ", " << close << "]: the largest difference of a column from the trapezoid";
        EXPECT_GT(sumExpected, 4.0) << "the trapezoid lies in the view (0.2 x 22.9 px per unit = 4.6)";
        EXPECT_NEAR(sumMeasured, sumExpected, 0.02 * sumExpected) << "shutter [" << open << ", " << close << "]";
    }
}

namespace {

/// A lit strip 0.2 x 2 at depth 4, from x0 to x0 + 0.2, over nothing, under a 200 x 200 light 64
/// away behind a camera at the origin looking down -z (fov_y 10, 64 x 16, 64 spp): where the
/// strip or the camera moves, its light hardly changes. `camera` and `strip`: keys added to the
/// camera and to the strip (each "" or starting with ", ").
std::string litStrip(float x0, const std::string& camera, const std::string& strip, int seed) {
    std::string json = R"({
      "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": 10, "resolution": [64, 16]CAMERA},
      "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}},
      "lights": [{"type": "parallelogram", "corner": [-100, -100, 60], "edge1": [0, 200, 0], "edge2": [200, 0, 0], "radiance": [1, 1, 1]}],
      "objects": [{"type": "quad", "corner": [X0, -1, -4], "edge1": [0.2, 0, 0], "edge2": [0, 2, 0], "material": "white"STRIP}],
      "render": {"spp": 64, "seed": SEED, "indirect": false}
    })";
    for (const auto& [key, value] : {std::pair<std::string, std::string>{"CAMERA", camera}, {"X0", std::to_string(x0)},
                                     {"STRIP", strip}, {"SEED", std::to_string(seed)}})
        json.replace(json.find(key), key.size(), value);
    return json;
}

/// The still strip's radiance (its middle column's mean, by MC at 64 spp without layers).
double litStripRadiance(float x0) {
    render::RenderOptions o;
    o.quiet = true;
    o.method = "mc";
    o.layers = "off";
    const std::string json = litStrip(x0, "", "", 3);
    const render::RenderResult still = renderJson(json, o);
    const render::Camera cam(parse(json).camera);
    const int mid = int(cam.project({x0 + 0.1f, 0.f, -4.f}).x);
    double radiance = 0;
    for (int y = 0; y < 16; ++y) radiance += still.color(mid, y).y / 16;
    return radiance;
}

/// A wall at depth 4 and a post 0.1 wide at depth 2 before a pinhole at the origin looking down
/// -z (fov_y 20, 32 x 32), `camera` a key added to its camera (its motion).
std::string wallAndPost(const std::string& camera) {
    std::string json = R"({
      "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": 20, "resolution": [32, 32], CAMERA},
      "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}},
      "lights": [{"type": "parallelogram", "corner": [-1, 3, -3], "edge1": [2, 0, 0], "edge2": [0, 0, 1], "radiance": [1, 1, 1]}],
      "objects": [{"type": "quad", "corner": [-10, -10, -4], "edge1": [20, 0, 0], "edge2": [0, 20, 0], "material": "white"},
                  {"type": "box", "min": [-0.05, -1, -2.05], "max": [0.05, 1, -1.95], "material": "white"}],
      "render": {"spp": 16, "seed": 3, "indirect": false}
    })";
    json.replace(json.find("CAMERA"), 6, camera);
    return json;
}

}  // namespace

TEST(Render, AMovingCameraIsTheSceneMovingTheOtherWay) {
    // The camera translating by -v over the shutter sees what a still camera sees of the scene
    // translating by +v, where the light hardly depends on where things are: a lit strip over
    // nothing under a 200 x 200 light 64 away behind the camera. The same sample numbers make
    // the same camera rays up to the translation, and the same light points, seen from a strip
    // 0.6 elsewhere (measured: up to 0.1% of the strip's radiance in a pixel), with and without
    // layers (the samples' screen motion and depth are taken from the camera where it is at each
    // end of the shutter and at the sample's time: without the camera's part of the motion the
    // layers' image differs by 0.12 of the strip's radiance), through a thin lens and a pinhole.
    // Each render is also checked against the strip's shutter average (as
    // Layers.AMovingSquareIsItsShutterAverage), so that the two cannot be wrong alike.
    auto scene = [](const std::string& cameraVelocity, const std::string& stripVelocity, bool lens) {
        const std::string aperture = lens ? R"(, "aperture_radius": 0.02, "focus_distance": 3)" : "";
        return litStrip(-0.4f, aperture + R"(, "velocity": [)" + cameraVelocity + "]", R"(, "velocity": [)" + stripVelocity + "]", 5);
    };
    render::RenderOptions o;
    o.quiet = true;
    o.method = "mc";
    const render::Camera cam(parse(scene("0, 0, 0", "0, 0, 0", false)).camera);
    const double radiance = litStripRadiance(-0.4f);
    ASSERT_GT(radiance, 0.01);
    for (bool lens : {false, true})
        for (const char* layers : {"off", "on"}) {
            o.layers = layers;
            const std::string cameraMoves = scene("-0.6, 0, 0", "0, 0, 0", lens), stripMoves = scene("0, 0, 0", "0.6, 0, 0", lens);
            ASSERT_TRUE(parse(cameraMoves).hasMotion());
            const render::RenderResult a = renderJson(cameraMoves, o), b = renderJson(stripMoves, o);
            const std::string what = std::string(lens ? "thin lens" : "pinhole") + ", layers " + layers;
            double worst = 0;
            for (int y = 0; y < 16; ++y)
                for (int x = 0; x < 64; ++x) worst = std::max(worst, double(std::abs(a.color(x, y).y - b.color(x, y).y)));
            EXPECT_LT(worst / radiance, 3e-3) << what << ": the largest difference of a pixel between the two renders";
            // The trapezoid, from the rays through the lens centre: x on the plane z = -4, where
            // the strip is at -0.4 .. -0.2 when the shutter opens and moves 0.6 relative to the
            // camera. (Through the lens the rays are those of a pinhole, blurred by 0.6 px.)
            auto covered = [&](double x) {
                const double s0 = std::max(0.0, (x + 0.2) / 0.6), s1 = std::min(1.0, (x + 0.4) / 0.6);
                return std::max(0.0, s1 - s0);
            };
            double worstColumn = 0;
            for (int x = 0; x < 64; ++x) {
                double measured = 0, expected = 0;
                for (int y = 0; y < 16; ++y) measured += a.color(x, y).y / 16 / radiance;
                for (int k = 0; k < 16; ++k) {
                    const render::Ray ray = cam.generate(x + (k + 0.5f) / 16, 8.f, {0, 0});
                    expected += covered(double(ray.direction.x) * -4.0 / ray.direction.z) / 16;
                }
                worstColumn = std::max(worstColumn, std::abs(measured - expected));
            }
            EXPECT_LT(worstColumn, lens ? 0.05 : 0.03) << what << ": the largest difference of a column from the trapezoid";
        }
}

TEST(Render, AMovingCamerasSamplesMoveOnTheScreenByItsParallax) {
    // A still wall at depth 4 and a still post at depth 2 before a pinhole that moves 0.2 to the
    // right and 0.5 forward over the shutter. A sample's hit point P, seen from the camera at
    // C(t) = (0.2 t, 0, -0.5 t), is at depth -P.z - 0.5 t (the depth the layers read its defocus
    // and its place in depth from) and moves on the screen by f (P.x - 0.2) / (-P.z - 0.5) -
    // f P.x / -P.z pixels across and the like down over the shutter (f: the focal length in
    // pixels): the post, nearer, moves farther. Before the camera could move, a still hit had no screen motion.
    const scene::SceneDesc desc = parse(wallAndPost(R"("velocity": [0.2, 0, -0.5])"));
    const scene::Scene sc(desc);
    const render::Camera cam(desc.camera);
    const render::PathSampler sampler(sc, cam, false, 3);
    const double f = cam.focalPixels();
    int wall = 0, post = 0;
    double postMotion = 0, wallMotion = 0;
    for (int x = 0; x < 32; ++x)
        for (uint32_t k = 0; k < 16; ++k) {
            const render::TracedSample s = sampler.trace(x, 16, k, false);
            ASSERT_TRUE(s.hit);
            const double px = s.position.x, pz = s.position.z, t = s.time;
            EXPECT_NEAR(s.depth, -pz - 0.5 * t, 1e-4) << "the depth from the camera at time " << t;
            const double motion = f * (px - 0.2) / (-pz - 0.5) - f * px / -pz;
            EXPECT_NEAR(s.motion.x, motion, 1e-3) << "at (" << px << ", " << pz << ")";
            // Image y grows downward; the forward motion spreads the rows apart.
            const double py = s.position.y;
            EXPECT_NEAR(s.motion.y, -(f * py / (-pz - 0.5) - f * py / -pz), 1e-3);
            const bool onPost = pz > -2.1;
            (onPost ? post : wall)++;
            (onPost ? postMotion : wallMotion) += s.motion.x;
        }
    ASSERT_GT(post, 8);
    ASSERT_GT(wall, 256);
    // About -0.2 f / 2 against -0.2 f / 4 (the forward motion adds a little).
    EXPECT_LT(postMotion / post, 1.7 * (wallMotion / wall));
    EXPECT_LT(wallMotion / wall, -0.04 * f);
}

TEST(Render, ATurningCamerasSamplesMoveAlikeAtEveryDepth) {
    // A pinhole at the origin looking at (0, 0, -1), its look_at moving 0.05 to the right over
    // the shutter: the camera turns by atan(0.05) = 2.9 degrees about its position, with
    // forward(t) = normalize(0.05 t, 0, -1). A turn has no parallax: a wall at depth 4 and a post
    // at depth 2 move alike on the screen, by about f tan(2.9 degrees) = 0.05 f pixels to the
    // left. Each sample's screen motion is its point's from the camera at the shutter's open to
    // the camera at its close, and its depth is along forward(t) at its own time.
    const scene::SceneDesc desc = parse(wallAndPost(R"("look_at_velocity": [0.05, 0, 0])"));
    ASSERT_TRUE(desc.hasMotion());
    const scene::Scene sc(desc);
    const render::Camera cam(desc.camera);
    const render::PathSampler sampler(sc, cam, false, 3);
    const double f = cam.focalPixels();
    // The camera's axes at time t, by hand: forward in the x-z plane, up = +y, right = forward x up.
    auto screenX = [&](const Vec3f& p, double t) {
        const double n = std::sqrt(0.05 * t * 0.05 * t + 1.0), fx = 0.05 * t / n, fz = -1.0 / n;
        const double rx = -fz, rz = fx;  // (fx, 0, fz) x (0, 1, 0)
        return f * (p.x * rx + p.z * rz) / (p.x * fx + p.z * fz);
    };
    auto depth = [&](const Vec3f& p, double t) {
        const double n = std::sqrt(0.05 * t * 0.05 * t + 1.0);
        return (p.x * 0.05 * t - p.z) / n;
    };
    double motion[2] = {0, 0};
    int count[2] = {0, 0};
    for (int x = 12; x < 20; ++x)  // near the middle, where the post is
        for (uint32_t k = 0; k < 16; ++k) {
            const render::TracedSample s = sampler.trace(x, 16, k, false);
            ASSERT_TRUE(s.hit);
            EXPECT_NEAR(s.depth, depth(s.position, s.time), 1e-4) << "the depth along forward at time " << s.time;
            EXPECT_NEAR(s.motion.x, screenX(s.position, 1.0) - screenX(s.position, 0.0), 2e-3);
            const int onPost = s.position.z > -2.1f;
            motion[onPost] += s.motion.x;
            ++count[onPost];
        }
    ASSERT_GT(count[0], 16);
    ASSERT_GT(count[1], 16);
    EXPECT_NEAR(motion[0] / count[0], -0.05 * f, 0.02 * 0.05 * f) << "the wall";
    EXPECT_NEAR(motion[1] / count[1], motion[0] / count[0], 0.01 * 0.05 * f) << "the post, at half the wall's depth";
}

TEST(Render, ATurningCameraBlursAStripOverItsSweep) {
    // A lit strip at depth 4 under a camera that turns as above (its look_at moving 0.1 over the
    // shutter): a pixel's value is the strip's radiance times the share of the shutter during
    // which its ray (the camera's at that time) meets the strip, averaged over the pixel. With
    // and without layers (the sweep, 9.1 px, twice the strip's width), the columns' means against
    // that share (integrated over 256 times and 16 positions in the pixel).
    render::RenderOptions o;
    o.quiet = true;
    o.method = "mc";
    const std::string turning = litStrip(-0.2f, R"(, "look_at_velocity": [0.1, 0, 0])", "", 7);
    const render::Camera cam(parse(turning).camera);
    const double radiance = litStripRadiance(-0.2f);
    ASSERT_GT(radiance, 0.01);
    std::vector<double> share(64, 0.0);
    for (int x = 0; x < 64; ++x)
        for (int k = 0; k < 16; ++k)
            for (int i = 0; i < 256; ++i) {
                const render::Ray ray = cam.generate(x + (k + 0.5f) / 16, 8.f, {0, 0}, (i + 0.5f) / 256);
                const double hx = double(ray.origin.x) + double(ray.direction.x) * (-4.0 - ray.origin.z) / ray.direction.z;
                share[x] += (hx >= -0.2 && hx <= 0.0) ? 1.0 / (16 * 256) : 0.0;
            }
    double total = 0;
    int swept = 0;
    for (double v : share) {
        total += v;
        swept += v > 0;
    }
    ASSERT_NEAR(total, 4.6, 0.1) << "the strip, 0.2 x 22.9 px per unit, lies in the view at every time";
    ASSERT_GE(swept, 13) << "its sweep, 0.1 f = 9.1 px, too";
    for (const char* layers : {"off", "on"}) {
        o.layers = layers;
        const render::RenderResult r = renderJson(turning, o);
        double worst = 0;
        for (int x = 0; x < 64; ++x) {
            double measured = 0;
            for (int y = 0; y < 16; ++y) measured += r.color(x, y).y / 16 / radiance;
            worst = std::max(worst, std::abs(measured - share[x]));
        }
        EXPECT_LT(worst, 0.03) << "layers " << layers << ": the largest difference of a column from the share";
    }
}

namespace {

/// A lit bar 1 x 0.08 at depth 4 before a pinhole (fov 20 degrees, 64 x 64, or `size` a side),
/// turning by `degrees` about the view axis through its centre over the shutter, without
/// indirect light.
std::string turningBarScene(float degrees, int size = 64, float fov = 20.f) {
    std::string json = R"({
      "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": FOV, "resolution": [SIZE, SIZE]},
      "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}},
      "lights": [{"type": "parallelogram", "corner": [-100, -100, 60], "edge1": [0, 200, 0], "edge2": [200, 0, 0], "radiance": [1, 1, 1]}],
      "objects": [{"type": "quad", "corner": [-0.5, -0.04, -4], "edge1": [1, 0, 0], "edge2": [0, 0.08, 0], "material": "white",
                   "angular_velocity": [0, 0, 1, DEGREES]}],
      "render": {"spp": 16, "seed": 9, "indirect": false}
    })";
    json.replace(json.find("DEGREES"), 7, std::to_string(degrees));
    json.replace(json.find("SIZE"), 4, std::to_string(size));
    json.replace(json.find("SIZE"), 4, std::to_string(size));
    json.replace(json.find("FOV"), 3, std::to_string(fov));
    return json;
}

/// The bar of turningBarScene rendered by `method` (64 samples a pixel for the still bar's
/// radiance by MC) at `spp` with `layers`, against the share of the shutter each pixel sees it
/// (the bar turned at 256 times, 4 x 4 points a pixel, the pixel's point on the plane from the
/// field of view alone), times the still bar's radiance. Returns the mean absolute difference
/// over the pixels and the largest over 8 x 8 blocks, in the bar's radiance. (At `size` x `size`
/// pixels: 64, one tile of the layers, or more.)
std::pair<double, double> turningBarErrors(float degrees, int spp, const char* layers, const char* method = "mc", int size = 64,
                                           float fov = 20.f) {
    render::RenderOptions o;
    o.quiet = true;
    o.method = "mc";
    o.spp = 64;
    o.layers = "off";
    const render::RenderResult still = renderJson(turningBarScene(0.f), o);  // (at 64 x 64: the same radiance)
    double radiance = 0;
    for (int y = 31; y < 33; ++y)
        for (int x = 16; x < 48; ++x) radiance += still.color(x, y).y / 64;
    EXPECT_GT(radiance, 0.01);
    o.spp = spp;
    o.layers = layers;
    o.method = method;
    const render::RenderResult r = renderJson(turningBarScene(degrees, size, fov), o);
    const double half = 4.0 * std::tan(0.5 * fov * kPi / 180.0);  // the plane's half-width seen
    double sum = 0, worstBlock = 0;
    const int n = size;
    double cosA[256], sinA[256];
    for (int i = 0; i < 256; ++i) {
        const double a = -degrees * kPi / 180.0 * (i + 0.5) / 256;  // the bar's frame at that time
        cosA[i] = std::cos(a), sinA[i] = std::sin(a);
    }
    std::vector<double> diff(size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            double share = 0;
            for (int k = 0; k < 16; ++k) {
                const double px = (x + (k % 4 + 0.5) / 4) / (n / 2.0) - 1.0, py = 1.0 - (y + (k / 4 + 0.5) / 4) / (n / 2.0);
                const double X = px * half, Y = py * half;
                for (int i = 0; i < 256; ++i) {
                    const double bx = X * cosA[i] - Y * sinA[i], by = X * sinA[i] + Y * cosA[i];
                    share += (std::abs(bx) <= 0.5 && std::abs(by) <= 0.04) ? 1.0 / (16 * 256) : 0.0;
                }
            }
            diff[size_t(y) * n + x] = r.color(x, y).y / radiance - share;
            sum += std::abs(diff[size_t(y) * n + x]);
        }
    for (int by = 0; by < n; by += 8)
        for (int bx = 0; bx < n; bx += 8) {
            double block = 0;
            for (int y = by; y < by + 8; ++y)
                for (int x = bx; x < bx + 8; ++x) block += diff[size_t(y) * n + x] / 64;
            worstBlock = std::max(worstBlock, std::abs(block));
        }
    return {sum / (double(n) * n), worstBlock};
}

}  // namespace

TEST(Render, ATurningBarSweepsItsShareOfTheShutter) {
    // Geometry and time: 64 samples a pixel without layers, a 40-degree turn (Embree's
    // quaternion steps, every sample at its own time).
    const auto [mean, block] = turningBarErrors(40.f, 64, "off");
    EXPECT_LT(mean, 0.01) << "the mean absolute difference of a pixel (measured 0.0045)";
    EXPECT_LT(block, 0.02) << "the largest of an 8 x 8 block's mean (0.011: 64 x 64 samples' noise)";
    // At 16 samples a pixel the layers reconstruct the turn from the samples around: each is
    // reprojected along its arc (the parabola through the chord's ends and its mid-shutter
    // point: ASpinningBarsSamplesFollowTheirArcs), following the motion its layer's grid finds.
    // Measured: 0.0040 a pixel against 0.0133 without layers (0.0045 along the chords alone).
    // (With a layer judged sharp by its mean motion, near nothing for a turn about its middle,
    // the layers left every sample where it was taken: the same 0.0133.)
    const auto [meanOn, blockOn] = turningBarErrors(40.f, 16, "on");
    const auto [meanOff, blockOff] = turningBarErrors(40.f, 16, "off");
    EXPECT_LT(meanOn, 0.6 * meanOff);
    EXPECT_LT(blockOn, 0.06) << "the trajectories' bias (0.033; 0.040 along the chords), within a block";
}

TEST(Render, ASpinningBarsSamplesFollowTheirArcs) {
    // The bar of turningBarScene spinning 90 and 120 degrees in the image plane, MC at 16 spp
    // with layers: each sample is reprojected along its arc through the chord's ends and its
    // mid-shutter point (TracedSample::sag, layers.cpp curvedShift, at the turn's pace:
    // ArcPace), the rays and D through the grid's sagittas and their affine fit. Measured, the
    // mean absolute difference a pixel from the share of the shutter that sees the bar (in its
    // radiance): 90 degrees 0.0041, 120 degrees 0.0044; along the parabola through the same
    // three points (before ArcPace) 0.0052 and 0.0073, along the chords (the sagitta taken as 0)
    // 0.0093 and 0.0122, without layers 0.0184 and 0.0211.
    const double mean90 = turningBarErrors(90.f, 16, "on").first;
    const double mean120 = turningBarErrors(120.f, 16, "on").first;
    EXPECT_LT(mean90, 0.0048);
    EXPECT_LT(mean120, 0.0058);
}

TEST(Render, ATurningBarsTipsAreReconstructedAcrossTiles) {
    // The spinning bar at 192 x 192 under a 15-degree field of view (3 x 3 tiles of the layers,
    // the bar 182 px long about the middle one's centre) turning 90 degrees: its tips' arcs cross
    // into the corner and edge tiles.
    // A moving layer's grid reaches from its tile as far as its samples move along each axis;
    // taken as their root mean square, it stopped short of the tips' motion, which is the largest
    // (a turn's grows with the radius), and the rays past the grid read its clamped edge: the
    // tips' colour filled boxes of their tiles outside the disc the bar sweeps (docs/layers.md,
    // "A turning fan's tips"). Measured, the largest 8 x 8 block's mean difference from the
    // share of the shutter the bar covers there: 0.153 with the root mean square (the mean over
    // the pixels 0.0084), 0.047 with the largest (0.0058), 0.033 (0.0042) along the turn's own
    // arcs (ArcPace) rather than parabolas.
    const auto [mean, block] = turningBarErrors(90.f, 16, "on", "mc", 192, 15.f);
    EXPECT_LT(block, 0.07) << "mean " << mean;
}

TEST(Render, ASamplesBendIsTheSagittaOfItsArc) {
    // The bar turning 90 degrees about the view axis through its centre: a point r from the
    // axis moves on the screen along an arc of radius f r / 4 pixels (depth 4), which strays
    // f r / 4 (1 - cos 45 degrees) from its chord at mid-shutter: the sample's bend.
    const scene::SceneDesc desc = parse(turningBarScene(90.f));
    const scene::Scene sc(desc);
    const render::Camera cam(desc.camera);
    const render::PathSampler sampler(sc, cam, false, 3);
    const double f = cam.focalPixels();
    int bar = 0;
    for (int y = 0; y < 64; y += 3)
        for (int x = 0; x < 64; x += 3)
            for (uint32_t k = 0; k < 4; ++k) {
                const render::TracedSample s = sampler.trace(x, y, k, false);
                if (!s.hit) continue;
                ++bar;
                const double r = f * std::hypot(s.position.x, s.position.y) / 4.0;
                EXPECT_NEAR(s.bend, r * (1.0 - std::cos(kPi / 4)), 1e-3 * r + 0.01) << "r = " << r << " px";
                // A spin in the image plane turns nothing in depth: the sample keeps its sagitta,
                // off the chord's middle towards the arc's, and as long as the bend (the arc is
                // symmetric about the chord's perpendicular).
                EXPECT_NEAR(std::hypot(s.sag.x, s.sag.y), s.bend, 1e-3 * r + 0.02) << "r = " << r << " px";
            }
    ASSERT_GT(bar, 20);
    // The same bar turning 90 degrees about the vertical axis turns in depth by more than
    // kCurvedTurnInDepth: no sagitta (its paths along their chords).
    std::string inDepth = turningBarScene(90.f);
    inDepth.replace(inDepth.find("[0, 0, 1, "), 10, "[0, 1, 0, ");
    const scene::SceneDesc turnDesc = parse(inDepth);
    const scene::Scene turnScene(turnDesc);
    const render::Camera turnCam(turnDesc.camera);
    const render::PathSampler turnSampler(turnScene, turnCam, false, 3);
    int turning = 0;
    for (int y = 24; y < 40; y += 2)
        for (int x = 0; x < 64; x += 2) {
            const render::TracedSample s = turnSampler.trace(x, y, 0, false);
            if (!s.hit || std::hypot(s.motion.x, s.motion.y) < 1.f) continue;
            ++turning;
            EXPECT_EQ(s.sag.x, 0.f);
            EXPECT_EQ(s.sag.y, 0.f);
        }
    EXPECT_GT(turning, 5);
    // A camera moving sideways and forward moves still points along straight lines on the
    // screen (x and y are both linear in 1 / depth): no bend, though the paths are 2.6 px and more.
    const scene::SceneDesc moving = parse(wallAndPost(R"("velocity": [0.2, 0, -0.5])"));
    const scene::Scene ms(moving);
    const render::Camera mcam(moving.camera);
    const render::PathSampler msampler(ms, mcam, false, 3);
    for (int x = 0; x < 32; ++x)
        for (uint32_t k = 0; k < 4; ++k) {
            const render::TracedSample s = msampler.trace(x, 16, k, false);
            ASSERT_TRUE(s.hit);
            EXPECT_GT(std::hypot(s.motion.x, s.motion.y), 2.5);
            EXPECT_LT(s.bend, 0.01);
        }
}

TEST(Render, TheFiltersKeepTheirOwnImageWhereASurfaceTurnsAway) {
    // The layers reproject each sample along its chord and hold one sharp image per layer at
    // mid-shutter. A plate 1 x 0.3 at depth 4 turning 120 degrees about (0, 1, 1) through its
    // centre turns away from the camera as it spins: its samples' paths bend up to 10 px from
    // their chords and their surface turns by more than kFaceTurn, so AAF keeps its own
    // composition within their reach, the image it gives without layers. The bar of
    // turningBarScene spinning 120 degrees in the image plane before the same wall bends as
    // far (11 px) but turns nothing towards the camera, and keeps the layers (which measured
    // better there on fans: docs/layers.md, "Arcs").
    auto scene = [](const char* object) {
        std::string json = R"({
          "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": 20, "resolution": [64, 64]},
          "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}, "wall": {"albedo": [0.4, 0.4, 0.4]}},
          "lights": [{"type": "parallelogram", "corner": [-100, -100, 60], "edge1": [0, 200, 0], "edge2": [200, 0, 0], "radiance": [1, 1, 1]}],
          "objects": [OBJECT, {"type": "quad", "corner": [-3, -3, -6], "edge1": [6, 0, 0], "edge2": [0, 6, 0], "material": "wall"}],
          "render": {"spp": 16, "seed": 9, "indirect": false}
        })";
        json.replace(json.find("OBJECT"), 6, object);
        return json;
    };
    const std::string plate = scene(R"({"type": "quad", "corner": [-0.5, -0.15, -4], "edge1": [1, 0, 0], "edge2": [0, 0.3, 0],
                                        "material": "white", "angular_velocity": [0, 1, 1, 120]})");
    const std::string bar = scene(R"({"type": "quad", "corner": [-0.5, -0.04, -4], "edge1": [1, 0, 0], "edge2": [0, 0.08, 0],
                                      "material": "white", "angular_velocity": [0, 0, 1, 120]})");
    render::RenderOptions o;
    o.quiet = true;
    o.method = "aaf";
    o.spp = 16;
    const double f = 32.0 / std::tan(10.0 * kPi / 180.0);
    // How many of 64 times the ray through a pixel's centre meets the object: the plate's
    // turned plane about (0, 0, -4), the bar's turned frame.
    auto swept = [&](int x, int y, bool isPlate) {
        int hits = 0;
        const double X = (x + 0.5 - 32) / f, Y = (32 - y - 0.5) / f;  // the ray (X, Y, -1) from the origin
        for (int i = 0; i < 64; ++i) {
            const double a = 120.0 * kPi / 180.0 * (i + 0.5) / 64;
            if (isPlate) {
                // Its frame turned about (0, 1, 1) / sqrt 2 through its centre.
                const Vec3f axis = normalize(Vec3f(0, 1, 1));
                const Vec3f n = rotate(Vec3f(0, 0, 1), axis, float(a)), e1 = rotate(Vec3f(1, 0, 0), axis, float(a));
                const Vec3f e2 = rotate(Vec3f(0, 1, 0), axis, float(a)), d(float(X), float(Y), -1.f), c(0, 0, -4);
                const float s = dot(n, c) / dot(n, d);  // n . (s d - c) = 0
                const Vec3f q = d * s - c;
                hits += s > 0 && std::abs(dot(q, e1)) <= 0.5f && std::abs(dot(q, e2)) <= 0.15f;
            } else {
                const double bx = 4 * X * std::cos(a) + 4 * Y * std::sin(a), by = -4 * X * std::sin(a) + 4 * Y * std::cos(a);
                hits += std::abs(bx) <= 0.5 && std::abs(by) <= 0.04;
            }
        }
        return hits;
    };
    for (const bool isPlate : {true, false}) {
        o.layers = "on";
        const render::RenderResult on = renderJson(isPlate ? plate : bar, o);
        o.layers = "off";
        const render::RenderResult off = renderJson(isPlate ? plate : bar, o);
        ASSERT_EQ(on.methodPixels.size(), size_t(64 * 64));
        int count = 0, left = 0, same = 0;
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const int hits = swept(x, y, isPlate);
                // (A pixel the object covers all the time is away from its silhouette.)
                if (hits == 0 || hits == 64) continue;
                ++count;
                left += on.methodPixels(x, y);
                same += length(on.color(x, y) - off.color(x, y)) <= 1e-6f * length(off.color(x, y));
            }
        EXPECT_GT(count, isPlate ? 250 : 800);
        if (isPlate) {
            EXPECT_EQ(left, count) << "the plate turning away: every pixel it sweeps left to AAF";
            EXPECT_EQ(same, count) << "... where AAF's image is the one it gives without layers";
        } else {
            // (A pixel whose 16 samples all met the bar is away from its silhouette too: 1 here.)
            EXPECT_LE(left, count / 100) << "the bar spinning in the image plane: the layers where it sweeps";
            EXPECT_LT(same, count / 10);
        }
    }
}

TEST(Render, CameraRaysInABatchAreTheRaysOneByOne) {
    // Camera::generate over a batch (the sampler's camera rays, a loop across them) against the
    // ray-by-ray generate(): a pinhole, a thin lens, a lens that translates and one that turns.
    // (To float rounding: the single rays are compiled here, with multiply-add contraction.)
    const char* cameras[] = {
        R"({"position": [0.1, 1.2, 2.3], "look_at": [0, 0.3, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [40, 30]})",
        R"({"position": [0.1, 1.2, 2.3], "look_at": [0, 0.3, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [40, 30],
            "aperture_radius": 0.1, "focus_distance": 2.1})",
        R"({"position": [0.1, 1.2, 2.3], "look_at": [0, 0.3, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [40, 30],
            "aperture_radius": 0.1, "focus_distance": 2.1, "velocity": [0.3, -0.1, 0.05]})",
        R"({"position": [0.1, 1.2, 2.3], "look_at": [0, 0.3, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [40, 30],
            "aperture_radius": 0.1, "focus_distance": 2.1, "look_at_velocity": [0.4, 0, 0]})"};
    for (const char* c : cameras) {
        std::string json = kPlaneScene;
        const size_t from = json.find(R"("camera": )") + 10, to = json.find("},", from) + 1;
        json.replace(from, to - from, c);
        const scene::Scene s(parse(json));
        const render::Camera cam(s.desc().camera);
        constexpr int n = 13;
        float px[n], py[n], time[n];
        Vec2f lens[n];
        for (int k = 0; k < n; ++k) {
            px[k] = 40.f * (k + 0.37f) / n, py[k] = 30.f * (n - k - 0.61f) / n, time[k] = k / float(n - 1);
            lens[k] = concentricDisc((k * 5 % n + 0.5f) / n, (k * 3 % n + 0.5f) / n);
        }
        Vec3f origin[n], direction[n];
        cam.generate(n, px, py, lens, time, origin, direction);
        for (int k = 0; k < n; ++k) {
            const render::Ray ray = cam.generate(px[k], py[k], lens[k], time[k]);
            for (int a = 0; a < 3; ++a) {
                EXPECT_NEAR(origin[k][a], ray.origin[a], 1e-6f) << c << " ray " << k;
                EXPECT_NEAR(direction[k][a], ray.direction[a], 1e-6f) << c << " ray " << k;
            }
        }
    }
}

TEST(Render, ThinLensRaysMeetOnTheFocalPlane) {
    scene::CameraDesc d;
    d.position = {1, 2, 3};
    d.lookAt = {0, 0, 0};
    d.apertureRadius = 0.3f;
    d.focusDistance = 2.5f;
    d.width = 100;
    d.height = 80;
    render::Camera cam(d);
    render::Ray a = cam.generate(30.5f, 20.25f, {0, 0});
    render::Ray b = cam.generate(30.5f, 20.25f, {0.7f, -0.5f});
    Vec3f fwd = normalize(d.lookAt - d.position);
    Vec3f pa = a.origin + a.direction * (2.5f / dot(a.direction, fwd));
    Vec3f pb = b.origin + b.direction * ((2.5f - dot(b.origin - d.position, fwd)) / dot(b.direction, fwd));
    EXPECT_LT(length(pa - pb), 1e-5f);
    Vec2f px = cam.project(pa);
    EXPECT_NEAR(px.x, 30.5f, 1e-3f);
    EXPECT_NEAR(px.y, 20.25f, 1e-3f);
}

TEST(Render, DefaultSamplesPerPixel) {
    // Without --spp: MC takes the scene's render.spp (256 here; no emitter in view, so no
    // top-up), à-trous 16 like the filters' initial samples (the README and --help say so).
    scene::Scene s(parse(kPlaneScene));
    render::RenderOptions o;
    o.quiet = true;
    EXPECT_EQ(render::render(s, o).sppAverage, 256.0);
    o.method = "atrous";
    EXPECT_EQ(render::render(s, o).sppAverage, 16.0);
    o.spp = 8;
    EXPECT_EQ(render::render(s, o).sppAverage, 8.0);
}

TEST(Render, ImageIsBitIdenticalOnOneAndTwoThreads) {
    // The plane, and the plank under a lens through the layered reconstruction (filter/layers.h).
    for (const char* method : {"mc", "aaf", "maaf", "atrous"})
    for (const char* json : {kPlaneScene, kPlankUnderLens}) {
        render::RenderOptions o;
        o.quiet = true;
        o.method = method;
        o.spp = 8;
        o.layers = json == kPlankUnderLens ? "on" : "auto";
        scene::Scene s(parse(json));
        render::RenderResult r1, r2;
        {
            ThreadLimit one(1);
            r1 = render::render(s, o);
        }
        {
            ThreadLimit two(2);
            r2 = render::render(s, o);
        }
        ASSERT_EQ(r1.color.size(), r2.color.size());
        EXPECT_EQ(r1.figure("layers_sample_bytes").has_value(), json == kPlankUnderLens);
        EXPECT_EQ(0, std::memcmp(r1.color.data(), r2.color.data(), r1.color.size() * sizeof(Vec3f))) << method;
        EXPECT_EQ(0, std::memcmp(r1.buffers.direct.data(), r2.buffers.direct.data(), r1.color.size() * sizeof(Vec3f)));
    }
}

TEST(Render, TextureSamplesChangeOnlyTexturedPixelsAndNotWithTheThreads) {
    // kPlaneScene checkered (cells 2.5 px wide): the filters whose colour is albedo x filtered
    // light take texture samples where a pixel's samples saw the albedo vary. The same image
    // on one and two threads; without texture samples the pixels whose samples saw one albedo
    // are the same bytes (only the albedo changed: the filtered light did not), and the others
    // differ. Without a texture no pixel takes them (the same image as --texture-spp 0).
    std::string json = kPlaneScene;
    const std::string plain = R"("grey": {"albedo": [0.5, 0.6, 0.7]})";
    json.replace(json.find(plain), plain.size(), R"("grey": {"albedo": [0.5, 0.6, 0.7], "texture": "checker", "texture_scale": 8})");
    for (const char* method : {"aaf", "maaf", "atrous"}) {
        render::RenderOptions o;
        o.quiet = true;
        o.method = method;
        o.spp = 16;
        o.layers = "off";
        scene::Scene s(parse(json));
        render::RenderResult r1, r2, none;
        {
            ThreadLimit one(1);
            r1 = render::render(s, o);
        }
        {
            ThreadLimit two(2);
            r2 = render::render(s, o);
        }
        EXPECT_EQ(0, std::memcmp(r1.color.data(), r2.color.data(), r1.color.size() * sizeof(Vec3f))) << method;
        const double textured = r1.figure("texture_pixels").value_or(-1);
        EXPECT_GT(textured, 0.2 * r1.color.size()) << method;
        EXPECT_LT(textured, 0.9 * r1.color.size()) << method;
        o.textureSpp = 0;
        none = render::render(s, o);
        EXPECT_EQ(none.figure("texture_pixels").value_or(-1), 0.0) << method;
        int changed = 0;
        for (size_t i = 0; i < r1.color.size(); ++i) {
            if (r1.buffers.albedo[i] == none.buffers.albedo[i])
                EXPECT_EQ(r1.color[i], none.color[i]) << method << " pixel " << i;
            else
                ++changed;
        }
        EXPECT_NEAR(changed, textured, 0.02 * textured) << method;  // (a pixel's texture samples may all agree with it)
        scene::Scene untextured(parse(kPlaneScene));
        o.textureSpp = 64;
        const render::RenderResult a = render::render(untextured, o);
        o.textureSpp = 0;
        const render::RenderResult b = render::render(untextured, o);
        EXPECT_EQ(a.figure("texture_pixels").value_or(-1), 0.0) << method;
        EXPECT_EQ(0, std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(Vec3f))) << method;
    }
}

namespace {

/// Plain MC at 1024 spp without layers (seed 9): the reference of the texture tests below.
Image3f mcReference(const scene::Scene& s) {
    render::RenderOptions o;
    o.quiet = true;
    o.method = "mc";
    o.spp = 1024;
    o.layers = "off";
    o.seed = 9;
    return render::render(s, o).color;
}

/// `method` at 16 spp with --layers on.
render::RenderOptions layeredOptions(const char* method) {
    render::RenderOptions o;
    o.quiet = true;
    o.method = method;
    o.spp = 16;
    o.layers = "on";
    return o;
}

/// `method` with layers (layeredOptions), with its texture samples and without (--texture-spp 0).
std::pair<render::RenderResult, render::RenderResult> withAndWithoutTextureSamples(const scene::Scene& s, const char* method) {
    render::RenderOptions o = layeredOptions(method);
    render::RenderResult with = render::render(s, o);
    o.textureSpp = 0;
    return {std::move(with), render::render(s, o)};
}

/// A checkered wall at the focal distance of a lens (128x32), with `objects` (JSON, each after a
/// comma) in front of it.
scene::Scene checkeredWall(int textureScale, const std::string& objects) {
    return scene::Scene(parse(R"({
      "camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0], "up": [0, 1, 0], "fov_y": 30, "resolution": [128, 32],
                 "aperture_radius": 0.05, "focus_distance": 3},
      "materials": {"tiles": {"albedo": [0.7, 0.7, 0.7], "texture": "checker", "texture_scale": )" +
                              std::to_string(textureScale) + R"(}, "red": {"albedo": [0.7, 0.2, 0.1]}},
      "lights": [{"type": "parallelogram", "corner": [-0.5, 2, 0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [10, 10, 10]}],
      "objects": [{"type": "quad", "corner": [-3, -1, 0], "edge1": [6, 0, 0], "edge2": [0, 3, 0], "material": "tiles"})" +
                              objects + R"(],
      "render": {"spp": 16, "seed": 5, "indirect": true}
    })"));
}

/// A checkered floor under a wide lens (96x64), seen from a camera at (0, 1, 3) looking at (0, 0,
/// lookAtZ), in focus at `focus`.
scene::Scene checkeredFloor(double lookAtZ, double focus) {
    return scene::Scene(parse(R"({
      "camera": {"position": [0, 1, 3], "look_at": [0, 0, )" + std::to_string(lookAtZ) +
                              R"(], "up": [0, 1, 0], "fov_y": 40, "resolution": [96, 64],
                 "aperture_radius": 0.15, "focus_distance": )" + std::to_string(focus) + R"(},
      "materials": {"tiles": {"albedo": [0.7, 0.7, 0.7], "texture": "checker", "texture_scale": 4}},
      "lights": [{"type": "parallelogram", "corner": [-0.5, 3, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [10, 10, 10]}],
      "objects": [{"type": "quad", "corner": [-6, 0, -6], "edge1": [0, 0, 12], "edge2": [12, 0, 0], "material": "tiles"}],
      "render": {"spp": 16, "seed": 5, "indirect": true}
    })"));
}

/// A post far out of focus in front of checkeredWall's left part.
constexpr const char* kPost = R"(, {"type": "box", "min": [-0.7, -0.5, 1.8], "max": [-0.6, 1.5, 1.9], "material": "red"})";

}  // namespace

TEST(Render, ALayeredPixelOnSharpLayersKeepsItsOwnCompositionWithTextureSamples) {
    // A checkered wall at the focal distance under a lens, a post in front of its left part far
    // out of focus, --layers on. Where every ray of a pixel ends in sharp still layers (the right
    // tile: 86% of the pixels) the pixel keeps the method's own composition, with the mean albedo
    // of its texture samples, which are taken only where a pixel's samples on the textured
    // surface are sharp and still.
    // Before, no texture sample was taken with layers and the wall's checker kept the noise of
    // 16 albedos a pixel: AAF relMSE 0.000334 against 0.000105 now, a-trous 0.000471 against
    // 0.000250 (seed 5).
    const scene::Scene s = checkeredWall(6, kPost);
    const Image3f reference = mcReference(s);
    for (const char* method : {"aaf", "atrous"}) {
        const auto [with, without] = withAndWithoutTextureSamples(s, method);
        render::RenderOptions o = layeredOptions(method);
        o.layers = "off";
        const double offPixels = render::render(s, o).figure("texture_pixels").value_or(0);
        const double own = with.figure("layers_own_pixels").value_or(-1);
        EXPECT_GT(own, 0.6) << method;  // the right tile and more
        EXPECT_LT(own, 0.95) << method;  // not where the post's blur reaches
        // Every pixel whose wall samples are sharp, which is every textured one, also under the
        // post's blur (there its sharp layer carries the pixel's mean albedo: the next test).
        EXPECT_EQ(with.figure("texture_pixels").value_or(0), offPixels) << method;
        EXPECT_EQ(without.figure("texture_pixels").value_or(-1), 0.0) << method;
        const double e = metrics::relMse(with.color, reference), e0 = metrics::relMse(without.color, reference);
        EXPECT_LT(e, 0.7 * e0) << method << ": " << e << " against " << e0;
    }
}

TEST(Render, ASharpTexturedSurfaceBehindADefocusedOccluderTakesItsTextureSamplesAlbedo) {
    // A checkered wall at the focal distance behind seven thin slats far out of focus, --layers
    // on. Where the slats' blur covers part of a pixel (its coverage below 1) the wall is a sharp
    // layer seen between them; a pixel whose wall samples are sharp and still takes texture
    // samples, and the wall's samples there carry the pixel's mean albedo (the path and texture
    // samples' that pass the slats). Before, those pixels took no texture samples and the wall
    // kept the noise of its few samples' albedos: in them relMSE with texture samples equal to
    // that without; now 0.62x (AAF) and 0.81x (a-trous), and the whole image's AAF 0.00077 ->
    // 0.00038.
    std::string objects;
    for (int i = -3; i <= 3; ++i) {
        const double x = 0.3 * i;
        objects += R"(, {"type": "box", "min": [)" + std::to_string(x) + R"(, -0.5, 1.8], "max": [)" + std::to_string(x + 0.04) +
                   R"(, 1.5, 1.84], "material": "red"})";
    }
    const scene::Scene s = checkeredWall(12, objects);
    const Image3f reference = mcReference(s);
    for (const char* method : {"aaf", "atrous"}) {
        const auto [with, without] = withAndWithoutTextureSamples(s, method);
        // The pixels the slats' blur reaches.
        double e = 0, e0 = 0;
        int mixed = 0;
        for (size_t p = 0; p < reference.size(); ++p) {
            if (!(without.buffers.coverage[p] < 0.999f)) continue;
            ++mixed;
            for (int c = 0; c < 3; ++c) {
                const double r = reference[p][c];
                e += sqr(with.color[p][c] - r) / (r * r + 0.01);
                e0 += sqr(without.color[p][c] - r) / (r * r + 0.01);
            }
        }
        EXPECT_GT(mixed, 1000) << method;  // of 4096
        EXPECT_LT(e, 0.9 * e0) << method << ": " << e / mixed / 3 << " against " << e0 / mixed / 3;
        EXPECT_LT(metrics::relMse(with.color, reference), 0.8 * metrics::relMse(without.color, reference)) << method;
    }
}

TEST(Render, ASharpTexturedPixelOnABlurredLayerKeepsItsOwnComposition) {
    // A checkered floor receding through the focal plane under a wide lens, --layers on: every
    // tile's layer is blurred (the floor's |c| spans 0-4 px in each), but the pixels near focus
    // are sharper than the layer's grid can reconstruct them (|c| below 1.41 px: the ones that
    // take texture samples). Where such a pixel's rays all end whole on the floor's still layer,
    // or touch only layers at its own depth (the floor split between two layers inside it), it
    // keeps the method's own composition with its texture samples' albedo; so do the sharp
    // pixels within kTextureReach of it, inside a texel beside its edge. Before, only pixels
    // whose every layer was sharp did, and the texture samples of the rest went unused: own
    // pixels 0.66 of the textured ones, relMSE 0.79 of that without texture samples (AAF and
    // a-trous, seed 5); with whole rays alone 0.90 and 0.61; now 1.40 and 0.49. (Here AAF
    // leaves every pixel to its own composition: there is no silhouette. The next test.)
    const scene::Scene s = checkeredFloor(0, 3.16);  // receding to the horizon
    const Image3f reference = mcReference(s);
    const double pixels = 96.0 * 64.0;
    for (const char* method : {"atrous"}) {
        const auto [with, without] = withAndWithoutTextureSamples(s, method);
        EXPECT_EQ(with.figure("layers_blurred_tiles").value_or(0), 1.0) << method;
        const double textured = with.figure("texture_pixels").value_or(0) / pixels;
        EXPECT_GT(textured, 0.1) << method;  // the band in focus
        EXPECT_LT(textured, 0.4) << method;
        const double own = with.figure("layers_own_pixels").value_or(-1);
        EXPECT_GT(own, 1.2 * textured) << method;
        const double e = metrics::relMse(with.color, reference), e0 = metrics::relMse(without.color, reference);
        EXPECT_LT(e, 0.55 * e0) << method << ": " << e << " against " << e0;
    }
}

TEST(Render, AFilterKeepsItsOwnImageAwayFromSilhouettes) {
    // With layers, aaf and maaf leave the pixels with no silhouette within kSilhouetteReach (no
    // pixel whose samples saw several surfaces) to their own
    // composition, the image they give without layers: the same pixels, bit for bit (the same
    // samples, texture samples and filters). A checkered floor seen from above through a wide
    // lens, in focus at the image's centre and blurred towards its top and bottom, has no
    // silhouette: the whole image. A checkered wall with a post far out of focus in front of its
    // left part: the pixels by the post's blurred edge are reconstructed, the rest are left.
    const scene::Scene floor = checkeredFloor(1.5, 1.8), wall = checkeredWall(6, kPost);
    for (const char* method : {"aaf", "maaf"}) {
        render::RenderOptions o = layeredOptions(method);
        const render::RenderResult on = render::render(floor, o);
        o.layers = "off";
        const render::RenderResult off = render::render(floor, o);
        EXPECT_EQ(on.figure("layers_blurred_tiles").value_or(-1), 0.0) << method;  // none reconstructed
        EXPECT_EQ(on.figure("layers_method_tiles").value_or(-1), 1.0) << method;
        EXPECT_EQ(on.figure("layers_own_pixels").value_or(-1), 1.0) << method;
        EXPECT_EQ(on.figure("texture_pixels"), off.figure("texture_pixels")) << method;
        EXPECT_TRUE(std::equal(on.color.data(), on.color.data() + on.color.size(), off.color.data())) << method;

        render::RenderOptions w = layeredOptions(method);
        const render::RenderResult layered = render::render(wall, w);
        w.layers = "off";
        const render::RenderResult plain = render::render(wall, w);
        ASSERT_EQ(layered.methodPixels.size(), layered.color.size()) << method;
        size_t left = 0, same = 0, silhouette = 0, reconstructed = 0;
        for (size_t p = 0; p < layered.color.size(); ++p) {
            const bool equal = layered.color[p] == plain.color[p];
            if (layered.methodPixels[p]) {
                ++left;
                same += equal;
                continue;
            }
            if (plain.buffers.coverage[p] < 0.999f) ++silhouette, reconstructed += !equal;
            // Near the post: some pixel within the reach saw two surfaces.
            const int x = int(p % 128), y = int(p / 128), r = filter::kSilhouetteReach;
            bool near = false;
            for (int yy = std::max(0, y - r); yy <= std::min(31, y + r); ++yy)
                for (int xx = std::max(0, x - r); xx <= std::min(127, x + r); ++xx) near |= plain.buffers.coverage[size_t(yy) * 128 + xx] < 1.f;
            EXPECT_TRUE(near) << method << " at " << x << ", " << y;
        }
        EXPECT_EQ(same, left) << method;
        EXPECT_GE(left, layered.color.size() / 4) << method;  // the right part
        // The post's blur, reconstructed where its rays do not all end on sharp layers (290 of
        // its 610 pixels; the rest keep the same composition: the first test).
        EXPECT_GT(silhouette, 200u) << method;
        EXPECT_GT(reconstructed, silhouette / 3) << method;
    }
}

TEST(Render, AnEmittersEdgeTakesItsDenseEmissionAtAnySampleCountBelowItsRays) {
    // A lamp seen from below, MC without layers: a pixel on its edge takes its emitted light from
    // kEmitterEdgeRays camera rays (denseEmission), the same value at 16 samples a pixel (topped
    // up to kEmitterEdgeSpp) and at kEmitterEdgeSpp, where before it kept those samples' own
    // (cornell at 256x256, 256 spp: relMSE 0.000190 before, 0.000131 with them, against a
    // 1024-spp render).
    const scene::Scene s(parse(R"({
      "camera": {"position": [0, 0, 0], "look_at": [0, 1, 0], "up": [0, 0, 1], "fov_y": 40, "resolution": [24, 24]},
      "materials": {"grey": {"albedo": [0.5, 0.5, 0.5]}},
      "lights": [{"type": "parallelogram", "corner": [-0.3, 1, -0.2], "edge1": [0.6, 0, 0], "edge2": [0, 0, 0.4], "radiance": [5, 5, 5]}],
      "objects": [{"type": "quad", "corner": [-3, 1.01, -3], "edge1": [0, 0, 6], "edge2": [6, 0, 0], "material": "grey"}],
      "render": {"spp": 16, "seed": 3, "indirect": false}
    })"));
    render::RenderOptions o;
    o.quiet = true;
    o.method = "mc";
    o.layers = "off";
    o.spp = 16;
    const render::RenderResult few = render::render(s, o);
    o.spp = int(render::kEmitterEdgeSpp);
    const render::RenderResult many = render::render(s, o);
    int edges = 0;
    for (size_t p = 0; p < few.buffers.emission.size(); ++p) {
        const Vec3f e = few.buffers.emission[p];
        if (!(e.x > 0.f && e.x < 5.f)) continue;  // the lamp's edge: partly lit
        ++edges;
        EXPECT_EQ(e, many.buffers.emission[p]) << "pixel " << p;
    }
    EXPECT_GE(edges, 20);  // the lamp's outline, about 2 x (14 + 10) pixels
}

TEST(Render, ALampOfTrianglesIsOneLightForTheFilters) {
    // kPlaneScene's light as the fan of four triangles about its centre: the filters see one
    // light (ViewGeometry::lights), with the whole light's centroid, size and parts, and every
    // sample's record names it; the image is the parallelogram's.
    const std::string fan = R"("lights": [
      {"type": "triangle", "corner": [0.2, 1, 0], "edge1": [-0.5, 0, -0.5], "edge2": [0.5, 0, -0.5], "radiance": [10, 10, 10]},
      {"type": "triangle", "corner": [0.2, 1, 0], "edge1": [0.5, 0, -0.5], "edge2": [0.5, 0, 0.5], "radiance": [10, 10, 10]},
      {"type": "triangle", "corner": [0.2, 1, 0], "edge1": [0.5, 0, 0.5], "edge2": [-0.5, 0, 0.5], "radiance": [10, 10, 10]},
      {"type": "triangle", "corner": [0.2, 1, 0], "edge1": [-0.5, 0, 0.5], "edge2": [-0.5, 0, -0.5], "radiance": [10, 10, 10]}],)";
    std::string json = kPlaneScene;
    const size_t from = json.find(R"("lights": [)"), to = json.find("\n", from);
    json = json.substr(0, from) + fan + json.substr(to);
    scene::Scene s(parse(json));
    ASSERT_EQ(s.desc().lights.size(), 4u);
    render::Camera camera(s.desc().camera);
    render::PathSampler sampler(s, camera, false, 5);
    const ViewGeometry view = sampler.view();
    ASSERT_EQ(view.lights.size(), 1u);
    const ViewGeometry::Light& l = view.lights[0];
    EXPECT_NEAR(length(l.center - Vec3f(0.2f, 1, 0)), 0.f, 1e-6f);
    EXPECT_NEAR(l.sigma, 0.5f, 1e-6f);  // sqrt(area) / 2 of the whole 1 x 1 light
    EXPECT_NEAR(dot(l.normal, Vec3f(0, -1, 0)), 1.f, 1e-6f);
    ASSERT_EQ(l.parts.size(), 4u);
    for (const auto& part : l.parts) {
        EXPECT_TRUE(part.triangle);
        EXPECT_NEAR(part.share, 0.25f, 1e-6f);
    }
    render::TracedSample t[16];
    sampler.traceBatch(12, 12, 0, 16, true, t);
    for (const auto& sample : t) {
        EXPECT_EQ(sample.record.light, 0u);
        EXPECT_NEAR(sample.d1, length(l.center - sample.position), 1e-5f);
    }
    render::RenderOptions o;
    o.quiet = true;
    o.spp = 256;
    const Image3f img = render::render(s, o).color;
    const Image3f whole = renderJson(kPlaneScene, o).color;
    double a = 0, b = 0;  // the images' means: 256 spp leave each pixel about 1% apart
    for (size_t i = 0; i < img.size(); ++i) {
        a += img[i].y;
        b += whole[i].y;
    }
    EXPECT_NEAR(a, b, 0.003 * b);
}

TEST(Render, TheSamplesThatChooseALightAreStratifiedOverIt) {
    // Light choice and light point are one 4D Sobol point (with the shutter time): of a pixel's
    // 16 samples, the 8 that choose each of two equal lights put exactly 4 in each half of it,
    // along either edge. (With the choice drawn apart, 3-5 splits were common.)
    std::string json = kPlaneScene;
    const size_t from = json.find(R"("lights": [)"), to = json.find("\n", from);
    json = json.substr(0, from) +
           R"("lights": [{"type": "parallelogram", "corner": [-1.5, 1, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [10, 10, 10]},
                         {"type": "parallelogram", "corner": [0.5, 1, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [10, 10, 10]}],)" +
           json.substr(to);
    scene::Scene s(parse(json));
    render::Camera camera(s.desc().camera);
    render::PathSampler sampler(s, camera, false, 7);
    const auto& lights = s.desc().lights;
    for (int y = 0; y < 24; y += 5)
        for (int x = 0; x < 24; x += 5) {
            render::TracedSample t[16];
            sampler.traceBatch(x, y, 0, 16, false, t);
            int chose[2] = {}, lowA[2] = {}, lowB[2] = {};
            for (const auto& sample : t) {
                ASSERT_TRUE(sample.hit);
                const uint32_t l = sample.record.light;
                const Vec3f d = sample.record.lightPoint - lights[l].corner;
                ++chose[l];
                lowA[l] += d.x < 0.5f;
                lowB[l] += d.z < 0.5f;
            }
            for (int l = 0; l < 2; ++l) {
                EXPECT_EQ(chose[l], 8) << x << "," << y;
                EXPECT_EQ(2 * lowA[l], chose[l]) << x << "," << y << " light " << l;
                EXPECT_EQ(2 * lowB[l], chose[l]) << x << "," << y << " light " << l;
            }
        }
}

/// Tilted lights of three powers (two parallelograms and a triangle) over a tilted floor, a
/// sphere and a box, through a thin lens that translates over the shutter: no ray, normal or
/// light point falls on round numbers, so that a sample computed by another instruction
/// sequence (a vector loop or its scalar remainder, with or without multiply-add contraction)
/// would differ in its last bits.
const char* kTiltedLights = R"({
  "camera": {"position": [0.13, 1.17, 2.31], "look_at": [0.05, 0.29, 0.02], "up": [0, 1, 0], "fov_y": 41,
             "resolution": [32, 32], "aperture_radius": 0.09, "focus_distance": 1.37, "velocity": [0.031, 0.007, 0]},
  "materials": {"grey": {"albedo": [0.61, 0.63, 0.58]}, "red": {"albedo": [0.7, 0.21, 0.13]}},
  "lights": [{"type": "parallelogram", "corner": [-0.43, 2.03, -0.37], "edge1": [0.71, 0.13, 0.05], "edge2": [0.07, -0.11, 0.83], "radiance": [17, 19, 21]},
             {"type": "triangle", "corner": [0.91, 1.71, 0.33], "edge1": [0.29, -0.07, 0.41], "edge2": [0.37, 0.03, -0.19], "radiance": [9, 7, 5]},
             {"type": "parallelogram", "corner": [-1.3, 1.2, 0.7], "edge1": [0.03, 0.31, 0.02], "edge2": [0.05, 0.07, -0.33], "radiance": [3, 4, 5]}],
  "objects": [{"type": "quad", "corner": [-3.1, 0.07, 2.9], "edge1": [6.3, -0.21, 0.11], "edge2": [0.13, 0.17, -6.1], "material": "grey"},
              {"type": "sphere", "center": [0.21, 0.43, 0.11], "radius": 0.23, "material": "red"},
              {"type": "box", "min": [-0.61, 0.1, -0.37], "max": [-0.17, 0.71, -0.05], "material": "grey"}],
  "render": {"spp": 16, "seed": 5, "indirect": true}
})";

/// samplePixels traces several pixels' samples as one wave (their shadow rays and bounces as
/// Embree streams; their camera rays, light samples and bounce directions as loops across the
/// wave): each sample must be what tracing its pixel alone gives, bit for bit, whatever the
/// wave's other pixels, counts and spans, and so wherever it falls in a batch.
void expectPixelsTracedTogetherAreThePixelsTracedAlone(const char* json) {
    scene::Scene s(parse(json));
    render::Camera camera(s.desc().camera);
    render::PathSampler sampler(s, camera, true, 3);
    std::vector<render::PathSampler::SampleRun> runs;
    uint32_t total = 0;
    for (int i = 0; i < 40; ++i) {
        const uint32_t count = uint32_t(i * 7 % 23), first = uint32_t(i % 5) * 3;  // 0 .. 22 samples, some empty
        runs.push_back({(i * 5) % 32, (i * 3) % 32, first, count, nullptr});
        total += count;
    }
    for (bool slopes : {false, true}) {
        std::vector<render::TracedSample> together(total), alone(total);
        uint32_t offset = 0;
        for (auto& r : runs) {
            r.out = together.data() + offset;
            sampler.traceBatch(r.x, r.y, r.first, r.count, slopes, alone.data() + offset);
            offset += r.count;
        }
        sampler.traceMany(runs.data(), runs.size(), slopes);
        int hits = 0, bounces = 0;
        for (uint32_t i = 0; i < total; ++i) {
            const render::TracedSample &a = together[i], &b = alone[i];
            ASSERT_EQ(a.hit, b.hit) << i;
            hits += a.hit;
            bounces += a.bounceHit;
            EXPECT_EQ(a.occluded, b.occluded) << i;
            EXPECT_EQ(a.bounceHit, b.bounceHit) << i;
            EXPECT_EQ(a.rays, b.rays) << i;
            EXPECT_EQ(a.tOccluder, b.tOccluder) << i;
            EXPECT_EQ(0, std::memcmp(&a.record, &b.record, sizeof(SampleRecord))) << i;
            EXPECT_EQ(0, std::memcmp(&a.position, &b.position, sizeof(Vec3f))) << i;
        }
        EXPECT_GT(hits, int(total) / 2);
        EXPECT_GT(bounces, 0);
    }
}

TEST(Render, PixelsTracedTogetherAreThePixelsTracedAlone) {
    expectPixelsTracedTogetherAreThePixelsTracedAlone(kPlankUnderLens);
    // (With the sampler's loops compiled with multiply-add contraction, 34 of the 892 records
    // compared here differed: those that fell in a vector loop in one wave and in its scalar
    // remainder in the other. The plank's axis-aligned floor and light hid it.)
    expectPixelsTracedTogetherAreThePixelsTracedAlone(kTiltedLights);
}

TEST(Render, LightSamplesTakenTogetherAreTheSamplesTakenOneByOne) {
    // PathSampler::sampleLights (the light choice by halving steps, gathers by light index)
    // against sampleLight (upper_bound on the cumulative shares): the same light and bits, for
    // choices on and next to every share's boundary, lights of no power among them (equal
    // shares), and receivers the lights face and those they do not.
    std::string json = kTiltedLights;
    const std::string dim = R"({"type": "parallelogram", "corner": [2, 2, 2], "edge1": [0.1, 0, 0], "edge2": [0, 0, 0.1], "radiance": [0, 0, 0]},)";
    json.insert(json.find("{\"type\": \"triangle\""), dim);
    scene::Scene s(parse(json));
    ASSERT_EQ(s.desc().lights.size(), 4u);
    render::Camera camera(s.desc().camera);
    render::PathSampler sampler(s, camera, true, 3);
    std::vector<float> choices = {0.f, 0.999999f};
    float total = 0, cumulative = 0;
    for (const auto& l : s.desc().lights) total += std::max(1e-12f, luminance(l.radiance) * l.area());
    for (const auto& l : s.desc().lights) {
        cumulative += std::max(1e-12f, luminance(l.radiance) * l.area()) / total;
        for (float c : {std::nextafter(cumulative, 0.f), cumulative, std::nextafter(cumulative, 1.f)})
            if (c < 1.f) choices.push_back(c);
    }
    constexpr int n = 203;  // not a multiple of any vector width
    std::vector<Vec3f> p(n), nrm(n);
    std::vector<Vec2f> u(n);
    std::vector<float> choice(n);
    uint32_t state = 12345;
    auto next = [&] { return (state = state * 1664525u + 1013904223u) * 0x1p-32f; };
    for (int k = 0; k < n; ++k) {
        p[k] = {next() * 4 - 2, next() * 2, next() * 4 - 2};
        nrm[k] = normalize(Vec3f(next() - 0.5f, next() - 0.3f, next() - 0.5f));
        u[k] = {next(), next()};
        choice[k] = k < int(choices.size()) ? choices[k] : next();
    }
    std::vector<render::PathSampler::LightSample> together(n);
    sampler.sampleLights(n, p.data(), nrm.data(), u.data(), choice.data(), together.data());
    int lit = 0, chosen[4] = {};
    for (int k = 0; k < n; ++k) {
        const render::PathSampler::LightSample alone = sampler.sampleLight(p[k], nrm[k], u[k], choice[k]);
        const render::PathSampler::LightSample& t = together[k];
        ASSERT_EQ(alone.light, t.light) << k << " choice " << choice[k];
        EXPECT_EQ(0, std::memcmp(&alone.point, &t.point, sizeof(Vec3f))) << k;
        EXPECT_EQ(0, std::memcmp(&alone.toLight, &t.toLight, sizeof(Vec3f))) << k;
        EXPECT_EQ(0, std::memcmp(&alone.irradiance, &t.irradiance, sizeof(Vec3f))) << k;
        EXPECT_EQ(0, std::memcmp(&alone.distance, &t.distance, sizeof(float))) << k;
        lit += maxComponent(t.irradiance) > 0;
        ++chosen[t.light];
    }
    EXPECT_GT(chosen[0], 0);
    EXPECT_GT(chosen[2], 0);
    EXPECT_GT(chosen[3], 0);
    EXPECT_GT(lit, n / 5);
    EXPECT_LT(lit, n);
}

TEST(Render, SamplesTracedAgainAreTheSamplesAndFindTheirSlot) {
    // What lets MAAF trace the samples of its outer-component pixels again instead of keeping
    // them: the sampler is deterministic per pixel and sample index (whatever the batches and
    // the span queries), and PixelStats::slotOf finds the slot add() put each sample in.
    scene::Scene s(parse(kPlankUnderLens));
    render::Camera camera(s.desc().camera);
    render::PathSampler sampler(s, camera, true, 11);
    const ViewGeometry view = sampler.view();
    constexpr uint32_t kInitial = 16, kTotal = 27;
    int twoSurfaces = 0, secondSlotSamples = 0;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            // As the method samples: 16 with spans (slopes), then adaptive samples without.
            render::SlotPool pool;
    render::PixelStats ps;
            render::TracedSample first[kTotal], again[kTotal];
            sampler.traceBatch(x, y, 0, kInitial, true, first);
            sampler.traceBatch(x, y, kInitial, kTotal - kInitial, false, first + kInitial);
            int slot[kTotal];
            for (uint32_t i = 0; i < kTotal; ++i) slot[i] = ps.add(first[i], view, i < kInitial, pool);
            // Traced again in other batches, without spans.
            sampler.traceBatch(x, y, 0, 5, false, again);
            sampler.traceBatch(x, y, 5, kTotal - 5, false, again + 5);
            for (uint32_t i = 0; i < kTotal; ++i) {
                const SampleRecord &a = first[i].record, &b = again[i].record;
                ASSERT_EQ(first[i].hit, again[i].hit) << x << "," << y << " #" << i;
                EXPECT_EQ(first[i].object, again[i].object);
                EXPECT_EQ(first[i].occluded, again[i].occluded) << x << "," << y << " #" << i;
                EXPECT_EQ(0, std::memcmp(&a.direct, &b.direct, sizeof(Vec3f)));
                EXPECT_EQ(0, std::memcmp(&a.indirect, &b.indirect, sizeof(Vec3f)));
                EXPECT_EQ(0, std::memcmp(&a.lightPoint, &b.lightPoint, sizeof(Vec3f)));
                EXPECT_EQ(0, std::memcmp(&a.bounceDir, &b.bounceDir, sizeof(Vec3f)));
                EXPECT_EQ(0, std::memcmp(&a.lens, &b.lens, sizeof(Vec2f)));
                EXPECT_EQ(a.unoccluded, b.unoccluded);
                EXPECT_EQ(ps.slotOf(again[i]), slot[i]) << x << "," << y << " #" << i;
                secondSlotSamples += slot[i] == 1;
            }
            twoSurfaces += ps.slot(1).n > 0;
        }
    EXPECT_GT(twoSurfaces, 20);  // the test sees both slots
    EXPECT_GT(secondSlotSamples, 100);
}

TEST(Render, MaafTracingAgainGivesTheImageOfTheRecords) {
    // The outer-component pixels' initial samples traced again (the default) give the image of
    // --maaf-keep-records bit for bit (all components everywhere, so that most pixels use them).
    scene::Scene s(parse(kPlankUnderLens));
    render::RenderOptions o;
    o.quiet = true;
    o.method = "maaf";
    o.maafFit = false;
    o.maafKeepRecords = true;
    render::RenderResult kept = render::render(s, o);
    o.maafKeepRecords = false;
    render::RenderResult traced = render::render(s, o);
    EXPECT_EQ(kept.figure("maaf_retrace"), 0.0);
    EXPECT_EQ(traced.figure("maaf_retrace"), 1.0);
    EXPECT_GT(traced.figure("maaf_outer_component_pixels").value_or(-1), 0.5 * 32 * 32);
    EXPECT_GT(traced.rays, kept.rays);  // the samples traced again
    ASSERT_EQ(kept.color.size(), traced.color.size());
    EXPECT_EQ(0, std::memcmp(kept.color.data(), traced.color.data(), kept.color.size() * sizeof(Vec3f)));
}

TEST(Render, MaafIsAafWhereNoFilterHasOuterComponents) {
    // By default MAAF runs AAF's pipeline (slopes, rates, filter) and MAAF's filter only where an
    // effect has outer components: with the central component alone (--maaf-components 1) the
    // image and the samples are AAF's bit for bit (a lens, a shadow and indirect light here).
    scene::Scene s(parse(kPlankUnderLens));
    render::RenderOptions o;
    o.quiet = true;
    o.method = "aaf";
    render::RenderResult aaf = render::render(s, o);
    o.method = "maaf";
    o.maafComponents = 1;
    render::RenderResult central = render::render(s, o);
    EXPECT_EQ(central.figure("maaf_outer_component_pixels").value_or(-1), 0.0);
    EXPECT_EQ(central.rays, aaf.rays);
    EXPECT_EQ(central.sppAverage, aaf.sppAverage);
    ASSERT_EQ(central.color.size(), aaf.color.size());
    EXPECT_EQ(0, std::memcmp(central.color.data(), aaf.color.data(), aaf.color.size() * sizeof(Vec3f)));

    // With outer components (all of them everywhere, so that most pixels use them) the samples
    // are still AAF's; only the pixels' filters differ, and the outer pixels' initial samples
    // are traced again.
    o.maafComponents = 5;
    o.maafFit = false;
    render::RenderResult outer = render::render(s, o);
    EXPECT_GT(outer.figure("maaf_outer_component_pixels").value_or(-1), 0.5 * 32 * 32);
    EXPECT_EQ(outer.sppAverage, aaf.sppAverage);
    EXPECT_GT(outer.rays, aaf.rays);
    EXPECT_NE(0, std::memcmp(outer.color.data(), aaf.color.data(), aaf.color.size() * sizeof(Vec3f)));
}

TEST(Render, MaafUsesTheCentralComponentOnAMovingSurface) {
    // MAAF's analysis has no time axis: a pixel whose primary surface moves over the shutter
    // takes the central component alone (MaafOptions::movingObjects). kPlankUnderLens with all
    // components everywhere (as above: most pixels use outer components while it is still).
    // With both objects moving, no pixel has outer components and the image and samples are
    // AAF's bit for bit; with the plank alone moving, the still floor keeps its outer components.
    const std::string moving = kPlankUnderLens;
    const std::string grey = R"("material": "grey"})", red = R"("material": "red"})";
    auto withVelocity = [](std::string text, const std::string& object, const char* velocity) {
        const size_t at = text.find(object);
        EXPECT_NE(at, std::string::npos);
        return text.replace(at, object.size(), object.substr(0, object.size() - 1) + R"(, "velocity": )" + velocity + "}");
    };
    const std::string plankMoves = withVelocity(moving, red, "[0.2, 0, 0]");
    const std::string bothMove = withVelocity(plankMoves, grey, "[0.05, 0, 0]");
    render::RenderOptions o;
    o.quiet = true;
    o.maafComponents = 5;
    o.maafFit = false;
    {
        const scene::Scene scene(parse(bothMove));
        o.method = "aaf";
        const render::RenderResult aaf = render::render(scene, o);
        o.method = "maaf";
        const render::RenderResult maaf = render::render(scene, o);
        EXPECT_EQ(maaf.figure("maaf_outer_component_pixels").value_or(-1), 0.0);
        EXPECT_EQ(maaf.rays, aaf.rays);
        ASSERT_EQ(maaf.color.size(), aaf.color.size());
        EXPECT_EQ(0, std::memcmp(maaf.color.data(), aaf.color.data(), aaf.color.size() * sizeof(Vec3f)));
    }
    const scene::Scene still(parse(kPlankUnderLens)), plank(parse(plankMoves));
    o.method = "maaf";
    const double outerStill = render::render(still, o).figure("maaf_outer_component_pixels").value_or(-1);
    const double outerFloor = render::render(plank, o).figure("maaf_outer_component_pixels").value_or(-1);
    EXPECT_GT(outerStill, 0.5 * 32 * 32);
    EXPECT_GT(outerFloor, 0.9 * outerStill);  // (the floor is most of the image)
}

namespace {
/// MAAF's render options at `spp` initial samples and `seed`, without progress output.
render::RenderOptions quietMaaf(int spp, uint32_t seed) {
    render::RenderOptions o;
    o.quiet = true;
    o.method = "maaf";
    o.spp = spp;
    o.seed = seed;
    return o;
}
}  // namespace

TEST(Render, MaafSparseComponentsGiveTheDenseImage) {
    // By default MAAF decides first which pixels' indirect filters have outer components
    // (filter::maafIndirectOuter) and computes the frames, components and accumulations only
    // within the filter's window of them; --maaf-dense computes them in every pixel. Cornell at
    // 96x96 (a lens, a grazing floor and ceiling: a few hundred pixels with outer components):
    // the same pixels, the same image bytes, less accumulator memory; also with a wider window
    // (the region follows it) and with seven components.
    scene::SceneDesc desc = scene::loadScene("cornell");
    desc.camera.width = desc.camera.height = 96;
    const scene::Scene scene(std::move(desc));
    for (auto [radius, components] : {std::pair{10, 5}, std::pair{16, 5}, std::pair{10, 7}}) {
        render::RenderOptions o = quietMaaf(4, 9);
        o.maafRadius = radius;
        o.maafComponents = components;
        const render::RenderResult sparse = render::render(scene, o);
        o.maafSparse = false;
        const render::RenderResult dense = render::render(scene, o);
        const double outer = sparse.figure("maaf_outer_component_pixels").value_or(-1);
        EXPECT_GT(outer, 20) << "radius " << radius << ", " << components << " components";
        EXPECT_LT(outer, 0.5 * 96 * 96);  // a sparse region, or the test shows nothing
        EXPECT_EQ(outer, dense.figure("maaf_outer_component_pixels").value_or(-2));
        EXPECT_LT(sparse.figure("maaf_accumulator_bytes").value_or(0), dense.figure("maaf_accumulator_bytes").value_or(0));
        EXPECT_EQ(sparse.rays, dense.rays);
        ASSERT_EQ(sparse.color.size(), dense.color.size());
        EXPECT_EQ(0, std::memcmp(sparse.color.data(), dense.color.data(), dense.color.size() * sizeof(Vec3f)))
            << "radius " << radius << ", " << components << " components";
    }
}

TEST(Render, MaafSparseShadowComponentsGiveTheDenseImage) {
    // A plank's narrow penumbra (no indirect light) with --maaf-shadow-components: the direct
    // light's filter has outer components there (filter::maafDirectOuter decides which pixels
    // first). Sparse and dense give the same pixels and the same image bytes; without shadow
    // components (the default) none, and AAF's image.
    const scene::Scene scene(parse(R"({
      "camera": {"position": [-0.4, 2.0, 0.0], "look_at": [-0.4, 0, 0], "up": [0, 0, -1], "fov_y": 40, "resolution": [128, 48]},
      "materials": {"floor": {"albedo": [0.7, 0.7, 0.7]}, "plank": {"albedo": [0.4, 0.3, 0.2]}},
      "lights": [{"type": "parallelogram", "corner": [1.8, 3, -0.4], "edge1": [0.8, 0, 0], "edge2": [0, 0, 0.8], "radiance": [60, 60, 60]}],
      "objects": [{"type": "quad", "corner": [-4, 0, 4], "edge1": [8, 0, 0], "edge2": [0, 0, -8], "material": "floor"},
                  {"type": "box", "min": [0.0, 0.2, -2], "max": [0.3, 0.25, 2], "material": "plank"}],
      "render": {"spp": 16, "seed": 1, "indirect": false}})"));
    render::RenderOptions o = quietMaaf(8, 4);
    o.maafShadowComponents = true;
    const render::RenderResult sparse = render::render(scene, o);
    o.maafSparse = false;
    const render::RenderResult dense = render::render(scene, o);
    const double shadowOuter = sparse.figure("maaf_shadow_outer_pixels").value_or(-1);
    EXPECT_GT(shadowOuter, 20);
    EXPECT_EQ(shadowOuter, sparse.figure("maaf_outer_component_pixels").value_or(-2));  // no indirect light
    EXPECT_EQ(shadowOuter, dense.figure("maaf_shadow_outer_pixels").value_or(-3));
    ASSERT_EQ(sparse.color.size(), dense.color.size());
    EXPECT_EQ(0, std::memcmp(sparse.color.data(), dense.color.data(), dense.color.size() * sizeof(Vec3f)));
    o.maafSparse = true;
    o.maafShadowComponents = false;
    const render::RenderResult none = render::render(scene, o);
    o.method = "aaf";
    const render::RenderResult aaf = render::render(scene, o);
    EXPECT_EQ(none.figure("maaf_outer_component_pixels").value_or(-1), 0.0);
    ASSERT_EQ(none.color.size(), aaf.color.size());
    EXPECT_EQ(0, std::memcmp(none.color.data(), aaf.color.data(), aaf.color.size() * sizeof(Vec3f)));
    EXPECT_NE(0, std::memcmp(sparse.color.data(), aaf.color.data(), aaf.color.size() * sizeof(Vec3f)));
}

namespace {
/// A path sample on surface `object` at depth 1 with the given direct light (albedo 1).
render::TracedSample surfaceSample(uint32_t object, float light) {
    render::TracedSample s;
    s.hit = true;
    s.object = object;
    s.albedo = Vec3f(1.f);
    s.normal = {0, 0, 1};
    s.position = {0, 0, object == 0 ? 0.f : 1.f};
    s.depth = 1;
    s.record.direct = Vec3f(light);
    return s;
}
}  // namespace

TEST(Render, MixedPixelsAreToppedUpByTheirRelativeVariance) {
    ViewGeometry view;
    view.focalPixels = 100;
    render::SlotPool pool;
    render::PixelStats one, mixed, alike, bright;
    for (int i = 0; i < 16; ++i) {
        one.add(surfaceSample(0, 1.f), view, false, pool);
        mixed.add(surfaceSample(i % 2, i % 2 ? 1.f : 0.05f), view, false, pool);   // an edge with contrast
        alike.add(surfaceSample(i % 2, 0.5f), view, false, pool);                  // two surfaces, same light
        bright.add(surfaceSample(i % 4 == 0, i % 4 == 0 ? 20.f : 0.f), view, false, pool);  // a small bright part
    }
    EXPECT_EQ(one.mixedTopUp(0.01f, 64), 0u);    // one surface: the filters reach it
    EXPECT_EQ(alike.mixedTopUp(0.01f, 64), 0u);  // no variance to remove
    // var / (mean^2 + 0.01) = 0.226 / 0.289 -> 78 samples at tau 0.01, capped at 64 in all.
    EXPECT_EQ(mixed.mixedTopUp(0.01f, 64), 48u);
    EXPECT_EQ(mixed.mixedTopUp(0.05f, 64), 0u);  // 15.6 samples: already 16
    EXPECT_EQ(mixed.mixedTopUp(0.01f, 16), 0u);  // the cap counts every sample
    EXPECT_GT(bright.mixedTopUp(0.05f, 1024), 16u);
    EXPECT_EQ(one.primary(), 0);
}

TEST(Render, MixedPixelsWhoseSurfacesAllMoveTakeFewerTopUps) {
    // A row of pixels, each with the edge of the test above (78 samples wanted at tau 0.01, 48
    // more) and a still miss, whose motion does not count. Their surface samples move 20 px
    // along the row, but in pixel 3 only 1.5 px (tau x 0.75: no change), in pixel 20 one sample
    // is still, and from pixel 25 on all are still but in pixel 30.
    constexpr int W = 41;
    ViewGeometry view;
    view.focalPixels = 100;
    render::PixelStatsImage stats(W, 1);
    LightFieldSamples lf(W, 1);
    {
        render::LightFieldStage record(&lf, [](size_t) { return 17u; });
        for (int x = 0; x < W; ++x)
            for (int i = 0; i < 17; ++i) {
                if (i == 16) {  // the miss, in the light field only
                    record.record(x, 0, render::TracedSample{}, -1);
                    continue;
                }
                render::TracedSample s = surfaceSample(i % 2, i % 2 ? 1.f : 0.05f);
                s.motion = x == 3 ? Vec2f{1.5f, 0.f} : (x >= 25 && x != 30) || (x == 20 && i == 3) ? Vec2f{0.f, 0.f} : Vec2f{20.f, 0.f};
                record.record(x, 0, s, stats(x, 0).add(s, view, false, stats.pool()));
            }
    }
    ASSERT_EQ(stats(0, 0).mixedTopUp(render::kMixedTau, render::kMixedSpp), 48u);
    const Image<uint32_t> pooled = render::mixedTopUps(stats, render::blurPooling(&lf, view, {}), 1.f);
    // Pixel 10's trail (pixels 0-20) moves but for pixel 20: tau x 0.5 x 20 x 20 / 21, 8.2
    // samples wanted, already 16.
    EXPECT_EQ(pooled(10, 0), 0u);
    EXPECT_EQ(pooled(3, 0), 48u);
    EXPECT_EQ(pooled(20, 0), 48u);
    EXPECT_EQ(pooled(27, 0), 48u);
    // Pixel 30's trail (20-40) is mostly still: only 21-24 and itself pool (tau x 2.4).
    EXPECT_GT(pooled(30, 0), 0u);
    EXPECT_LT(pooled(30, 0), 48u);
    Image<uint8_t> bent(W, 1);
    bent(10, 0) = 1;  // a surface turning towards the camera near: aaf and maaf compose it themselves
    EXPECT_EQ(render::mixedTopUps(stats, render::blurPooling(&lf, view, bent), 1.f)(10, 0), 48u);
    const Image<uint32_t> alone = render::mixedTopUps(stats, render::blurPooling(nullptr, view, {}), 1.f);  // --layers off
    for (int x = 0; x < W; ++x) EXPECT_EQ(alone(x, 0), 48u);
}

TEST(Render, MixedPixelsWhoseSurfacesAreAllDefocusedTakeFewerTopUps) {
    // Still pixels with the edge of the tests above (48 more samples wanted at tau alone), their
    // surface samples at depths whose circles of confusion are 4 px (pixel 0: tau x 0.5 x 16,
    // 9.8 samples wanted, already 16), 1.71 px (pixel 1: tau x 1.47, 53 wanted), 1 px (pixel 2:
    // below kLayerBlurFrom, no change); in pixel 3 one sample of the 4-px ones is in focus.
    ViewGeometry view;
    view.focalPixels = 100;
    view.apertureRadius = 0.04f;
    view.focusDistance = 1;
    ASSERT_NEAR(std::abs(view.defocusSlope(0.5f)), 4.f, 1e-5f);
    ASSERT_NEAR(std::abs(view.defocusSlope(0.7f)), 1.714f, 1e-3f);
    ASSERT_NEAR(std::abs(view.defocusSlope(0.8f)), 1.f, 1e-5f);
    constexpr int W = 4;
    const float depth[W] = {0.5f, 0.7f, 0.8f, 0.5f};
    render::PixelStatsImage stats(W, 1);
    LightFieldSamples lf(W, 1);
    {
        render::LightFieldStage record(&lf, [](size_t) { return 16u; });
        for (int x = 0; x < W; ++x)
            for (int i = 0; i < 16; ++i) {
                render::TracedSample s = surfaceSample(i % 2, i % 2 ? 1.f : 0.05f);
                s.depth = x == 3 && i == 5 ? 1.f : depth[x];
                record.record(x, 0, s, stats(x, 0).add(s, view, false, stats.pool()));
            }
    }
    for (int x = 0; x < W; ++x) ASSERT_EQ(stats(x, 0).mixedTopUp(render::kMixedTau, render::kMixedSpp), 48u);
    const Image<uint32_t> pooled = render::mixedTopUps(stats, render::blurPooling(&lf, view, {}), 1.f);
    EXPECT_EQ(pooled(0, 0), 0u);
    EXPECT_GT(pooled(1, 0), 30u);
    EXPECT_LT(pooled(1, 0), 45u);
    EXPECT_EQ(pooled(2, 0), 48u);
    EXPECT_EQ(pooled(3, 0), 48u);
    Image<uint8_t> bent(W, 1);
    bent(0, 0) = 1;  // aaf and maaf compose it themselves
    EXPECT_EQ(render::mixedTopUps(stats, render::blurPooling(&lf, view, bent), 1.f)(0, 0), 48u);
}

TEST(Render, PixelStatsTakeFurtherSlotsOnlyForASecondSurface) {
    // One surface: no block from the pool, and slots 1.. read as empty. A second surface takes
    // one block, which the third shares; a fourth goes nowhere. Moving the image of statistics
    // keeps every pixel's block (the pool stays where it is).
    ViewGeometry view;
    view.width = view.height = 2;
    view.focalPixels = 100;
    render::PixelStatsImage stats(2, 2);
    render::SlotPool& pool = stats.pool();
    auto sample = [](uint32_t object) {
        render::TracedSample s = surfaceSample(object, 0.5f);
        s.position = {0, 0, float(object)};
        return s;
    };
    for (int i = 0; i < 10; ++i) EXPECT_EQ(stats(0, 0).add(sample(0), view, false, pool), 0);
    EXPECT_EQ(pool.blocks(), 0u);
    EXPECT_EQ(stats(0, 0).slot(1).n, 0u);
    EXPECT_EQ(stats(0, 0).slot(2).n, 0u);
    EXPECT_EQ(stats(1, 1).add(sample(0), view, false, pool), 0);
    EXPECT_EQ(stats(1, 1).add(sample(1), view, false, pool), 1);
    EXPECT_EQ(pool.blocks(), 1u);
    EXPECT_EQ(stats(1, 1).add(sample(2), view, false, pool), 2);
    EXPECT_EQ(stats(1, 1).add(sample(3), view, false, pool), -1);
    EXPECT_EQ(stats(1, 1).add(sample(1), view, false, pool), 1);
    EXPECT_EQ(pool.blocks(), 1u);
    EXPECT_EQ(stats(0, 0).add(sample(5), view, false, pool), 1);
    EXPECT_EQ(pool.blocks(), 2u);
    render::PixelStatsImage moved = std::move(stats);
    EXPECT_EQ(moved(1, 1).slot(1).n, 2u);
    EXPECT_EQ(moved(1, 1).slot(2).n, 1u);
    EXPECT_EQ(moved(1, 1).slot(1).object, 1u);
    EXPECT_EQ(moved(0, 0).slot(1).object, 5u);
    EXPECT_EQ(moved(0, 0).primary(), 0);
    EXPECT_EQ(moved(1, 1).primary(), 1);
}

TEST(Render, TextureSamplesJoinTheAlbedoOfTheSurfacesThePixelSaw) {
    // A pixel on one surface whose samples saw two albedos (a checker's edge): its albedo
    // varies, a texture sample on that surface joins the stored mean albedo, one on a surface
    // the pixel's path samples never saw (or a miss) does not; the light stays demodulated
    // by the path samples' own albedo. An untextured surface has no albedo variance.
    ViewGeometry view;
    view.width = view.height = 1;
    view.focalPixels = 100;
    render::SlotPool pool;
    render::PixelStats edge, plain;
    for (int i = 0; i < 4; ++i) {
        render::TracedSample s = surfaceSample(0, 1.f);
        s.albedo = Vec3f(i < 2 ? 0.8f : 0.2f);  // half light, half dark cells
        edge.add(s, view, false, pool);
        plain.add(surfaceSample(0, 1.f), view, false, pool);
    }
    EXPECT_EQ(plain.albedoVariance(), 0.f);
    // Luminance 0.8 and 0.2 equally: mean 0.5, variance 0.09, relative 0.36.
    EXPECT_NEAR(edge.albedoVariance(), 0.36f, 1e-5f);
    render::TracedSample dark = surfaceSample(0, 0.f);
    dark.albedo = Vec3f(0.2f);
    for (int i = 0; i < 4; ++i) EXPECT_TRUE(edge.addPrimary(dark));
    EXPECT_FALSE(edge.addPrimary(surfaceSample(7, 0.f)));  // another surface
    EXPECT_FALSE(edge.addPrimary(render::TracedSample()));  // a miss
    FrameBuffers fb(1, 1);
    edge.store(fb, 0, 0, view);
    EXPECT_NEAR(fb.albedo[0].x, (2 * 0.8f + 2 * 0.2f + 4 * 0.2f) / 8.f, 1e-6f);  // 0.35
    // Demodulated by the path samples' mean albedo (0.5): their mean of albedo x light is 0.5.
    EXPECT_NEAR(fb.direct[0].x, 1.f, 1e-6f);
    EXPECT_EQ(fb.spp[0], 4.f);  // texture samples are not path samples
    // The miss counts towards the pixel's coverage (4 + 4 of 4 + 5 samples on the surface).
    EXPECT_NEAR(fb.coverage[0], 8.f / 9.f, 1e-6f);
    // A silhouette's pixel: two path samples on the surface, two that hit nothing. Primary
    // samples refine the surface's share of the pixel: four on it and eight misses make it
    // (2 + 4) / (4 + 12) = 0.375 of the surface-or-nothing share (all of it here); one on a
    // surface the path samples did not see counts for neither.
    render::PixelStats rim;
    for (int i = 0; i < 4; ++i) rim.add(i < 2 ? surfaceSample(0, 1.f) : render::TracedSample(), view, false, pool);
    EXPECT_TRUE(rim.mixed());
    EXPECT_FALSE(plain.mixed());
    for (int i = 0; i < 4; ++i) EXPECT_TRUE(rim.addPrimary(surfaceSample(0, 0.f)));
    for (int i = 0; i < 8; ++i) EXPECT_FALSE(rim.addPrimary(render::TracedSample()));
    EXPECT_FALSE(rim.addPrimary(surfaceSample(7, 0.f)));
    rim.store(fb, 0, 0, view);
    EXPECT_NEAR(fb.coverage[0], 6.f / 16.f, 1e-6f);
    EXPECT_NEAR(fb.albedo[0].x, 1.f, 1e-6f);
}

TEST(Render, APixelKeepsItsFirstSurfacesApartAndTheRestAsColour) {
    // Five surfaces and a miss in one pixel: the slot with the most samples is the primary, the
    // other slots become FrameBuffers::other in slot order, and the surfaces beyond the slots go
    // to `rest`; the decomposition reproduces the Monte Carlo colour exactly.
    ViewGeometry view;
    view.width = view.height = 1;
    view.focalPixels = 100;
    const int counts[] = {3, 6, 4, 2, 1};  // samples per surface (objects 0..4)
    render::SlotPool pool;
    render::PixelStats ps;
    for (uint32_t object = 0; object < 5; ++object)
        for (int i = 0; i < counts[object]; ++i) {
            render::TracedSample s = surfaceSample(object, 0.1f + 0.2f * float(object) + 0.01f * float(i));
            s.albedo = Vec3f(0.2f + 0.1f * float(object));
            s.position = {0, 0, float(object)};  // each on its own plane
            EXPECT_EQ(ps.add(s, view, false, pool), object < uint32_t(render::PixelStats::kSlots) ? int(object) : -1);
        }
    render::TracedSample miss;
    ps.add(miss, view, false, pool);
    ASSERT_GE(render::PixelStats::kSlots, 3);
    FrameBuffers fb(1, 1);
    ps.store(fb, 0, 0, view);
    EXPECT_EQ(ps.primary(), 1);
    EXPECT_EQ(fb.object[0], 1.f);
    EXPECT_NEAR(fb.coverage[0], 6.f / 17.f, 1e-6f);
    float covered = fb.coverage[0];
    for (int k = 0; k < FrameBuffers::kOtherSurfaces; ++k) {
        const int object = k == 0 ? 0 : k + 1;  // slot order without the primary
        EXPECT_EQ(fb.other[k].object[0], float(object));
        EXPECT_NEAR(fb.other[k].coverage[0], float(counts[object]) / 17.f, 1e-6f);
        EXPECT_NEAR(fb.other[k].albedo[0].x, 0.2f + 0.1f * float(object), 1e-6f);
        covered += fb.other[k].coverage[0];
    }
    EXPECT_LT(covered, 1.f - 1.5f / 17.f);  // the last surfaces and the miss are left over
    EXPECT_GT(maxComponent(fb.rest[0]), 0.f);
    const Vec3f mc = fb.compose(0, fb.direct[0], fb.indirect[0]);
    const Vec3f filtered = fb.composeFiltered(fb.direct, fb.indirect)[0];  // no neighbours: own light
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(mc[c], fb.color[0][c], 1e-6f);
        EXPECT_NEAR(filtered[c], fb.color[0][c], 1e-6f);
    }
}

TEST(Render, DefocusWidthIsTheSmallestCircleOfConfusionAmongTheSamples) {
    // b of the defocus filter (filter/defocus.h): the smallest |s_u| among a pixel's samples, also
    // where they straddle the focal plane; 0 once one of them is in focus.
    ViewGeometry view;
    view.width = view.height = 1;
    view.focalPixels = 100;
    view.apertureRadius = 0.1f;
    view.focusDistance = 2;  // s_u = 10 (1/z - 1/2)
    auto at = [](float depth) {
        render::TracedSample s = surfaceSample(0, 1.f);
        s.depth = depth;
        s.position = {0, 0, depth};
        return s;
    };
    FrameBuffers fb(1, 1);
    render::SlotPool pool;
    render::PixelStats near, straddle, inFocus;
    for (int i = 0; i < 8; ++i) {
        near.add(at(i % 2 ? 1.f : 0.5f), view, true, pool);          // s_u = 5, 15
        straddle.add(at(i % 2 ? 1.f : 10.f), view, true, pool);      // s_u = 5, -4
        inFocus.add(at(i % 3 ? 1.f : 2.f), view, true, pool);        // s_u = 5, 0
    }
    near.store(fb, 0, 0, view);
    EXPECT_NEAR(fb.defocus[0], 5.f, 1e-5f);
    straddle.store(fb, 0, 0, view);
    EXPECT_NEAR(fb.defocus[0], 4.f, 1e-5f);
    inFocus.store(fb, 0, 0, view);
    EXPECT_NEAR(fb.defocus[0], 0.f, 1e-5f);
    render::PixelStats none;  // no samples with slopes
    none.add(at(1.f), view, false, pool);
    none.store(fb, 0, 0, view);
    EXPECT_EQ(fb.defocus[0], 0.f);
}

TEST(Render, BounceFractionAndDistancesComeFromTheInitialSamples) {
    // 16 initial samples (slopes), 12 of whose bounce rays hit at distances 2..16, then 4
    // adaptive samples whose bounces hit at 0.5: those count towards neither.
    ViewGeometry view;
    view.width = view.height = 1;
    render::SlotPool pool;
    render::PixelStats ps;
    for (int i = 0; i < 20; ++i) {
        render::TracedSample s = surfaceSample(0, 1.f);
        s.bounceHit = i >= 16 || i % 4 != 0;
        s.bounceDistance = s.bounceHit ? (i >= 16 ? 0.5f : float(i + 1)) : kInf;
        ps.add(s, view, i < 16, pool);
    }
    FrameBuffers fb(1, 1);
    ps.store(fb, 0, 0, view);
    EXPECT_FLOAT_EQ(fb.bounced[0], 0.75f);
    EXPECT_FLOAT_EQ(fb.zMin[0], 2.f);
    EXPECT_FLOAT_EQ(fb.zMax[0], 16.f);
    render::PixelStats none;  // no bounce hit: no distances, fraction 0
    none.add(surfaceSample(0, 1.f), view, true, pool);
    none.store(fb, 0, 0, view);
    EXPECT_EQ(fb.bounced[0], 0.f);
    EXPECT_GE(fb.zMin[0], kInf);
}

TEST(Render, EmitterEdgesAndTheirDefocusRimsAreToppedUp) {
    // 16x12 pixels of 16 samples on a dark surface; pixel (5, 5) saw an emitter with 4 of them,
    // (6, 5) with all 16, both with circles of confusion up to 2.5 px. Pixels within
    // ceil(2.5) + 1 = 4 of either that did not see only the emitter are topped up (their 16
    // samples miss the few percent of the blurred emitter that reach them); farther ones, pixels
    // that saw nothing but the emitter and pixels past the target are not.
    const int W = 16, H = 12;
    render::PixelStatsImage stats(W, H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            render::PixelStats& s = stats(x, y);
            s.n = 16;
            s.suLo = -0.5f;
            s.suHi = 0.5f;
        }
    stats(5, 5).nEmitter = 4;
    stats(5, 5).suLo = -2.5f;
    stats(6, 5).nEmitter = 16;
    stats(6, 5).suLo = -2.5f;
    stats(3, 3).n = 300;
    auto extra = render::emitterTopUps(stats, 256);
    EXPECT_EQ(extra(5, 5), 240u);  // the edge pixel itself
    EXPECT_EQ(extra(6, 5), 0u);    // every sample saw the emitter
    EXPECT_EQ(extra(1, 1), 240u);  // 4 px from (5, 5) on both axes
    EXPECT_EQ(extra(10, 9), 240u); // 4 px from (6, 5)
    EXPECT_EQ(extra(3, 3), 0u);
    EXPECT_EQ(extra(0, 5), 0u);    // 5 px from (5, 5)
    EXPECT_EQ(extra(11, 5), 0u);   // 5 px from (6, 5)
    EXPECT_EQ(extra(5, 10), 0u);
    uint32_t total = 0;
    for (size_t i = 0; i < extra.size(); ++i) total += extra[i];
    EXPECT_EQ(total, 240u * (10 * 9 - 2));  // x 1..10, y 1..9, less (6, 5) and (3, 3)
    // A pinhole (no circle of confusion): the 8 neighbours only.
    for (size_t i = 0; i < stats.size(); ++i) stats[i].suLo = stats[i].suHi = 0.f;
    stats(6, 5).nEmitter = 0;
    extra = render::emitterTopUps(stats, 256);
    total = 0;
    for (size_t i = 0; i < extra.size(); ++i) total += extra[i];
    EXPECT_EQ(total, 240u * 9);
}

TEST(Render, EmitterRimsTakeTheirEmissionFromManyCameraRays) {
    // Cornell at 64x64 (its light seen directly, a lens): where the emitter top-up applies, the
    // emission plane is the mean over kEmitterEdgeRays camera rays, the same rays as the path
    // samples' (so its first 16 agree with them exactly), and closer to a 16384-ray truth than
    // what the pixel's own path samples saw.
    scene::SceneDesc desc = scene::loadScene("cornell");
    desc.camera.width = desc.camera.height = 64;
    const scene::Scene scene(std::move(desc));
    render::RenderOptions o;
    o.quiet = true;
    o.method = "mc";
    o.spp = 16;
    o.seed = 5;
    const render::RenderResult r = render::render(scene, o);
    const render::PathSampler sampler(scene, render::Camera(scene.desc().camera), scene.desc().render.indirect, 5);
    const FrameBuffers& fb = r.buffers;
    int rim = 0;
    double errDense = 0, errSamples = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const size_t p = size_t(y) * 64 + x;
            if (fb.spp[p] < render::kEmitterEdgeSpp) continue;  // not topped up
            ++rim;
            const Vec3f dense = sampler.meanEmission(x, y, render::kEmitterEdgeRays);
            EXPECT_EQ(fb.emission[p].x, dense.x);
            const Vec3f truth = sampler.meanEmission(x, y, 16384);
            const Vec3f own = sampler.meanEmission(x, y, uint32_t(fb.spp[p]));  // what its samples saw
            errDense += sqr(double(dense.x - truth.x));
            errSamples += sqr(double(own.x - truth.x));
        }
    EXPECT_GT(rim, 20) << "the light's edge and rim";
    EXPECT_LT(errDense, 0.5 * errSamples);
    // The first 16 camera rays are the path samples' own.
    for (int x = 20; x < 44; ++x) {
        render::TracedSample s[16];
        sampler.traceBatch(x, 4, 0, 16, false, s);
        Vec3f sum(0.f);
        for (const auto& t : s) sum += t.emission;
        const Vec3f e = sampler.meanEmission(x, 4, 16);
        EXPECT_NEAR(e.x, sum.x / 16.f, 1e-5f * (1.f + sum.x));
    }
}
