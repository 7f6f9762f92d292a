// `mpirun -n N wedge render` (docs/mpi.md): the same files as one process, bit for bit, for every
// method, at a resolution whose rows do not divide among the ranks; --stats' ranks and rays per
// rank; `experiment`'s results; bad input under MPI (one message, exit 2 on every rank, nothing
// written); a rank that fails or hangs ends the job instead of hanging it. Skipped when wedge was built without MPI.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "test_util.h"

using namespace wedge::test;
namespace fs = std::filesystem;

namespace {

#ifdef WEDGE_MPIEXEC
constexpr const char* kMpiexec = WEDGE_MPIEXEC;
#else
constexpr const char* kMpiexec = "";
#endif

#define REQUIRE_MPI()                                                        \
    do {                                                                     \
        if (std::string(kMpiexec).empty()) GTEST_SKIP() << "built without MPI"; \
    } while (0)

/// Runs `wedge ARGS` under `mpirun -n N` (N 0: without mpirun), under a 120 s timeout so that a
/// hang fails the test instead of stalling it; returns the exit code, stderr in `err`.
int runRanks(int n, const std::string& args, std::string* err = nullptr, const std::string& env = "") {
    const std::string dir = tempDir();
    std::string launcher;
    if (n > 0) {
        launcher = std::string(kMpiexec) + " --oversubscribe --bind-to none -n " + std::to_string(n) + " ";
        if (geteuid() == 0) launcher += "--allow-run-as-root ";
        launcher += "--mca btl self,vader ";  // one machine: shared memory only
        // Each job its own session directory: two jobs of ctest -j starting together both
        // created /tmp/ompi.HOST.UID and one failed with "mkdir ... File exists" (Open MPI 4.1,
        // seen once in CI on Mpi.AFailingRankEndsTheJobWithItsMessage).
        launcher += "--mca orte_tmpdir_base " + dir + " ";
        for (const char* var : {"WEDGE_MPI_FAULT", "WEDGE_MPI_TIMEOUT"})
            if (env.find(var) != std::string::npos) launcher += std::string("-x ") + var + " ";
    }
    const std::string cmd = env + " timeout 120 " + launcher + WEDGE_BIN + " " + args + " >" + dir + "/out.txt 2>" + dir +
                            "/err.txt";
    const int status = std::system(cmd.c_str());
    if (err) *err = readFile(dir + "/err.txt");
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

nlohmann::json readJson(const std::string& path) { return nlohmann::json::parse(readFile(path)); }

size_t occurrences(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

/// Renders `args` (a scene and flags) in one process and under -n 2 and -n 3; the EXR (every
/// buffer) and PFM files are the same bytes, and the rays per rank add up to one process's rays.
void expectSameAsOneProcess(const std::string& args) {
    const std::string dir = tempDir();
    std::string err;
    ASSERT_EQ(runRanks(0, args + " -o " + dir + "/one.exr -o " + dir + "/one.pfm --stats " + dir + "/one.json", &err), 0)
        << args << "\n" << err;
    const nlohmann::json one = readJson(dir + "/one.json");
    EXPECT_EQ(one["ranks"], 1);
    EXPECT_EQ(one["rays_per_rank"].size(), 1u);
    EXPECT_EQ(one["rays_per_rank"][0], one["rays"]);
    for (int n : {2, 3}) {
        const std::string base = dir + "/n" + std::to_string(n);
        ASSERT_EQ(runRanks(n, args + " -o " + base + ".exr -o " + base + ".pfm --stats " + base + ".json", &err), 0)
            << args << " -n " << n << "\n" << err;
        EXPECT_TRUE(readFile(base + ".exr") == readFile(dir + "/one.exr")) << args << ": EXR differs at -n " << n;
        EXPECT_TRUE(readFile(base + ".pfm") == readFile(dir + "/one.pfm")) << args << ": PFM differs at -n " << n;
        const nlohmann::json s = readJson(base + ".json");
        EXPECT_EQ(s["ranks"], n);
        ASSERT_EQ(s["rays_per_rank"].size(), size_t(n));
        uint64_t sum = 0;
        for (const auto& r : s["rays_per_rank"]) {
            EXPECT_GT(r.get<uint64_t>(), 0u);
            sum += r.get<uint64_t>();
        }
        EXPECT_EQ(sum, one["rays"].get<uint64_t>()) << args << " -n " << n;
        EXPECT_EQ(s["rays"], one["rays"]);
        EXPECT_EQ(s["spp_average"], one["spp_average"]);
        EXPECT_GT(s["mpi_bytes_exchanged"].get<double>(), 0);
    }
}

// 64x48: 48 rows over 2 and 3 ranks, and 16-pixel tiles; 47 rows do not divide at all.
TEST(Mpi, McIsBitIdenticalToOneProcess) {
    REQUIRE_MPI();
    // cornell has a lens: mc reconstructs with layers, so the light field is exchanged too.
    expectSameAsOneProcess("render cornell --method mc --spp 4 --resolution 64x47 --quiet");
    expectSameAsOneProcess("render cornell --method mc --spp 4 --layers off --resolution 64x48 --quiet");
}

TEST(Mpi, AafIsBitIdenticalToOneProcess) {
    REQUIRE_MPI();
    expectSameAsOneProcess("render cornell --method aaf --spp 4 --resolution 64x47 --quiet");
    expectSameAsOneProcess("render cornell --method aaf --spp 4 --layers on --resolution 64x48 --quiet");
}

TEST(Mpi, MaafIsBitIdenticalToOneProcess) {
    REQUIRE_MPI();
    // Both ways to the initial samples of the pixels with outer components: traced again, kept.
    expectSameAsOneProcess("render cornell --method maaf --spp 4 --resolution 64x47 --quiet");
    expectSameAsOneProcess("render cornell --method maaf --spp 4 --maaf-keep-records --resolution 64x48 --quiet");
}

/// A 64x48 scene file of `objects` (JSON, white) before a white wall, under one parallelogram
/// light, 4 spp and seed 5; its path.
std::string barScene(const std::string& objects) {
    const std::string path = tempDir() + "/bar.json";
    writeFile(path, R"({
      "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": 20, "resolution": [64, 48]},
      "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}},
      "lights": [{"type": "parallelogram", "corner": [-1, 2, -3], "edge1": [0, 0, -2], "edge2": [2, 0, 0], "radiance": [5, 5, 5]}],
      "objects": [)" + objects + R"(,
                  {"type": "quad", "corner": [-3, -3, -6], "edge1": [6, 0, 0], "edge2": [0, 6, 0], "material": "white"}],
      "render": {"spp": 4, "seed": 5, "indirect": true}
    })");
    return path;
}

TEST(Mpi, AafAroundATurningBarIsBitIdenticalToOneProcess) {
    REQUIRE_MPI();
    // A bar turning 120 degrees about (0, 1, 1) before a wall, and a moving post across the edge
    // of its reach: aaf keeps its own image within reach of the samples whose paths bend
    // (LightFieldSamples::bentReach), and the layers' along the rest of the post. A rank marks
    // the pixels of its rows, and the marks are exchanged before the mask is made (without the
    // exchange the images differ at -n 2 and -n 3: the rows are dealt in turn, so a rank's marks
    // alone reach nearly, not exactly, as far).
    const std::string scene = barScene(R"({"type": "quad", "corner": [-0.45, -0.45, -4], "edge1": [0.5, 0, 0], "edge2": [0, 0.08, 0], "material": "white",
                                           "angular_velocity": [0, 1, 1, 120]},
                                          {"type": "box", "min": [0.2, -0.6, -3.5], "max": [0.3, 0.3, -3.4], "material": "white", "velocity": [0.1, 0, 0]})");
    expectSameAsOneProcess("render " + scene + " --method aaf --spp 4 --quiet");
}

TEST(Mpi, McAroundASpinningBarIsBitIdenticalToOneProcess) {
    REQUIRE_MPI();
    // A bar spinning 90 degrees in the image plane before a wall: its samples keep their paths'
    // sagittas beside them (LightFieldSag), which the ranks exchange with the samples.
    const std::string scene = barScene(R"({"type": "quad", "corner": [-0.45, -0.04, -4], "edge1": [0.9, 0, 0], "edge2": [0, 0.08, 0], "material": "white",
                                           "angular_velocity": [0, 0, 1, 90]})");
    expectSameAsOneProcess("render " + scene + " --method mc --spp 4 --quiet");
}

TEST(Mpi, McAndAtrousBesideATurningBoxAreBitIdenticalToOneProcess) {
    REQUIRE_MPI();
    // docs/turning-room.json: a box turning 120 degrees about its diagonal, a sphere moving in
    // depth, the camera moving in. The layers leave the samples of pixels whose paths bend
    // (LightFieldSamples::bentReach) out of a moving layer's reach, from whichever rank's rows a
    // tile gathers them: the marks are exchanged with the samples. (Before, only aaf and maaf
    // exchanged them, in bentPixels: mc and à-trous differed at -n 2 and -n 3 in the tiles
    // around the box; found by rendering every docs/ scene on two ranks.)
    const std::string scene = std::string(WEDGE_SOURCE_DIR) + "/docs/turning-room.json";
    expectSameAsOneProcess("render " + scene + " --method mc --spp 4 --resolution 96x96 --quiet");
    expectSameAsOneProcess("render " + scene + " --method atrous --spp 4 --resolution 96x96 --quiet");
}

TEST(Mpi, AtrousIsBitIdenticalToOneProcess) {
    REQUIRE_MPI();
    expectSameAsOneProcess("render cornell --method atrous --spp 4 --resolution 64x47 --quiet");
    expectSameAsOneProcess("render grids --method atrous --spp 4 --resolution 64x48 --quiet");
}

TEST(Mpi, ASceneErrorIsReportedOnceWithExitTwoAndNothingWritten) {
    REQUIRE_MPI();
    const std::string dir = tempDir();
    writeFile(dir + "/bad.json", R"({"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "fov_y": 40, "resolution": [8, 8]},
                                     "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": -1}]})");
    std::string err;
    EXPECT_EQ(runRanks(3, "render " + dir + "/bad.json -o " + dir + "/x.exr --stats " + dir + "/s.json", &err), 2) << err;
    EXPECT_EQ(occurrences(err, "wedge: error:"), 1u) << err;
    EXPECT_NE(err.find("bad.json"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir + "/x.exr"));
    EXPECT_FALSE(fs::exists(dir + "/s.json"));
    // A bad flag likewise.
    EXPECT_EQ(runRanks(2, "render cornell --spp 0 -o " + dir + "/x.exr", &err), 2) << err;
    EXPECT_EQ(occurrences(err, "wedge: error:"), 1u) << err;
    EXPECT_FALSE(fs::exists(dir + "/x.exr"));
}

/// A small cornell render over `ranks` ranks with a fault injected through `env`
/// (WEDGE_MPI_FAULT, WEDGE_MPI_TIMEOUT): returns the job's exit code and checks that it wrote
/// nothing.
int runFaultyJob(int ranks, const std::string& env, std::string* err) {
    const std::string dir = tempDir();
    const int rc = runRanks(ranks, "render cornell --spp 2 --resolution 32x24 --quiet -o " + dir + "/x.exr", err, env);
    EXPECT_FALSE(fs::exists(dir + "/x.exr")) << *err;
    return rc;
}

TEST(Mpi, AFailingRankEndsTheJobWithItsMessage) {
    REQUIRE_MPI();
    // Rank 1 fails at its first exchange while ranks 0 and 2 go on to theirs: they learn of it
    // there and every rank exits with its code (1: an internal error), nothing written.
    std::string err;
    EXPECT_EQ(runFaultyJob(3, "WEDGE_MPI_FAULT=1:fail", &err), 1) << err;
    EXPECT_EQ(occurrences(err, "wedge: internal error (rank 1): injected failure"), 1u) << err;
}

TEST(Mpi, AHangingRankEndsTheJobAfterTheTimeout) {
    REQUIRE_MPI();
    // Rank 1 never reaches its exchange: rank 0 gives up after WEDGE_MPI_TIMEOUT seconds and
    // aborts the job (within runRanks' 120 s, which would report a hang as -1 or 124).
    std::string err;
    const int rc = runFaultyJob(2, "WEDGE_MPI_FAULT=1:hang WEDGE_MPI_TIMEOUT=2", &err);
    EXPECT_NE(rc, 0) << err;
    EXPECT_NE(rc, 124) << "timed out: the job hung\n" << err;
    EXPECT_NE(err.find("wedge: error (rank 0): waited"), std::string::npos) << err;
}

TEST(Mpi, ARankThatDiesEndsTheJob) {
    REQUIRE_MPI();
    // Rank 1 is killed (SIGKILL) at its first exchange: mpirun ends the job and says which rank.
    std::string err;
    const int rc = runFaultyJob(2, "WEDGE_MPI_FAULT=1:die", &err);
    EXPECT_NE(rc, 0) << err;
    EXPECT_NE(rc, 124) << "timed out: the job hung\n" << err;
    EXPECT_NE(err.find("rank 1"), std::string::npos) << err;
}

TEST(Mpi, OneRankUnderMpirunIsOneProcess) {
    REQUIRE_MPI();
    const std::string dir = tempDir();
    std::string err;
    ASSERT_EQ(runRanks(0, "render grids --spp 2 --resolution 24x16 --quiet -o " + dir + "/a.exr", &err), 0) << err;
    ASSERT_EQ(runRanks(1, "render grids --spp 2 --resolution 24x16 --quiet -o " + dir + "/b.exr --stats " + dir + "/b.json", &err),
              0)
        << err;
    EXPECT_TRUE(readFile(dir + "/a.exr") == readFile(dir + "/b.exr"));
    EXPECT_EQ(readJson(dir + "/b.json")["ranks"], 1);
}

/// results.json without what depends on the clock (stage times, efficiencies, overheads).
nlohmann::json withoutTimes(nlohmann::json j) {
    if (j.is_object()) {
        nlohmann::json out = nlohmann::json::object();
        for (auto& [k, v] : j.items())
            if (k != "seconds" && k.find("efficiency") == std::string::npos && k != "overhead") out[k] = withoutTimes(v);
        return out;
    }
    if (j.is_array())
        for (auto& v : j) v = withoutTimes(v);
    return j;
}

TEST(Mpi, ExperimentResultsAreTheOneProcessesApartFromTimes) {
    REQUIRE_MPI();
    // Its renders (the reference's halves, the methods, the variance renders, an equal-quality
    // search) split over the ranks; only rank 0 writes.
    const std::string dir = tempDir();
    const std::string args = "experiment cornell --methods mc,aaf --spp 2 --reference-spp 16 --resolution 32x24 --equal-quality --quiet --out ";
    std::string err;
    ASSERT_EQ(runRanks(0, args + dir + "/one", &err), 0) << err;
    ASSERT_EQ(runRanks(3, args + dir + "/three", &err), 0) << err;
    const nlohmann::json one = readJson(dir + "/one/results.json"), three = readJson(dir + "/three/results.json");
    ASSERT_FALSE(one.empty());
    EXPECT_EQ(withoutTimes(one), withoutTimes(three));
    EXPECT_TRUE(fs::exists(dir + "/three/index.html"));
    // The second run of each takes the reference from its cache, on every rank alike.
    ASSERT_EQ(runRanks(2, args + dir + "/three", &err), 0) << err;
    EXPECT_EQ(withoutTimes(readJson(dir + "/three/results.json")), withoutTimes(one));
}

TEST(Mpi, OtherCommandsRunOnRankZeroAlone) {
    REQUIRE_MPI();
    std::string err;
    const std::string dir = tempDir();
    // `scenes` prints once; `compare` with a missing file fails once with exit 2.
    EXPECT_EQ(runRanks(2, "compare " + dir + "/none.exr " + dir + "/none2.exr", &err), 2) << err;
    EXPECT_EQ(occurrences(err, "wedge: error:"), 1u) << err;
}

}  // namespace
