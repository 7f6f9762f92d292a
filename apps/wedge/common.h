// Helpers shared by the subcommands.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "scene/scene_desc.h"

namespace wedge::app {

/// Applies a "WxH" resolution override (empty: unchanged); throws wedge::Error on bad syntax.
void applyResolution(scene::SceneDesc& desc, const std::string& resolution);
/// Prints the scene's warnings (what it asks for that wedge does not render) to stderr.
void printWarnings(const scene::SceneDesc& desc);
/// Writes JSON through a temporary file and a rename.
void writeJsonFile(const std::string& path, const nlohmann::json& j);

}  // namespace wedge::app
