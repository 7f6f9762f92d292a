// The sampling stage's ceiling (issue 29): the rays one MC render asks Embree for, recorded by
// kind (render::PathSampler::logRays), traced again by Embree alone, with no shading, no random
// numbers and no bookkeeping. Each kind is traced five ways: one ray at a time (rtcIntersect1 /
// rtcOccluded1), in 16-wide packets (rtcIntersect16 / rtcOccluded16: one pixel's batch), in
// 8-wide packets (AVX2's width), and as streams of 256 (rtcIntersect1M / rtcOccluded1M: 16
// pixels' samples), incoherent and coherent (Embree then packs the stream into packets itself). BM_EmbreeCeiling/wedge traces every kind
// the way the sampler does, BM_EmbreeCeiling/best each kind its fastest way: their Mrays/s over
// BM_Sampling's is the fraction of Embree's own speed that wedge's sampling reaches.
// Run: build/bench/wedge_bench --benchmark_filter='Embree|Sampling/sponza'
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>

#include "render/camera.h"
#include "render/path_sampler.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"

using namespace wedge;

namespace {

using Kind = scene::RayLog::Kind;
enum class Mode { kSingle, kPacket, kStream, kCoherentStream, kPacket8 };

struct Recorded {
    std::unique_ptr<scene::Scene> scene;
    scene::RayLog log;
};

/// Sponza at 256x256, 16 spp, the MC render's path samples (no spans), traced once and kept.
const Recorded& recorded() {
    static const Recorded r = [] {
        Recorded out;
        scene::SceneDesc d = scene::loadScene("sponza");
        d.camera.width = 256;
        d.camera.height = 256;
        out.scene = std::make_unique<scene::Scene>(std::move(d));
        render::Camera camera(out.scene->desc().camera);
        render::PathSampler sampler(*out.scene, camera, out.scene->desc().render.indirect, 1);
        sampler.logRays(&out.log);
        render::TracedSample batch[16];
        for (int y = 0; y < camera.height(); ++y)
            for (int x = 0; x < camera.width(); ++x) sampler.traceBatch(x, y, 0, 16, false, batch);
        return out;
    }();
    return r;
}

void fill(const scene::RaySegment& r, RTCRay& ray) {
    ray.org_x = r.org.x; ray.org_y = r.org.y; ray.org_z = r.org.z;
    ray.dir_x = r.dir.x; ray.dir_y = r.dir.y; ray.dir_z = r.dir.z;
    ray.tnear = 0.f;
    ray.tfar = r.tFar;
    ray.time = r.time;
    ray.mask = 0xffffffffu;
    ray.id = 0;
    ray.flags = 0;
}

/// One packet's query, for Embree's RTCRayHit8 and RTCRayHit16.
void tracePacket(int* valid, RTCScene scene, RTCIntersectContext& ctx, RTCRayHit8& rh, bool occlusion) {
    if (occlusion) rtcOccluded8(valid, scene, &ctx, &rh.ray);
    else rtcIntersect8(valid, scene, &ctx, &rh);
}
void tracePacket(int* valid, RTCScene scene, RTCIntersectContext& ctx, RTCRayHit16& rh, bool occlusion) {
    if (occlusion) rtcOccluded16(valid, scene, &ctx, &rh.ray);
    else rtcIntersect16(valid, scene, &ctx, &rh);
}
/// Every ray in packets of W (the last one padded with inactive lanes); returns how many hit.
template <class RayHitN, size_t W>
size_t tracePackets(RTCScene scene, RTCIntersectContext& ctx, const std::vector<scene::RaySegment>& rays, bool occlusion) {
    alignas(64) RayHitN rh;
    alignas(64) int valid[W];
    size_t hits = 0;
    for (size_t b = 0; b < rays.size(); b += W) {
        const size_t n = std::min(W, rays.size() - b);
        for (size_t i = 0; i < W; ++i) {
            const auto& r = rays[b + std::min(i, n - 1)];
            valid[i] = i < n ? -1 : 0;
            rh.ray.org_x[i] = r.org.x; rh.ray.org_y[i] = r.org.y; rh.ray.org_z[i] = r.org.z;
            rh.ray.dir_x[i] = r.dir.x; rh.ray.dir_y[i] = r.dir.y; rh.ray.dir_z[i] = r.dir.z;
            rh.ray.tnear[i] = 0.f;
            rh.ray.tfar[i] = r.tFar;
            rh.ray.time[i] = r.time;
            rh.ray.mask[i] = 0xffffffffu;
            rh.ray.id[i] = unsigned(i);
            rh.ray.flags[i] = 0;
            rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
        }
        tracePacket(valid, scene, ctx, rh, occlusion);
        for (size_t i = 0; i < n; ++i) hits += occlusion ? rh.ray.tfar[i] < 0 : rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
    }
    return hits;
}

/// Traces every ray of `kind` once in `mode`; returns how many hit (so nothing is optimised away).
size_t traceAll(RTCScene scene, const std::vector<scene::RaySegment>& rays, Kind kind, Mode mode) {
    const bool occlusion = kind == Kind::kShadow || kind == Kind::kBounceShadow;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = kind == Kind::kPrimary || mode == Mode::kCoherentStream ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT
                                                                         : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    size_t hits = 0;
    if (mode == Mode::kSingle) {
        for (const auto& r : rays) {
            RTCRayHit rh;
            fill(r, rh.ray);
            if (occlusion) {
                rtcOccluded1(scene, &ctx, &rh.ray);
                hits += rh.ray.tfar < 0;
            } else {
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(scene, &ctx, &rh);
                hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
            }
        }
    } else if (mode == Mode::kPacket) {
        hits += tracePackets<RTCRayHit16, 16>(scene, ctx, rays, occlusion);
    } else if (mode == Mode::kPacket8) {
        hits += tracePackets<RTCRayHit8, 8>(scene, ctx, rays, occlusion);
    } else {
        constexpr size_t kStream = 256;
        std::vector<RTCRayHit> rh(kStream);
        for (size_t b = 0; b < rays.size(); b += kStream) {
            const size_t n = std::min(kStream, rays.size() - b);
            for (size_t i = 0; i < n; ++i) {
                fill(rays[b + i], rh[i].ray);
                rh[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rh[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            }
            if (occlusion) {
                rtcOccluded1M(scene, &ctx, &rh[0].ray, unsigned(n), sizeof(RTCRayHit));
                for (size_t i = 0; i < n; ++i) hits += rh[i].ray.tfar < 0;
            } else {
                rtcIntersect1M(scene, &ctx, rh.data(), unsigned(n), sizeof(RTCRayHit));
                for (size_t i = 0; i < n; ++i) hits += rh[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
            }
        }
    }
    return hits;
}

void BM_EmbreeAlone(benchmark::State& state) {
    const Recorded& r = recorded();
    const Kind kind = Kind(state.range(0));
    const Mode mode = Mode(state.range(1));
    const auto& rays = r.log.rays[kind];
    for (auto _ : state) benchmark::DoNotOptimize(traceAll(r.scene->embree(), rays, kind, mode));
    state.counters["Mrays/s"] = benchmark::Counter(double(rays.size()) * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["rays"] = double(rays.size());
    static const char* kinds[] = {"primary", "shadow", "bounce", "bounce-shadow"};
    static const char* modes[] = {"single", "packet16", "stream256", "stream256-coherent", "packet8"};
    state.SetLabel(std::string(kinds[kind]) + " " + modes[int(mode)]);
}
BENCHMARK(BM_EmbreeAlone)->ArgsProduct({{0, 1, 2, 3}, {0, 1, 2, 3, 4}})->Unit(benchmark::kMillisecond)->MinTime(1.0);

/// All kinds together: arg 0 the sampler's modes (primary rays in one pixel's packets, the
/// others in streams of up to 256), arg 1 each
/// kind in its fastest mode, chosen by timing each (fastest of three passes) before the run.
void BM_EmbreeCeiling(benchmark::State& state) {
    const Recorded& r = recorded();
    Mode modes[scene::RayLog::kKinds] = {Mode::kPacket, Mode::kStream, Mode::kStream, Mode::kStream};
    std::string label = "wedge's modes";
    if (state.range(0) == 1) {
        label = "fastest:";
        for (int k = 0; k < scene::RayLog::kKinds; ++k) {
            double fastest = 1e30;
            for (Mode m : {Mode::kSingle, Mode::kPacket, Mode::kStream, Mode::kCoherentStream, Mode::kPacket8})
                for (int pass = 0; pass < 3; ++pass) {
                    const auto t0 = std::chrono::steady_clock::now();
                    benchmark::DoNotOptimize(traceAll(r.scene->embree(), r.log.rays[k], Kind(k), m));
                    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                    if (s < fastest) fastest = s, modes[k] = m;
                }
            static const char* names[] = {" single", " packet16", " stream256", " stream256-coherent", " packet8"};
            label += names[int(modes[k])];
        }
    }
    size_t total = 0;
    for (int k = 0; k < scene::RayLog::kKinds; ++k) total += r.log.rays[k].size();
    for (auto _ : state)
        for (int k = 0; k < scene::RayLog::kKinds; ++k)
            benchmark::DoNotOptimize(traceAll(r.scene->embree(), r.log.rays[k], Kind(k), modes[k]));
    state.counters["Mrays/s"] = benchmark::Counter(double(total) * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
    state.SetLabel(label);
}
BENCHMARK(BM_EmbreeCeiling)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace

