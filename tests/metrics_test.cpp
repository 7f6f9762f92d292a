// Metrics module: relMSE, SMAPE, PSNR and SSIM on synthetic images with known answers, and the
// `wedge compare` command over image files.
#include <gtest/gtest.h>
#include <filesystem>
#include <sstream>
#include <limits>

#include <cmath>
#include <fstream>
#include <random>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/image_io.h"
#include "metrics/metrics.h"
#include "test_util.h"

using namespace wedge;
using namespace wedge::metrics;

namespace {

Image3f constant(int w, int h, float v) { return Image3f(w, h, Vec3f(v)); }

/// A deterministic pattern with structure at several scales, values in [0, 1].
Image3f pattern(int w, int h) {
    Image3f img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float v = 0.5f + 0.25f * std::sin(0.7f * x) * std::cos(0.4f * y) + ((x / 4 + y / 4) % 2 ? 0.2f : -0.2f);
            img(x, y) = {v, 0.5f * v, 1.f - v};
        }
    return img;
}

}  // namespace

TEST(Metrics, IdenticalImagesHaveZeroErrorAndPerfectSimilarity) {
    Image3f a = pattern(24, 20);
    Metrics m = compare(a, a);
    EXPECT_EQ(m.relMse, 0.0);
    EXPECT_EQ(m.smape, 0.0);
    EXPECT_TRUE(std::isinf(m.psnr) && m.psnr > 0);
    EXPECT_NEAR(m.ssim, 1.0, 1e-9);
}

TEST(Metrics, RelMseOfAConstantOffset) {
    // (1.1 - 1)^2 / (1 + 0.01), no 0.5 factor.
    EXPECT_NEAR(relMse(constant(8, 8, 1.1f), constant(8, 8, 1.f)), 0.01 / 1.01, 1e-6);
    // Against black the epsilon is the whole denominator: 0.5^2 / 0.01 = 25.
    EXPECT_NEAR(relMse(constant(8, 8, 0.5f), constant(8, 8, 0.f)), 25.0, 1e-4);
    // Half the pixels wrong by 100% of a bright reference: mean of 1 * 100/100.01 and 0.
    Image3f ref = constant(4, 2, 10.f), test = ref;
    for (int x = 0; x < 4; ++x) test(x, 0) = Vec3f(20.f);
    EXPECT_NEAR(relMse(test, ref), 0.5 * 100.0 / 100.01, 1e-6);
    // The mean of the per-pixel map is the metric.
    Image1f map = relativeErrorMap(test, ref);
    double mean = 0;
    for (size_t i = 0; i < map.size(); ++i) mean += map[i];
    EXPECT_NEAR(mean / map.size(), relMse(test, ref), 1e-7);
}

TEST(Metrics, ReferenceNoiseIsTheShareOfTheReferencesOwnError) {
    // A truth T, a reference r made of two independent halves (3 and 5 samples of per-sample
    // std 0.06), and a test image x with its own independent error. The estimate from the halves
    // must be what the reference adds to relMSE(x, r) on top of relMSE(x, T) (statistical bound:
    // 196K terms, a few percent).
    const int W = 256, H = 256, nA = 3, nB = 5;
    std::mt19937 rng(7);
    auto gauss = [&] {  // Box-Muller from the engine's raw output (portable)
        double u1 = (double(rng()) + 1.0) / 4294967297.0, u2 = double(rng()) / 4294967296.0;
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
    };
    Image3f truth = pattern(W, H), a(W, H), b(W, H), x(W, H);
    for (size_t i = 0; i < truth.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            float t = 0.3f + truth[i][c];
            truth[i][c] = t;
            a[i][c] = t + float(0.06 * gauss() / std::sqrt(double(nA)));
            b[i][c] = t + float(0.06 * gauss() / std::sqrt(double(nB)));
            x[i][c] = t + float(0.03 * gauss());
        }
    Image3f r = combineHalves(a, nA, b, nB);
    EXPECT_NEAR(r[5].x, (3 * a[5].x + 5 * b[5].x) / 8, 1e-6);
    const double noise = referenceNoise(a, nA, b, nB);
    EXPECT_NEAR(noise, relMse(r, truth), 0.03 * relMse(r, truth)) << "the reference's own relMSE";
    const double own = relMse(x, truth), measured = relMse(x, r);
    EXPECT_GT(measured - own, 0.5 * noise) << "the reference's noise does inflate the measurement";
    EXPECT_NEAR(measured - noise, own, 0.03 * own);
    // Identical halves: no noise.
    EXPECT_EQ(referenceNoise(a, 2, a, 2), 0.0);
}

TEST(Metrics, RegionErrorsSplitTheErrorByPixelClass) {
    // 12x8: objects 0 (x < 6) and 1 (x >= 6), pixel (0, 0) background, (2, 6) mixed, the right
    // object's rows y >= 4 defocused, pixels (3, 1), (0, 3) and the defocused (9, 7) partly
    // occluded (0.5, 0.0625, 0.5) and (3, 2) wholly (1). Relative squared error 1 (eps 0: test 2
    // against 1) at (0, 0) background, (2, 6) mixed, (5, 3) edge (next to object 1), (1, 1) edge
    // (next to the background pixel), (3, 1) penumbra, (9, 6) defocused, (3, 3) and (3, 2)
    // interior.
    const int W = 12, H = 8;
    Image3f ref = constant(W, H, 1.f), test = ref;
    Image1f object(W, H), coverage(W, H), defocus(W, H), occluded(W, H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            object(x, y) = x < 6 ? 0.f : 1.f;
            coverage(x, y) = 1.f;
            defocus(x, y) = x >= 6 && y >= 4 ? 3.f : 0.f;
        }
    object(0, 0) = -1;
    coverage(2, 6) = 0.5f;
    occluded(3, 1) = 0.5f;
    occluded(0, 3) = 0.0625f;
    occluded(3, 2) = 1.f;     // umbra: interior
    occluded(9, 7) = 0.5f;    // penumbra before defocused
    occluded(5, 5) = 0.5f;    // edge first (next to object 1)
    for (auto [x, y] : {std::pair{0, 0}, {2, 6}, {5, 3}, {9, 6}, {1, 1}, {3, 3}, {3, 1}, {3, 2}})
        test(x, y) = Vec3f(2.f);
    const RegionPlanes planes{object, coverage, defocus, occluded};
    auto r = regionErrors(test, ref, planes, 2, 0.f);
    ASSERT_EQ(r.size(), 6u);
    double pixels = 0, share = 0;
    for (const auto& c : r) {
        pixels += c.pixels;
        share += c.share;
    }
    EXPECT_NEAR(pixels, 1.0, 1e-12);
    EXPECT_NEAR(share, 1.0, 1e-12);
    EXPECT_EQ(r[0].name, "background");
    EXPECT_NEAR(r[0].pixels, 1.0 / 96, 1e-12);
    EXPECT_NEAR(r[0].share, 1.0 / 8, 1e-12);
    EXPECT_NEAR(r[0].relMse, 1.0, 1e-12);
    EXPECT_NEAR(r[1].share, 1.0 / 8, 1e-12);  // mixed: (2, 6)
    EXPECT_NEAR(r[2].share, 2.0 / 8, 1e-12);  // edge: (5, 3), (1, 1)
    EXPECT_EQ(r[3].name, "penumbra");
    EXPECT_NEAR(r[3].pixels, 3.0 / 96, 1e-12);  // (3, 1), (0, 3), (9, 7); not (5, 5) or (3, 2)
    EXPECT_NEAR(r[3].share, 1.0 / 8, 1e-12);    // (3, 1)
    EXPECT_NEAR(r[3].relMse, 1.0 / 3, 1e-12);
    EXPECT_EQ(r[4].name, "defocused");
    EXPECT_NEAR(r[4].share, 1.0 / 8, 1e-12);  // (9, 6)
    EXPECT_EQ(r[5].name, "interior");
    EXPECT_NEAR(r[5].share, 2.0 / 8, 1e-12);  // (3, 3), (3, 2)
    // Edge pixels: around the background and the mixed pixel, and columns 4..7 along the border.
    EXPECT_GT(r[2].pixels, 0.3);
    EXPECT_LT(r[5].pixels + r[4].pixels + r[3].pixels, 0.7);
    for (const auto& c : r) EXPECT_EQ(c.variance, 0.0) << "no variance map given";

    // A variance map is averaged over each class's pixels: 3 on the background pixel, 1 elsewhere
    // except 5 at the interior pixel (3, 3).
    Image1f variance(W, H, 1.f);
    variance(0, 0) = 3.f;
    variance(3, 3) = 5.f;
    auto v = regionErrors(test, ref, planes, 2, 0.f, &variance);
    EXPECT_NEAR(v[0].variance, 3.0, 1e-12);
    EXPECT_NEAR(v[1].variance, 1.0, 1e-12);
    EXPECT_NEAR(v[3].variance, 1.0, 1e-12);
    EXPECT_NEAR(v[5].variance, 1.0 + 4.0 / (v[5].pixels * W * H), 1e-9);
    for (size_t k = 0; k < r.size(); ++k) EXPECT_EQ(v[k].relMse, r[k].relMse);

    // The two halves: per-pixel classes (indices into regionNames()), then the split over them.
    const Image<uint8_t> classes = regionClasses(planes);
    EXPECT_EQ(regionNames()[classes(0, 0)], "background");
    EXPECT_EQ(regionNames()[classes(3, 1)], "penumbra");
    EXPECT_EQ(regionNames()[classes(9, 7)], "penumbra");
    EXPECT_EQ(regionNames()[classes(3, 2)], "interior");
    auto w = regionErrors(test, ref, classes, 0.f, &variance);
    for (size_t k = 0; k < r.size(); ++k) {
        EXPECT_EQ(w[k].relMse, v[k].relMse);
        EXPECT_EQ(w[k].variance, v[k].variance);
    }
    EXPECT_THROW(regionErrors(test, ref, Image<uint8_t>(4, 4), 0.f), Error);
    const Image1f small(4, 4);
    EXPECT_THROW(regionClasses({object, coverage, defocus, small}), Error);
}

TEST(Metrics, SeedVarianceSplitsNoiseFromBias) {
    // Two renders of a constant 1 with a bias of 0.1 and independent Gaussian noise of sigma 0.2:
    // relMSE against the truth is (0.01 + 0.04) / 1.01, the variance part 0.04 / 1.01, the
    // squared bias 0.01 / 1.01. 64x64x3 values: the estimates are within a few percent.
    const int W = 64, H = 64;
    const float bias = 0.1f, sigma = 0.2f;
    std::mt19937 rng(7);
    std::normal_distribution<float> noise(0.f, sigma);
    Image3f truth = constant(W, H, 1.f), a(W, H), b(W, H);
    for (size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            a[i][c] = 1.f + bias + noise(rng);
            b[i][c] = 1.f + bias + noise(rng);
        }
    const double expectVar = double(sigma) * sigma / 1.01, expectBias2 = double(bias) * bias / 1.01;
    const double var = seedVariance(a, b, truth);
    EXPECT_NEAR(var, expectVar, 0.05 * expectVar);
    EXPECT_NEAR(relMse(a, truth) - var, expectBias2, 0.25 * expectBias2);
    EXPECT_NEAR(mapMean(seedVarianceMap(a, b, truth)), var, 1e-12);
    // The product of the two errors has the squared bias as its mean, without the variance.
    EXPECT_NEAR(mapMean(seedBiasMap(a, b, truth)), expectBias2, 0.25 * expectBias2);
    EXPECT_NEAR(mapMean(seedBiasMap(truth, truth, constant(W, H, 1.1f))), 0.01 / 1.22, 1e-6);
    // Unbiased and noise-free renders: nothing either way.
    EXPECT_EQ(seedVariance(truth, truth, truth), 0.0);
    // It is symmetric in the two renders, and (a - b)^2 / 2 per value: for a = 1.2, b = 0.8
    // against 1 with eps 0, 0.08.
    EXPECT_NEAR(seedVariance(a, b, truth), seedVariance(b, a, truth), 1e-12);
    EXPECT_NEAR(seedVariance(constant(3, 2, 1.2f), constant(3, 2, 0.8f), constant(3, 2, 1.f), 0.f), 0.08, 1e-6);
    EXPECT_THROW(seedVariance(a, constant(3, 2, 1.f), truth), Error);
}

TEST(Metrics, SmapeOfKnownPairs) {
    EXPECT_NEAR(smape(constant(4, 4, 1.f), constant(4, 4, 0.f)), 1.0 / 1.01, 1e-6);
    EXPECT_NEAR(smape(constant(4, 4, 3.f), constant(4, 4, 1.f)), 2.0 / 4.01, 1e-6);
    // Symmetric in its arguments.
    Image3f a = pattern(9, 7), b = constant(9, 7, 0.3f);
    EXPECT_NEAR(smape(a, b), smape(b, a), 1e-12);
}

TEST(Metrics, PsnrOnToneMappedValues) {
    // Display values 0.1 apart everywhere: MSE 0.01, PSNR 20 dB.
    Image3f test = constant(8, 8, io::srgbDecode(0.6f)), ref = constant(8, 8, io::srgbDecode(0.5f));
    EXPECT_NEAR(psnr(test, ref), 20.0, 1e-3);
    // Values above 1 are clamped by the tone map: 2 and 5 look the same.
    EXPECT_TRUE(std::isinf(psnr(constant(4, 4, 2.f), constant(4, 4, 5.f))));
    // White against black: MSE 1, PSNR 0 dB.
    EXPECT_NEAR(psnr(constant(4, 4, 1.f), constant(4, 4, 0.f)), 0.0, 1e-5);
}

TEST(Metrics, ToneMapMatchesThePngWriter) {
    for (float v : {0.f, 0.001f, 0.0031308f, 0.02f, 0.18f, 0.5f, 1.f, 3.f})
        EXPECT_NEAR(toneMap(v), io::srgbEncode(v), 1e-6f) << v;
    EXPECT_EQ(toneMap(-1.f), 0.f);
    EXPECT_EQ(toneMap(std::nanf("")), 0.f);
}

TEST(Metrics, SsimOfConstantImagesIsTheLuminanceTerm) {
    // No variance: SSIM = (2 a b + C1) / (a^2 + b^2 + C1), C1 = 0.0001.
    const float a = 0.5f, b = 0.25f;
    double expected = (2.0 * a * b + 1e-4) / (a * a + b * b + 1e-4);
    Image3f x = constant(16, 16, io::srgbDecode(a)), y = constant(16, 16, io::srgbDecode(b));
    EXPECT_NEAR(ssim(x, y), expected, 1e-5);
    // Smaller than the 11x11 window still works (the window is cut to the image).
    EXPECT_NEAR(ssim(constant(3, 2, io::srgbDecode(a)), constant(3, 2, io::srgbDecode(b))), expected, 1e-5);
}

TEST(Metrics, SsimOfAnInvertedPatternIsNegative) {
    // y = 1 - x has the same local variance but covariance -var: the structure term is
    // (C2 - 2 var) / (2 var + C2), so SSIM < 0 wherever the pattern has contrast.
    Image1f x(20, 20), y(20, 20);
    for (int j = 0; j < 20; ++j)
        for (int i = 0; i < 20; ++i) {
            x(i, j) = (i + j) % 2 ? 0.8f : 0.2f;
            y(i, j) = 1.f - x(i, j);
        }
    Image1f m = ssimMap(x, y);
    for (size_t i = 0; i < m.size(); ++i) EXPECT_LT(m[i], -0.9f);
    Image1f same = ssimMap(x, x);
    for (size_t i = 0; i < same.size(); ++i) EXPECT_NEAR(same[i], 1.f, 1e-5f);
}

TEST(Metrics, SsimDropsMonotonicallyWithNoise) {
    Image3f ref = pattern(32, 32);
    double previous = 1.0;
    for (float amplitude : {0.02f, 0.05f, 0.1f, 0.2f}) {
        Image3f noisy = ref;
        uint32_t state = 12345;
        for (size_t i = 0; i < noisy.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                state = state * 1664525u + 1013904223u;
                noisy[i][c] = std::max(0.f, noisy[i][c] + amplitude * (float(state >> 8) / float(1 << 24) - 0.5f));
            }
        double s = ssim(noisy, ref);
        EXPECT_LT(s, previous) << amplitude;
        EXPECT_GT(s, 0.0);
        previous = s;
    }
}

TEST(Metrics, CompareRejectsSizeMismatch) {
    EXPECT_THROW(compare(constant(4, 4, 1.f), constant(4, 5, 1.f)), Error);
}

TEST(Metrics, Log10MapFloorsAtTheLowEnd) {
    Image1f v(3, 1);
    v[0] = 0.f;
    v[1] = 1e-2f;
    v[2] = 10.f;
    Image1f l = log10Map(v, -4.f);
    EXPECT_NEAR(l[0], -4.f, 1e-6f);
    EXPECT_NEAR(l[1], -2.f, 1e-6f);
    EXPECT_NEAR(l[2], 1.f, 1e-6f);
}

TEST(CompareCommand, NonFinitePixelsAreNamedNotAveraged) {
    // A NaN or infinite pixel made relMSE "nan" with exit code 0; now the file, the count and the
    // first such pixel are named, in the test image, the reference or --variance-from's image.
    std::string dir = test::tempDir();
    Image3f bad = constant(6, 5, 1.f);
    bad(4, 2).y = std::numeric_limits<float>::quiet_NaN();
    bad(5, 3).x = std::numeric_limits<float>::infinity();
    io::writePfm(dir + "/bad.pfm", bad);
    io::writePfm(dir + "/ok.pfm", constant(6, 5, 1.f));
    for (const char* args : {"bad.pfm ok.pfm", "ok.pfm bad.pfm", "ok.pfm ok.pfm --variance-from bad.pfm"}) {
        std::string cmd = "compare";
        std::istringstream words(args);
        for (std::string w; words >> w;) {
            cmd += ' ';
            if (w.find(".pfm") != std::string::npos) cmd += dir + '/';
            cmd += w;
        }
        std::string out, err;
        EXPECT_EQ(test::runWedge(cmd + " --heatmap " + dir + "/heat.png", &out, &err), 2) << args;
        EXPECT_NE(err.find(dir + "/bad.pfm: 2 of 30 pixels are not finite (NaN or infinite), the first at x = 4, y = 2"),
                  std::string::npos)
            << err;
        EXPECT_FALSE(std::filesystem::exists(dir + "/heat.png"));
    }
}

TEST(CompareCommand, PrintsJsonAndWritesAHeatMap) {
    std::string dir = test::tempDir();
    io::writePfm(dir + "/ref.pfm", constant(6, 5, 1.f));
    io::writePfm(dir + "/test.pfm", constant(6, 5, 1.1f));
    std::string out, err;
    ASSERT_EQ(test::runWedge("compare " + dir + "/test.pfm " + dir + "/ref.pfm --json --heatmap " + dir + "/heat.png",
                             &out, &err),
              0)
        << err;
    auto j = nlohmann::json::parse(out);
    EXPECT_NEAR(j["relmse"].get<double>(), 0.01 / 1.01, 1e-5);
    EXPECT_NEAR(j["smape"].get<double>(), 0.1 / 2.11, 1e-5);
    Image3f heat = io::readPng(dir + "/heat.png");
    EXPECT_EQ(heat.width(), 6);
    EXPECT_EQ(heat.height(), 5);
}

TEST(CompareCommand, RegionsSplitARendersErrorAndNeedItsPlanes) {
    std::string dir = test::tempDir(), out, err;
    ASSERT_EQ(test::runWedge("render cornell --method mc --spp 2 --resolution 24x24 --quiet -o " + dir + "/x.exr", &out, &err), 0)
        << err;
    ASSERT_EQ(test::runWedge("render cornell --method mc --spp 32 --resolution 24x24 --quiet --seed 9 -o " + dir + "/r.exr",
                             &out, &err),
              0)
        << err;
    ASSERT_EQ(test::runWedge("compare " + dir + "/x.exr " + dir + "/r.exr --regions --json", &out, &err), 0) << err;
    auto j = nlohmann::json::parse(out);
    double share = 0, pixels = 0, weighted = 0;
    for (const char* name : {"background", "mixed", "edge", "defocused", "penumbra", "interior"}) {
        ASSERT_TRUE(j["regions"].contains(name)) << name;
        share += j["regions"][name]["share"].get<double>();
        pixels += j["regions"][name]["pixels"].get<double>();
        weighted += j["regions"][name]["pixels"].get<double>() * j["regions"][name]["relmse"].get<double>();
    }
    EXPECT_NEAR(share, 1.0, 1e-9);
    EXPECT_NEAR(pixels, 1.0, 1e-9);
    EXPECT_NEAR(weighted, j["relmse"].get<double>(), 1e-6 * j["relmse"].get<double>());
    EXPECT_GT(j["regions"]["mixed"]["pixels"].get<double>(), 0.0) << "the box's edges mix surfaces";
    EXPECT_GT(j["regions"]["penumbra"]["pixels"].get<double>(), 0.0) << "the boxes' soft shadows";
    // A PFM has no planes to split by.
    io::writePfm(dir + "/x.pfm", io::readColor(dir + "/x.exr"));
    EXPECT_EQ(test::runWedge("compare " + dir + "/x.pfm " + dir + "/r.exr --regions", &out, &err), 2);
    EXPECT_NE(err.find("--regions"), std::string::npos) << err;
    EXPECT_NE(err.find("x.pfm"), std::string::npos) << err;
}

TEST(CompareCommand, VarianceFromASecondRenderSplitsTheError) {
    // Monte Carlo is unbiased: with a second render of another seed, nearly all of its relMSE
    // against a reference of 16x the samples is variance (the reference's own noise, about a
    // sixteenth of it, and the estimates' scatter are the rest).
    std::string dir = test::tempDir(), out, err;
    const std::string common = "--method mc --spp 2 --resolution 48x48 --quiet ";
    ASSERT_EQ(test::runWedge("render cornell " + common + "--seed 1 -o " + dir + "/a.exr", &out, &err), 0) << err;
    ASSERT_EQ(test::runWedge("render cornell " + common + "--seed 2 -o " + dir + "/b.exr", &out, &err), 0) << err;
    ASSERT_EQ(test::runWedge("render cornell --method mc --spp 32 --resolution 48x48 --quiet --seed 9 -o " + dir + "/r.exr",
                             &out, &err),
              0)
        << err;
    ASSERT_EQ(test::runWedge("compare " + dir + "/a.exr " + dir + "/r.exr --regions --json --variance-from " + dir + "/b.exr",
                             &out, &err),
              0)
        << err;
    auto j = nlohmann::json::parse(out);
    const double relmse = j["relmse"].get<double>(), variance = j["variance"].get<double>();
    EXPECT_GT(variance, 0.75 * relmse);
    EXPECT_LT(variance, 1.1 * relmse);
    EXPECT_NEAR(j["bias2_and_reference_noise"].get<double>(), relmse - variance, 1e-12);
    double weighted = 0;
    for (const auto& [name, r] : j["regions"].items())
        weighted += r["pixels"].get<double>() * r["variance"].get<double>();
    EXPECT_NEAR(weighted, variance, 1e-6 * variance);
    // The text form names both parts.
    ASSERT_EQ(test::runWedge("compare " + dir + "/a.exr " + dir + "/r.exr --variance-from " + dir + "/b.exr", &out, &err), 0);
    EXPECT_NE(out.find("variance"), std::string::npos) << out;
    EXPECT_NE(out.find("squared bias"), std::string::npos) << out;
    // The squared bias where it sits, on the error heat map's scale.
    ASSERT_EQ(test::runWedge("compare " + dir + "/a.exr " + dir + "/r.exr --variance-from " + dir + "/b.exr --bias-heatmap " +
                                 dir + "/bias.png",
                             &out, &err),
              0)
        << err;
    Image3f bias = io::readPng(dir + "/bias.png");
    EXPECT_EQ(bias.width(), 48);
    EXPECT_EQ(bias.height(), 48);
    // It needs the second render, and says so before writing anything.
    EXPECT_EQ(test::runWedge("compare " + dir + "/a.exr " + dir + "/r.exr --bias-heatmap " + dir + "/bias2.png", &out, &err), 2);
    EXPECT_NE(err.find("--variance-from"), std::string::npos) << err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/bias2.png"));
    // A second render of another size is bad input that names it.
    io::writePfm(dir + "/small.pfm", constant(4, 4, 1.f));
    EXPECT_EQ(test::runWedge("compare " + dir + "/a.exr " + dir + "/r.exr --variance-from " + dir + "/small.pfm", &out, &err), 2);
    EXPECT_NE(err.find("small.pfm"), std::string::npos) << err;
    EXPECT_NE(err.find("--variance-from"), std::string::npos) << err;
}

TEST(CompareCommand, TheReferencesOwnNoiseIsMeasuredAndTakenOff) {
    // A 4-spp render against a 16-spp reference: a quarter of the relMSE is the reference's own
    // noise. A second 16-spp reference with another seed measures it, and the net relMSE is what
    // a 16x better reference measures (its own noise, 1/16 of the 16-spp one's, taken off too).
    std::string dir = test::tempDir(), out, err;
    const std::string common = " --method mc --resolution 48x48 --layers off --quiet ";
    for (const char* r : {"--spp 4 --seed 1 -o a.exr", "--spp 16 --seed 9 -o r1.exr", "--spp 16 --seed 10 -o r2.exr",
                          "--spp 256 --seed 11 -o big.exr"}) {
        std::string args = r;
        args.replace(args.find("-o ") + 3, 0, dir + "/");
        ASSERT_EQ(test::runWedge("render cornell" + common + args, &out, &err), 0) << err;
    }
    auto json = [&](const std::string& args) {
        EXPECT_EQ(test::runWedge("compare " + args + " --json", &out, &err), 0) << err;
        return nlohmann::json::parse(out);
    };
    const double truthA = json(dir + "/a.exr " + dir + "/big.exr")["relmse"].get<double>();
    const double truthR1 = json(dir + "/r1.exr " + dir + "/big.exr")["relmse"].get<double>();
    // (Each relMSE against big.exr holds big.exr's noise, about a sixteenth of r1's.)
    auto j = json(dir + "/a.exr " + dir + "/r1.exr --regions --reference-noise-from " + dir + "/r2.exr");
    const double relmse = j["relmse"].get<double>(), noise = j["reference_noise"].get<double>();
    EXPECT_NEAR(noise, truthR1 * 15.0 / 16.0, 0.15 * truthR1);
    EXPECT_NEAR(j["relmse_net"].get<double>(), relmse - noise, 1e-12);
    EXPECT_NEAR(j["relmse_net"].get<double>(), truthA - truthR1 / 16.0, 0.08 * truthA);
    EXPECT_GT(noise, 0.1 * relmse);  // the correction matters here
    double weighted = 0;
    for (const auto& [name, r] : j["regions"].items()) {
        weighted += r["pixels"].get<double>() * r["reference_noise"].get<double>();
        EXPECT_NEAR(r["relmse_net"].get<double>(), r["relmse"].get<double>() - r["reference_noise"].get<double>(), 1e-12);
    }
    EXPECT_NEAR(weighted, noise, 1e-6 * noise);
    // With --variance-from as well, the squared bias is what is left of the net relMSE, overall
    // and per region. (r2.exr stands in for a second render of a.exr's kind: any image does for
    // the arithmetic.)
    j = json(dir + "/a.exr " + dir + "/r1.exr --regions --variance-from " + dir + "/r2.exr --reference-noise-from " +
             dir + "/r2.exr");
    EXPECT_NEAR(j["bias2"].get<double>(), relmse - j["variance"].get<double>() - noise, 1e-12);
    for (const auto& [name, r] : j["regions"].items())
        EXPECT_NEAR(r["bias2"].get<double>(),
                    r["relmse"].get<double>() - r["variance"].get<double>() - r["reference_noise"].get<double>(), 1e-12)
            << name;
    // The text form names it.
    ASSERT_EQ(test::runWedge("compare " + dir + "/a.exr " + dir + "/r1.exr --reference-noise-from " + dir + "/r2.exr", &out, &err), 0);
    EXPECT_NE(out.find("net relMSE"), std::string::npos) << out;
    // A second reference of another size, or not finite, is bad input that names it.
    io::writePfm(dir + "/small.pfm", constant(4, 4, 1.f));
    EXPECT_EQ(test::runWedge("compare " + dir + "/a.exr " + dir + "/r1.exr --reference-noise-from " + dir + "/small.pfm", &out, &err), 2);
    EXPECT_NE(err.find(dir + "/small.pfm: --reference-noise-from"), std::string::npos) << err;
    EXPECT_EQ(test::runWedge("compare " + dir + "/a.exr " + dir + "/r1.exr --reference-noise-from " + dir + "/missing.exr", &out, &err), 2);
    EXPECT_NE(err.find("missing.exr"), std::string::npos) << err;
}

TEST(CompareCommand, BadInputExitsWithTwo) {
    std::string dir = test::tempDir();
    io::writePfm(dir + "/a.pfm", constant(4, 4, 1.f));
    io::writePfm(dir + "/b.pfm", constant(5, 4, 1.f));
    std::string err;
    EXPECT_EQ(test::runWedge("compare " + dir + "/a.pfm " + dir + "/b.pfm", nullptr, &err), 2);
    EXPECT_NE(err.find("size mismatch"), std::string::npos) << err;
    EXPECT_EQ(test::runWedge("compare " + dir + "/a.pfm " + dir + "/missing.pfm", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge("compare " + dir + "/a.pfm " + dir + "/a.pfm --heatmap " + dir + "/h.jpg", nullptr, &err), 2);
}

TEST(CompareCommand, AnExrBombIsRefusedBeforeAllocating) {
    // 50000 x 50000 in a 400 KB file: `wedge compare` grew to 24 GB before; now exit 2 at once.
    std::string dir = test::tempDir(), err;
    test::writeFile(dir + "/bomb.exr", test::exrHeader(0, 0, 49999, 49999, 3, 50000));
    io::writePfm(dir + "/r.pfm", constant(4, 4, 1.f));
    EXPECT_EQ(test::runWedge("compare " + dir + "/bomb.exr " + dir + "/r.pfm", nullptr, &err), 2);
    EXPECT_NE(err.find(dir + "/bomb.exr: "), std::string::npos) << err;
    EXPECT_NE(err.find("16384"), std::string::npos) << err;
    // --max-memory lowers the limit every reader checks.
    io::writePfm(dir + "/a.pfm", constant(64, 64, 1.f));
    EXPECT_EQ(test::runWedge("compare " + dir + "/a.pfm " + dir + "/a.pfm --max-memory 10K", nullptr, &err), 2);
    EXPECT_NE(err.find("a.pfm: the PFM's 64x64 pixels needs 96.0 KiB, more than the memory limit of 10.0 KiB (--max-memory)"),
              std::string::npos)
        << err;
    EXPECT_EQ(test::runWedge("compare " + dir + "/a.pfm " + dir + "/a.pfm --max-memory 1G", nullptr, &err), 0) << err;
    EXPECT_EQ(test::runWedge("compare " + dir + "/a.pfm " + dir + "/a.pfm --max-memory lots", nullptr, &err), 2);
    EXPECT_NE(err.find("--max-memory: 'lots' is not a memory size"), std::string::npos) << err;
}
