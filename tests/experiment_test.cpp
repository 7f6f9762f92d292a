// `wedge experiment`: the boundary search behind equal quality and equal time, the files a tiny
// experiment writes (results.json rows, a self-contained index.html, the cached reference), bad
// input, and the report as headless Chromium shows it (a screenshot that must not be blank).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "io/image_io.h"
#include "render/experiment.h"
#include "test_util.h"

using namespace wedge;
namespace fs = std::filesystem;

namespace {

/// A small experiment in a fresh directory; returns the directory.
std::string runTinyExperiment(const std::string& extra = "", std::string* err = nullptr) {
    std::string dir = test::tempDir() + "/exp";
    std::string e;
    int rc = test::runWedge("experiment cornell --methods mc,atrous --spp 2 --reference-spp 16 --resolution 24x24 "
                            "--threads 1 --equal-quality --equal-time --out " + dir + " " + extra,
                            nullptr, &e);
    EXPECT_EQ(rc, 0) << e;
    if (err) *err = e;
    return dir;
}

}  // namespace

TEST(ExperimentSearch, FindsTheBoundaryFromBelowAndAbove) {
    for (int boundary : {1, 2, 5, 37, 100, 256}) {
        for (int start : {1, 4, 16, 300}) {
            if (start > 256) continue;
            int evaluations = 0;
            auto above = [&](int s) {
                EXPECT_GE(s, 1);
                EXPECT_LE(s, 256);
                ++evaluations;
                return s >= boundary;
            };
            render::SearchBracket b = render::searchBoundary(above, start, start >= boundary, 30.0, 256, 0.0);
            EXPECT_EQ(b.hi, boundary) << "start " << start;
            EXPECT_EQ(b.lo, boundary - 1) << "start " << start;
            EXPECT_LE(evaluations, 12) << "boundary " << boundary << " start " << start;
        }
    }
}

TEST(ExperimentSearch, ReportsATargetOutOfReach) {
    auto never = [](int) { return false; };
    render::SearchBracket b = render::searchBoundary(never, 4, false, 1000.0, 64, 0.1);
    EXPECT_EQ(b.hi, 65);
    EXPECT_EQ(b.lo, 64);
}

TEST(ExperimentSearch, ToleranceStopsEarly) {
    int evaluations = 0;
    auto above = [&](int s) {
        ++evaluations;
        return s >= 700;
    };
    render::SearchBracket b = render::searchBoundary(above, 16, false, 100.0, 4096, 0.25);
    EXPECT_GE(b.hi, 700);
    EXPECT_LT(b.lo, 700);
    EXPECT_LE(double(b.hi), double(b.lo) * 1.25 + 1);
    EXPECT_LE(evaluations, 8);
}

TEST(ExperimentCommand, WritesRowsAndASelfContainedReport) {
    std::string dir = runTinyExperiment("--quiet --repeat 2");
    auto rows = nlohmann::json::parse(test::readFile(dir + "/results.json"));
    ASSERT_TRUE(rows.is_array());
    std::set<std::string> seen;
    for (const auto& r : rows) {
        for (const char* key : {"method", "spp", "spp_average", "seconds", "relmse", "psnr", "ssim"})
            EXPECT_TRUE(r.contains(key)) << key << " missing in " << r.dump();
        EXPECT_TRUE(r["seconds"].contains("total"));
        EXPECT_TRUE(r["seconds"].contains("sampling"));
        std::string setting = r["setting"];
        seen.insert(r["method"].get<std::string>() + "/" + setting);
        if (setting == "equal_quality" && r["reached"].get<bool>()) {
            EXPECT_LE(r["relmse"].get<double>(), r["target_relmse"].get<double>());
        }
        if (setting == "equal_time" && r["reached"].get<bool>()) {
            EXPECT_LE(r["seconds"]["total"].get<double>(), r["target_seconds"].get<double>());
        }
        EXPECT_TRUE(fs::is_regular_file(dir + "/" + r["image"].get<std::string>()));
    }
    // atrous is the anchor here (no aaf/maaf requested): mc gets searched, atrous does not.
    EXPECT_TRUE(seen.count("mc/base") && seen.count("atrous/base"));
    EXPECT_TRUE(seen.count("mc/equal_quality") && seen.count("mc/equal_time"));
    EXPECT_FALSE(seen.count("atrous/equal_quality"));
    // The reference's own noise (from its two halves) is part of every relMSE: positive, below
    // the 2-spp mc's error (the reference has 16), and the net relMSE is what is left.
    for (const auto& r : rows) {
        ASSERT_TRUE(r.contains("reference_noise_relmse") && r.contains("relmse_net")) << r.dump();
        const double noise = r["reference_noise_relmse"].get<double>(), relmse = r["relmse"].get<double>();
        EXPECT_GT(noise, 0.0);
        EXPECT_NEAR(r["relmse_net"].get<double>(), relmse - noise, 1e-12);
        if (r["method"] == "mc" && r["setting"] == "base") {
            EXPECT_LT(noise, 0.5 * relmse);
        }
        // Base rows split the net relMSE into variance (from a render with another seed) and
        // squared bias. Monte Carlo has no bias: its variance is nearly all of its net relMSE.
        ASSERT_EQ(r.contains("variance_relmse"), r["setting"] == "base") << r.dump();
        if (r["setting"] != "base") continue;
        const double variance = r["variance_relmse"].get<double>(), net = r["relmse_net"].get<double>();
        EXPECT_GT(variance, 0.0);
        EXPECT_NEAR(r["bias2_relmse"].get<double>(), net - variance, 1e-12);
        if (r["method"] == "mc") {
            EXPECT_LT(std::abs(net - variance), 0.3 * variance) << r.dump();
        }
        // ... and over the render's pixel classes: the classes cover the image, and their
        // pixel-weighted relMSE and variance add up to the row's.
        ASSERT_TRUE(r.contains("regions")) << r.dump();
        double pixels = 0, share = 0, weighted = 0, weightedVariance = 0;
        for (const auto& [name, c] : r["regions"].items()) {
            pixels += c["pixels"].get<double>();
            share += c["share"].get<double>();
            weighted += c["pixels"].get<double>() * c["relmse"].get<double>();
            weightedVariance += c["pixels"].get<double>() * c["variance"].get<double>();
        }
        EXPECT_EQ(r["regions"].size(), 6u);
        EXPECT_NEAR(pixels, 1.0, 1e-9);
        EXPECT_NEAR(share, 1.0, 1e-9);
        EXPECT_NEAR(weighted, relmse, 1e-6 * relmse);
        EXPECT_NEAR(weightedVariance, variance, 1e-6 * variance);
        EXPECT_GT(r["regions"]["penumbra"]["pixels"].get<double>(), 0.0) << "the tiny scene has soft shadows";
    }
    for (const auto& r : rows) {
        if (r["method"] == "atrous") {
            EXPECT_GT(r["seconds"]["filter"].get<double>(), 0.0);
        }
        EXPECT_EQ(r["anchor"], "atrous");
    }

    std::string html = test::readFile(dir + "/index.html");
    // Self-contained: every image is inline and nothing is loaded from elsewhere.
    std::regex src("src=\"([^\"]*)\"");
    int images = 0;
    for (auto it = std::sregex_iterator(html.begin(), html.end(), src); it != std::sregex_iterator(); ++it) {
        EXPECT_EQ((*it)[1].str().rfind("data:image/png;base64,", 0), 0u) << (*it)[1].str().substr(0, 60);
        ++images;
    }
    // Reference + 4 rows, each with 2 insets, and a heat map per row.
    EXPECT_EQ(images, 5 * 3 + 4);
    EXPECT_NE(html.find("Fig. 12"), std::string::npos);
    EXPECT_NE(html.find("speedup"), std::string::npos);
    EXPECT_NE(html.find("its own noise"), std::string::npos);
    EXPECT_NE(html.find("net relMSE"), std::string::npos);
    EXPECT_NE(html.find("bias&sup2;"), std::string::npos);
    EXPECT_NE(html.find("Where the error sits"), std::string::npos);
    // The convergence plot, an inline SVG of every render: one line per method through its
    // renders' distinct sample counts (the base spp and the searches' probes), one marker each.
    std::map<std::string, std::set<int>> rendered;
    for (const auto& r : rows) {
        rendered[r["method"]].insert(r["spp"].get<int>());
        if (r.contains("probes"))
            for (const auto& p : r["probes"]) rendered[r["method"]].insert(p["spp"].get<int>());
    }
    const size_t svgAt = html.find("<h2>Convergence</h2>");
    ASSERT_NE(svgAt, std::string::npos);
    const std::string svg = html.substr(html.find("<svg", svgAt), html.find("</svg>", svgAt) - html.find("<svg", svgAt));
    std::regex polyline("<polyline[^>]*points=\"([^\"]*)\"");
    std::vector<size_t> points;
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), polyline); it != std::sregex_iterator(); ++it) {
        const std::string list = (*it)[1].str();
        points.push_back(size_t(std::count(list.begin(), list.end(), ',')));
    }
    ASSERT_EQ(rendered.size(), 2u);
    EXPECT_GT(rendered["mc"].size(), 1u) << "mc was searched";
    size_t markers = 0;
    for (size_t k = std::string::npos; (k = svg.find("<circle", k + 1)) != std::string::npos;) ++markers;
    EXPECT_EQ(markers, rendered["mc"].size() + rendered["atrous"].size());
    // mc's line comes first (the rows' order); atrous, with one render, has a marker and no line.
    ASSERT_GE(points.size(), 1u);
    EXPECT_EQ(points[0], rendered["mc"].size());
    EXPECT_EQ(points.size(), rendered["atrous"].size() > 1 ? 2u : 1u);
    EXPECT_TRUE(fs::is_regular_file(dir + "/table.md"));
    const std::string table = test::readFile(dir + "/table.md");
    EXPECT_NE(table.find("| where | background | mixed | edge | penumbra | defocused | interior |"), std::string::npos)
        << table;
}

TEST(ExperimentCommand, CachesTheReferenceAndShowsProgressUnlessQuiet) {
    std::string dir = test::tempDir() + "/exp";
    std::string args = "experiment cornell --methods mc,atrous --spp 2 --reference-spp 16 --out " + dir + " --resolution ";
    std::string args16 = args + "16x16";
    std::string out, err;
    ASSERT_EQ(test::runWedge(args16, &out, &err), 0) << err;
    EXPECT_NE(err.find("rendering the reference"), std::string::npos) << err;
    EXPECT_NE(err.find("100%"), std::string::npos) << "a progress bar on stderr";
    EXPECT_NE(out.find("| atrous |"), std::string::npos) << out;
    int cached = 0;
    for (const auto& e : fs::directory_iterator(dir + "/cache")) cached += e.path().extension() == ".exr";
    EXPECT_EQ(cached, 1);
    ASSERT_EQ(test::runWedge(args16, &out, &err), 0) << err;
    EXPECT_NE(err.find("reference from cache"), std::string::npos) << err;
    // Quiet: nothing on stdout or stderr.
    ASSERT_EQ(test::runWedge(args16 + " --quiet", &out, &err), 0) << err;
    EXPECT_EQ(out, "");
    EXPECT_EQ(err, "");
    // The methods' --sampler is not the reference's (its cache key names none): rendered afresh
    // with the methods' independent samples, the reference is the same file.
    const std::string dirIndependent = test::tempDir() + "/exp-independent";
    ASSERT_EQ(test::runWedge("experiment cornell --methods mc --spp 2 --reference-spp 16 --quiet --sampler independent --out " +
                                 dirIndependent + " --resolution 16x16",
                             &out, &err),
              0)
        << err;
    for (const auto& e : fs::directory_iterator(dir + "/cache")) {
        if (e.path().extension() == ".exr") {
            EXPECT_EQ(test::readFile(e.path().string()), test::readFile(dirIndependent + "/cache/" + e.path().filename().string()));
        }
    }
    // A different resolution is a different reference.
    ASSERT_EQ(test::runWedge(args + "12x12 --quiet", &out, &err), 0) << err;
    cached = 0;
    for (const auto& e : fs::directory_iterator(dir + "/cache")) cached += e.path().extension() == ".exr";
    EXPECT_EQ(cached, 2);
}

TEST(ExperimentCommand, EditingAMeshOrItsMaterialRendersTheReferenceAgain) {
    // The cache key holds the scene as loaded, not only the scene file's text: an MTL whose Kd
    // changed (the scene file untouched) must not reuse the old reference.
    std::string dir = test::tempDir() + "/edit";
    fs::create_directories(dir);
    test::writeFile(dir + "/q.obj", "mtllib q.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nusemtl m\nf 1 4 3 2\n");
    test::writeFile(dir + "/q.mtl", "newmtl m\nKd 0.5 0.5 0.5\n");
    test::writeFile(dir + "/s.json", R"({
      "camera": {"position": [0, 2, 2], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 50, "resolution": [12, 12]},
      "materials": {},
      "lights": [{"type": "sphere", "center": [0, 1.5, 0], "radius": 0.2, "radiance": [5, 5, 5]}],
      "objects": [{"type": "mesh", "file": "q.obj"}],
      "render": {"spp": 4, "seed": 1, "indirect": false}
    })");
    const std::string args = "experiment " + dir + "/s.json --methods mc --spp 2 --reference-spp 8 --out " + dir + "/out";
    auto entries = [&] {
        int n = 0;
        for (const auto& e : fs::directory_iterator(dir + "/out/cache")) n += e.path().extension() == ".exr";
        return n;
    };
    std::string out, err;
    ASSERT_EQ(test::runWedge(args, &out, &err), 0) << err;
    ASSERT_EQ(test::runWedge(args, &out, &err), 0) << err;
    EXPECT_NE(err.find("reference from cache"), std::string::npos) << err;
    EXPECT_EQ(entries(), 1);
    test::writeFile(dir + "/q.mtl", "newmtl m\nKd 0.9 0.2 0.2\n");
    ASSERT_EQ(test::runWedge(args, &out, &err), 0) << err;
    EXPECT_EQ(err.find("reference from cache"), std::string::npos) << err;
    EXPECT_EQ(entries(), 2);
}

TEST(ExperimentCommand, BadInputExitsWithTwo) {
    std::string dir = test::tempDir();
    test::writeFile(dir + "/file", "x");
    const std::string base = "experiment cornell --resolution 8x8 --spp 2 --reference-spp 8 --quiet ";
    std::string err;
    EXPECT_EQ(test::runWedge(base + "--methods mc,bogus --out " + dir + "/a", nullptr, &err), 2);
    EXPECT_NE(err.find("bogus"), std::string::npos) << err;
    EXPECT_EQ(test::runWedge(base + "--methods mc,mc --out " + dir + "/a", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge(base + "--methods mc --anchor atrous --out " + dir + "/a", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge(base + "--methods mc --out " + dir + "/file", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge(base + "--methods mc --out " + dir + "/missing/parent", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge(base + "--methods mc --reference-spp 2 --out " + dir + "/a", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge(base + "--methods mc --resolution 8by8 --out " + dir + "/a", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge(base + "--methods mc --repeat 0 --out " + dir + "/a", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge("experiment no-such-scene --quiet --out " + dir + "/a", nullptr, &err), 2);
    EXPECT_EQ(test::runWedge("experiment cornell --quiet", nullptr, &err), 2) << "--out is required";
    EXPECT_FALSE(fs::exists(dir + "/a")) << "nothing is written for bad input";
}

// The report as people see it: headless Chromium renders index.html, and the screenshot must
// show the images (many distinct colours, a good share of non-white pixels). Chromium is a
// build dependency (scripts/install-deps.sh); without it this test fails rather than skips.
TEST(ExperimentReport, OpensInHeadlessChromiumAndShowsItsImages) {
    std::string browser;
    for (const char* name : {"chromium", "chromium-browser"})
        if (std::system((std::string("command -v ") + name + " >/dev/null 2>&1").c_str()) == 0) browser = name;
    ASSERT_FALSE(browser.empty()) << "chromium not found: run scripts/install-deps.sh (Debian package 'chromium')";

    std::string dir = runTinyExperiment("--quiet");
    std::string profile = test::tempDir(), shot = test::tempDir() + "/shot.png";
    std::string cmd = "timeout 60 " + browser +
                      " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run"
                      " --disable-background-networking --disable-component-update --disable-sync"
                      " --user-data-dir=" + profile + " --screenshot=" + shot +
                      " --window-size=1200,1400 file://" + fs::absolute(dir + "/index.html").string() + " >/dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    ASSERT_TRUE(fs::is_regular_file(shot));
    Image3f img = io::readPng(shot);
    ASSERT_EQ(img.width(), 1200);
    std::set<uint32_t> colours;
    size_t nonWhite = 0;
    for (size_t i = 0; i < img.size(); ++i) {
        uint32_t r = uint32_t(io::srgbEncode(img[i].x) * 255.f + 0.5f), g = uint32_t(io::srgbEncode(img[i].y) * 255.f + 0.5f),
                 b = uint32_t(io::srgbEncode(img[i].z) * 255.f + 0.5f);
        colours.insert(r << 16 | g << 8 | b);
        nonWhite += (r < 240 || g < 240 || b < 240);
    }
    // Text and table rules alone give grey levels; the renders, insets and heat maps give the colours.
    EXPECT_GT(colours.size(), 500u);
    EXPECT_GT(double(nonWhite) / double(img.size()), 0.1);
    // The Cornell box's red wall is on screen.
    size_t red = 0;
    for (size_t i = 0; i < img.size(); ++i) red += img[i].x > 0.1f && img[i].x > 3 * img[i].y && img[i].x > 3 * img[i].z;
    EXPECT_GT(red, 1000u);
}
