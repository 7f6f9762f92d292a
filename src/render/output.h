// Files a render produces: the image in the format its extension names (.exr with every buffer
// as named channels, .png tone-mapped, .pfm colour), the --stats JSON and the timing summary.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/image_io.h"
#include "render/renderer.h"

namespace wedge::render {

/// The output formats `-o` accepts.
const std::vector<std::string>& outputExtensions();
/// The channels of the .exr output: R, G, B, then every buffer under its own name ("depth",
/// "normal.X", ...); they point into `result`.
std::vector<io::ExrChannel> exrChannels(const RenderResult& result);
void writeOutput(const RenderResult& result, const std::string& path);
nlohmann::json statsJson(const RenderResult& result, const std::string& sceneName);
std::string timingSummary(const RenderResult& result);

}  // namespace wedge::render
