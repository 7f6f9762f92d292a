// Reading a whole file as bytes, with an error that names the file.
#pragma once

#include <string>

namespace wedge::io {

/// The file's bytes. Throws Error(file, ...) where it does not exist, is a directory or cannot
/// be read.
std::string readTextFile(const std::string& file);

}  // namespace wedge::io
