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
/// --stats: timings, counts, the method's figures and `nonfinite_pixels`.
nlohmann::json statsJson(const RenderResult& result, const std::string& sceneName);
/// Pixels whose sampled light (emission, direct, indirect, further surfaces, rest) or final
/// colour is NaN or infinite: every pixel with a non-finite sample, and every pixel a filter made
/// non-finite. A correct render has none; the count makes one that has them visible.
size_t nonFinitePixels(const RenderResult& result);
/// Where a scene has lights but no light sample reached any surface with light (--stats
/// lit_samples 0: every light faces away from what the camera sees and what that sees), what
/// to say about its black image; empty otherwise. `wedge render` prints it as a warning, the
/// Python module raises it as one.
std::string unlitWarning(const scene::SceneDesc& desc, const RenderResult& result);
std::string timingSummary(const RenderResult& result);

}  // namespace wedge::render
