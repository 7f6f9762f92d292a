#include "fuzz/targets.h"

#include <CLI/CLI.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string_view>

#include <unistd.h>

#include "apps/wedge/commands.h"
#include "core/error.h"
#include "core/memory_limit.h"
#include "io/image_io.h"
#include "scene/scene_loader.h"

namespace fs = std::filesystem;

namespace wedge::fuzz {

namespace {

constexpr std::string_view kSeparator = "\n@@@ ";

/// 64 MiB: an input may ask for any image up to the limit, and ASan poisons and unpoisons the
/// shadow of every allocation (an eighth of its size) however little of it is used; at 1 GiB,
/// headers mutated to large windows held fuzz_exr to about 200 executions a second. Above the
/// limit an image is the clear error a machine with less memory would give, which is what the
/// fuzzer should see of it.
constexpr uint64_t kFuzzMemoryLimit = uint64_t(64) << 20;

std::string g_dir;

/// A file name from the input, kept inside the scratch folder: no separators, no dot files.
std::string safeName(std::string name) {
    for (char& c : name)
        if (!(std::isalnum((unsigned char)c) || c == '.' || c == '_' || c == '-')) c = '_';
    if (name.empty() || name[0] == '.') name = "_" + name;
    return name.substr(0, 64);
}

/// Writes the input's files into the scratch folder (emptied first); returns their paths.
std::vector<std::string> serve(const uint8_t* data, size_t size, const std::string& firstName) {
    initialize();
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(g_dir, ec)) fs::remove_all(entry.path(), ec);
    std::vector<std::string> paths;
    for (const File& f : splitFiles(data, size, firstName)) {
        std::string path = g_dir + "/" + f.name;
        std::ofstream(path, std::ios::binary).write(f.content.data(), std::streamsize(f.content.size()));
        paths.push_back(path);
    }
    return paths;
}

/// Runs `fn`; bad input's wedge::Error is the expected way out.
template <class Fn>
bool refusing(Fn&& fn) {
    try {
        fn();
        return true;
    } catch (const Error&) {
        return false;
    }
}

bool sceneJson(const uint8_t* data, size_t size) {
    const auto paths = serve(data, size, "scene.json");
    return refusing([&] { scene::loadScene(paths[0]); });
}

bool objMtl(const uint8_t* data, size_t size) {
    const auto paths = serve(data, size, "m.obj");
    return refusing([&] {
        std::vector<scene::Material> materials;
        scene::TriangleMesh mesh;
        std::vector<scene::AreaLight> promoted;
        std::vector<std::string> warnings;
        scene::loadObj(paths[0], "fuzz.json: objects[0].file", -1, materials, mesh, promoted, warnings);
    });
}

/// One image file, named `name` (its format), through `read`.
template <class Read>
bool imageFile(const uint8_t* data, size_t size, const char* name, Read read) {
    const auto paths = serve(data, size, name);
    return refusing([&] { read(paths[0]); });
}

bool png(const uint8_t* data, size_t size) { return imageFile(data, size, "a.png", io::readPng); }
bool jpeg(const uint8_t* data, size_t size) { return imageFile(data, size, "a.jpg", io::readJpeg); }
bool exr(const uint8_t* data, size_t size) { return imageFile(data, size, "a.exr", io::readExr); }
bool pfm(const uint8_t* data, size_t size) { return imageFile(data, size, "a.pfm", io::readPfm); }

/// `wedge compare TEST REF --json` as the command line runs it; REF is the input's second file
/// (its name gives its format), or TEST itself.
bool compare(const uint8_t* data, size_t size) {
    const auto paths = serve(data, size, "test.exr");
    return refusing([&] {
        CLI::App app;
        app::registerCompare(app);
        std::vector<std::string> args = {"--json", paths.size() > 1 ? paths[1] : paths[0], paths[0], "compare"};
        app.parse(args);  // CLI11 takes the arguments in reverse order
    });
}

}  // namespace

std::vector<File> splitFiles(const uint8_t* data, size_t size, const std::string& firstName) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    std::vector<File> files;
    size_t start = 0;
    std::string name = firstName;
    // "@@@ NAME" on the first line names the first file too (compare's formats).
    if (text.substr(0, kSeparator.size() - 1) == kSeparator.substr(1)) {
        const size_t nameEnd = text.find('\n');
        if (nameEnd != std::string_view::npos) {
            name = safeName(std::string(text.substr(kSeparator.size() - 1, nameEnd - kSeparator.size() + 1)));
            start = nameEnd + 1;
        }
    }
    const std::string first = name;
    while (true) {
        const size_t next = text.find(kSeparator, start);
        files.push_back({name, std::string(text.substr(start, next == std::string_view::npos ? next : next - start))});
        if (next == std::string_view::npos) break;
        const size_t nameStart = next + kSeparator.size(), nameEnd = text.find('\n', nameStart);
        if (nameEnd == std::string_view::npos) break;
        name = safeName(std::string(text.substr(nameStart, nameEnd - nameStart)));
        if (name == first) name = "_" + name;  // never overwrites the first file
        start = nameEnd + 1;
    }
    return files;
}

void initialize() {
    static std::once_flag once;
    std::call_once(once, [] {
        setMemoryLimit(kFuzzMemoryLimit);
        const char* tmp = std::getenv("TMPDIR");
        std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/wedge-fuzz-XXXXXX";
        if (!mkdtemp(pattern.data())) std::abort();
        g_dir = pattern;
        std::atexit([] {
            std::error_code ec;
            fs::remove_all(g_dir, ec);
        });
    });
}

const std::vector<Target>& targets() {
    static const std::vector<Target> all = {{"scene", sceneJson}, {"obj", objMtl}, {"png", png},        {"jpeg", jpeg},
                                            {"exr", exr},         {"pfm", pfm},    {"compare", compare}};
    return all;
}

const Target* target(const std::string& name) {
    for (const Target& t : targets())
        if (name == t.name) return &t;
    return nullptr;
}

}  // namespace wedge::fuzz
