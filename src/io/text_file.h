// Reading a whole file as bytes, with an error that names the file; escaping text for HTML and
// SVG (the experiment report and its plots).
#pragma once

#include <string>

namespace wedge::io {

/// The file's bytes. Throws Error(file, ...) where it does not exist, is a directory or cannot
/// be read.
std::string readTextFile(const std::string& file);
/// `s` with <, >, & and " as entities, for HTML or SVG text and attribute values.
std::string htmlEscape(const std::string& s);

}  // namespace wedge::io
