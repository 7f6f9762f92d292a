// À-trous filter (filter/atrous.h): invariants on synthetic buffers (a constant image stays
// constant, edges across normal and depth discontinuities and hit/miss borders are kept, noise
// goes down) and the method end to end against plain MC on a tiny Cornell box.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "filter/atrous.h"
#include "metrics/metrics.h"
#include "render/methods.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"

using namespace wedge;
using namespace wedge::filter;

namespace {

/// Guide planes of a flat wall facing the camera (normal +z), one footprint apart per pixel.
struct Planes {
    Image3f signal, normal, position;
    Image1f footprint, variance;
    Planes(int w, int h, float value = 0.f, float var = 0.01f)
        : signal(w, h, Vec3f(value)), normal(w, h, Vec3f(0, 0, 1)), position(w, h), footprint(w, h, 0.01f),
          variance(w, h, var) {
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) position(x, y) = {0.01f * x, -0.01f * y, 0.f};
    }
    AtrousInput input() const { return {signal, normal, position, footprint, variance}; }
};

uint32_t lcg(uint32_t& s) { return s = s * 1664525u + 1013904223u; }
float uniform(uint32_t& s) { return float(lcg(s) >> 8) / float(1 << 24); }

AtrousParams params(bool guided) {
    AtrousParams p;
    p.varianceGuided = guided;
    return p;
}

}  // namespace

TEST(Atrous, ConstantImageStaysConstant) {
    // Whatever the guides say (random normals, depths and variances), renormalised weights keep
    // a constant signal constant.
    Planes pl(24, 20, 0.7f);
    uint32_t s = 7;
    for (size_t i = 0; i < pl.signal.size(); ++i) {
        pl.normal[i] = normalize(Vec3f(uniform(s) - 0.5f, uniform(s) - 0.5f, 1.f));
        pl.position[i].z = uniform(s);
        pl.variance[i] = uniform(s) * 0.1f;
        if (i % 17 == 0) pl.footprint[i] = 0.f;  // some pixels without a hit
    }
    for (bool guided : {true, false}) {
        Image3f out = atrousFilter(pl.input(), params(guided));
        for (size_t i = 0; i < out.size(); ++i)
            for (int c = 0; c < 3; ++c) ASSERT_NEAR(out[i][c], 0.7f, 1e-5f) << "pixel " << i << " guided " << guided;
    }
}

TEST(Atrous, KeepsEdgesAcrossNormalDiscontinuities) {
    // A crease: left half faces +z with light 1, right half faces +x with light 0. Positions are
    // all equal and the variance large, so only the normal weight can stop the filter.
    const int w = 32, h = 16;
    auto makeCrease = [&](bool differentNormals) {
        Planes pl(w, h, 0.f, 100.f);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                pl.position(x, y) = Vec3f(0.f);
                bool left = x < w / 2;
                pl.signal(x, y) = Vec3f(left ? 1.f : 0.f);
                pl.normal(x, y) = left || !differentNormals ? Vec3f(0, 0, 1) : Vec3f(1, 0, 0);
            }
        return pl;
    };
    for (bool guided : {true, false}) {
        Planes crease = makeCrease(true);
        Image3f out = atrousFilter(crease.input(), params(guided));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) ASSERT_NEAR(out(x, y).x, x < w / 2 ? 1.f : 0.f, 1e-3f) << x << "," << y;
        // Control: with one normal on both sides the same filter does blur across the edge.
        Planes flat = makeCrease(false);
        Image3f blurred = atrousFilter(flat.input(), params(guided));
        EXPECT_LT(blurred(w / 2 - 1, h / 2).x, 0.9f);
        EXPECT_GT(blurred(w / 2, h / 2).x, 0.1f);
    }
}

TEST(Atrous, KeepsEdgesAcrossDepthDiscontinuities) {
    // Two parallel walls (same normal), the right one 0.5 behind: the plane distance stops the
    // filter; colour alone would not (large variance).
    const int w = 32, h = 16;
    Planes pl(w, h, 0.f, 100.f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool left = x < w / 2;
            pl.signal(x, y) = Vec3f(left ? 1.f : 0.f);
            pl.position(x, y).z = left ? 0.f : -0.5f;
        }
    Image3f out = atrousFilter(pl.input(), params(true));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) ASSERT_NEAR(out(x, y).x, x < w / 2 ? 1.f : 0.f, 1e-3f) << x << "," << y;
}

TEST(Atrous, PixelsWithoutHitsNeverMixWithSurfaces) {
    Planes pl(20, 20, 1.f, 100.f);
    for (int y = 0; y < 20; ++y)
        for (int x = 10; x < 20; ++x) {
            pl.footprint(x, y) = 0.f;
            pl.normal(x, y) = Vec3f(0.f);
            pl.signal(x, y) = Vec3f(5.f);
        }
    Image3f out = atrousFilter(pl.input(), params(true));
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x) ASSERT_FLOAT_EQ(out(x, y).x, x < 10 ? 1.f : 5.f);
}

TEST(Atrous, ReducesNoiseOnAFlatWall) {
    // Noise of standard deviation 0.2 around 0.5, with the matching variance: the output's
    // spread drops by more than a factor of 10 and its mean stays put.
    const int w = 48, h = 48;
    Planes pl(w, h, 0.f, 0.04f);
    uint32_t s = 3;
    for (size_t i = 0; i < pl.signal.size(); ++i) {
        float n = (uniform(s) + uniform(s) + uniform(s) - 1.5f) * 0.4f;  // variance 3 * 0.16 / 12 = 0.04
        pl.signal[i] = Vec3f(0.5f + n);
    }
    auto stats = [](const Image3f& img) {
        double m = 0, m2 = 0;
        for (size_t i = 0; i < img.size(); ++i) {
            m += img[i].x;
            m2 += double(img[i].x) * img[i].x;
        }
        m /= img.size();
        return std::pair<double, double>(m, m2 / img.size() - m * m);
    };
    auto [meanIn, varIn] = stats(pl.signal);
    for (bool guided : {true, false}) {
        auto [meanOut, varOut] = stats(atrousFilter(pl.input(), params(guided)));
        EXPECT_NEAR(meanOut, meanIn, 0.01);
        EXPECT_LT(varOut, varIn / 10) << "guided " << guided;
    }
}

TEST(Atrous, EdgeStoppingWeightIsOneForIdenticalPixelsAndInUnitRange) {
    EdgeGuide p{Vec3f(0, 0, 1), Vec3f(0.f), 0.01f, 0.5f, Vec3f(0.5f)};
    AtrousParams prm;
    EXPECT_FLOAT_EQ(edgeStoppingWeight(p, p, prm, 1, 0.1f), 1.f);
    EdgeGuide q = p;
    q.luminance = 0.6f;
    q.normal = normalize(Vec3f(0.1f, 0, 1));
    float wq = edgeStoppingWeight(p, q, prm, 1, 0.1f);
    EXPECT_GT(wq, 0.f);
    EXPECT_LT(wq, 1.f);
    q.footprint = 0;  // a miss never mixes with a hit
    EXPECT_EQ(edgeStoppingWeight(p, q, prm, 1, 0.1f), 0.f);
}

TEST(Atrous, FrameBuffersComposeFilteredLightWithAlbedoCoverageAndOffSurface) {
    FrameBuffers fb(8, 6);
    for (size_t i = 0; i < fb.color.size(); ++i) {
        fb.direct[i] = Vec3f(0.3f, 0.2f, 0.1f);
        fb.indirect[i] = Vec3f(0.1f);
        fb.albedo[i] = Vec3f(float(i % 5) / 5.f);
        fb.emission[i] = Vec3f(i % 7 == 0 ? 2.f : 0.f);
        fb.coverage[i] = i % 3 == 0 ? 0.5f : 1.f;
        fb.rest[i] = Vec3f(i % 3 == 0 ? 0.25f : 0.f);
        fb.normal[i] = Vec3f(0, 0, 1);
        fb.footprint[i] = 0.01f;
        fb.variance[i] = 0.01f;
    }
    Image3f out = atrousFilter(fb, AtrousParams{});
    for (size_t i = 0; i < out.size(); ++i)
        for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(out[i][c],
                        fb.emission[i][c] + fb.coverage[i] * fb.albedo[i][c] * (fb.direct[i][c] + fb.indirect[i][c]) +
                            fb.rest[i][c],
                        1e-5f);
}

TEST(Atrous, RejectsMismatchedPlanesAndBadParameters) {
    Planes pl(8, 8);
    Image1f small(4, 4);
    EXPECT_THROW(atrousFilter(AtrousInput{pl.signal, pl.normal, pl.position, small, pl.variance}, AtrousParams{}), Error);
    AtrousParams bad;
    bad.iterations = 0;
    EXPECT_THROW(atrousFilter(pl.input(), bad), Error);
    bad = AtrousParams{};
    bad.sigmaNormal = 0;
    EXPECT_THROW(atrousFilter(pl.input(), bad), Error);
}

TEST(AtrousMethod, BeatsMonteCarloAtTheSameSamplesOnCornell) {
    scene::SceneDesc desc = scene::loadScene("cornell");
    desc.camera.width = desc.camera.height = 40;
    scene::Scene scene(std::move(desc));
    render::RenderOptions o;
    o.quiet = true;
    o.spp = 64;
    o.seed = 1234;
    Image3f reference = render::render(scene, o).color;
    o.spp = 4;
    o.seed = 1;
    render::RenderResult mc = render::render(scene, o);
    o.method = "atrous";
    render::RenderResult at = render::render(scene, o);
    EXPECT_GT(at.seconds.get("filter"), 0.0);
    EXPECT_GE(at.sppAverage, 4.0);  // plus the emitter-edge top-up
    // The emitter's edge and its rim (one pixel here, the circles of confusion being below a
    // pixel at 40x40) are topped up: under 6% of the pixels.
    EXPECT_LT(at.sppAverage, 4.0 + 0.06 * render::kEmitterEdgeSpp);
    double eMc = metrics::relMse(mc.color, reference), eAt = metrics::relMse(at.color, reference);
    EXPECT_LT(eAt, 0.8 * eMc) << "mc " << eMc << " atrous " << eAt;
    EXPECT_GT(metrics::ssim(at.color, reference), metrics::ssim(mc.color, reference));
}
