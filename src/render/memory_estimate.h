// What a render will hold at its peak, estimated from the scene's resolution and the options
// before anything is built, so that a render too large for the machine is a clear error at once
// (core/memory_limit.h) instead of an out-of-memory kill minutes later. Used by `wedge render`
// and, for each render it keeps images of, by `wedge experiment`.
#pragma once

#include <cstdint>
#include <string>

#include "render/renderer.h"
#include "scene/scene_desc.h"

namespace wedge::render {

/// The peak bytes of render(scene, options) for this scene description, and what it is made of
/// ("a 512x512 mc render" and, where the layers keep their samples, "keeping 16 samples a pixel").
struct RenderMemory {
    uint64_t bytes = 0;
    std::string what;
};
RenderMemory renderMemory(const scene::SceneDesc& desc, const RenderOptions& options);

/// The render's buffers beside the samples the layers keep, for a width x height image: what
/// renderMemory counts a pixel (the layers' stage takes its grids' budget from the memory limit
/// less these and the kept samples: filter::LayerOptions::memoryHeld).
uint64_t bufferBytes(int width, int height);

/// Throws wedge::Error naming the scene file when renderMemory's bytes exceed the memory limit.
void checkRenderMemory(const scene::SceneDesc& desc, const RenderOptions& options);

}  // namespace wedge::render
