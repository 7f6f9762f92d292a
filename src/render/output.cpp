#include "render/output.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <vector>

#include "io/image_io.h"

namespace wedge::render {

const std::vector<std::string>& outputExtensions() {
    static const std::vector<std::string> ext = {".exr", ".png", ".pfm"};
    return ext;
}

std::vector<io::ExrChannel> exrChannels(const RenderResult& r) {
    // Final colour as R, G, B, then every buffer under its own name (pbrt's GBufferFilm style).
    std::vector<io::ExrChannel> channels;
    const float* c = &r.color[0].x;
    channels.push_back({"R", c, 3});
    channels.push_back({"G", c + 1, 3});
    channels.push_back({"B", c + 2, 3});
    r.buffers.forEachPlane([&](const std::string& name, int n, const float* data) {
        static const char* rgb[] = {"R", "G", "B"};
        static const char* xyz[] = {"X", "Y", "Z"};
        bool vector = name == "normal" || name == "position";
        if (n == 1) channels.push_back({name, data, 1});
        else
            for (int k = 0; k < n; ++k) channels.push_back({name + "." + (vector ? xyz[k] : rgb[k]), data + k, n});
    });
    return channels;
}

void writeOutput(const RenderResult& r, const std::string& path) {
    std::string e = io::extension(path);
    if (e != ".exr") return io::writeColor(path, r.color);
    io::writeExr(path, r.color.width(), r.color.height(), exrChannels(r));
}

std::string unlitWarning(const scene::SceneDesc& desc, const RenderResult& result) {
    if (desc.lights.empty() || result.figure("lit_samples").value_or(1.0) != 0.0) return {};
    return "no light reached any surface the camera sees, nor any they see (the image is black but for emitters): "
           "does every light face away? A parallelogram or triangle emits towards edge1 x edge2 only; swap the two to "
           "turn it round";
}

size_t nonFinitePixels(const RenderResult& r) {
    const FrameBuffers& b = r.buffers;
    auto sampled = [&](size_t p) {  // the planes that sum samples' light
        bool ok = isFinite(b.emission[p]) && isFinite(b.direct[p]) && isFinite(b.indirect[p]) && isFinite(b.rest[p]);
        for (const auto& o : b.other) ok = ok && isFinite(o.direct[p]) && isFinite(o.indirect[p]);
        return ok;
    };
    const bool hasBuffers = b.width == r.color.width() && b.height == r.color.height() && b.emission.size() == r.color.size();
    size_t count = 0;
    for (size_t p = 0; p < r.color.size(); ++p) count += !isFinite(r.color[p]) || (hasBuffers && !sampled(p));
    return count;
}

nlohmann::json statsJson(const RenderResult& r, const std::string& sceneName) {
    nlohmann::json j;
    j["scene"] = sceneName;
    j["method"] = r.method;
    j["resolution"] = {r.color.width(), r.color.height()};
    j["spp_average"] = r.sppAverage;
    j["rays"] = r.rays;
    j["threads"] = r.threads;
    // Over several MPI ranks (docs/mpi.md): the rays each traced; they sum to `rays`.
    j["ranks"] = std::max<size_t>(1, r.raysPerRank.size());
    j["rays_per_rank"] = r.raysPerRank.empty() ? std::vector<uint64_t>{r.rays} : r.raysPerRank;
    nlohmann::json sec = nlohmann::json::object();
    for (auto& [stage, s] : r.seconds.stages()) sec[stage] = s;
    j["seconds"] = sec;
    double sampling = r.seconds.get("sampling");
    j["rays_per_second"] = sampling > 0 ? double(r.rays) / sampling : 0.0;
    for (auto& [k, v] : r.extra) j[k] = v;
    j["nonfinite_pixels"] = nonFinitePixels(r);
    return j;
}

std::string timingSummary(const RenderResult& r) {
    std::ostringstream os;
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s  %dx%d  %.1f spp average  %.2f Mrays  %d threads\n", r.method.c_str(),
                  r.color.width(), r.color.height(), r.sppAverage, double(r.rays) * 1e-6, r.threads);
    os << buf;
    for (auto& [stage, s] : r.seconds.stages()) {
        std::snprintf(buf, sizeof buf, "  %-22s %8.3f s\n", stage.c_str(), s);
        os << buf;
    }
    double sampling = r.seconds.get("sampling");
    if (sampling > 0) {
        std::snprintf(buf, sizeof buf, "  %-22s %8.2f Mrays/s\n", "sampling throughput", double(r.rays) / sampling * 1e-6);
        os << buf;
    }
    return os.str();
}

}  // namespace wedge::render
