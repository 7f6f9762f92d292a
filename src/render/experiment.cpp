#include "render/experiment.h"

#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unistd.h>

#include "core/error.h"
#include "core/memory_limit.h"
#include "core/parallel.h"
#include "core/sampler.h"
#include "io/image_io.h"
#include "io/plot.h"
#include "io/output_file.h"
#include "io/text_file.h"
#include "render/distribution.h"
#include "render/memory_estimate.h"

namespace fs = std::filesystem;

namespace wedge::render {

namespace {

// Heat maps: log10 of the per-pixel relative squared error over [-4, 0] (10^-4 dark, 1 yellow).
constexpr float kHeatLo = -4.f, kHeatHi = 0.f;
// The stops of io::writePngHeat's ramp, for the legend.
constexpr const char* kHeatGradient = "#440154, #3b528b, #21918c, #5ec962, #fde725";

// ---- small helpers ------------------------------------------------------------------------------

std::string format(const char* fmt, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, fmt, v);
    return buf;
}

std::string seconds(double s) { return s >= 10 ? format("%.1f s", s) : format("%.3f s", s); }

/// The "where" tables (Markdown and HTML): one class's cell, and what the classes are.
std::string regionCell(const metrics::RegionError& c) {
    return c.pixels > 0 ? format("%.3g", c.relMse) + ", " + format("%.3g", c.variance) : "-";
}
constexpr const char* kRegionLegend =
    "background, mixed surfaces, edge (within 2 px of those or of another object), penumbra (some but not all of "
    "the initial shadow rays blocked), defocused, interior";

/// Scene name usable in file names.
std::string fileStem(const std::string& name) {
    std::string stem = fs::path(name).stem().string();
    for (char& c : stem)
        if (!std::isalnum((unsigned char)c) && c != '-' && c != '_') c = '_';
    return stem.empty() ? "scene" : stem;
}

uint64_t fnv1a(const void* data, size_t size, uint64_t h) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 1099511628211ULL;
    return h;
}
uint64_t fnv1a(const std::string& bytes, uint64_t h = 1469598103934665603ULL) { return fnv1a(bytes.data(), bytes.size(), h); }
template <class T>
uint64_t fnv1a(const std::vector<T>& v, uint64_t h) {
    h = fnv1a(std::to_string(v.size()), h);
    return v.empty() ? h : fnv1a(v.data(), v.size() * sizeof(T), h);
}
uint64_t fnv1a(const Vec3f& v, uint64_t h) { return fnv1a(&v, sizeof v, h); }
uint64_t fnv1a(float v, uint64_t h) { return fnv1a(&v, sizeof v, h); }

/// Everything in a scene that shapes its image, as loaded: the meshes OBJ files give and the
/// materials and texture maps MTL files give, not only the scene file's text, so that editing
/// a mesh, an MTL or a texture renders the reference again instead of reusing a stale one.
uint64_t sceneHash(const scene::SceneDesc& d) {
    uint64_t h = fnv1a(fs::is_regular_file(d.file) ? io::readTextFile(d.file) : std::string());
    for (const auto& m : d.meshes) {
        h = fnv1a(m.positions, h);
        h = fnv1a(m.indices, h);
        h = fnv1a(m.materialIds, h);
        h = fnv1a(m.shapeIds, h);
        h = fnv1a(m.cornerNormals, h);
        h = fnv1a(m.cornerUVs, h);
        h = fnv1a(m.velocity, h);
    }
    for (const auto& m : d.materials) {
        h = fnv1a(m.name + "|" + m.texture, fnv1a(m.albedo, fnv1a(m.emission, fnv1a(m.textureScale, h))));
        if (m.map) {
            h = fnv1a(m.map->file + (m.map->clamp ? "|clamp" : "|repeat"), h);
            h = fnv1a(&m.map->scale, sizeof m.map->scale, fnv1a(&m.map->offset, sizeof m.map->offset, h));
            h = fnv1a(m.map->texels.data(), m.map->texels.size() * sizeof(Vec3f), h);
        }
    }
    for (const auto& l : d.lights) {
        h = fnv1a(l.corner, fnv1a(l.edge1, fnv1a(l.edge2, fnv1a(l.radiance, fnv1a(l.radius, h)))));
        h = fnv1a(std::to_string(int(l.shape)), h);
    }
    for (const auto& s : d.spheres) h = fnv1a(s.center, fnv1a(s.radius, fnv1a(s.velocity, fnv1a(std::to_string(s.material), h))));
    const auto& c = d.camera;
    h = fnv1a(c.position, fnv1a(c.lookAt, fnv1a(c.up, h)));
    for (float v : {c.fovY, c.apertureRadius, c.focusDistance, c.shutterOpen, c.shutterClose}) h = fnv1a(v, h);
    return fnv1a(d.render.indirect ? "indirect" : "direct", h);
}

std::string base64(const std::string& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t n = uint32_t((unsigned char)bytes[i]) << 16;
        if (i + 1 < bytes.size()) n |= uint32_t((unsigned char)bytes[i + 1]) << 8;
        if (i + 2 < bytes.size()) n |= uint32_t((unsigned char)bytes[i + 2]);
        out += table[(n >> 18) & 63];
        out += table[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? table[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? table[n & 63] : '=';
    }
    return out;
}

using io::htmlEscape;

Image3f crop(const Image3f& img, int x0, int y0, int size) {
    Image3f out(size, size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) out(x, y) = img(std::min(x0 + x, img.width() - 1), std::min(y0 + y, img.height() - 1));
    return out;
}

nlohmann::json secondsJson(const StageTimes& t) {
    nlohmann::json j = nlohmann::json::object();
    for (auto& [stage, s] : t.stages()) j[stage] = s;
    return j;
}

nlohmann::json finiteOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

double overhead(const StageTimes& t) {
    double total = t.get("total");
    return total > 0 ? (t.get("prefilter") + t.get("filter")) / total : 0;
}

bool isUnavailable(const Error& e) { return std::string(e.what()).find("not available") != std::string::npos; }

// ---- the experiment -----------------------------------------------------------------------------

class Experiment {
public:
    Experiment(const scene::Scene& scene, const ExperimentOptions& options) : m_scene(scene), m_options(options) {}

    ExperimentResult run();

private:
    void say(const std::string& line) const {
        if (!m_options.quiet) std::fprintf(stderr, "experiment: %s\n", line.c_str());
    }
    void loadOrRenderReference();
    /// relMSE net of the reference's own noise: what a noise-free reference would measure.
    double netRelMse(const ExperimentProbe& p) const { return p.metrics.relMse - m_result.referenceNoise; }
    /// The squared bias of a base row: its net relMSE minus its variance.
    double bias2(const ExperimentRow& r) const { return netRelMse(r.probe) - r.variance; }
    /// The variance part of a base row's relMSE, per pixel: the method rendered again with another seed.
    Image1f measureVariance(const std::string& method, const ExperimentProbe& p);
    /// The options of one render: the base options with this method, spp and seed.
    RenderOptions renderOptions(const std::string& method, int spp, uint32_t seed, bool quiet) const {
        RenderOptions o = m_options.base;
        o.method = method;
        o.spp = spp;
        o.seed = seed;
        o.quiet = quiet;
        return o;
    }
    /// The experiment's certain need against the memory limit before anything is rendered or
    /// written: the reference's two halves (the first kept while the second renders) or the
    /// largest base render, with the reference and the base rows' images beside it.
    void checkMemoryAhead() const;
    /// The bytes of the images held now: the reference, every probe's and the rows' copies.
    uint64_t keptBytes() const;
    /// Renders `method` at `spp` (memoised per method); nullopt when the method is not available.
    const ExperimentProbe* evaluate(const std::string& method, int spp);
    void searchEqualQuality(const std::string& method, double target);
    void searchEqualTime(const std::string& method, double target);
    void writeImages();
    void writeResultsJson() const;
    std::string markdownTable() const;
    std::string convergenceSvg() const;
    void writeHtml() const;

    const scene::Scene& m_scene;
    ExperimentOptions m_options;
    ExperimentResult m_result;
    Image3f m_reference;
    std::map<std::string, std::map<int, ExperimentProbe>> m_memo;
    int m_renders = 0;
    int m_cap = 0;
    // Insets: two squares of m_insetSize pixels at these corners.
    std::vector<std::pair<int, int>> m_insets;
    int m_insetSize = 0;
    std::string m_referenceImage;
};

void Experiment::loadOrRenderReference() {
    const auto& desc = m_scene.desc();
    const uint64_t hash = sceneHash(desc);
    char key[256];
    std::snprintf(key, sizeof key, "reference-%s-%dx%d-%dspp-seed%u-%016" PRIx64, fileStem(m_result.scene).c_str(),
                  m_result.width, m_result.height, m_result.referenceSpp, m_result.referenceSeed, hash);
    fs::path exr = fs::path(m_options.cacheDir) / (std::string(key) + ".exr");
    fs::path meta = fs::path(m_options.cacheDir) / (std::string(key) + ".json");
    bool cached = false;
    if (fs::is_regular_file(exr) && fs::is_regular_file(meta)) {
        try {
            m_reference = io::readColor(exr.string());
            nlohmann::json j = nlohmann::json::parse(io::readTextFile(meta.string()));
            m_result.referenceSeconds = j.at("seconds").get<double>();
            m_result.referenceNoise = j.at("noise_relmse").get<double>();  // older entries lack it: render again
            cached = m_reference.sameSize(m_result.width, m_result.height);
        } catch (const std::exception&) {
            // A damaged or older cache entry is rendered again and overwritten.
        }
    }
    // Over MPI ranks, every rank must take the same way (the reference's renders are collective).
    const std::vector<uint64_t> ranksCached = gatherCounts(m_options.base.distribution, cached ? 1 : 0);
    for (size_t r = 1; r < ranksCached.size(); ++r)
        if (ranksCached[r] != ranksCached[0])
            throw Error("--cache " + m_options.cacheDir, "rank 0 and rank " + std::to_string(r) +
                                                             " see different reference caches (give every rank the same cache directory)");
    if (cached) {
        m_result.referenceCached = true;
        say("reference from cache " + exr.string());
        return;
    }
    // Two independent halves (the second with its own seed): their difference measures the
    // reference's own noise.
    const int nA = m_result.referenceSpp / 2, nB = m_result.referenceSpp - nA;
    say("rendering the reference: mc, " + std::to_string(m_result.referenceSpp) + " spp in two independent halves");
    RenderOptions o = renderOptions("mc", nA, m_result.referenceSeed, m_options.quiet);
    o.layers = "off";  // plain Monte Carlo: the layered reconstruction's smoothing is a bias at any spp
    // The default sampler whatever the methods' (--sampler): the cache key names no sampler, and
    // the reference is the best estimate at its samples.
    o.sampler = RenderOptions().sampler;
    RenderResult a = render(m_scene, o);
    o.spp = nB;
    o.seed = hashCombine(m_result.referenceSeed, 0x68616c66U);
    RenderResult b = render(m_scene, o);
    m_reference = metrics::combineHalves(a.color, nA, b.color, nB);
    m_result.referenceNoise = metrics::referenceNoise(a.color, nA, b.color, nB);
    m_result.referenceSeconds = a.seconds.get("total") + b.seconds.get("total");
    if (!m_options.writes) return;
    fs::create_directories(m_options.cacheDir);
    io::writeColor(exr.string(), m_reference);
    nlohmann::json j;
    j["scene"] = m_result.scene;
    j["resolution"] = {m_result.width, m_result.height};
    j["spp"] = m_result.referenceSpp;
    j["seed"] = m_result.referenceSeed;
    j["seconds"] = m_result.referenceSeconds;
    j["noise_relmse"] = m_result.referenceNoise;
    io::writeTextFile(meta.string(), j.dump(2) + "\n");
}

void Experiment::checkMemoryAhead() const {
    const scene::SceneDesc& desc = m_scene.desc();
    const uint64_t pixels = uint64_t(desc.camera.width) * uint64_t(desc.camera.height);
    RenderOptions ref = renderOptions("mc", m_options.referenceSpp - m_options.referenceSpp / 2, 0, true);
    ref.layers = "off";  // as loadOrRenderReference renders it
    uint64_t renders = 2 * renderMemory(desc, ref).bytes;
    for (const auto& m : m_options.methods)
        renders = std::max(renders, renderMemory(desc, renderOptions(m, m_options.spp, 0, true)).bytes);
    // The reference (12 bytes a pixel) and, per method, its base probe, the row's copy of it (12
    // and 1 byte a pixel each: colour and pixel classes) and its variance map (4).
    const uint64_t images = pixels * (sizeof(Vec3f) + m_options.methods.size() * (2 * (sizeof(Vec3f) + 1) + sizeof(float)));
    checkMemory(desc.file,
                "an experiment at " + std::to_string(desc.camera.width) + "x" + std::to_string(desc.camera.height) +
                    " (its largest render, " + formatBytes(double(renders)) + ", beside the reference and the " +
                    std::to_string(m_options.methods.size()) + " base rows' images)",
                renders + images);
}

uint64_t Experiment::keptBytes() const {
    uint64_t n = m_reference.size() * sizeof(Vec3f);
    auto add = [&](const ExperimentProbe& p) { n += p.color.size() * sizeof(Vec3f) + p.regions.size(); };
    for (const auto& [method, probes] : m_memo)
        for (const auto& [spp, p] : probes) add(p);
    for (const auto& row : m_result.rows) {
        add(row.probe);
        for (const auto& p : row.probes) add(p);
    }
    return n;
}

const ExperimentProbe* Experiment::evaluate(const std::string& method, int spp) {
    auto& memo = m_memo[method];
    if (auto it = memo.find(spp); it != memo.end()) return &it->second;
    RenderOptions o = renderOptions(method, spp, m_result.seed, m_options.quiet);
    // The searches keep every probe's image (and the rows copies of them): checked before each
    // render, with what is held so far, as the grid grows.
    {
        const RenderMemory r = renderMemory(m_scene.desc(), o);
        const uint64_t kept = keptBytes();
        checkMemory(m_scene.desc().file,
                    r.what + " at " + std::to_string(spp) + " spp beside the experiment's " + formatBytes(double(kept)) +
                        " of images kept so far",
                    r.bytes + kept + uint64_t(m_result.width) * uint64_t(m_result.height) * (sizeof(Vec3f) + 1));
    }
    RenderResult r;
    try {
        r = render(m_scene, o);
    } catch (const Error& e) {
        if (isUnavailable(e)) return nullptr;
        throw;
    }
    // Timing noise on a shared machine: keep the fastest of --repeat renders (the images are
    // identical, the seed being the same).
    for (int k = 1; k < m_options.repeat; ++k) {
        o.quiet = true;
        RenderResult again = render(m_scene, o);
        if (again.seconds.get("total") < r.seconds.get("total")) r.seconds = again.seconds;
    }
    ExperimentProbe p;
    p.spp = spp;
    p.sppAverage = r.sppAverage;
    p.seconds = r.seconds;
    p.metrics = metrics::compare(r.color, m_reference);
    if (spp == m_options.spp) {  // the base rows' probes: only they are split over pixel classes
        const FrameBuffers& fb = r.buffers;
        p.regions = metrics::regionClasses({fb.object, fb.coverage, fb.defocus, fb.occluded});
    }
    p.color = std::move(r.color);
    ++m_renders;
    say(format("[%.0f] ", m_renders) + method + " " + std::to_string(spp) + " spp: relMSE " +
        format("%.4g", p.metrics.relMse) + ", " + seconds(p.seconds.get("total")));
    return &memo.emplace(spp, std::move(p)).first->second;
}

Image1f Experiment::measureVariance(const std::string& method, const ExperimentProbe& p) {
    // Another seed, independent of the base render's samples.
    const RenderOptions o = renderOptions(method, p.spp, hashCombine(m_result.seed, 0x76617232U), true);
    return metrics::seedVarianceMap(p.color, render(m_scene, o).color, m_reference);
}

void Experiment::searchEqualQuality(const std::string& method, double target) {
    const ExperimentProbe& start = *evaluate(method, m_options.spp);
    std::vector<int> order;
    auto above = [&](int s) {
        order.push_back(s);
        return evaluate(method, s)->metrics.relMse <= target;
    };
    // relMSE ~ 1/spp for Monte Carlo noise.
    double guess = start.metrics.relMse > 0 && target > 0 ? double(start.spp) * start.metrics.relMse / target : m_cap;
    if (!std::isfinite(guess)) guess = m_cap;
    SearchBracket b = searchBoundary(above, start.spp, start.metrics.relMse <= target, guess, m_cap, m_options.tolerance);
    ExperimentRow row;
    row.method = method;
    row.setting = "equal_quality";
    row.target = target;
    row.reached = b.hi <= m_cap;
    row.probe = m_memo[method].at(row.reached ? b.hi : b.lo);
    row.probes.push_back(start);
    for (int s : order) row.probes.push_back(m_memo[method].at(s));
    m_result.rows.push_back(std::move(row));
}

void Experiment::searchEqualTime(const std::string& method, double target) {
    const ExperimentProbe& start = *evaluate(method, m_options.spp);
    std::vector<int> order;
    auto above = [&](int s) {
        order.push_back(s);
        return evaluate(method, s)->seconds.get("total") > target;
    };
    // total ~ fixed + perSample * spp.
    double perSample = std::max(1e-9, start.seconds.get("sampling") / start.spp);
    double fixed = std::max(0.0, start.seconds.get("total") - start.seconds.get("sampling"));
    double guess = std::max(1.0, (target - fixed) / perSample);
    SearchBracket b =
        searchBoundary(above, start.spp, start.seconds.get("total") > target, guess, m_cap, m_options.tolerance);
    ExperimentRow row;
    row.method = method;
    row.setting = "equal_time";
    row.target = target;
    // The largest spp within the time; if even 1 spp takes longer, 1 spp (not reached). At the cap
    // the method is faster than the anchor even there (also marked not reached).
    row.reached = b.lo >= 1 && b.lo < m_cap;
    row.probe = m_memo[method].at(b.lo >= 1 ? b.lo : b.hi);
    row.probes.push_back(start);
    for (int s : order) row.probes.push_back(m_memo[method].at(s));
    m_result.rows.push_back(std::move(row));
}

ExperimentResult Experiment::run() {
    const auto& desc = m_scene.desc();
    m_result.scene = m_options.sceneName;
    m_result.width = desc.camera.width;
    m_result.height = desc.camera.height;
    m_result.seed = m_options.seed.value_or(desc.render.seed);
    // Independent of every method's samples (which depend on the seed only through hashes of it).
    m_result.referenceSeed = hashCombine(m_result.seed, 0x72656672U);
    m_result.referenceSpp = m_options.referenceSpp;
    m_cap = m_options.maxSpp > 0 ? m_options.maxSpp : std::max(m_options.spp, m_options.referenceSpp / 4);

    checkMemoryAhead();  // before anything is written

    if (m_options.writes) fs::create_directories(fs::path(m_options.outDir) / "images");
    if (m_options.cacheDir.empty()) m_options.cacheDir = (fs::path(m_options.outDir) / "cache").string();

    // Warm-up: the first render of a process pays for starting the worker threads.
    {
        (void)render(m_scene, renderOptions("mc", 1, m_result.seed, true));
    }
    loadOrRenderReference();

    // Base rows: every available method at --spp.
    std::vector<std::string> available;
    for (const auto& m : m_options.methods) {
        const ExperimentProbe* p = evaluate(m, m_options.spp);
        if (!p) {
            m_result.skipped.push_back(m);
            if (m_options.writes) std::fprintf(stderr, "wedge: warning: experiment: method '%s' is not available yet; skipped\n", m.c_str());
            continue;
        }
        available.push_back(m);
        ExperimentRow row;
        row.method = m;
        row.setting = "base";
        row.probe = *p;
        const Image1f variance = measureVariance(m, *p);
        row.variance = metrics::mapMean(variance);
        row.regions = metrics::regionErrors(p->color, m_reference, p->regions, metrics::kRelMseEpsilon, &variance);
        say(m + " " + std::to_string(p->spp) + " spp with another seed: variance " + format("%.4g", row.variance) +
            ", squared bias " + format("%.4g", bias2(row)));
        m_result.rows.push_back(std::move(row));
    }
    if (available.empty()) throw Error("experiment", "none of the requested methods is available");

    // The anchor: the method whose quality and time the others are measured against.
    std::string anchor = m_options.anchor;
    if (anchor.empty()) {
        for (const char* m : {"maaf", "aaf", "atrous"})
            if (anchor.empty() && std::find(available.begin(), available.end(), m) != available.end()) anchor = m;
        if (anchor.empty()) anchor = available.front();
    } else if (std::find(available.begin(), available.end(), anchor) == available.end()) {
        throw Error("--anchor " + anchor, "the anchor method is not available yet");
    }
    m_result.anchor = anchor;
    const ExperimentProbe anchorProbe = m_memo[anchor].at(m_options.spp);

    for (const auto& m : available) {
        if (m == anchor) continue;
        if (m_options.equalQuality) {
            say("equal quality: " + m + " to relMSE " + format("%.4g", anchorProbe.metrics.relMse) + " (" + anchor + ")");
            searchEqualQuality(m, anchorProbe.metrics.relMse);
        }
        if (m_options.equalTime) {
            say("equal time: " + m + " to " + seconds(anchorProbe.seconds.get("total")) + " (" + anchor + ")");
            searchEqualTime(m, anchorProbe.seconds.get("total"));
        }
    }
    // Re-time every row's render (--repeat more times, the fastest counts): a search decides on
    // one measurement, but the table should not carry a burst of load on a shared machine.
    say("re-timing the rows");
    for (auto& row : m_result.rows) {
        ExperimentProbe& p = m_memo[row.method].at(row.probe.spp);
        if (!p.retimed) {
            const RenderOptions o = renderOptions(row.method, p.spp, m_result.seed, true);
            for (int k = 0; k < m_options.repeat; ++k) {
                StageTimes t = render(m_scene, o).seconds;
                if (t.get("total") < p.seconds.get("total")) p.seconds = t;
            }
            p.retimed = true;
        }
        row.probe.seconds = p.seconds;
    }
    for (auto& row : m_result.rows) {
        double err = row.probe.metrics.relMse * row.probe.seconds.get("total");
        row.efficiency = err > 0 ? 1.0 / err : 0.0;
        double net = netRelMse(row.probe) * row.probe.seconds.get("total");
        row.netEfficiency = net > 0 ? 1.0 / net : 0.0;
    }

    if (!m_options.writes) return m_result;
    writeImages();
    writeResultsJson();
    std::string table = markdownTable();
    io::writeTextFile((fs::path(m_options.outDir) / "table.md").string(), table);
    writeHtml();
    if (!m_options.quiet) std::fputs(table.c_str(), stdout);
    say("wrote " + (fs::path(m_options.outDir) / "index.html").string());
    return m_result;
}

void Experiment::writeImages() {
    const fs::path dir = fs::path(m_options.outDir) / "images";
    const int w = m_result.width, h = m_result.height;
    m_referenceImage = "images/reference.png";
    io::writePng((fs::path(m_options.outDir) / m_referenceImage).string(), m_reference);

    // Insets where the base renders err most on average (log error, so that a few very wrong pixels
    // do not decide alone), two non-overlapping squares.
    m_insetSize = std::max(8, std::min(w, h) / 6);
    Image1f score(w, h, 0.f);
    for (const auto& row : m_result.rows) {
        if (row.setting != "base") continue;
        Image1f e = metrics::log10Map(metrics::relativeErrorMap(row.probe.color, m_reference), kHeatLo);
        for (size_t i = 0; i < e.size(); ++i) score[i] += e[i] - kHeatLo;
    }
    const int s = std::min({m_insetSize, w, h});
    m_insetSize = s;
    const int stride = std::max(1, s / 4);
    std::vector<std::pair<double, std::pair<int, int>>> windows;
    for (int y0 = 0; y0 + s <= h; y0 += stride)
        for (int x0 = 0; x0 + s <= w; x0 += stride) {
            double sum = 0;
            for (int y = y0; y < y0 + s; ++y)
                for (int x = x0; x < x0 + s; ++x) sum += score(x, y);
            windows.push_back({sum, {x0, y0}});
        }
    std::stable_sort(windows.begin(), windows.end(), [](auto& a, auto& b) { return a.first > b.first; });
    for (const auto& [sum, corner] : windows) {
        bool overlaps = false;
        for (const auto& c : m_insets)
            if (std::abs(c.first - corner.first) < s && std::abs(c.second - corner.second) < s) overlaps = true;
        if (!overlaps) m_insets.push_back(corner);
        if (m_insets.size() == 2) break;
    }

    auto writeInsets = [&](const Image3f& img, const std::string& stem) {
        for (size_t k = 0; k < m_insets.size(); ++k)
            io::writePng((dir / (stem + "-inset" + std::to_string(k) + ".png")).string(),
                         crop(img, m_insets[k].first, m_insets[k].second, s));
    };
    writeInsets(m_reference, "reference");
    for (auto& row : m_result.rows) {
        std::string stem = row.method + "-" + row.setting;
        row.image = "images/" + stem + ".png";
        row.heatmap = "images/" + stem + "-error.png";
        io::writePng((fs::path(m_options.outDir) / row.image).string(), row.probe.color);
        io::writePngHeat((fs::path(m_options.outDir) / row.heatmap).string(),
                         metrics::log10Map(metrics::relativeErrorMap(row.probe.color, m_reference), kHeatLo), kHeatLo,
                         kHeatHi);
        writeInsets(row.probe.color, stem);
    }
}

void Experiment::writeResultsJson() const {
    nlohmann::json rows = nlohmann::json::array();
    auto probeJson = [](const ExperimentProbe& p) {
        nlohmann::json j;
        j["spp"] = p.spp;
        j["spp_average"] = p.sppAverage;
        j["seconds"] = secondsJson(p.seconds);
        j["relmse"] = p.metrics.relMse;
        return j;
    };
    for (const auto& row : m_result.rows) {
        nlohmann::json j;
        j["method"] = row.method;
        j["setting"] = row.setting;
        j["spp"] = row.probe.spp;
        j["spp_average"] = row.probe.sppAverage;
        j["seconds"] = secondsJson(row.probe.seconds);
        j["relmse"] = row.probe.metrics.relMse;
        j["smape"] = row.probe.metrics.smape;
        j["psnr"] = finiteOrNull(row.probe.metrics.psnr);
        j["ssim"] = row.probe.metrics.ssim;
        j["efficiency"] = row.efficiency;
        j["reference_noise_relmse"] = m_result.referenceNoise;
        j["relmse_net"] = netRelMse(row.probe);
        j["efficiency_net"] = row.netEfficiency;
        if (row.variance >= 0) {
            j["variance_relmse"] = row.variance;
            j["bias2_relmse"] = bias2(row);
        }
        if (!row.regions.empty()) {
            nlohmann::json r = nlohmann::json::object();
            for (const auto& c : row.regions)
                r[c.name] = {{"pixels", c.pixels}, {"share", c.share}, {"relmse", c.relMse}, {"variance", c.variance}};
            j["regions"] = r;
        }
        j["overhead"] = overhead(row.probe.seconds);
        j["scene"] = m_result.scene;
        j["resolution"] = {m_result.width, m_result.height};
        j["seed"] = m_result.seed;
        j["reference_spp"] = m_result.referenceSpp;
        j["anchor"] = m_result.anchor;
        j["threads"] = ThreadLimit::current();
        j["repeat"] = m_options.repeat;
        j["image"] = row.image;
        j["heatmap"] = row.heatmap;
        if (row.setting != "base") {
            j[row.setting == "equal_quality" ? "target_relmse" : "target_seconds"] = row.target;
            j["reached"] = row.reached;
            nlohmann::json probes = nlohmann::json::array();
            for (const auto& p : row.probes) probes.push_back(probeJson(p));
            j["probes"] = probes;
        }
        rows.push_back(j);
    }
    io::writeTextFile((fs::path(m_options.outDir) / "results.json").string(), rows.dump(2) + "\n");
}

/// The Fig. 12 layout as Markdown: the base rows with their stage times, then each method's
/// equal-quality spp and time and the anchor's speedup over it, then equal-time quality.
std::string Experiment::markdownTable() const {
    std::ostringstream os;
    auto find = [&](const std::string& method, const std::string& setting) -> const ExperimentRow* {
        for (const auto& r : m_result.rows)
            if (r.method == method && r.setting == setting) return &r;
        return nullptr;
    };
    const ExperimentRow* anchor = find(m_result.anchor, "base");
    const ExperimentRow* mcBase = find("mc", "base");
    if (!m_options.commandLine.empty()) os << "`" << m_options.commandLine << "`\n\n";
    os << "| " << m_result.scene << " " << m_result.width << "x" << m_result.height
       << " | spp | sampling | prefilter | filter | overhead | total | relMSE | net relMSE | variance | bias² | PSNR | SSIM | efficiency | net efficiency |";
    if (m_options.equalQuality) os << " EQ spp | EQ total | " << m_result.anchor << " speedup |";
    if (m_options.equalTime) os << " ET spp | ET relMSE |";
    os << "\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|";
    if (m_options.equalQuality) os << "---|---|---|";
    if (m_options.equalTime) os << "---|---|";
    os << "\n";
    for (const auto& r : m_result.rows) {
        if (r.setting != "base") continue;
        const auto& p = r.probe;
        os << "| " << r.method << " | " << format("%.1f", p.sppAverage) << " | " << seconds(p.seconds.get("sampling"))
           << " | " << seconds(p.seconds.get("prefilter")) << " | " << seconds(p.seconds.get("filter")) << " | "
           << format("%.1f%%", 100 * overhead(p.seconds)) << " | " << seconds(p.seconds.get("total")) << " | "
           << format("%.4g", p.metrics.relMse) << " | " << format("%.4g", netRelMse(p)) << " | "
           << format("%.4g", r.variance) << " | " << format("%.4g", bias2(r)) << " | " << format("%.2f", p.metrics.psnr) << " | " << format("%.4f", p.metrics.ssim) << " | ";
        if (mcBase && mcBase->efficiency > 0) os << format("%.2fx mc", r.efficiency / mcBase->efficiency);
        else os << format("%.4g", r.efficiency);
        os << " | ";
        if (r.netEfficiency <= 0) os << "-";
        else if (mcBase && mcBase->netEfficiency > 0) os << format("%.2fx mc", r.netEfficiency / mcBase->netEfficiency);
        else os << format("%.4g", r.netEfficiency);
        os << " |";
        if (m_options.equalQuality) {
            const ExperimentRow* eq = find(r.method, "equal_quality");
            if (eq) {
                os << " " << (eq->reached ? "" : ">") << eq->probe.spp << " | " << seconds(eq->probe.seconds.get("total"))
                   << " | " << (eq->reached ? "" : ">")
                   << format("%.2fx", eq->probe.seconds.get("total") / anchor->probe.seconds.get("total")) << " |";
            } else {
                os << " - | - | - |";
            }
        }
        if (m_options.equalTime) {
            const ExperimentRow* et = find(r.method, "equal_time");
            if (et) os << " " << et->probe.spp << (et->reached ? "" : "*") << " | " << format("%.4g", et->probe.metrics.relMse) << " |";
            else os << " - | - |";
        }
        os << "\n";
    }
    os << "\nReference: mc " << m_result.referenceSpp << " spp in two independent halves; its own noise, estimated from "
       << "them, is relMSE " << format("%.4g", m_result.referenceNoise)
       << " (part of every relMSE here; net relMSE = relMSE minus it, what a noise-free reference would measure). "
       << "Variance: half the relative squared difference from a render with another seed; bias² = net relMSE - "
          "variance. "
       << ThreadLimit::current() << " threads"
       << (m_options.repeat > 1 ? ", times the fastest of " + std::to_string(m_options.repeat) + " renders" : "")
       << ". relMSE with eps 0.01, no 0.5 factor; PSNR/SSIM on tone-mapped images. "
       << "Efficiency = 1/(relMSE x total seconds), net efficiency the same with the net relMSE";
    if (mcBase) os << ", relative to mc at the same spp";
    os << ".";
    if (m_options.equalQuality)
        os << " EQ: smallest spp reaching " << m_result.anchor << "'s relMSE (\">\": not reached within " << m_cap
           << " spp); speedup = EQ total / " << m_result.anchor << " total.";
    if (m_options.equalTime) os << " ET: largest spp within " << m_result.anchor << "'s total time (\"*\": bound hit).";
    if (!m_result.skipped.empty()) {
        os << " Not available:";
        for (const auto& s : m_result.skipped) os << " " << s;
        os << ".";
    }
    os << "\n";
    // Where the error sits: the base rows' relMSE and variance over their renders' pixel classes.
    if (anchor && !anchor->regions.empty()) {
        const auto& names = metrics::regionNames();
        os << "\n| where |";
        for (const auto& n : names) os << " " << n << " |";
        os << "\n|---|";
        for (size_t k = 0; k < names.size(); ++k) os << "---|";
        os << "\n| pixels (" << m_result.anchor << ") |";
        for (const auto& c : anchor->regions) os << " " << format("%.1f%%", 100 * c.pixels) << " |";
        os << "\n";
        for (const auto& r : m_result.rows) {
            if (r.setting != "base" || r.regions.empty()) continue;
            os << "| " << r.method << " |";
            for (const auto& c : r.regions) os << " " << regionCell(c) << " |";
            os << "\n";
        }
        os << "\nWhere: relMSE, variance of each base render over its own pixel classes (`wedge compare --regions`): "
           << kRegionLegend << ". The relMSE here includes the reference's own noise.\n";
    }
    return os.str();
}

/// relMSE against total seconds, log-log, for every render the experiment made (base renders and
/// the searches' probes), one line per method in order of spp: the convergence plot of the
/// filtering papers, from the experiment's own renders, as an inline SVG.
std::string Experiment::convergenceSvg() const {
    io::LinePlot plot;
    plot.title = m_result.scene + ": relMSE against time";
    plot.xLabel = "seconds (render total)";
    plot.yLabel = "relMSE";
    plot.logX = plot.logY = true;
    double xLo = INFINITY, xHi = 0, yLo = INFINITY, yHi = 0;
    std::vector<std::string> order;
    for (const auto& r : m_result.rows)
        if (std::find(order.begin(), order.end(), r.method) == order.end()) order.push_back(r.method);
    for (const auto& method : order) {
        auto it = m_memo.find(method);
        if (it == m_memo.end()) continue;
        io::PlotSeries series;
        series.label = method;
        series.marker = 0;
        // The colours of examples/convergence.py.
        series.color = method == "mc"     ? io::displayColor(0.27f, 0.27f, 0.27f)
                       : method == "aaf"  ? io::displayColor(0.12f, 0.47f, 0.71f)
                       : method == "maaf" ? io::displayColor(0.84f, 0.15f, 0.16f)
                                          : io::displayColor(0.17f, 0.63f, 0.17f);
        for (const auto& [spp, p] : it->second) {  // std::map: in order of spp
            const double t = p.seconds.get("total"), e = p.metrics.relMse;
            if (!(t > 0 && e > 0)) continue;  // no point on a log axis
            series.xs.push_back(t);
            series.ys.push_back(e);
            xLo = std::min(xLo, t), xHi = std::max(xHi, t), yLo = std::min(yLo, e), yHi = std::max(yHi, e);
        }
        if (!series.xs.empty()) plot.series.push_back(std::move(series));
    }
    if (plot.series.empty()) return "<p>No render with a positive time and relMSE.</p>";
    // A margin of a fifth of a decade on each side, wide enough for one point alone.
    plot.xMin = xLo / 1.6, plot.xMax = xHi * 1.6, plot.yMin = yLo / 1.6, plot.yMax = yHi * 1.6;
    return io::svgPlot(plot, 640, 420);
}

void Experiment::writeHtml() const {
    const fs::path out(m_options.outDir);
    auto embed = [&](const std::string& relative) {
        return "data:image/png;base64," + base64(io::readTextFile((out / relative).string()));
    };
    auto td = [](const std::string& s) { return "<td>" + s + "</td>"; };
    const ExperimentRow* anchor = nullptr;
    for (const auto& r : m_result.rows)
        if (r.method == m_result.anchor && r.setting == "base") anchor = &r;
    auto settingLabel = [](const std::string& s) {
        return s == "base" ? std::string("base spp") : s == "equal_quality" ? std::string("equal quality")
                                                                            : std::string("equal time");
    };

    std::ostringstream h;
    h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>wedge experiment: "
      << htmlEscape(m_result.scene) << "</title>\n<style>\n"
      << "body{font-family:system-ui,sans-serif;margin:16px;background:#fff;color:#222}\n"
      << "table{border-collapse:collapse;margin:8px 0 16px}td,th{border:1px solid #bbb;padding:3px 7px;text-align:right}\n"
      << "th{background:#eee}td:first-child,th:first-child{text-align:left}\n"
      << ".grid{display:flex;flex-wrap:wrap;gap:12px}figure{margin:0;width:260px}\n"
      << ".frame{position:relative;width:260px;line-height:0}.frame img{width:100%}\n"
      << "img{image-rendering:pixelated}.box{position:absolute;border:2px solid #f0f;box-sizing:border-box}\n"
      << ".box.b1{border-color:#0ff}.insets{display:flex;gap:4px;margin-top:4px}.insets img{width:128px;height:128px}\n"
      << ".insets img:first-child{outline:2px solid #f0f}.insets img:nth-child(2){outline:2px solid #0ff}\n"
      << ".heat{width:260px;margin-top:4px}figcaption{font-size:13px;margin:4px 0}\n"
      << ".legend{display:inline-block;width:200px;height:12px;vertical-align:middle;background:linear-gradient(90deg,"
      << kHeatGradient << ")}\ncode{font-size:12px}\n</style></head><body>\n";
    h << "<h1>" << htmlEscape(m_result.scene) << " &mdash; " << m_result.width << "&times;" << m_result.height << ", "
      << m_options.spp << " spp</h1>\n<p>Reference: mc " << m_result.referenceSpp << " spp in two independent halves (seed "
      << m_result.referenceSeed << "), " << seconds(m_result.referenceSeconds)
      << (m_result.referenceCached ? " (cached)" : "") << "; its own noise, estimated from the halves' difference, is "
      << "relMSE " << format("%.4g", m_result.referenceNoise) << ", part of every relMSE below. Methods use seed "
      << m_result.seed << ". Anchor for equal "
      << "quality and equal time: <b>" << htmlEscape(m_result.anchor) << "</b>. Threads: " << ThreadLimit::current()
      << (m_options.repeat > 1 ? "; times are the fastest of " + std::to_string(m_options.repeat) + " renders" : "")
      << ".";
    if (!m_result.skipped.empty()) {
        h << " Not available yet:";
        for (const auto& s : m_result.skipped) h << " " << htmlEscape(s);
        h << ".";
    }
    h << "</p>\n";
    if (!m_options.commandLine.empty()) h << "<p><code>" << htmlEscape(m_options.commandLine) << "</code></p>\n";

    // Fig. 12 of the MAAF paper: spp, sampling, prefilter, filter, overhead, total, speedup at
    // equal quality, and the equal-quality spp and times of the others.
    h << "<h2>Timings (layout of MAAF Fig. 12)</h2>\n<table><tr><th>method</th><th>spp</th><th>sampling</th>"
         "<th>pre filt.</th><th>filter</th><th>overhead</th><th>total</th>";
    if (m_options.equalQuality)
        h << "<th>EQ spp</th><th>EQ sampling</th><th>EQ filter</th><th>EQ total</th><th>speedup of "
          << htmlEscape(m_result.anchor) << "</th>";
    h << "</tr>\n";
    for (const auto& r : m_result.rows) {
        if (r.setting != "base") continue;
        const auto& t = r.probe.seconds;
        h << "<tr>" << td(htmlEscape(r.method)) << td(format("%.1f", r.probe.sppAverage)) << td(seconds(t.get("sampling")))
          << td(seconds(t.get("prefilter"))) << td(seconds(t.get("filter"))) << td(format("%.1f%%", 100 * overhead(t)))
          << td(seconds(t.get("total")));
        if (m_options.equalQuality) {
            const ExperimentRow* eq = nullptr;
            for (const auto& e : m_result.rows)
                if (e.method == r.method && e.setting == "equal_quality") eq = &e;
            if (eq) {
                const auto& et = eq->probe.seconds;
                std::string gt = eq->reached ? "" : "&gt;";
                h << td(gt + format("%.1f", eq->probe.sppAverage)) << td(seconds(et.get("sampling")))
                  << td(seconds(et.get("prefilter") + et.get("filter"))) << td(gt + seconds(et.get("total")))
                  << td(gt + format("%.2fx", et.get("total") / anchor->probe.seconds.get("total")));
            } else {
                h << "<td colspan=\"5\">" << (r.method == m_result.anchor ? "anchor" : "") << "</td>";
            }
        }
        h << "</tr>\n";
    }
    h << "</table>\n";
    if (m_options.equalQuality)
        h << "<p>EQ: the smallest spp at which the method reaches " << htmlEscape(m_result.anchor) << "'s relMSE ("
          << format("%.4g", anchor->probe.metrics.relMse) << "), found by bisection; &gt; means not reached within "
          << m_cap << " spp. Speedup = EQ total / " << htmlEscape(m_result.anchor) << " total.</p>\n";

    h << "<h2>Quality</h2>\n<table><tr><th>method</th><th>setting</th><th>spp</th><th>total</th><th>relMSE</th>"
         "<th>net relMSE</th><th>variance</th><th>bias&sup2;</th><th>SMAPE</th><th>PSNR (dB)</th><th>SSIM</th><th>efficiency 1/(relMSE&middot;s)</th>"
         "<th>net efficiency</th></tr>\n";
    for (const auto& r : m_result.rows) {
        const auto& m = r.probe.metrics;
        std::string mark = r.setting != "base" && !r.reached ? " (bound)" : "";
        h << "<tr>" << td(htmlEscape(r.method)) << td(settingLabel(r.setting) + mark) << td(format("%.1f", r.probe.sppAverage))
          << td(seconds(r.probe.seconds.get("total"))) << td(format("%.4g", m.relMse))
          << td(format("%.4g", netRelMse(r.probe))) << td(r.variance >= 0 ? format("%.4g", r.variance) : "-")
          << td(r.variance >= 0 ? format("%.4g", bias2(r)) : "-") << td(format("%.4f", m.smape))
          << td(format("%.2f", m.psnr)) << td(format("%.4f", m.ssim)) << td(format("%.4g", r.efficiency))
          << td(r.netEfficiency > 0 ? format("%.4g", r.netEfficiency) : "-") << "</tr>\n";
    }
    h << "</table>\n<p>relMSE = mean (x&minus;r)&sup2;/(r&sup2;+0.01), no 0.5 factor, linear radiance; net relMSE = "
         "relMSE &minus; the reference's own noise; variance = half the relative squared difference from a render "
         "with another seed (base rows), bias&sup2; = net relMSE &minus; variance. PSNR and SSIM "
         "(11&times;11 Gaussian, &sigma; 1.5) on tone-mapped images (clamp, sRGB).</p>\n";

    // Where the error sits: the base rows over their renders' pixel classes.
    if (anchor && !anchor->regions.empty()) {
        h << "<h2>Where the error sits</h2>\n<table><tr><th>method</th>";
        for (const auto& n : metrics::regionNames()) h << "<th>" << n << "</th>";
        h << "</tr>\n<tr>" << td("pixels (" + htmlEscape(m_result.anchor) + ")");
        for (const auto& c : anchor->regions) h << td(format("%.1f%%", 100 * c.pixels));
        h << "</tr>\n";
        for (const auto& r : m_result.rows) {
            if (r.setting != "base" || r.regions.empty()) continue;
            h << "<tr>" << td(htmlEscape(r.method));
            for (const auto& c : r.regions) h << td(regionCell(c));
            h << "</tr>\n";
        }
        h << "</table>\n<p>relMSE, variance of each base render over its own pixel classes (as <code>wedge compare "
             "--regions</code>): "
          << kRegionLegend << ". The relMSE here includes the reference's own noise.</p>\n";
    }

    // Images side by side, with insets and heat maps.
    auto boxes = [&]() {
        std::string s;
        for (size_t k = 0; k < m_insets.size(); ++k)
            s += "<div class=\"box b" + std::to_string(k) + "\" style=\"left:" +
                 format("%.3f", 100.0 * m_insets[k].first / m_result.width) + "%;top:" +
                 format("%.3f", 100.0 * m_insets[k].second / m_result.height) + "%;width:" +
                 format("%.3f", 100.0 * m_insetSize / m_result.width) + "%;height:" +
                 format("%.3f", 100.0 * m_insetSize / m_result.height) + "%\"></div>";
        return s;
    };
    auto insets = [&](const std::string& stem) {
        std::string s = "<div class=\"insets\">";
        for (size_t k = 0; k < m_insets.size(); ++k)
            s += "<img alt=\"inset " + std::to_string(k) + "\" src=\"" +
                 embed("images/" + stem + "-inset" + std::to_string(k) + ".png") + "\">";
        return s + "</div>";
    };
    h << "<h2>Images</h2>\n<p>Insets where the base renders err most. Heat maps: log<sub>10</sub> relative squared "
         "error, <span class=\"legend\"></span> from 10<sup>&minus;4</sup> to 1.</p>\n<div class=\"grid\">\n";
    h << "<figure><div class=\"frame\"><img alt=\"reference\" src=\"" << embed(m_referenceImage) << "\">" << boxes()
      << "</div><figcaption><b>reference</b> mc " << m_result.referenceSpp << " spp</figcaption>" << insets("reference")
      << "</figure>\n";
    for (const auto& r : m_result.rows) {
        h << "<figure><div class=\"frame\"><img alt=\"" << htmlEscape(r.method + " " + r.setting) << "\" src=\""
          << embed(r.image) << "\">" << boxes() << "</div><figcaption><b>" << htmlEscape(r.method) << "</b> "
          << settingLabel(r.setting) << ": " << format("%.1f", r.probe.sppAverage) << " spp, "
          << seconds(r.probe.seconds.get("total")) << ", relMSE " << format("%.4g", r.probe.metrics.relMse)
          << "</figcaption>" << insets(r.method + "-" + r.setting) << "<img class=\"heat\" alt=\"error\" src=\""
          << embed(r.heatmap) << "\"></figure>\n";
    }
    h << "</div>\n";
    // Below the images, which stay on the first screen.
    h << "<h2>Convergence</h2>\n<p>relMSE against total seconds, log-log, of every render this experiment made "
         "(the base renders and the searches' probes, each at the time it was first measured), in order of spp.</p>\n"
      << convergenceSvg();

    bool searched = false;
    for (const auto& r : m_result.rows) searched |= r.setting != "base";
    if (searched) {
        h << "<h2>Searches</h2>\n<table><tr><th>method</th><th>setting</th><th>target</th><th>renders (spp: relMSE, "
             "total)</th></tr>\n";
        for (const auto& r : m_result.rows) {
            if (r.setting == "base") continue;
            std::string list;
            for (const auto& p : r.probes)
                list += std::to_string(p.spp) + ": " + format("%.4g", p.metrics.relMse) + ", " +
                        seconds(p.seconds.get("total")) + "; ";
            h << "<tr>" << td(htmlEscape(r.method)) << td(settingLabel(r.setting))
              << td(r.setting == "equal_quality" ? format("relMSE %.4g", r.target) : seconds(r.target))
              << "<td style=\"text-align:left\">" << list << "</td></tr>\n";
        }
        h << "</table>\n";
    }
    h << "</body></html>\n";
    io::writeTextFile((out / "index.html").string(), h.str());
}

}  // namespace

void checkExperimentOptions(const ExperimentOptions& o) {
    const auto known = methods();
    if (o.methods.empty()) throw Error("--methods", "expected at least one method");
    for (size_t i = 0; i < o.methods.size(); ++i) {
        const auto& m = o.methods[i];
        if (std::find(known.begin(), known.end(), m) == known.end()) {
            std::string list;
            for (auto& k : known) list += (list.empty() ? "" : ", ") + k;
            throw Error("--methods", "unknown method '" + m + "' (expected some of " + list + ")");
        }
        if (std::find(o.methods.begin(), o.methods.begin() + i, m) != o.methods.begin() + i)
            throw Error("--methods", "method '" + m + "' is listed twice");
    }
    if (!o.anchor.empty() && std::find(o.methods.begin(), o.methods.end(), o.anchor) == o.methods.end())
        throw Error("--anchor " + o.anchor, "not one of --methods");
    if (o.spp <= 0) throw Error("--spp", "expected a positive number of samples per pixel");
    if (o.referenceSpp <= o.spp)
        throw Error("--reference-spp", "expected more samples than --spp (" + std::to_string(o.spp) + ")");
    if (o.maxSpp < 0) throw Error("--max-spp", "expected a non-negative number");
    if (!(o.tolerance >= 0)) throw Error("--tolerance", "expected a non-negative number");
    if (o.repeat < 1) throw Error("--repeat", "expected at least 1 render per probe");
    if (o.outDir.empty()) throw Error("--out", "expected a directory");
    if (fs::exists(o.outDir) && !fs::is_directory(o.outDir)) throw Error("--out " + o.outDir, "not a directory");
    fs::path dir = fs::absolute(o.outDir).lexically_normal();
    if (!dir.has_filename()) dir = dir.parent_path();  // "out/" names "out"
    fs::path parent = dir.parent_path();
    if (!fs::is_directory(parent)) throw Error("--out " + o.outDir, "parent directory does not exist");
    if (!o.cacheDir.empty() && fs::exists(o.cacheDir) && !fs::is_directory(o.cacheDir))
        throw Error("--cache " + o.cacheDir, "not a directory");
}

ExperimentResult runExperiment(const scene::Scene& scene, const ExperimentOptions& options) {
    ExperimentOptions o = options;
    if (o.methods.empty()) o.methods = methods();
    checkExperimentOptions(o);
    return Experiment(scene, o).run();
}

}  // namespace wedge::render
