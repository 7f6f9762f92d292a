// The memory a file or a flag may ask wedge to allocate: sizes that come from outside (an image
// header, a scene's resolution x samples, a flag) are checked against one limit before anything
// is allocated, so that a hostile or mistaken size is a clear error ("needs 9.3 GiB, more than
// the limit of 7.8 GiB") instead of the kernel's OOM killer minutes later. The limit is the
// machine's physical memory unless --max-memory (or a fuzzer) sets it.
#pragma once

#include <cstdint>
#include <string>

namespace wedge {

/// The current limit in bytes: setMemoryLimit's, else the machine's physical memory.
uint64_t memoryLimit();
/// 0 restores the default (physical memory).
void setMemoryLimit(uint64_t bytes);
/// "512M", "8G", "1.5GiB", "1000000" (bytes) -> bytes; throws wedge::Error naming `where`.
uint64_t parseMemorySize(const std::string& text, const std::string& where);
/// "1.5 GiB", "12 MiB", "300 bytes".
std::string formatBytes(double bytes);
/// "<what> needs N, more than the memory limit of M (...)" when `bytes` exceeds memoryLimit(),
/// else "" (for readers that must release a library's state before they throw).
std::string overMemoryLimit(const std::string& what, uint64_t bytes);
/// Throws wedge::Error(where, overMemoryLimit(what, bytes)) when `bytes` exceeds memoryLimit().
void checkMemory(const std::string& where, const std::string& what, uint64_t bytes);

}  // namespace wedge
