// Each subcommand registers itself on the CLI11 app from its own file; main() only parses and
// maps errors to exit codes (bad input: 2).
#pragma once

#include <CLI/CLI.hpp>

namespace wedge::app {

void registerRender(CLI::App& app);
void registerScenes(CLI::App& app);
void registerCompare(CLI::App& app);
void registerExperiment(CLI::App& app);
void registerAnalyze(CLI::App& app);
void registerRaster(CLI::App& app);

}  // namespace wedge::app
