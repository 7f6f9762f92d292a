// What `wedge raster` writes besides images: the --stats JSON of one render and, for a cache-size
// sweep, a CSV table, a JSON summary and the plot of shaded quads against cache entries for DS and
// AAS (the analogue of Vaidyanathan et al. 2012, Fig. 8).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "raster/raster_renderer.h"

namespace wedge::raster {

nlohmann::json statsJson(const RasterStats& stats, const std::string& sceneName);
/// One row per cache size: counts for DS and AAS and the AAS / DS ratio of shaded quads.
std::string sweepCsv(const SweepResult& sweep);
nlohmann::json sweepJson(const SweepResult& sweep, const std::string& sceneName);
Image3f sweepPlot(const SweepResult& sweep, const std::string& sceneName);

}  // namespace wedge::raster
