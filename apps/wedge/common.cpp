#include "apps/wedge/common.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <unistd.h>

#include "core/error.h"
#include "core/image.h"
#include "core/memory_limit.h"
#include "io/output_file.h"

namespace wedge::app {

void addMaxMemory(CLI::App* cmd) {
    cmd->add_option_function<std::string>(
        "--max-memory", [](const std::string& size) { setMemoryLimit(parseMemorySize(size, "--max-memory")); },
        "Refuse inputs that would need more memory than this (e.g. 8G, 512M; default: the machine's memory)");
}

void printWarnings(const scene::SceneDesc& desc) {
    for (const auto& w : desc.warnings) std::fprintf(stderr, "wedge: warning: %s\n", w.c_str());
}

void applyResolution(scene::SceneDesc& desc, const std::string& resolution) {
    if (resolution.empty()) return;
    constexpr int kMax = kMaxImageSide;
    // Digits only (sscanf's %d would take "-3" and overflow on "99999999999"), then the bound.
    auto side = [](const std::string& digits) {
        if (digits.empty() || digits.size() > 6 || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
        return std::stoi(digits);
    };
    size_t x = resolution.find_first_of("xX");
    int w = x == std::string::npos ? -1 : side(resolution.substr(0, x));
    int h = x == std::string::npos ? -1 : side(resolution.substr(x + 1));
    if (w <= 0 || h <= 0 || w > kMax || h > kMax)
        throw Error("--resolution " + resolution,
                    "expected WxH with integers from 1 to " + std::to_string(kMax) + ", e.g. 256x256");
    desc.camera.width = w;
    desc.camera.height = h;
}

namespace {
/// A flag's value as a finite number, or nothing.
std::optional<double> finiteNumber(const std::string& text) {
    const char* begin = text.c_str();
    char* end = nullptr;
    errno = 0;
    double v = std::strtod(begin, &end);
    if (end == begin || *end != 0 || errno == ERANGE || !std::isfinite(v)) return std::nullopt;
    return v;
}

CLI::Validator numberCheck(std::string what, std::function<bool(double)> ok) {
    return CLI::Validator(
        [what, ok](std::string& text) -> std::string {
            std::optional<double> v = finiteNumber(text);
            return v && ok(*v) ? std::string() : "expected " + what + ", got '" + text + "'";
        },
        "NUMBER");
}

std::string shortNumber(double v) {
    char s[32];
    std::snprintf(s, sizeof s, "%.10g", v);
    return s;
}
}  // namespace

CLI::Validator positiveNumber() { return numberCheck("a positive number", [](double v) { return v > 0; }); }
CLI::Validator nonNegativeNumber() { return numberCheck("a number >= 0", [](double v) { return v >= 0; }); }
CLI::Validator numberIn(double lo, double hi) {
    return numberCheck("a number in [" + shortNumber(lo) + ", " + shortNumber(hi) + "]",
                       [lo, hi](double v) { return v >= lo && v <= hi; });
}

nlohmann::json metricsJson(const metrics::Metrics& m, std::optional<double> variance, std::optional<double> noise) {
    nlohmann::json j;
    j["relmse"] = m.relMse;
    j["smape"] = m.smape;
    j["psnr"] = std::isfinite(m.psnr) ? nlohmann::json(m.psnr) : nlohmann::json(nullptr);  // null: identical
    j["ssim"] = m.ssim;
    if (variance) {
        j["variance"] = *variance;
        j["bias2_and_reference_noise"] = m.relMse - *variance;
    }
    if (noise) {
        j["reference_noise"] = *noise;
        j["relmse_net"] = m.relMse - *noise;
        if (variance) j["bias2"] = m.relMse - *variance - *noise;
    }
    return j;
}

void checkSecondImage(const Image3f& second, const std::string& secondName, const std::string& flag,
                      const Image3f& first, const std::string& firstName) {
    metrics::requireFinite(second, secondName);
    if (!second.sameSize(first))
        throw Error(secondName, flag + ": image size " + std::to_string(second.width()) + "x" +
                                    std::to_string(second.height()) + " differs from " + firstName + "'s " +
                                    std::to_string(first.width()) + "x" + std::to_string(first.height()));
}

void writeJsonFile(const std::string& path, const nlohmann::json& j) { io::writeTextFile(path, j.dump(2) + "\n"); }

}  // namespace wedge::app
