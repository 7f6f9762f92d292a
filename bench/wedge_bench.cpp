// Google Benchmark for the hot paths: sample generation, path sampling (rays/s on a built-in
// scene), the image-space filters (AAF, MAAF accumulation and filter) on rendered buffers,
// loading a large OBJ (the text check and the whole load), and the lights' closed-form irradiance.
// Run: make bench  (or build/bench/wedge_bench --benchmark_filter=...).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

#include "core/sampler.h"
#include "filter/aaf.h"
#include "filter/maaf.h"
#include "io/text_file.h"
#include "render/renderer.h"
#include "scene/light_irradiance.h"
#include "scene/obj_check.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"

using namespace wedge;

namespace {

std::unique_ptr<scene::Scene> loadScene(const std::string& name, int w, int h) {
    scene::SceneDesc d = scene::loadScene(name);
    d.camera.width = w;
    d.camera.height = h;
    return std::make_unique<scene::Scene>(std::move(d));
}

void BM_PixelSampler(benchmark::State& state) {
    PixelSampler s(1, 12345);
    uint32_t i = 0;
    for (auto _ : state) {
        Vec2f v = s.get2D(i++ & 1023, 3);
        benchmark::DoNotOptimize(v);
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PixelSampler);

/// Monte Carlo sampling of a built-in scene at 256x256, 16 spp; reports rays per second.
void BM_Sampling(benchmark::State& state, const char* sceneName) {
    auto scene = loadScene(sceneName, 256, 256);
    render::RenderOptions o;
    o.quiet = true;
    o.spp = 16;
    uint64_t rays = 0;
    double seconds = 0;
    for (auto _ : state) {
        render::RenderResult r = render::render(*scene, o);
        rays += r.rays;
        seconds += r.seconds.get("sampling");
    }
    state.counters["Mrays/s"] = double(rays) / seconds * 1e-6;
}
BENCHMARK_CAPTURE(BM_Sampling, cornell, "cornell")->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Sampling, sponza, "sponza")->Unit(benchmark::kMillisecond)->Iterations(3);

/// A whole method on cornell at 256x256; per-stage seconds as counters.
void BM_Method(benchmark::State& state, const char* method) {
    auto scene = loadScene("cornell", 256, 256);
    render::RenderOptions o;
    o.quiet = true;
    o.method = method;
    o.spp = 16;
    render::RenderResult r;
    for (auto _ : state) r = render::render(*scene, o);
    for (auto& [stage, s] : r.seconds.stages()) state.counters[stage] = s;
    state.counters["spp"] = r.sppAverage;
}
BENCHMARK_CAPTURE(BM_Method, mc, "mc")->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Method, aaf, "aaf")->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Method, maaf, "maaf")->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Method, atrous, "atrous")->Unit(benchmark::kMillisecond)->Iterations(3);

/// Frame buffers and filter frames of a W x H plane seen head-on, one world unit per pixel.
void planeBuffers(FrameBuffers& fb, Image<filter::AxisFrame>& frames) {
    for (int y = 0; y < fb.height; ++y)
        for (int x = 0; x < fb.width; ++x) {
            size_t i = size_t(y) * fb.width + x;
            fb.object[i] = 0;
            fb.normal[i] = {0, 0, 1};
            fb.position[i] = {float(x), float(y), 0};
            fb.footprint[i] = 1;
            fb.coverage[i] = 1;
            frames[i] = {{{1, 0, 0}, {0, 1, 0}}, {1, 1}};
        }
}

/// The AAF separable filter alone on a 512x512 plane with spatially varying widths.
void BM_AafFilter(benchmark::State& state) {
    const int W = 512, H = 512;
    FrameBuffers fb(W, H);
    Image<filter::AxisFrame> frames(W, H);
    planeBuffers(fb, frames);
    Image3f signal(W, H);
    Image1f omega(W, H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            size_t i = size_t(y) * W + x;
            signal[i] = Vec3f(float(hash32(uint32_t(i)) & 255) / 255.f);
            omega[i] = 0.1f + 0.3f * float((x / 64 + y / 64) % 3);
        }
    for (auto _ : state) benchmark::DoNotOptimize(filter::aafFilter(signal, omega, fb, frames, filter::AafOptions()));
    state.SetItemsProcessed(state.iterations() * W * H);
}
BENCHMARK(BM_AafFilter)->Unit(benchmark::kMillisecond);

/// MAAF's image-space filter alone (eq. 21 on both axes, filter/maaf.h) on a 512x512 plane:
/// central-only pixels with, every 64 columns, a 16-column band of pixels with 3 component
/// pairs on both axes (about the share of outer-component pixels in the 512x512 scenes), each
/// pixel's accumulations (rgb and weight) from 4 samples.
void BM_MaafFilter(benchmark::State& state) {
    const int W = 512, H = 512, pairs = 3;
    FrameBuffers fb(W, H);
    Image<filter::AxisFrame> frames(W, H);
    planeBuffers(fb, frames);
    Image<filter::MaafPixel> stored(W, H);
    filter::MaafOptions o;
    o.pairs = pairs;
    // buildAxis's widths on this plane (one world unit per pixel): the Fourier std times the
    // spatial scale, no narrower than maxRadius pixels.
    const float sxFloor = 1.f / float(o.maxRadius);
    filter::WedgeShape wedge;
    wedge.omegaYMax = 0.8;
    wedge.sMin = 0.6;
    wedge.sMax = 1.5;
    const std::vector<filter::MaafComponent> central = filter::maafComponents(1, wedge),
                                             outer = filter::maafComponents(pairs, wedge);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            size_t i = size_t(y) * W + x;
            const auto& comps = x % 64 < 16 ? outer : central;
            filter::MaafPixel m{};
            for (int k = 0; k < 2; ++k) {
                m.axis[k].pairs = int(comps.size());
                for (const auto& c : comps) {
                    m.axis[k].cx[c.p] = float(c.cx);
                    m.axis[k].sx[c.p] = std::max(float(c.sx) * o.spatialScale, sxFloor);
                    m.axis[k].weight[c.p] = float((c.p ? 2 : 1) * c.mu);
                    m.axis[k].cy[c.p] = float(c.cy);
                }
            }
            stored[i] = m;
        }
    filter::MaafEffect effect(stored);
    filter::MaafAccumulator acc(effect, pairs, 3);
    for (size_t i = 0; i < stored.size(); ++i) {
        for (uint32_t s = 0; s < 4; ++s) {
            auto rnd = [&](uint32_t j) { return float(hash32(uint32_t(i) * 16 + s * 4 + j) & 0xffff) / 65535.f; };
            const float value[3] = {rnd(0), rnd(1), rnd(2)}, yy[2] = {2 * rnd(3) - 1, 2 * rnd(0) - 1}, u[2] = {0, 0};
            acc.add(i, value, 1.f, yy, u, stored[i]);
        }
        acc.scale(i, 0.25f);
    }
    const Image3f fallback(W, H);
    for (auto _ : state) benchmark::DoNotOptimize(acc.filter(effect, fb, frames, fallback, o));
    state.SetItemsProcessed(state.iterations() * W * H);
}
BENCHMARK(BM_MaafFilter)->Unit(benchmark::kMillisecond);

/// The OBJ text check (scene/obj_check.h) on sponza's 26 MB, which runs beside tinyobjloader's
/// parse; bytes per second.
void BM_ObjCheck(benchmark::State& state) {
    const std::string text = io::readTextFile(scene::scenesDirectory() + "/sponza/sponza.obj");
    for (auto _ : state) benchmark::DoNotOptimize(scene::checkObjText(text, "bench", "sponza.obj"));
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(text.size()));
}
BENCHMARK(BM_ObjCheck)->Unit(benchmark::kMillisecond);

/// Loading sponza (the checked parse, materials, normals) as a scene description.
void BM_LoadSponza(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(scene::loadScene("sponza").triangleCount());
}
BENCHMARK(BM_LoadSponza)->Unit(benchmark::kMillisecond)->Iterations(3);

/// The closed-form irradiance at 1024 receivers under a round lamp of state.range(0) triangles
/// (a fan), light by light (arg 1 = 0) or over the group's outline (scene::LightIrradiance).
void BM_LampIrradiance(benchmark::State& state) {
    const int n = int(state.range(0));
    std::vector<scene::AreaLight> lamp;
    const Vec3f centre(0.f, 2.f, 0.f);
    auto rim = [&](int i) { return Vec3f(0.4f * std::cos(2 * kPi * i / n), 0.f, 0.4f * std::sin(2 * kPi * i / n)); };
    for (int i = 0; i < n; ++i) lamp.push_back({centre, rim(i), rim(i + 1), Vec3f(5.f), scene::AreaLight::Shape::Triangle});
    const scene::LightIrradiance grouped(lamp);
    const bool outline = state.range(1) != 0;
    for (auto _ : state) {
        Vec3f sum(0.f);
        for (int k = 0; k < 1024; ++k) {
            const Vec3f x(float(k % 32) / 16.f - 1.f, 0.f, float(k / 32) / 16.f - 1.f), up(0.f, 1.f, 0.f);
            sum += outline ? grouped(x, up) : scene::unoccludedIrradiance(lamp, x, up);
        }
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(state.iterations() * 1024);
}
BENCHMARK(BM_LampIrradiance)->ArgsProduct({{12, 250}, {0, 1}})->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
