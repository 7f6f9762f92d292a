// Helpers shared by the subcommands.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "metrics/metrics.h"
#include "scene/scene_desc.h"

namespace wedge::app {

/// Applies a "WxH" resolution override (empty: unchanged); throws wedge::Error on bad syntax.
void applyResolution(scene::SceneDesc& desc, const std::string& resolution);
/// Prints the scene's warnings (what it asks for that wedge does not render) to stderr.
void printWarnings(const scene::SceneDesc& desc);
/// Numeric flag checks. CLI11's own (PositiveNumber, Range) let NaN through, since every
/// comparison with it is false, and PositiveNumber reports its range as 2.2e-308 to 1.8e308;
/// these accept finite numbers only and say what they expect: "expected a positive number,
/// got 'nan'".
CLI::Validator positiveNumber();
CLI::Validator nonNegativeNumber();
CLI::Validator numberIn(double lo, double hi);
/// --max-memory SIZE on `cmd`: the limit that sizes from files and flags are checked against
/// before anything is allocated (core/memory_limit.h); the machine's memory by default.
void addMaxMemory(CLI::App* cmd);
/// What `wedge compare --json` prints of an image against a reference, and the Python module's
/// compare() returns: relmse, smape, psnr (null for identical images) and ssim; with `variance`
/// (the test's, from a render with another seed) variance and bias2_and_reference_noise; with
/// `noise` (the reference's own, from a reference with another seed) reference_noise and
/// relmse_net; with both, bias2.
nlohmann::json metricsJson(const metrics::Metrics& m, std::optional<double> variance, std::optional<double> noise);
/// The checks `wedge compare` makes of a second image beside `first` (`--variance-from` beside
/// the test, `--reference-noise-from` beside the reference), and the Python module's compare() of
/// the same keywords: finite, and of `first`'s size, else an Error naming the file and the flag.
void checkSecondImage(const Image3f& second, const std::string& secondName, const std::string& flag,
                      const Image3f& first, const std::string& firstName);
/// Writes JSON through a temporary file and a rename.
void writeJsonFile(const std::string& path, const nlohmann::json& j);

}  // namespace wedge::app
