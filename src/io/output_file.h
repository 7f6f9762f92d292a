// Output files are whole or absent: every writer goes through a temporary file beside the
// output and a rename, so a failed write (a full disk; a file over `ulimit -f`) or an interrupted
// run leaves no half-written file and the previous output, if any, as it was. SIGINT and SIGTERM
// remove the temporaries of the writes under way before the process ends.
#pragma once

#include <functional>
#include <string>

namespace wedge::io {

/// Calls `write(tmp)` for a temporary path beside `path`, then renames it onto `path`; removes
/// the temporary when `write` throws or the rename fails (wedge::Error naming `path`).
void atomicWrite(const std::string& path, const std::function<void(const std::string& tmp)>& write);
/// `text` through atomicWrite, its close checked: a full disk shows when the buffer is flushed.
void writeTextFile(const std::string& path, const std::string& text);

/// SIGINT and SIGTERM: remove the temporaries of the writes under way, print "wedge:
/// interrupted by SIGINT; no output written past this point" and exit with 128 + the signal
/// number (130, 143), as a shell reports a process it interrupted. SIGXFSZ is ignored, so that a
/// file over `ulimit -f` fails its write (EFBIG) and is a clear error instead of a killed process.
void installSignalHandlers();

}  // namespace wedge::io
