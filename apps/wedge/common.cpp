#include "apps/wedge/common.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "core/error.h"

namespace wedge::app {

void printWarnings(const scene::SceneDesc& desc) {
    for (const auto& w : desc.warnings) std::fprintf(stderr, "wedge: warning: %s\n", w.c_str());
}

void applyResolution(scene::SceneDesc& desc, const std::string& resolution) {
    if (resolution.empty()) return;
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(resolution.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w <= 0 ||
        h <= 0 || w > 16384 || h > 16384)
        throw Error("--resolution " + resolution, "expected WxH with positive integers, e.g. 256x256");
    desc.camera.width = w;
    desc.camera.height = h;
}

void writeJsonFile(const std::string& path, const nlohmann::json& j) {
    std::string tmp = path + ".tmp" + std::to_string(getpid());
    {
        std::ofstream out(tmp);
        if (!out) throw Error(path, "cannot open for writing");
        out << j.dump(2) << "\n";
        if (!out) throw Error(path, "write failed");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw Error(path, "cannot write");
    }
}

}  // namespace wedge::app
