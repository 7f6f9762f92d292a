// Shared helpers for the tests: temporary directories, running the CLI, an Error's message.
#pragma once

#include <string>
#include <vector>

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
/// A baseline JPEG of 8-bit samples (`components` 3: RGB, 1: greyscale), row-major, through
/// libjpeg: what texture maps in the wild are (wedge itself writes none).
void writeJpeg(const std::string& path, int w, int h, int components, const std::vector<unsigned char>& samples, int quality);
/// Runs the wedge binary with `args` (a shell-quoted string); returns the exit code and captures
/// stderr into `err` and stdout into `out` when given.
int runWedge(const std::string& args, std::string* out = nullptr, std::string* err = nullptr);
/// The bytes of a scan-line EXR header over the data window (x0, y0)-(x1, y1) with `channels`
/// FLOAT channels, no compression, then `offsets` line offsets that point past the end of the
/// file (the layout of OpenEXR's "OpenEXR File Layout"): a header that asks for what it likes
/// with almost no file behind it. `compression` is the header's compression byte (0 none, 9
/// DWAB); `extra` is appended to the header's attributes as it is (name, type, size, value).
std::string exrHeader(int x0, int y0, int x1, int y1, int channels, size_t offsets, int compression = 0,
                      const std::string& extra = "");
/// The repository's source directory.
std::string sourceDir();

}  // namespace wedge::test
