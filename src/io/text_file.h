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

/// Why `path` is not a regular file: "" if it is one, else "no such file", "is a directory" or
/// the system's reason ("File name too long"). Never throws: std::filesystem's throwing queries
/// do on a name over NAME_MAX, and that escaped wedge's errors (fuzz_obj, a 4 KB map_Kd name).
std::string notARegularFile(const std::string& path);

}  // namespace wedge::io
