// Line-level checks of the numbers in Wavefront OBJ and MTL text, run before tinyobjloader reads
// the files. tinyobjloader is lenient where wedge must not be: a token that is not a number reads
// as 0 (`v nan 0 0`, `v 0 0 x`, `v 0.5.5 0 0`), a missing one too (`v 0 0`), and an MTL colour
// given with one component, which the MTL format reads as grey (`Kd 0.5` is 0.5 0.5 0.5), reads
// as (0.5, 0, 0). Such a file rendered without a word. These checks make every malformed line an
// error that names the file and the line, and report the grey colours for the caller to widen.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace wedge::scene {

/// Throws Error(where, "'<file>' line N: ...") at the first malformed line of OBJ text:
/// - `v`: 3 to 7 finite numbers (x y z, an optional w, optional r g b);
/// - `vn`: 3 finite numbers; `vt`: 1 to 3;
/// - `f`: at least 3 corners `v`, `v/t`, `v//n` or `v/t/n` of non-zero integers, each naming an
///   element of the file (negative: counted back from the last one defined above the face).
/// What wedge does not use (groups, smoothing, lines, points) is not checked beyond what
/// tinyobjloader checks. Returns a warning (else "") naming the first line
/// whose first word is not an OBJ statement (`v1 0 0`, `/v 0 0 0`): tinyobjloader skips such
/// lines, so a mistyped `v` or `f` silently loses geometry.
std::string checkObjText(std::string_view text, const std::string& where, const std::string& file);

/// The MTL files an OBJ's `mtllib` statements make tinyobjloader read, in its order: per
/// statement, the first of its names found in `searchDir` (or the working directory where
/// `searchDir` is empty) that no earlier statement read.
std::vector<std::string> mtlFilesOf(std::string_view objText, const std::string& searchDir);

/// A material of MTL text, in `newmtl` order: which of its colours have one component, and its
/// `map_Kd` statement after the keyword, options and file name (the file name ends it; the caller
/// checks that tinyobjloader's ends it too: its `-s 4 4 t.png` takes the file name for -s's third
/// number and loses it).
struct MtlColours {
    std::string name;
    bool greyKd = false, greyKe = false;
    std::string mapKd;
};

/// Throws Error(where, "'<file>' line N: ...") at the first malformed colour that wedge renders, a Kd or
/// Ke that is not 1 or 3 finite numbers (`spectral` and `xyz` colours are named as unsupported).
/// Returns the named materials in the order tinyobjloader lists them.
std::vector<MtlColours> checkMtlText(std::string_view text, const std::string& where, const std::string& file);

}  // namespace wedge::scene
