// The fuzz targets: one function per reader wedge exposes to users' files, each taking one input
// as libFuzzer hands it over. Bad input must end in a wedge::Error (exit 2 in the CLI); the
// functions catch that and nothing else, so a crash, a sanitizer report or any other exception
// is a finding. fuzz_main.cpp makes each a libFuzzer binary (`make fuzz`);
// tests/fuzz_regression_test.cpp replays fuzz/regressions/ and the seed corpora through the
// same functions in every build.
//
// An input may carry several files: the first is the target's own (scene.json, m.obj, a.png,
// ...), and each line "@@@ NAME" starts another, served under NAME next to it (a scene's meshes
// and textures, an OBJ's MTL, compare's reference image).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace wedge::fuzz {

/// True when wedge accepted the input, false when it refused it with a wedge::Error.
using Entry = bool (*)(const uint8_t* data, size_t size);

struct Target {
    const char* name;  // fuzz_<name>, fuzz/corpus/<name>/, fuzz/regressions/<name>/
    Entry run;
};

/// Every target, in `bench/fuzz.sh`'s order.
const std::vector<Target>& targets();
/// The target named `name`; nullptr if there is none.
const Target* target(const std::string& name);

/// Once per process, before the first input: a private scratch folder for the inputs' files
/// and a memory limit that a sanitizer's allocator can afford (core/memory_limit.h).
void initialize();

/// One input's files: the first named `firstName` (or by a "@@@ NAME" first line), the rest as
/// their "@@@ NAME" lines say.
struct File {
    std::string name, content;
};
std::vector<File> splitFiles(const uint8_t* data, size_t size, const std::string& firstName);

}  // namespace wedge::fuzz
