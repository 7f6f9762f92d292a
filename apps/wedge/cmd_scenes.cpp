// wedge scenes: the built-in scenes, with their descriptions and attributions.
#include <cstdio>

#include "apps/wedge/commands.h"
#include "scene/scene_loader.h"

namespace wedge::app {

void registerScenes(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand("scenes", "List the built-in scenes");
    cmd->callback([] {
        for (const auto& s : scene::builtinScenes()) {
            std::printf("%-12s %s\n", s.name.c_str(), s.description.c_str());
            if (!s.attribution.empty()) std::printf("%-12s   %s\n", "", s.attribution.c_str());
            std::printf("%-12s   %s\n", "", s.file.c_str());
        }
    });
}

}  // namespace wedge::app
