// JSON stats, the sweep's CSV and JSON, and its plot (Vaidyanathan et al. 2012, Fig. 8).
#include "raster/raster_report.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "io/plot.h"

namespace wedge::raster {

namespace {

nlohmann::json countsJson(const CacheCounts& c) {
    return {{"lookups", c.lookups},
            {"hits", c.hits},
            {"misses", c.misses},
            {"evictions", c.evictions},
            {"shaded_quads", c.shadedQuads},
            {"shader_invocations", c.shaderInvocations}};
}

}  // namespace

nlohmann::json statsJson(const RasterStats& s, const std::string& sceneName) {
    nlohmann::json j;
    j["scene"] = sceneName;
    j["shading"] = shadingModeName(s.shading);
    j["cache_entries"] = s.cacheEntries;
    j["resolution"] = {s.width, s.height};
    j["spp"] = s.spp;
    j["triangles"] = s.triangles;
    j["split_edge_px"] = s.maxTriangleEdge;
    j["culled_triangles"] = s.culledTriangles;
    j["split_budget_reached"] = s.splitBudgetReached;
    j["near_plane_fallback_triangles"] = s.fallbackTriangles;
    j["samples"] = s.samples;
    j["visible_samples"] = s.visibleSamples;
    j["samples_tested"] = s.sampleTests;
    j["bound_rejects"] = s.boundRejects;
    j["near_plane_fallback_samples"] = s.fallbackSamples;
    j["shaded_quads"] = s.cache.shadedQuads;
    j["shader_invocations"] = s.cache.shaderInvocations;
    j["lookups"] = s.cache.lookups;
    j["hits"] = s.cache.hits;
    j["misses"] = s.cache.misses;
    j["evictions"] = s.cache.evictions;
    j["hit_rate"] = s.cache.lookups ? double(s.cache.hits) / double(s.cache.lookups) : 0.0;
    j["shaded_quads_unbounded_cache"] = s.quadsUnboundedCache;
    j["shaded_quads_per_object"] = s.cache.shadedQuadsPerObject;
    j["mean_grid_spacing_px"] = {{"along_motion", s.meanSpacingMu}, {"across_motion", s.meanSpacingPerp}};
    if (s.relMse >= 0) {
        j["rel_mse_vs_reference"] = s.relMse;
        j["psnr_vs_reference"] = s.psnr;
    } else {
        j["rel_mse_vs_reference"] = nullptr;
    }
    if (s.relMseTruth >= 0) {
        j["rel_mse_vs_truth"] = s.relMseTruth;
        j["truth_seconds"] = s.truthSeconds;
    }
    j["seconds"] = s.seconds;
    j["reference_seconds"] = s.referenceSeconds;
    nlohmann::json stages = nlohmann::json::object();
    for (auto& [name, sec] : s.stages.stages()) stages[name] = sec;
    j["stage_seconds"] = stages;
    return j;
}

std::string sweepCsv(const SweepResult& sweep) {
    std::ostringstream out;
    out << "cache_entries,ds_shaded_quads,ds_hits,ds_misses,aas_shaded_quads,aas_hits,aas_misses,aas_over_ds\n";
    for (const SweepRow& r : sweep.rows) {
        double ratio = r.ds.shadedQuads ? double(r.aas.shadedQuads) / double(r.ds.shadedQuads) : 0.0;
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.4f", ratio);
        out << r.cacheEntries << ',' << r.ds.shadedQuads << ',' << r.ds.hits << ',' << r.ds.misses << ','
            << r.aas.shadedQuads << ',' << r.aas.hits << ',' << r.aas.misses << ',' << buf << '\n';
    }
    return out.str();
}

nlohmann::json sweepJson(const SweepResult& sweep, const std::string& sceneName) {
    nlohmann::json j;
    j["scene"] = sceneName;
    nlohmann::json rows = nlohmann::json::array();
    for (const SweepRow& r : sweep.rows)
        rows.push_back({{"cache_entries", r.cacheEntries}, {"ds", countsJson(r.ds)}, {"aas", countsJson(r.aas)}});
    j["rows"] = rows;
    j["ds"] = statsJson(sweep.ds, sceneName);
    j["aas"] = statsJson(sweep.aas, sceneName);
    j["rel_mse_aas_vs_ds"] = sweep.aasVsDsRelMse;
    j["psnr_aas_vs_ds"] = sweep.aasVsDsPsnr;
    if (sweep.referenceRelMseTruth >= 0) j["rel_mse_reference_vs_truth"] = sweep.referenceRelMseTruth;
    j["seconds"] = sweep.seconds;
    return j;
}

Image3f sweepPlot(const SweepResult& sweep, const std::string& sceneName) {
    io::LinePlot plot;
    std::string name = sceneName;
    if (auto slash = name.find_last_of('/'); slash != std::string::npos) name = name.substr(slash + 1);
    plot.title = "SHADED QUADS VS CACHE SIZE: " + name;
    plot.xLabel = "CACHE ENTRIES";
    plot.yLabel = "SHADED QUADS";
    plot.logX = plot.logY = true;
    const Vec3f blue = io::displayColor(0.12f, 0.35f, 0.75f), orange = io::displayColor(0.90f, 0.45f, 0.05f);
    io::PlotSeries ds{"DS", {}, {}, blue, true, 0}, aas{"AAS", {}, {}, orange, true, 2};
    io::PlotSeries dsInf{"DS, UNBOUNDED CACHE", {}, {}, blue * 0.7f + Vec3f(0.3f), true, -1, 6};
    io::PlotSeries aasInf{"AAS, UNBOUNDED CACHE", {}, {}, orange * 0.7f + Vec3f(0.3f), true, -1, 6};
    double yLo = kInf, yHi = 0;
    for (const SweepRow& r : sweep.rows) {
        double k = double(r.cacheEntries);
        ds.xs.push_back(k);
        ds.ys.push_back(double(r.ds.shadedQuads));
        aas.xs.push_back(k);
        aas.ys.push_back(double(r.aas.shadedQuads));
        plot.xTicks.push_back(k);
        yLo = std::min({yLo, double(r.ds.shadedQuads), double(r.aas.shadedQuads)});
        yHi = std::max({yHi, double(r.ds.shadedQuads), double(r.aas.shadedQuads)});
    }
    if (sweep.rows.empty()) return io::renderPlot(plot, 760, 500);
    double k0 = double(sweep.rows.front().cacheEntries), k1 = double(sweep.rows.back().cacheEntries);
    plot.xMin = std::min(k0, k1) / 1.3;
    plot.xMax = std::max(k0, k1) * 1.3;
    dsInf.xs = aasInf.xs = {plot.xMin, plot.xMax};
    dsInf.ys = {double(sweep.ds.quadsUnboundedCache), double(sweep.ds.quadsUnboundedCache)};
    aasInf.ys = {double(sweep.aas.quadsUnboundedCache), double(sweep.aas.quadsUnboundedCache)};
    yLo = std::min({yLo, dsInf.ys[0], aasInf.ys[0]});
    plot.yMin = std::max(1.0, yLo / 1.5);
    plot.yMax = yHi * 1.5;
    plot.series = {ds, aas, dsInf, aasInf};
    return io::renderPlot(plot, 760, 500);
}

}  // namespace wedge::raster
