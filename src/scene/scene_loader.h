// Scene files (JSON, version 1) and built-in scene names -> SceneDesc. All validation lives
// here: every error names the file and the JSON path and is a wedge::Error.
#pragma once

#include <string>
#include <vector>

#include "scene/scene_desc.h"

namespace wedge::scene {

/// Loads a scene from a file path or a built-in name (see builtinScenes()).
SceneDesc loadScene(const std::string& pathOrName);
/// Parses scene JSON text as if read from `file` (relative mesh paths resolve against `baseDir`).
SceneDesc parseScene(const std::string& jsonText, const std::string& file, const std::string& baseDir);

struct BuiltinScene {
    std::string name, file, description, attribution;
};
/// Names for a warning, quoted, the first three and a count: "'a', 'b', 'c' and 2 more".
std::string nameList(const std::vector<std::string>& names);
/// The scenes shipped under scenes/ (listed in scenes/index.json).
std::vector<BuiltinScene> builtinScenes();
/// The directory built-in names resolve against: $WEDGE_SCENES, else the source tree's scenes/.
std::string scenesDirectory();

/// Loads a Wavefront OBJ (with its MTL) into `mesh`, appending its materials to `materials`
/// unless `overrideMaterial` >= 0. The text is checked line by line first (obj_check.h).
/// Emissive faces become lights in `promoted`: parallelogram faces, and pairs of triangles that
/// make one, as parallelograms; the rest as triangles (a polygon by its fan). What wedge does not
/// render (specular terms, transparency, maps it cannot read, lines that are no OBJ statement)
/// is named in `warnings`.
void loadObj(const std::string& path, const std::string& where, int overrideMaterial, std::vector<Material>& materials,
             TriangleMesh& mesh, std::vector<AreaLight>& promoted, std::vector<std::string>& warnings);

}  // namespace wedge::scene
