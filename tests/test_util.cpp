#include "test_util.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>
// jpeglib.h needs FILE and size_t declared first.
#include <jpeglib.h>

#include <stdexcept>

namespace fs = std::filesystem;

namespace wedge::test {

namespace {
struct TempRoot {
    fs::path path;
    TempRoot() {
        path = fs::temp_directory_path() / ("wedge-test-" + std::to_string(getpid()));
        fs::create_directories(path);
    }
    ~TempRoot() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};
TempRoot& root() {
    static TempRoot r;
    return r;
}
}  // namespace

std::string tempDir() {
    static int counter = 0;
    std::string name = "d";  // not "d" + to_string(): GCC 12 warns falsely (-Wrestrict, bug 105329)
    name += std::to_string(counter++);
    fs::path p = root().path / name;
    fs::create_directories(p);
    return p.string();
}

void writeFile(const std::string& path, const std::string& text) {
    std::ofstream out(path);
    out << text;
}

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

int runWedge(const std::string& args, std::string* out, std::string* err) {
    std::string dir = tempDir();
    std::string cmd = std::string(WEDGE_BIN) + " " + args + " >" + dir + "/out.txt 2>" + dir + "/err.txt";
    int status = std::system(cmd.c_str());
    if (out) *out = readFile(dir + "/out.txt");
    if (err) *err = readFile(dir + "/err.txt");
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string sourceDir() { return WEDGE_SOURCE_DIR; }

void writeJpeg(const std::string& path, int w, int h, int components, const std::vector<unsigned char>& samples, int quality) {
    FILE* fp = std::fopen(path.c_str(), "wb");
    if (!fp) throw std::runtime_error("cannot write " + path);
    jpeg_compress_struct c;
    jpeg_error_mgr err;
    c.err = jpeg_std_error(&err);
    jpeg_create_compress(&c);
    jpeg_stdio_dest(&c, fp);
    c.image_width = JDIMENSION(w);
    c.image_height = JDIMENSION(h);
    c.input_components = components;
    c.in_color_space = components == 3 ? JCS_RGB : JCS_GRAYSCALE;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, quality, TRUE);
    jpeg_start_compress(&c, TRUE);
    while (c.next_scanline < c.image_height) {
        JSAMPROW row = const_cast<unsigned char*>(&samples[size_t(c.next_scanline) * w * components]);
        jpeg_write_scanlines(&c, &row, 1);
    }
    jpeg_finish_compress(&c);
    jpeg_destroy_compress(&c);
    std::fclose(fp);
}

std::string exrHeader(int x0, int y0, int x1, int y1, int channels, size_t offsets, int compression,
                      const std::string& extra) {
    std::string b;
    auto i32 = [&](uint32_t v) {
        for (int k = 0; k < 4; ++k) b += char(v >> (8 * k));
    };
    auto attribute = [&](const char* name, const char* type, uint32_t size) {
        b += name;
        b += '\0';
        b += type;
        b += '\0';
        i32(size);
    };
    auto box = [&](int a, int c, int d, int e) {
        for (int v : {a, c, d, e}) i32(uint32_t(v));
    };
    b += "\x76\x2f\x31\x01";  // magic
    i32(2);                       // version 2, scan lines
    attribute("channels", "chlist", uint32_t(channels * (4 + 16) + 1));
    for (int c = 0; c < channels; ++c) {
        b += {'c', char('0' + c / 10 % 10), char('0' + c % 10), '\0'};  // c00, c01...: sorted, as the list must be
        i32(2);                    // FLOAT
        b += std::string(4, '\0');  // pLinear, reserved
        i32(1);
        i32(1);                    // x and y sampling
    }
    b += '\0';
    attribute("compression", "compression", 1);
    b += char(compression);
    attribute("dataWindow", "box2i", 16);
    box(x0, y0, x1, y1);
    attribute("displayWindow", "box2i", 16);
    box(0, 0, 0, 0);
    attribute("lineOrder", "lineOrder", 1);
    b += '\0';
    attribute("pixelAspectRatio", "float", 4);
    i32(0x3f800000);  // 1.0f
    attribute("screenWindowCenter", "v2f", 8);
    i32(0);
    i32(0);
    attribute("screenWindowWidth", "float", 4);
    i32(0x3f800000);
    b += extra;
    b += '\0';  // end of the header
    for (size_t k = 0; k < offsets; ++k) b += std::string("\xff\xff\xff\x00\x00\x00\x00\x00", 8);
    return b;
}


}  // namespace wedge::test
