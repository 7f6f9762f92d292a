// wedge compare TEST REF [--json] [--heatmap OUT.png] [--regions] [--variance-from OTHER
// [--bias-heatmap OUT.png]] [--reference-noise-from REF2]: relMSE, SMAPE, PSNR and SSIM of a
// rendering against a reference (metrics/metrics.h), a heat map of the per-pixel relative squared
// error on a log scale, where that error sits (metrics::regionErrors), how much of it is variance
// (metrics::seedVariance, from a second render with another seed), where the squared bias is
// (metrics::seedBiasMap), and how much is the reference's own noise (from a second reference).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>

#include "apps/wedge/commands.h"
#include "apps/wedge/common.h"
#include "core/error.h"
#include "io/image_io.h"
#include "metrics/metrics.h"

namespace wedge::app {

namespace {

struct CompareArgs {
    std::string test, reference, heatmap, varianceFrom, biasHeatmap, noiseFrom;
    bool json = false, regions = false;
};

/// A plane of a wedge EXR that --regions needs; a clear error when the file has no such plane.
Image1f plane(const io::ExrImage& exr, const std::string& path, const std::string& name) {
    auto it = exr.channels.find(name);
    if (it == exr.channels.end())
        throw Error(path, "--regions needs the '" + name + "' plane of an EXR written by `wedge render -o x.exr`");
    Image1f img(exr.width, exr.height);
    std::copy(it->second.begin(), it->second.end(), img.data());
    return img;
}

// Heat maps show log10 relative squared error from 10^-4 (dark) to 10^0 (yellow).
constexpr float kHeatLo = -4.f, kHeatHi = 0.f;
// Bias heat maps: the squared bias is a part of the error, so one decade lower.
constexpr float kBiasHeatLo = -5.f, kBiasHeatHi = -1.f;

void runCompare(const CompareArgs& a) {
    if (!a.heatmap.empty()) io::checkOutputPath(a.heatmap, {".png"});
    if (!a.biasHeatmap.empty()) {
        if (a.varianceFrom.empty())
            throw Error("--bias-heatmap", "needs --variance-from OTHER (a second render with another seed)");
        io::checkOutputPath(a.biasHeatmap, {".png"});
    }
    Image3f test = io::readColor(a.test), reference = io::readColor(a.reference);
    metrics::checkComparable(test, a.test, reference, a.reference);
    // The variance part of TEST's error, from a render made alike with another seed.
    std::optional<Image3f> other;
    std::optional<Image1f> variance;
    if (!a.varianceFrom.empty()) {
        other = io::readColor(a.varianceFrom);
        checkSecondImage(*other, a.varianceFrom, "--variance-from", test, a.test);
        variance = metrics::seedVarianceMap(test, *other, reference);
    }
    const double varianceMean = variance ? metrics::mapMean(*variance) : 0.0;
    // The reference's own noise, from a second reference made alike with another seed: every
    // relMSE against REF holds it, E[relMSE(x, REF)] = relMSE(x, truth) + E[Var REF / (REF^2 +
    // eps)], and half REF and REF2's relative squared difference estimates the second term, per
    // pixel (metrics::seedVarianceMap of the two references). The net relMSE is what a
    // noise-free reference would measure; it is what separates two good filters (against a
    // 1024-spp reference the reference's noise can be a third of a filtered render's relMSE).
    std::optional<Image1f> noise;
    if (!a.noiseFrom.empty()) {
        const Image3f second = io::readColor(a.noiseFrom);
        checkSecondImage(second, a.noiseFrom, "--reference-noise-from", reference, a.reference);
        noise = metrics::seedVarianceMap(reference, second, reference);
    }
    const double noiseMean = noise ? metrics::mapMean(*noise) : 0.0;
    std::vector<metrics::RegionError> regions;
    if (a.regions) {
        if (io::extension(a.test) != ".exr")
            throw Error(a.test, "--regions needs an EXR written by `wedge render -o x.exr` (its coverage and object planes)");
        const io::ExrImage exr = io::readExr(a.test);
        const Image1f object = plane(exr, a.test, "object"), coverage = plane(exr, a.test, "coverage"),
                      defocus = plane(exr, a.test, "slope.defocus"), occluded = plane(exr, a.test, "slope.occluded");
        regions = metrics::regionErrors(test, reference, {object, coverage, defocus, occluded}, 2,
                                        metrics::kRelMseEpsilon, variance ? &*variance : nullptr,
                                        noise ? &*noise : nullptr);
    }
    metrics::Metrics m = metrics::compare(test, reference);
    if (!a.heatmap.empty())
        io::writePngHeat(a.heatmap, metrics::log10Map(metrics::relativeErrorMap(test, reference), kHeatLo), kHeatLo,
                         kHeatHi);
    if (!a.biasHeatmap.empty())
        io::writePngHeat(a.biasHeatmap,
                         metrics::log10Map(metrics::seedBiasMap(test, *other, reference), kBiasHeatLo),
                         kBiasHeatLo, kBiasHeatHi);
    if (a.json) {
        nlohmann::json j = metricsJson(m, variance ? std::optional<double>(varianceMean) : std::nullopt,
                                       noise ? std::optional<double>(noiseMean) : std::nullopt);
        j["test"] = a.test;
        j["reference"] = a.reference;
        j["relmse_epsilon"] = metrics::kRelMseEpsilon;
        if (a.regions) {
            nlohmann::json r = nlohmann::json::object();
            for (const auto& c : regions) {
                r[c.name] = {{"pixels", c.pixels}, {"share", c.share}, {"relmse", c.relMse}};
                if (variance) r[c.name]["variance"] = c.variance;
                if (noise) {
                    r[c.name]["reference_noise"] = c.noise;
                    r[c.name]["relmse_net"] = c.relMse - c.noise;
                    if (variance) r[c.name]["bias2"] = c.relMse - c.noise - c.variance;
                }
            }
            j["regions"] = r;
        }
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("relMSE %.6g  (eps %.2g, no 0.5 factor)\n", m.relMse, double(metrics::kRelMseEpsilon));
        std::printf("SMAPE  %.6g\n", m.smape);
        std::printf("PSNR   %.3f dB  (tone-mapped)\n", m.psnr);
        std::printf("SSIM   %.5f  (tone-mapped)\n", m.ssim);
        if (variance) {
            std::printf("variance %.6g  (half the relative squared difference from %s)\n", varianceMean,
                        a.varianceFrom.c_str());
            if (!noise)
                std::printf("rest     %.6g  (relMSE - variance: squared bias + the reference's own noise)\n",
                            m.relMse - varianceMean);
        }
        if (noise) {
            std::printf("reference noise %.6g  (half the relative squared difference of %s from %s)\n", noiseMean,
                        a.reference.c_str(), a.noiseFrom.c_str());
            std::printf("net relMSE      %.6g  (relMSE - reference noise: against a noise-free reference)\n",
                        m.relMse - noiseMean);
            if (variance)
                std::printf("bias2           %.6g  (net relMSE - variance)\n", m.relMse - varianceMean - noiseMean);
        }
        if (a.regions) {
            std::printf("%-11s %8s %8s %10s%s%s%s\n", "region", "pixels", "error", "relMSE", variance ? "   variance" : "",
                        noise ? "  ref noise  net relMSE" : "", variance && noise ? "      bias2" : "");
            for (const auto& c : regions) {
                std::printf("%-11s %7.1f%% %7.1f%% %10.4g", c.name.c_str(), 100 * c.pixels, 100 * c.share, c.relMse);
                if (variance) std::printf(" %10.4g", c.variance);
                if (noise) std::printf(" %10.4g  %10.4g", c.noise, c.relMse - c.noise);
                if (variance && noise) std::printf(" %10.4g", c.relMse - c.noise - c.variance);
                std::printf("\n");
            }
        }
    }
}

}  // namespace

void registerCompare(CLI::App& app) {
    auto args = std::make_shared<CompareArgs>();
    CLI::App* cmd = app.add_subcommand("compare", "Error metrics of an image against a reference");
    addMaxMemory(cmd);
    cmd->add_option("test", args->test, "Image to measure (.exr, .png, .pfm)")->required();
    cmd->add_option("reference", args->reference, "Reference image (.exr, .png, .pfm)")->required();
    cmd->add_flag("--json", args->json, "Print the metrics as JSON");
    cmd->add_flag("--regions", args->regions,
                  "Split relMSE over pixel classes of TEST's own planes (an EXR from wedge render): background, "
                  "mixed surfaces, edge (within 2 px), penumbra (some of the shadow rays blocked), defocused, interior");
    cmd->add_option("--variance-from", args->varianceFrom,
                    "A render made like TEST but with another --seed: splits TEST's relMSE into variance and the "
                    "rest (squared bias + the reference's own noise)");
    cmd->add_option("--reference-noise-from", args->noiseFrom,
                    "A second reference made like REFERENCE but with another --seed: estimates REFERENCE's own noise "
                    "(part of every relMSE against it) and reports relMSE net of it, overall and per region");
    cmd->add_option("--heatmap", args->heatmap, "Write a heat map of log10 relative squared error (10^-4..1) as PNG");
    cmd->add_option("--bias-heatmap", args->biasHeatmap,
                    "With --variance-from: write a heat map of the squared bias, (TEST - REF)(OTHER - REF) / (REF^2 + "
                    "0.01), log10 from 10^-5 to 10^-1, as PNG");
    cmd->callback([args] { runCompare(*args); });
}

}  // namespace wedge::app
