// Shared helpers for the tests: temporary directories, running the CLI, tiny scenes.
#pragma once

#include <string>

namespace wedge::test {

/// A fresh empty directory under the system temp dir, removed at process exit.
std::string tempDir();
/// Writes `text` to `path`.
void writeFile(const std::string& path, const std::string& text);
/// The bytes of the file at `path` ("" if it cannot be read).
std::string readFile(const std::string& path);
/// Runs the wedge binary with `args` (a shell-quoted string); returns the exit code and captures
/// stderr into `err` and stdout into `out` when given.
int runWedge(const std::string& args, std::string* out = nullptr, std::string* err = nullptr);
/// The repository's source directory.
std::string sourceDir();

}  // namespace wedge::test
