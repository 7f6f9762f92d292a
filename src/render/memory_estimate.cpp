#include "render/memory_estimate.h"

#include <algorithm>

#include "core/light_field.h"
#include "core/memory_limit.h"
#include "core/parallel.h"
#include "filter/layers.h"

namespace wedge::render {

namespace {

/// The peak memory of a render per pixel, measured (/usr/bin/time, cornell at 512x512 less
/// 128x128, default options, no lens: the layers off): mc 0.67 KB, atrous 0.66, aaf 0.72,
/// maaf 1.0. Rounded up.
constexpr uint64_t kRenderBytesPerPixel = 1200;
/// MAAF's --maaf-keep-records keeps every initial sample: 64 bytes each (SampleRecord).
constexpr uint64_t kRecordBytes = 64;
/// The layers keep every sample (core/light_field.h) until they reconstruct: 24 bytes each (28
/// where an object turns: keepsSags),
/// within the 1200 a pixel the rest of their stage needs (measured, cornell's lens, mc at 32 spp,
/// 256x256: 786 bytes a pixel with --layers off, 1647 with them on, 1968 estimated).
constexpr uint64_t kLightFieldSampleBytes = sizeof(LightFieldSample);

}  // namespace

uint64_t bufferBytes(int width, int height) { return uint64_t(std::max(0, width)) * uint64_t(std::max(0, height)) * kRenderBytesPerPixel; }

RenderMemory renderMemory(const scene::SceneDesc& desc, const RenderOptions& options) {
    const uint64_t pixels = uint64_t(desc.camera.width) * uint64_t(desc.camera.height);
    const int spp = renderSpp(desc, options);
    uint64_t perPixel = kRenderBytesPerPixel, threadBytes = 0;
    RenderMemory m;
    m.what = "a " + std::to_string(desc.camera.width) + "x" + std::to_string(desc.camera.height) + " " + options.method +
             " render";
    if (options.method == "maaf" && options.maafKeepRecords) {
        perPixel += uint64_t(spp) * kRecordBytes;
        m.what += " keeping its " + std::to_string(spp) + " sample records a pixel (--maaf-keep-records)";
    }
    // At least the initial samples; the adaptive ones are checked as they are added.
    if (spp > 0 && keepsLightField(desc, options, spp)) {
        perPixel += uint64_t(spp) * (kLightFieldSampleBytes + (keepsSags(desc) ? sizeof(LightFieldSag) : 0)) +
                    3 * sizeof(float);  // and LightFieldSamples::bentReach and the emissions
        m.what += " keeping its " + std::to_string(spp) + " samples a pixel for the layers (--layers)";
        // ... and each thread the samples one tile gathers, a tile and its widest margins. (Not
        // the tiles' grids, which depend on the scene: the stage reserves them tile by tile from
        // what the limit leaves, filter::LayerOptions::memoryHeld; docs/layers.md, "The grids'
        // budget".)
        threadBytes = filter::gatheredBytesPerThread(desc.camera.width, desc.camera.height, spp);
    }
    m.bytes = pixels * perPixel + uint64_t(std::max(1, ThreadLimit::current())) * threadBytes;
    return m;
}

void checkRenderMemory(const scene::SceneDesc& desc, const RenderOptions& options) {
    const RenderMemory m = renderMemory(desc, options);
    checkMemory(desc.file, m.what, m.bytes);
}

}  // namespace wedge::render
