// Shared helpers for the tests: temporary directories, running the CLI, an Error's message.
#pragma once

#include <string>

#include "core/error.h"

namespace wedge::test {

/// The message of the wedge::Error that `run` throws, or "" if it throws none.
template <class Fn>
std::string errorOf(Fn&& run) {
    try {
        run();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

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
