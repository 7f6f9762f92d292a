// The flags that choose a render's method and options, and their mapping to
// render::RenderOptions, written once: `wedge render` registers all of them, `wedge experiment`
// the method options, and the Python module (python/wedge_module.cpp) parses its keywords with
// them (render(scene, max_extra_spp=32) is --max-extra-spp=32), so all three accept the same
// names, check them alike and report the same message. A new RenderOptions field gets its flag in
// addMethodFlags() and so reaches all three.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "render/renderer.h"
#include "scene/scene_desc.h"

namespace wedge::app {

struct RenderFlags {
    std::string resolution;  // "WxH"; empty: the scene's
    int threads = 0;         // 0: all cores
    int spp = 0;             // 0: the method's default
    long long seed = -1;     // -1: the scene's render.seed
    render::RenderOptions options;

    /// The options with --spp and --seed applied; throws wedge::Error if --aov is no directory.
    render::RenderOptions renderOptions() const;
    /// Applies --resolution to the scene description.
    void applyTo(scene::SceneDesc& desc) const;
};

/// --method, --spp, --seed, --threads, --resolution, --aov, the method options and --quiet.
void addRenderFlags(CLI::App& cmd, RenderFlags& flags);
/// The method options: every flag that sets a RenderOptions field other than the method, the
/// sample count, the seed, --aov and --quiet.
void addMethodFlags(CLI::App& cmd, render::RenderOptions& options);

}  // namespace wedge::app
