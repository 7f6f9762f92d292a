// Command line: every malformed input ends with exit code 2, a message that names the file and
// the field, and no output file.
#include <gtest/gtest.h>

#include <filesystem>
#include <sys/wait.h>
#include <nlohmann/json.hpp>

#include "io/image_io.h"
#include "test_util.h"

using namespace wedge::test;
namespace fs = std::filesystem;

namespace {

const char* kGood = R"({
  "camera": {"position": [0, 1, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [8, 8]},
  "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}},
  "lights": [{"type": "parallelogram", "corner": [-0.5, 2, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [5, 5, 5]}],
  "objects": [OBJECT],
  "render": {"spp": 2, "seed": 1, "indirect": true}
})";

std::string scene(const std::string& object, const std::string& patchFrom = "", const std::string& patchTo = "") {
    std::string s = kGood;
    s.replace(s.find("OBJECT"), 6, object);
    if (!patchFrom.empty()) {
        auto p = s.find(patchFrom);
        EXPECT_NE(p, std::string::npos) << patchFrom;
        s.replace(p, patchFrom.size(), patchTo);
    }
    return s;
}

const std::string kSphere = R"({"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "white"})";

struct Case {
    const char* name;
    std::string json;
    const char* expect;  // substring of the message
};

/// Renders `json` (written as bad.json) and checks exit code 2, the message and no output.
void expectRejected(const std::string& json, const std::string& expect, const std::string& extraArgs = "") {
    std::string dir = tempDir();
    writeFile(dir + "/bad.json", json);
    std::string out = dir + "/out.png";
    std::string err;
    int code = runWedge("render " + dir + "/bad.json -o " + out + " --quiet " + extraArgs, nullptr, &err);
    EXPECT_EQ(code, 2) << err;
    EXPECT_NE(err.find(expect), std::string::npos) << "message was: " << err;
    EXPECT_FALSE(fs::exists(out)) << "no output may be written on error";
    for (auto& e : fs::directory_iterator(dir)) EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos);
}

}  // namespace

TEST(Cli, GoodSceneRenders) {
    std::string dir = tempDir();
    writeFile(dir + "/good.json", scene(kSphere));
    std::string err;
    EXPECT_EQ(runWedge("render " + dir + "/good.json -o " + dir + "/a.png -o " + dir + "/a.exr -o " + dir +
                           "/a.pfm --stats " + dir + "/s.json --quiet",
                       nullptr, &err),
              0)
        << err;
    for (const char* f : {"a.png", "a.exr", "a.pfm", "s.json"}) EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;
    // --stats counts the pixels with a non-finite sample or colour: a correct render has none.
    const auto stats = nlohmann::json::parse(readFile(dir + "/s.json"));
    ASSERT_TRUE(stats.contains("nonfinite_pixels")) << stats.dump();
    EXPECT_EQ(stats["nonfinite_pixels"], 0);
    ASSERT_TRUE(stats.contains("nonfinite_samples")) << stats.dump();
    EXPECT_EQ(stats["nonfinite_samples"], 0);
}

TEST(Cli, ALightFacingAwayFromEverythingIsWarnedOf) {
    // The light of kGood above the sphere with its edges swapped emits upwards, away from
    // everything: the render is black, and says why (the file still written, exit 0). --stats
    // counts the samples a light sample reached with light (lit_samples): none.
    std::string dir = tempDir(), err;
    writeFile(dir + "/away.json", scene(kSphere, "\"edge1\": [1, 0, 0], \"edge2\": [0, 0, 1]", "\"edge1\": [0, 0, 1], \"edge2\": [1, 0, 0]"));
    writeFile(dir + "/good.json", scene(kSphere));
    for (const char* method : {"mc", "aaf"}) {
        EXPECT_EQ(runWedge(std::string("render ") + dir + "/away.json --method " + method + " --quiet -o " + dir + "/a.png --stats " + dir +
                               "/s.json",
                           nullptr, &err),
                  0)
            << err;
        EXPECT_NE(err.find("away.json: no light reached any surface the camera sees"), std::string::npos) << err;
        EXPECT_NE(err.find("swap the two"), std::string::npos) << err;
        EXPECT_TRUE(fs::exists(dir + "/a.png"));
        EXPECT_EQ(nlohmann::json::parse(readFile(dir + "/s.json")).value("lit_samples", -1.0), 0.0);
        EXPECT_EQ(runWedge(std::string("render ") + dir + "/good.json --method " + method + " --quiet -o " + dir + "/b.png --stats " + dir +
                               "/t.json",
                           nullptr, &err),
                  0)
            << err;
        EXPECT_EQ(err.find("no light reached"), std::string::npos) << err;
        EXPECT_GT(nlohmann::json::parse(readFile(dir + "/t.json")).value("lit_samples", -1.0), 0.0);
    }
}

TEST(Cli, TheExrFileIsTheSameOnAnyNumberOfThreads) {
    // OpenEXR compresses blocks of lines on its own thread pool; the file's bytes, not only the
    // image, must not depend on --threads.
    std::string dir = tempDir();
    writeFile(dir + "/good.json", scene(kSphere));
    std::string err;
    for (const char* t : {"1", "2"})
        ASSERT_EQ(runWedge("render " + dir + "/good.json --method maaf --resolution 64x48 --threads " + t + " -o " + dir + "/t" + t +
                               ".exr --quiet",
                           nullptr, &err),
                  0)
            << err;
    const std::string one = readFile(dir + "/t1.exr");
    EXPECT_GT(one.size(), 1000u);
    EXPECT_TRUE(one == readFile(dir + "/t2.exr"));
}

TEST(Cli, AovMapsShowCoverageAndTheUnfilteredShare) {
    // A floor filling the view: one surface everywhere, so the coverage and unfiltered-share maps
    // are uniform; a sphere over the floor adds silhouette pixels that see two surfaces.
    const std::string floor = R"({"type": "quad", "corner": [-20, -0.5, 20], "edge1": [40, 0, 0], "edge2": [0, 0, -40], "material": "white"})";
    auto spread = [](const std::string& png) {
        wedge::Image3f img = wedge::io::readPng(png);
        float lo = 1e9f, hi = -1e9f;
        for (size_t i = 0; i < img.size(); ++i) {
            lo = std::min(lo, img[i].x + img[i].y + img[i].z);
            hi = std::max(hi, img[i].x + img[i].y + img[i].z);
        }
        return hi - lo;
    };
    for (bool sphere : {false, true}) {
        std::string dir = tempDir();
        writeFile(dir + "/s.json", scene(sphere ? kSphere + ", " + floor : floor, "[0, 1, 3]", "[0, 1.5, 0.5]"));
        std::string err;
        fs::create_directories(dir + "/aov");
        ASSERT_EQ(runWedge("render " + dir + "/s.json --method aaf --quiet --resolution 24x24 --aov " + dir + "/aov", nullptr, &err), 0) << err;
        for (const char* map : {"aaf_spp", "aaf_defocus_b", "aaf_coverage", "aaf_rest_share", "aaf_unfiltered"})
            EXPECT_TRUE(fs::exists(dir + "/aov/" + map + ".png")) << map;
        EXPECT_EQ(spread(dir + "/aov/aaf_rest_share.png"), 0.f);
        if (sphere) EXPECT_GT(spread(dir + "/aov/aaf_coverage.png"), 0.1f);
        else EXPECT_EQ(spread(dir + "/aov/aaf_coverage.png"), 0.f);
    }
}

TEST(Cli, UnknownKey) { expectRejected(scene(kSphere, "\"render\": {", "\"bogus\": 1, \"render\": {"), "bad.json: bogus: unknown key"); }

TEST(Cli, UnknownNestedKey) {
    expectRejected(scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "white", "color": 1})"),
                   "bad.json: objects[0].color: unknown key");
}

TEST(Cli, WrongType) {
    expectRejected(scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": "big", "material": "white"})"),
                   "bad.json: objects[0].radius: expected a positive number");
}

TEST(Cli, NegativeRadius) {
    expectRejected(scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": -1, "material": "white"})"),
                   "objects[0].radius: expected a positive number");
}

TEST(Cli, MissingField) {
    expectRejected(scene(R"({"type": "sphere", "radius": 1, "material": "white"})"), "objects[0].center: missing required field");
}

TEST(Cli, UnknownMaterial) {
    expectRejected(scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "chrome"})"),
                   "objects[0].material: unknown material 'chrome'");
}

TEST(Cli, NonPositiveResolution) {
    expectRejected(scene(kSphere, "\"resolution\": [8, 8]", "\"resolution\": [0, 8]"),
                   "camera.resolution[0]: expected a positive resolution");
}

TEST(Cli, BadVectorLength) {
    expectRejected(scene(kSphere, "\"look_at\": [0, 0, 0]", "\"look_at\": [0, 0]"), "camera.look_at: expected an array of 3 numbers");
}

TEST(Cli, SyntaxErrorNamesLine) {
    expectRejected(scene(kSphere, "\"render\": {", "\"render\": {,"), "bad.json:6:");
}

TEST(Cli, DuplicateKeyNamesItsPath) {
    // nlohmann keeps the last of two equal keys; wedge refuses the scene instead of rendering
    // with one of them silently. The same key in two different objects is fine.
    expectRejected(scene(kSphere, "\"fov_y\": 40", "\"fov_y\": 40, \"fov_y\": 50"), "bad.json: camera.fov_y: duplicate key 'fov_y'");
    expectRejected(scene(kSphere + ", " + kSphere, "\"radius\": 0.5, \"material\": \"white\"}]",
                         "\"radius\": 0.5, \"radius\": 1, \"material\": \"white\"}]"),
                   "bad.json: objects[1].radius: duplicate key 'radius'");
}

TEST(Cli, SphereLightsAreCheckedAndRender) {
    // A sphere light takes a centre, a positive radius and a radiance; anything else is named.
    const std::string parallelogram =
        R"({"type": "parallelogram", "corner": [-0.5, 2, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [5, 5, 5]})";
    auto sphereLight = [&](const std::string& light) { return scene(kSphere, parallelogram, light); };
    expectRejected(sphereLight(R"({"type": "sphere", "center": [0, 2, 0], "radius": -1, "radiance": [5, 5, 5]})"),
                   "bad.json: lights[0].radius: expected a positive number");
    expectRejected(sphereLight(R"({"type": "sphere", "center": [0, 2, 0], "radiance": [5, 5, 5]})"), "bad.json: lights[0].radius: missing required field");
    expectRejected(sphereLight(R"({"type": "sphere", "center": [0, 2, 0], "radius": 0.2, "corner": [0, 0, 0], "radiance": [5, 5, 5]})"),
                   "bad.json: lights[0].corner: unknown key");
    expectRejected(sphereLight(R"({"type": "sphere", "center": [0, 2, 0], "radius": 1e20, "radiance": [5, 5, 5]})"),
                   "bad.json: lights[0]: reaches");
    expectRejected(sphereLight(R"({"type": "disc", "center": [0, 2, 0], "radius": 1, "radiance": [5, 5, 5]})"),
                   "bad.json: lights[0].type: unknown light type 'disc' (expected \"parallelogram\", \"triangle\" or \"sphere\")");
    std::string dir = tempDir(), err;
    writeFile(dir + "/s.json", sphereLight(R"({"type": "sphere", "center": [0, 2, 0], "radius": 0.2, "radiance": [5, 5, 5]})"));
    for (const char* method : {"mc", "aaf", "maaf", "atrous"}) {
        EXPECT_EQ(runWedge("render " + dir + "/s.json --quiet --method " + method + " -o " + dir + "/s.png", nullptr, &err), 0)
            << method << ": " << err;
        EXPECT_TRUE(fs::exists(dir + "/s.png"));
    }
}

TEST(Cli, NumberOutOfRangeNamesItsPath) {
    expectRejected(scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1e400, "material": "white"})"),
                   "bad.json: objects[0].radius: invalid JSON: number overflow");
    expectRejected(scene(kSphere, "\"edge2\": [0, 0, 1]", "\"edge2\": [0, 0, -1e999]"),
                   "bad.json: lights[0].edge2[2]: invalid JSON: number overflow");
}

TEST(Cli, NumbersAreCheckedAsTheFloatsTheSceneKeeps) {
    // 1e308 is a finite double and an infinite float: a light of that radiance loaded, and
    // `--method aaf` rendered NaN pixels (and the PNG writer converted NaN to int).
    for (const char* method : {"mc", "aaf"})
        expectRejected(scene(kSphere, "\"radiance\": [5, 5, 5]", "\"radiance\": [1e308, 5, 5]"),
                       "bad.json: lights[0].radiance[0]: '1e+308' is not a finite number within +-3.4e38", std::string("--method ") + method);
    expectRejected(scene(kSphere, "\"fov_y\": 40", "\"fov_y\": -3.5e38"), "bad.json: camera.fov_y: expected a positive number");
    expectRejected(scene(kSphere, "\"up\": [0, 1, 0]", "\"up\": [0, 3.5e38, 0]"),
                   "bad.json: camera.up[1]: '3.5e+38' is not a finite number within +-3.4e38");
    // Positive as a double, zero as a float.
    expectRejected(scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1e-50, "material": "white"})"),
                   "bad.json: objects[0].radius: expected a positive number ('1e-50' is 0 as the float it is stored in)");
    // The largest float still loads (and is then refused for what it is: a coordinate too far).
    expectRejected(scene(R"({"type": "sphere", "center": [3.4e38, 0, 0], "radius": 1, "material": "white"})"),
                   "bad.json: objects[0]: reaches");
}

TEST(Cli, RadianceBeyondWhatSinglePrecisionSquaresIsAnError) {
    // A light of radiance 1e20 gave à-trous a NaN image (the pixels' luminance variance
    // overflowed); the scene file now names the value.
    expectRejected(scene(kSphere, "\"radiance\": [5, 5, 5]", "\"radiance\": [5, 1e20, 5]"),
                   "bad.json: lights[0].radiance: radiance (5, 1e+20, 5) above 1e15, the most wedge renders");
    expectRejected(scene(kSphere, "\"albedo\": [0.8, 0.8, 0.8]}", "\"albedo\": [0.8, 0.8, 0.8], \"emission\": [2e15, 0, 0]}"),
                   "bad.json: materials.white.emission: radiance (2e+15, 0, 0) above 1e15");
}

TEST(Cli, CoordinatesBeyondWhatEmbreeTracesAreErrors) {
    // A sphere of radius 1e20 aborted the process in Embree (`ray.valid()`: a ray origin beyond
    // 1.8e18); now the scene file names what reaches that far.
    expectRejected(scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1e20, "material": "white"})"),
                   "bad.json: objects[0]: reaches (-1e+20, -1e+20, -1e+20); wedge renders coordinates within +-1e15");
    expectRejected(scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "white", "velocity": [1e30, 0, 0]})"),
                   "bad.json: objects[0]: reaches (1e+30, -0.5, -0.5) over the shutter");
    expectRejected(scene(kSphere, "\"edge1\": [1, 0, 0]", "\"edge1\": [1e20, 0, 0]"), "bad.json: lights[0]: reaches (1e+20, 2, -0.5)");
    expectRejected(scene(kSphere, "\"position\": [0, 1, 3]", "\"position\": [0, 1, 3e16]"), "bad.json: camera.position: reaches");
    // A moving camera, at its shutter's close (the shutter is read first: its length scales it).
    expectRejected(scene(kSphere, "\"position\": [0, 1, 3]", "\"position\": [0, 1, 3], \"velocity\": [0, 0, 1e14], \"shutter\": [0, 20]"),
                   "bad.json: camera.velocity: reaches (0, 1, 2e+15) over the shutter");
    // A turning camera (its look_at moving) must keep a view direction that is not up's.
    expectRejected(scene(kSphere, "\"position\": [0, 1, 3]", "\"position\": [0, 1, 3], \"look_at_velocity\": [0, 0, 3]"),
                   "bad.json: camera.look_at_velocity: the view direction (look_at - position) turns parallel to camera.up during the shutter");
    expectRejected(scene(kSphere, "\"position\": [0, 1, 3]", "\"position\": [0, 1, 3], \"look_at_velocity\": [0, 2, 6]"),
                   "bad.json: camera.look_at_velocity: the view direction (look_at - position) turns to nothing during the shutter");
    expectRejected(scene(kSphere, "\"position\": [0, 1, 3]", "\"position\": [0, 1, 3], \"velocity\": [0, 1]"),
                   "bad.json: camera.velocity: expected an array of 3 numbers");
    expectRejected(scene(kSphere, "\"position\": [0, 1, 3]", "\"position\": [0, 1, 3], \"velocity\": [0, \"fast\", 0]"),
                   "bad.json: camera.velocity[1]");
    std::string dir = tempDir(), err;
    writeFile(dir + "/far.json", scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1e12, "material": "white"})"));
    EXPECT_EQ(runWedge("render " + dir + "/far.json --quiet -o " + dir + "/far.png", nullptr, &err), 0) << err;
}

TEST(Cli, MissingSceneFile) {
    std::string err;
    EXPECT_EQ(runWedge("render /nonexistent/room.json --quiet", nullptr, &err), 2);
    EXPECT_NE(err.find("/nonexistent/room.json"), std::string::npos) << err;
}

TEST(Cli, UnknownBuiltinScene) {
    std::string err;
    EXPECT_EQ(runWedge("render nosuchscene --quiet", nullptr, &err), 2);
    EXPECT_NE(err.find("nosuchscene"), std::string::npos) << err;
    EXPECT_NE(err.find("cornell"), std::string::npos) << "lists the built-ins: " << err;
}

TEST(Cli, MissingMeshFile) {
    expectRejected(scene(R"({"type": "mesh", "file": "nothere.obj"})"), "objects[0].file: mesh file");
}

TEST(Cli, MeshThatIsNotAnObj) {
    std::string dir = tempDir();
    writeFile(dir + "/notobj.obj", "this is a PNG, honest\n\x89PNG\x01\x02\x03\n");
    std::string json = scene(R"({"type": "mesh", "file": ")" + dir + R"(/notobj.obj"})");
    expectRejected(json, "objects[0].file: '" + dir + "/notobj.obj' contains no faces");
}

TEST(Cli, ObjWithBadFaceIndex) {
    std::string dir = tempDir();
    writeFile(dir + "/broken.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
    expectRejected(scene(R"({"type": "mesh", "file": ")" + dir + R"(/broken.obj", "material": "white"})"),
                   "objects[0].file: '" + dir + "/broken.obj' line 4: face corner '7' refers to vertex 7, but the file has 3 `v` lines");
}

TEST(Cli, ObjWhoseMtlIsMissingSaysSo) {
    std::string dir = tempDir();
    writeFile(dir + "/m.obj", "mtllib nothere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
    expectRejected(scene(R"({"type": "mesh", "file": ")" + dir + R"(/m.obj"})"),
                   "has faces without a material (tinyobjloader: Material file [ nothere.mtl ] not found");
}

TEST(Cli, ObjOrMtlWithAMalformedNumber) {
    // tinyobjloader read these as 0 and the scene rendered; now they are errors naming the line.
    std::string dir = tempDir();
    writeFile(dir + "/nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
    expectRejected(scene(R"({"type": "mesh", "file": ")" + dir + R"(/nan.obj", "material": "white"})"),
                   "objects[0].file: '" + dir + "/nan.obj' line 3: `v` expects 3 to 7 numbers (x y z [w] [r g b]), and 'nan' is not a finite number within +-3.4e38");
    writeFile(dir + "/m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
    writeFile(dir + "/m.mtl", "newmtl a\nKd 0.5 0.5 x\n");
    expectRejected(scene(R"({"type": "mesh", "file": ")" + dir + R"(/m.obj"})"),
                   "objects[0].file: '" + dir + "/m.mtl' line 2: `Kd` expects r g b (or one number for grey), and 'x' is not a finite number within +-3.4e38");
}

TEST(Cli, ObjWithBadNormalIndex) {
    std::string dir = tempDir();
    writeFile(dir + "/badvn.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//4\n");
    expectRejected(scene(R"({"type": "mesh", "file": ")" + dir + R"(/badvn.obj", "material": "white"})"),
                   "badvn.obj' line 5: face corner '3//4' refers to normal 4, but the file has 1 `vn` line");
}

TEST(Cli, NoLight) {
    expectRejected(scene(kSphere, "\"lights\": [{\"type\": \"parallelogram\", \"corner\": [-0.5, 2, -0.5], \"edge1\": [1, 0, 0], \"edge2\": [0, 0, 1], \"radiance\": [5, 5, 5]}]",
                         "\"lights\": []"),
                   "lights: the scene has no light");
}

TEST(Cli, MtlTermsThatAreNotRenderedAreNamed) {
    // Valid input that wedge does not render (specular terms, texture maps) renders, with one
    // warning per MTL that names the materials; a plain Lambertian material is not named.
    std::string dir = tempDir();
    writeFile(dir + "/quad.obj",
              "mtllib quad.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nusemtl shiny\nf 1 4 3\nusemtl matte\nf 1 3 2\n");
    writeFile(dir + "/quad.mtl",
              "newmtl shiny\nKd 0.5 0.5 0.5\nKs 0.7 0.7 0.7\nmap_Kd wood.png\nd 0.5\nnewmtl matte\nKd 0.4 0.4 0.4\nd 1\n");
    writeFile(dir + "/s.json", scene(R"({"type": "mesh", "file": "quad.obj"})"));
    std::string err;
    ASSERT_EQ(runWedge("render " + dir + "/s.json --quiet -o " + dir + "/x.png", nullptr, &err), 0) << err;
    EXPECT_TRUE(fs::exists(dir + "/x.png"));
    EXPECT_NE(err.find("warning: " + dir + "/s.json: objects[0].file: '" + dir + "/quad.obj'"), std::string::npos) << err;
    EXPECT_NE(err.find("specular terms (Ks) of 'shiny'"), std::string::npos) << err;
    EXPECT_NE(err.find("the diffuse maps of 'shiny' (map_Kd '" + dir + "/wood.png' does not exist)"), std::string::npos) << err;
    EXPECT_NE(err.find("the transparency (d < 1) of 'shiny'"), std::string::npos) << err;
    EXPECT_EQ(err.find("matte"), std::string::npos) << err;

    writeFile(dir + "/quad.mtl", "newmtl shiny\nKd 0.5 0.5 0.5\nnewmtl matte\nKd 0.4 0.4 0.4\n");
    ASSERT_EQ(runWedge("render " + dir + "/s.json --quiet -o " + dir + "/x.png", nullptr, &err), 0) << err;
    EXPECT_EQ(err.find("warning"), std::string::npos) << err;
}

TEST(Cli, TurningObjectsAreCheckedAsTheyTurn) {
    // `angular_velocity` turns a mesh, quad or box about its pivot; what it cannot mean is an error.
    const std::string box = R"({"type": "box", "min": [-0.5, 0, -0.5], "max": [0.5, 1, 0.5], "material": "white", )";
    expectRejected(scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "white", "angular_velocity": [0, 1, 0, 90]})"),
                   "bad.json: objects[0].angular_velocity: a sphere does not turn (meshes, quads and boxes do)");
    expectRejected(scene(box + R"("pivot": [0, 0, 0]})"), "bad.json: objects[0].pivot: a pivot needs an angular_velocity to turn about it");
    expectRejected(scene(box + R"("angular_velocity": [0, 0, 0, 90]})"), "bad.json: objects[0].angular_velocity: the axis must be non-zero");
    expectRejected(scene(box + R"("angular_velocity": [0, 1, 0]})"),
                   "bad.json: objects[0].angular_velocity: expected [axis_x, axis_y, axis_z, degrees per unit of shutter time]");
    expectRejected(scene(box + R"("angular_velocity": [0, 1, 0, "fast"]})"), "bad.json: objects[0].angular_velocity[3]");
    expectRejected(scene(box + R"("angular_velocity": [0, 1, 0, 1e30]})"),
                   "bad.json: objects[0].angular_velocity: turns 1000000000000000000 degrees over the shutter; wedge takes at most 3600");
    // About a pivot far away the box sweeps a sphere of that radius.
    expectRejected(scene(box + R"("angular_velocity": [0, 1, 0, 10], "pivot": [1e16, 0, 0]})"), "bad.json: objects[0].pivot: reaches");
    std::string dir = tempDir(), err;
    writeFile(dir + "/turn.json", scene(box + R"("angular_velocity": [0, 1, 0, 30]})"));
    EXPECT_EQ(runWedge("render " + dir + "/turn.json --quiet -o " + dir + "/x.png", nullptr, &err), 0) << err;
    // wedge raster moves its triangles by translation alone, and says so.
    EXPECT_EQ(runWedge("raster " + dir + "/turn.json --quiet --spp 1 --no-reference -o " + dir + "/y.png", nullptr, &err), 2) << err;
    EXPECT_NE(err.find("turn.json: box[0]: angular_velocity: wedge raster moves objects by translation alone"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir + "/y.png"));
}

TEST(Cli, RasterRefusesAMovingCamera) {
    // wedge raster's screen motion is its triangles' own; a moving camera is wedge render's, and
    // the rasterizer says so instead of rendering it still.
    std::string dir = tempDir(), err;
    writeFile(dir + "/s.json", scene(kSphere, "\"position\": [0, 1, 3]", "\"position\": [0, 1, 3], \"velocity\": [0.5, 0, 0]"));
    EXPECT_EQ(runWedge("raster " + dir + "/s.json --quiet --spp 1 --no-reference -o " + dir + "/x.png", nullptr, &err), 2) << err;
    EXPECT_NE(err.find("s.json: camera.velocity: wedge raster renders a still camera"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir + "/x.png"));
    EXPECT_EQ(runWedge("render " + dir + "/s.json --quiet -o " + dir + "/x.png", nullptr, &err), 0) << err;
    writeFile(dir + "/t.json", scene(kSphere, "\"position\": [0, 1, 3]", "\"position\": [0, 1, 3], \"look_at_velocity\": [0.5, 0, 0]"));
    EXPECT_EQ(runWedge("raster " + dir + "/t.json --quiet --spp 1 --no-reference -o " + dir + "/y.png", nullptr, &err), 2) << err;
    EXPECT_NE(err.find("t.json: camera.look_at_velocity: wedge raster renders a still camera"), std::string::npos) << err;
}

TEST(Cli, RasterNamesTheMaterialsWhoseMapsItDoesNotRender) {
    // wedge raster shades with Kd alone: its warning names the materials with a map_Kd as the
    // loader's warnings do (the first three and a count).
    std::string dir = tempDir();
    wedge::Image3f texels(2, 2);
    for (size_t i = 0; i < texels.size(); ++i) texels[i] = wedge::Vec3f(0.25f * float(i));
    wedge::io::writePng(dir + "/t.png", texels);
    std::string obj = "mtllib quad.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n", mtl;
    for (const char* m : {"m1", "m2", "m3", "m4"}) {
        obj += std::string("usemtl ") + m + "\nf 1/1 4/4 3/3\n";
        mtl += std::string("newmtl ") + m + "\nKd 0.5 0.5 0.5\nmap_Kd t.png\n";
    }
    writeFile(dir + "/quad.obj", obj);
    writeFile(dir + "/quad.mtl", mtl);
    writeFile(dir + "/s.json", scene(R"({"type": "mesh", "file": "quad.obj"})"));
    std::string err;
    ASSERT_EQ(runWedge("raster " + dir + "/s.json --quiet --spp 1 --resolution 8x8 --no-reference -o " + dir + "/x.png", nullptr,
                       &err),
              0)
        << err;
    EXPECT_NE(err.find("s.json: wedge raster renders the map_Kd of 'quad.obj:m1', 'quad.obj:m2', 'quad.obj:m3' and 1 more as their Kd alone"),
              std::string::npos)
        << err;
}

TEST(Cli, MtlColoursObeyTheSceneFileRules) {
    // An MTL's Kd and Ke are checked as the scene file's "albedo" and "emission" are: they were
    // clamped silently before (a negative albedo to 0, an albedo of 1.2 to 1). Emission above 1
    // is a light's radiance (the Cornell box's Ke 17 12 4) and renders.
    std::string dir = tempDir();
    writeFile(dir + "/quad.obj", "mtllib quad.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nusemtl a\nf 1 4 3\nf 1 3 2\n");
    const std::string json = scene(R"({"type": "mesh", "file": "quad.obj"})");
    auto run = [&](const std::string& mtl, std::string& err) {
        writeFile(dir + "/quad.mtl", "newmtl a\n" + mtl);
        writeFile(dir + "/s.json", json);
        fs::remove(dir + "/x.png");
        return runWedge("render " + dir + "/s.json --quiet -o " + dir + "/x.png", nullptr, &err);
    };
    std::string err;
    for (const char* mtl : {"Kd -0.1 0.5 0.5\n", "Kd 1.2 0.5 0.5\n"}) {
        EXPECT_EQ(run(mtl, err), 2) << mtl;
        EXPECT_NE(err.find("s.json: objects[0].file: '" + dir + "/quad.obj': material 'a' (its MTL): Kd components must lie in [0, 1]"),
                  std::string::npos) << err;
        EXPECT_FALSE(fs::exists(dir + "/x.png"));
    }
    EXPECT_EQ(run("Kd 0.5 0.5 0.5\nKe -5 0 0\n", err), 2);
    EXPECT_NE(err.find("material 'a' (its MTL): Ke components must lie in [0, 1e15], got -5 0 0"), std::string::npos) << err;
    EXPECT_EQ(run("Kd 0.5 0.5 0.5\nKe 1e20 0 0\n", err), 2);
    EXPECT_NE(err.find("material 'a' (its MTL): Ke components must lie in [0, 1e15], got 1e+20 0 0"), std::string::npos) << err;
    EXPECT_EQ(run("Kd 0.5 0.5 0.5\nKe 17 12 4\n", err), 0) << err;
    EXPECT_TRUE(fs::exists(dir + "/x.png"));
}

TEST(Cli, BadFlags) {
    std::string dir = tempDir();
    writeFile(dir + "/good.json", scene(kSphere));
    std::string g = dir + "/good.json --quiet ";
    std::string err;
    EXPECT_EQ(runWedge("render " + g + "--spp -3", nullptr, &err), 2) << err;
    EXPECT_EQ(runWedge("render " + g + "--spp abc", nullptr, &err), 2) << err;
    EXPECT_EQ(runWedge("render " + g + "--method magic", nullptr, &err), 2) << err;
    EXPECT_NE(err.find("--method"), std::string::npos) << err;
    EXPECT_EQ(runWedge("render " + g + "--threads -1", nullptr, &err), 2) << err;
    EXPECT_EQ(runWedge("render " + g + "--method maaf --maaf-radius 0", nullptr, &err), 2) << err;
    EXPECT_NE(err.find("--maaf-radius"), std::string::npos) << err;
    EXPECT_EQ(runWedge("render " + g + "--method maaf --maaf-radius 129", nullptr, &err), 2) << err;
    EXPECT_EQ(runWedge("render " + g + "--method maaf --maaf-components 2", nullptr, &err), 2) << err;
    EXPECT_NE(err.find("--maaf-components"), std::string::npos) << err;
    EXPECT_EQ(runWedge("render " + g + "--sampler halton", nullptr, &err), 2) << err;
    EXPECT_NE(err.find("--sampler"), std::string::npos) << err;
    EXPECT_EQ(runWedge("render " + g + "--resolution 12by3", nullptr, &err), 2) << err;
    EXPECT_NE(err.find("--resolution"), std::string::npos) << err;
    EXPECT_EQ(runWedge("render " + g + "-o " + dir + "/x.jpg", nullptr, &err), 2) << err;
    EXPECT_NE(err.find("x.jpg"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir + "/x.jpg"));
    EXPECT_EQ(runWedge("render " + g + "-o /nonexistent-dir/x.png", nullptr, &err), 2) << err;
    EXPECT_EQ(runWedge("render", nullptr, &err), 2) << err;
    EXPECT_EQ(runWedge("frobnicate", nullptr, &err), 2) << err;
}

TEST(Cli, NumericFlagsRejectNanAndSayTheirRange) {
    // CLI11's range checks pass NaN (every comparison with it is false): before, --sigma-color nan
    // rendered and failed in the filter, without naming the flag, and an "x" resolution side of
    // 11 digits went through sscanf's int overflow.
    std::string dir = tempDir();
    writeFile(dir + "/good.json", scene(kSphere));
    const std::string g = dir + "/good.json --quiet -o " + dir + "/x.png ";
    struct Case { std::string args, expect; };
    for (const Case& c : std::vector<Case>{
             {"render " + g + "--method atrous --sigma-color nan", "--sigma-color: expected a number in [1e-06, 1000000], got 'nan'"},
             {"render " + g + "--method atrous --sigma-normal inf", "--sigma-normal: expected a number in [1e-06, 1000000], got 'inf'"},
             {"render " + g + "--resolution 99999999999x2", "--resolution 99999999999x2: expected WxH with integers from 1 to 16384"},
             {"render " + g + "--resolution -3x2", "expected WxH with integers from 1 to 16384"},
             {"experiment " + dir + "/good.json --methods mc --spp 4 --reference-spp 0 --out " + dir + "/e",
              "--reference-spp: expected a number in [1, 1048576], got '0'"},
             {"experiment " + dir + "/good.json --methods mc --spp 4 --reference-spp 8 --threads -1 --out " + dir + "/e",
              "--threads: expected a number in [0, 1024], got '-1'"},
             {"raster " + g + "--shading ds --cache-entries 4 --stats " + dir + "/s.json --lens-cutoff nan",
              "--lens-cutoff: expected a positive number, got 'nan'"}}) {
        std::string err;
        EXPECT_EQ(runWedge(c.args, nullptr, &err), 2) << c.args << "\n" << err;
        EXPECT_NE(err.find(c.expect), std::string::npos) << c.args << "\n" << err;
        EXPECT_FALSE(fs::exists(dir + "/x.png"));
        EXPECT_FALSE(fs::exists(dir + "/e"));
    }
    std::string err;
    EXPECT_EQ(runWedge("render " + g + "--method atrous --sigma-color 0.5 --resolution 6X4", nullptr, &err), 0) << err;
}

TEST(Cli, ScenesListsBuiltins) {
    std::string out;
    EXPECT_EQ(runWedge("scenes", &out), 0);
    for (const char* name : {"cornell", "grids", "conference", "sponza", "bunny"}) EXPECT_NE(out.find(name), std::string::npos) << name;
}

/// Runs `script` with /bin/sh (std::system's shell), $WEDGE standing for the binary; returns the
/// exit status.
int runShell(const std::string& script) {
    const int status = std::system(("WEDGE='" + std::string(WEDGE_BIN) + "'; " + script).c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Cli, AnInterruptedRenderExitsNonZeroAndWritesNothing) {
    // A render far longer than the second before the signal: exit 128 + the signal, a message,
    // and neither the outputs nor their temporaries on disk.
    for (const char* sig : {"INT", "TERM"}) {
        std::string dir = tempDir();
        writeFile(dir + "/good.json", scene(kSphere));
        const int rc = runShell("timeout 120 $WEDGE render " + dir + "/good.json --spp 100000 --resolution 256x256 -o " + dir +
                                "/a.exr -o " + dir + "/a.png --stats " + dir + "/s.json --quiet 2>" + dir +
                                "/err.txt & pid=$!; sleep 1; kill -" + sig + " $pid; wait $pid");
        EXPECT_EQ(rc, std::string(sig) == "INT" ? 130 : 143) << sig;
        const std::string err = readFile(dir + "/err.txt");
        EXPECT_NE(err.find(std::string(sig) == "INT" ? "wedge: interrupted by SIGINT" : "wedge: terminated by SIGTERM"),
                  std::string::npos)
            << err;
        for (auto& e : fs::directory_iterator(dir)) {
            const std::string name = e.path().filename().string();
            EXPECT_TRUE(name == "good.json" || name == "err.txt") << "left behind: " << name;
        }
    }
}

TEST(Cli, AFailedWriteIsAnErrorAndKeepsThePreviousOutput) {
    // Outputs larger than `ulimit -f` allows (a full disk, as the writer sees it: EFBIG): exit
    // 2 naming the file, the previous outputs byte for byte as they were, no temporaries.
    std::string dir = tempDir(), err;
    writeFile(dir + "/good.json", scene(kSphere));
    const std::string outs = " -o " + dir + "/a.exr -o " + dir + "/a.png -o " + dir + "/a.pfm";
    ASSERT_EQ(runWedge("render " + dir + "/good.json --quiet" + outs, nullptr, &err), 0) << err;
    std::vector<std::string> before;
    for (const char* f : {"a.exr", "a.png", "a.pfm"}) before.push_back(readFile(dir + "/" + f));
    for (const char* f : {"a.exr", "a.png", "a.pfm"}) {
        // 2 blocks of 512 bytes: less than any of the three at 128x128 (the PNG is 14 KB).
        const int rc = runShell("ulimit -f 2; $WEDGE render " + dir + "/good.json --quiet --resolution 128x128 -o " + dir +
                                "/" + f + " 2>" + dir + "/err.txt");
        EXPECT_EQ(rc, 2) << f;
        const std::string e = readFile(dir + "/err.txt");
        EXPECT_NE(e.find(dir + "/" + f + ": "), std::string::npos) << e;
    }
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(readFile(dir + "/" + std::string(k == 0 ? "a.exr" : k == 1 ? "a.png" : "a.pfm")) == before[k]) << k;
    for (auto& e : fs::directory_iterator(dir)) EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
    // A path no one can write (not even root): a clear error, no file.
    EXPECT_EQ(runWedge("render " + dir + "/good.json --quiet -o /proc/wedge-test.exr", nullptr, &err), 2);
    EXPECT_NE(err.find("/proc/wedge-test.exr: "), std::string::npos) << err;
}

TEST(Cli, ARenderTooLargeForTheMemoryLimitIsRefusedBeforeItStarts) {
    std::string dir = tempDir(), err;
    writeFile(dir + "/good.json", scene(kSphere));
    EXPECT_EQ(runWedge("render " + dir + "/good.json --resolution 16384x16384 --quiet -o " + dir + "/a.png", nullptr, &err), 2);
    EXPECT_NE(err.find("good.json: a 16384x16384 mc render needs 300.0 GiB, more than the memory limit of"), std::string::npos) << err;
    EXPECT_EQ(runWedge("render " + dir + "/good.json --method maaf --quiet --max-memory 64K -o " + dir + "/a.png", nullptr, &err), 2);
    EXPECT_NE(err.find("a 8x8 maaf render needs 75.0 KiB, more than the memory limit of 64.0 KiB (--max-memory)"), std::string::npos)
        << err;
    EXPECT_FALSE(fs::exists(dir + "/a.png"));
    EXPECT_EQ(runWedge("render " + dir + "/good.json --method maaf --quiet --max-memory 1G -o " + dir + "/a.png", nullptr, &err), 0) << err;
}

TEST(Cli, ARenderKeepingItsSamplesForTheLayersCountsThem) {
    // With a lens the layers keep every sample (24 bytes, and 12 a pixel beside them) until they
    // reconstruct: 8x8 pixels at 64 spp add 96.75 KiB to the 75 KiB of the render's buffers, and
    // the one thread the samples a tile gathers (all of them here, 66 bytes each, and 4 a pixel
    // beside them: 264.25 KiB); without a lens nothing is kept.
    std::string dir = tempDir(), err;
    writeFile(dir + "/lens.json", scene(kSphere, "\"fov_y\": 40", "\"fov_y\": 40, \"aperture_radius\": 0.05, \"focus_distance\": 3"));
    writeFile(dir + "/pinhole.json", scene(kSphere));
    EXPECT_EQ(runWedge("render " + dir + "/lens.json --spp 64 --layers on --threads 1 --quiet --max-memory 128K -o " + dir + "/a.png", nullptr, &err),
              2);
    EXPECT_NE(err.find("lens.json: a 8x8 mc render keeping its 64 samples a pixel for the layers (--layers) needs 436.0 KiB, "
                       "more than the memory limit of 128.0 KiB (--max-memory)"),
              std::string::npos)
        << err;
    EXPECT_FALSE(fs::exists(dir + "/a.png"));
    EXPECT_EQ(runWedge("render " + dir + "/lens.json --spp 64 --layers off --quiet --max-memory 128K -o " + dir + "/a.png", nullptr, &err), 0) << err;
    EXPECT_EQ(runWedge("render " + dir + "/pinhole.json --spp 64 --layers on --quiet --max-memory 128K -o " + dir + "/b.png", nullptr, &err), 0) << err;
}

TEST(Cli, ARasterTooLargeForTheMemoryLimitIsRefusedBeforeItStarts) {
    std::string dir = tempDir(), err;
    writeFile(dir + "/good.json", scene(kSphere));
    const std::string g = "raster " + dir + "/good.json --quiet --max-memory 1G ";
    struct Case { std::string args, expect; };
    for (const Case& c : std::vector<Case>{
             // The visibility samples: 2^30 at 64 bytes.
             {g + "--resolution 4096x4096 --spp 64 -o " + dir + "/a.png",
              "good.json: a 4096x4096 raster at 64 spp (1073741824 samples, at 64 bytes) with a shading cache of 64 "
              "entries (--cache-entries) needs 65.0 GiB, more than the memory limit of 1.0 GiB (--max-memory)"},
             // The cache's nodes and map, allocated whole when the cache is made.
             {g + "--cache-entries 1073741824 -o " + dir + "/a.png", "with a shading cache of 1073741824 entries (--cache-entries) needs 64.0 GiB"},
             // A --truth-spp pass (64 spp at most) beside the render's samples.
             {g + "--resolution 2048x2048 --spp 1 --truth-spp 4096 -o " + dir + "/a.png",
              "a 2048x2048 raster at 1 spp (4194304 samples, and 268435456 of a --truth-spp pass, at 64 bytes)"},
             // The sweep's largest cache; no --out folder is made.
             {g + "--sweep-cache 16,1073741824 --out " + dir + "/sweep", "a shading cache of 1073741824 entries (--cache-entries)"}}) {
        EXPECT_EQ(runWedge(c.args, nullptr, &err), 2) << c.args << "\n" << err;
        EXPECT_NE(err.find(c.expect), std::string::npos) << c.args << "\n" << err;
        EXPECT_FALSE(fs::exists(dir + "/a.png"));
        EXPECT_FALSE(fs::exists(dir + "/sweep"));
    }
    EXPECT_EQ(runWedge(g + "--resolution 8x8 --spp 4 --no-reference -o " + dir + "/a.png", nullptr, &err), 0) << err;
    EXPECT_TRUE(fs::exists(dir + "/a.png"));
}

TEST(Cli, AnExperimentTooLargeForTheMemoryLimitIsRefusedBeforeItStarts) {
    std::string dir = tempDir(), err;
    writeFile(dir + "/good.json", scene(kSphere));
    // The reference's two halves (each a 4096x4096 mc render: 18.8 GiB) before anything is written.
    EXPECT_EQ(runWedge("experiment " + dir + "/good.json --methods mc --spp 4 --reference-spp 8 --resolution 4096x4096 "
                       "--quiet --max-memory 1G --out " + dir + "/e",
                       nullptr, &err),
              2);
    EXPECT_NE(err.find("good.json: an experiment at 4096x4096 (its largest render, 37.5 GiB, beside the reference and the 1 "
                       "base rows' images) needs 38.2 GiB, more than the memory limit of 1.0 GiB (--max-memory)"),
              std::string::npos)
        << err;
    EXPECT_FALSE(fs::exists(dir + "/e"));
}
