// wedge compare TEST REF [--json] [--heatmap OUT.png]: relMSE, SMAPE, PSNR and SSIM of a
// rendering against a reference (metrics/metrics.h), and a heat map of the per-pixel relative
// squared error on a log scale.
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "apps/wedge/commands.h"
#include "core/error.h"
#include "io/image_io.h"
#include "metrics/metrics.h"

namespace wedge::app {

namespace {

struct CompareArgs {
    std::string test, reference, heatmap;
    bool json = false;
};

// Heat maps show log10 relative squared error from 10^-4 (dark) to 10^0 (yellow).
constexpr float kHeatLo = -4.f, kHeatHi = 0.f;

void runCompare(const CompareArgs& a) {
    if (!a.heatmap.empty()) io::checkOutputPath(a.heatmap, {".png"});
    Image3f test = io::readColor(a.test), reference = io::readColor(a.reference);
    if (!test.sameSize(reference))
        throw Error(a.test, "image size mismatch: " + std::to_string(test.width()) + "x" + std::to_string(test.height()) +
                                " against " + std::to_string(reference.width()) + "x" +
                                std::to_string(reference.height()) + " in " + a.reference);
    metrics::Metrics m = metrics::compare(test, reference);
    if (!a.heatmap.empty())
        io::writePngHeat(a.heatmap, metrics::log10Map(metrics::relativeErrorMap(test, reference), kHeatLo), kHeatLo,
                         kHeatHi);
    if (a.json) {
        nlohmann::json j;
        j["test"] = a.test;
        j["reference"] = a.reference;
        j["relmse"] = m.relMse;
        j["relmse_epsilon"] = metrics::kRelMseEpsilon;
        j["smape"] = m.smape;
        j["psnr"] = std::isfinite(m.psnr) ? nlohmann::json(m.psnr) : nlohmann::json(nullptr);  // null: identical
        j["ssim"] = m.ssim;
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("relMSE %.6g  (eps %.2g, no 0.5 factor)\n", m.relMse, double(metrics::kRelMseEpsilon));
        std::printf("SMAPE  %.6g\n", m.smape);
        std::printf("PSNR   %.3f dB  (tone-mapped)\n", m.psnr);
        std::printf("SSIM   %.5f  (tone-mapped)\n", m.ssim);
    }
}

}  // namespace

void registerCompare(CLI::App& app) {
    auto args = std::make_shared<CompareArgs>();
    CLI::App* cmd = app.add_subcommand("compare", "Error metrics of an image against a reference");
    cmd->add_option("test", args->test, "Image to measure (.exr, .png, .pfm)")->required();
    cmd->add_option("reference", args->reference, "Reference image (.exr, .png, .pfm)")->required();
    cmd->add_flag("--json", args->json, "Print the metrics as JSON");
    cmd->add_option("--heatmap", args->heatmap, "Write a heat map of log10 relative squared error (10^-4..1) as PNG");
    cmd->callback([args] { runCompare(*args); });
}

}  // namespace wedge::app
