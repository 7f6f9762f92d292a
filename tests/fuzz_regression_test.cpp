// The fuzz targets (fuzz/targets.h) on every file of fuzz/regressions/<target>/ (inputs that
// once crashed, hung or broke a sanitizer) and fuzz/corpus/<target>/ (the seeds), in every
// build: under `make test-sanitize` they run with ASan and UBSan. A target lets only a
// wedge::Error out as a refusal; anything else (another exception, a crash, a report) fails here.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "fuzz/targets.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace wedge;

namespace {

struct Replay {
    int files = 0, accepted = 0;
};

/// Every regular file under `dir` through `target`.
Replay replay(const fuzz::Target& target, const fs::path& dir) {
    Replay r;
    if (!fs::is_directory(dir)) return r;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
        if (!entry.is_regular_file()) continue;
        SCOPED_TRACE(entry.path().string());
        std::ifstream in(entry.path(), std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        ++r.files;
        r.accepted += target.run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    }
    return r;
}

const fs::path kFuzzDir = fs::path(WEDGE_SOURCE_DIR) / "fuzz";

}  // namespace

TEST(FuzzRegressions, SeedsAreReadAndSomeAreAccepted) {
    // A corpus of inputs that are all refused would fuzz the first check and nothing past it.
    for (const fuzz::Target& t : fuzz::targets()) {
        SCOPED_TRACE(t.name);
        const Replay r = replay(t, kFuzzDir / "corpus" / t.name);
        EXPECT_GE(r.files, 2);
        EXPECT_GE(r.accepted, 1);
    }
}

TEST(FuzzRegressions, FindingsEndInAnErrorOrAResultNotACrash) {
    // Each was a crash, a hang, a sanitizer report or an exception other than wedge::Error;
    // replay() fails on any of those. (Some are refused, some load: a map_Kd whose name is too
    // long for the file system is a texture not rendered, named in a warning.)
    int files = 0;
    for (const fuzz::Target& t : fuzz::targets()) files += replay(t, kFuzzDir / "regressions" / t.name).files;
    EXPECT_GE(files, 5) << "fuzz/regressions/ holds the findings (docs/reliability.md)";
}

TEST(FuzzRegressions, AnInputCarriesNamedFiles) {
    const std::string input = "{\"a\": 1}\n@@@ m.obj\nv 0 0 0\n@@@ ../x/.mtl\nnewmtl a\n@@@ scene.json\n";
    const auto files = fuzz::splitFiles(reinterpret_cast<const uint8_t*>(input.data()), input.size(), "scene.json");
    ASSERT_EQ(files.size(), 4u);
    EXPECT_EQ(files[0].name, "scene.json");
    EXPECT_EQ(files[0].content, "{\"a\": 1}");
    EXPECT_EQ(files[1].name, "m.obj");
    EXPECT_EQ(files[1].content, "v 0 0 0");
    EXPECT_EQ(files[2].name, "_.._x_.mtl") << "kept inside the scratch folder";
    EXPECT_EQ(files[3].name, "_scene.json") << "never replaces the first file";
    EXPECT_EQ(files[3].content, "");
    const std::string named = "@@@ a.png\nPNG\n@@@ a.png\nsame name";
    const auto pair = fuzz::splitFiles(reinterpret_cast<const uint8_t*>(named.data()), named.size(), "test.exr");
    ASSERT_EQ(pair.size(), 2u);
    EXPECT_EQ(pair[0].name, "a.png");
    EXPECT_EQ(pair[0].content, "PNG");
    EXPECT_EQ(pair[1].name, "_a.png");
}
