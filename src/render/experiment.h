// `wedge experiment`: renders a scene with several methods against a Monte Carlo reference and
// compares them the way the filtering papers do (MAAF, Wu et al. 2017, Sec. 7 and Fig. 12): at
// the same base sample count, at equal quality (the spp at which a method reaches the anchor
// method's relMSE) and at equal time (the spp at which it takes the anchor's time). Both are
// found by bisection over the method's integer --spp inside a bracket that a power-law guess
// (relMSE ~ 1/spp, time ~ a + b spp) and doubling establish. Writes DIR/results.json (a list of
// rows), DIR/index.html (self-contained: images as base64 PNG, insets, heat maps, the Fig. 12
// style table, the convergence plot of its renders as inline SVG), DIR/table.md and the images under DIR/images/. Times are wall-clock stage times
// of render(); each probe keeps the fastest of --repeat renders, and the rows of the table are
// re-timed --repeat more times at the end (the fastest counts), since a shared machine's load
// comes in bursts.
//
// The reference is plain MC at --reference-spp with an independent seed (a hash of the seed), so
// the methods' errors are not correlated with it; it is cached under the cache directory, keyed
// by scene name, a hash of the scene file, resolution, spp and seed. It is rendered as two
// independent halves, whose difference estimates its own noise (metrics::referenceNoise): every
// relMSE measured against it carries that much on top of the method's error against the truth,
// which pulls all ratios towards 1. Rows report the net relMSE (relMSE - noise) and the net
// efficiency beside the measured ones.
//
// Each base row is rendered once more with another seed (not timed): half the two renders'
// relative squared difference is the variance part of the row's relMSE (metrics::seedVariance),
// and the net relMSE minus it the squared bias, so a row says whether a method errs by noise
// (too few samples, too narrow a filter) or by bias (too wide a filter).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "core/timer.h"
#include "metrics/metrics.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace wedge::render {

struct ExperimentOptions {
    std::string sceneName;             // how the user named the scene (built-in name or path)
    std::vector<std::string> methods;  // report order; empty: every method render() knows
    int spp = 4;                       // the base sample count of every method
    int referenceSpp = 1024;
    std::optional<uint32_t> seed;      // default: the scene's render.seed
    std::string outDir;
    std::string cacheDir;              // default: <outDir>/cache
    std::string anchor;                // default: maaf, else aaf, else atrous, else the first method
    bool equalTime = false, equalQuality = false;
    bool quiet = false;
    // Over MPI ranks (base.distribution, docs/mpi.md) every rank runs the experiment, each render
    // split over them; the others than rank 0 neither write files nor print (writes = false).
    bool writes = true;
    int maxSpp = 0;                    // search cap; 0: referenceSpp / 4
    double tolerance = 0.1;            // searches stop when hi <= lo (1 + tolerance) or hi - lo <= 1
    int repeat = 1;                    // renders per probe; the fastest one's times count
    RenderOptions base;                // method parameters (atrous sigmas, maaf components, ...)
    std::string commandLine;           // shown in the report
};

/// One render of a search or a row.
struct ExperimentProbe {
    int spp = 0;
    double sppAverage = 0;
    StageTimes seconds;
    metrics::Metrics metrics;
    Image3f color;
    Image<uint8_t> regions;  // each pixel's class (metrics::regionClasses) from the render's own planes
    bool retimed = false;  // the final re-timing of the rows has run
};

struct ExperimentRow {
    std::string method;
    std::string setting;  // "base", "equal_quality" or "equal_time"
    ExperimentProbe probe;
    double efficiency = 0;     // 1 / (relMSE * total seconds)
    double netEfficiency = 0;  // 1 / ((relMSE - reference noise) * total seconds); 0 if not positive
    // Base rows: the variance part of relMSE (from a render with another seed); the squared bias
    // is the net relMSE minus it. Negative: not measured (the other settings' rows).
    double variance = -1;
    // Base rows: relMSE and variance split over the render's pixel classes (`wedge compare --regions`).
    std::vector<metrics::RegionError> regions;
    // Searches: the target (relMSE or seconds), whether it was reached within the cap, and every
    // render the search made, in order.
    double target = 0;
    bool reached = true;
    std::vector<ExperimentProbe> probes;
    std::string image, heatmap;  // paths relative to outDir
};

struct ExperimentResult {
    std::string scene;
    int width = 0, height = 0;
    uint32_t seed = 0, referenceSeed = 0;
    int referenceSpp = 0;
    double referenceSeconds = 0;
    double referenceNoise = 0;  // the reference's own relMSE against the truth (estimated)
    bool referenceCached = false;
    std::string anchor;
    std::vector<std::string> skipped;  // requested methods that are not available yet
    std::vector<ExperimentRow> rows;
};

/// Validates the options (wedge::Error on bad input) before any rendering.
void checkExperimentOptions(const ExperimentOptions& options);

/// Runs the experiment and writes every output file.
ExperimentResult runExperiment(const scene::Scene& scene, const ExperimentOptions& options);

/// The bracket a boundary search ends with: above(lo) is false (lo = 0: nothing below was
/// false, i.e. above(1) holds) and above(hi) is true (hi = cap + 1: above(cap) is false).
struct SearchBracket {
    int lo = 0, hi = 0;
};

/// Brackets the smallest s in [1, cap] with above(s) true, for a predicate that is false below
/// some s and true from there on. `start` has been evaluated already (`startAbove`); `guess` is a
/// model's estimate of the answer. Aims a little past the guess, doubles (or halves) until the
/// bracket closes, then bisects at the geometric midpoint until hi <= lo (1 + tolerance) or
/// hi - lo <= 1. Every s it evaluates lies in [1, cap].
template <class Above>
SearchBracket searchBoundary(Above&& above, int start, bool startAbove, double guess, int cap, double tolerance) {
    SearchBracket b{0, cap + 1};
    (startAbove ? b.hi : b.lo) = start;
    auto probe = [&](int s) { (above(s) ? b.hi : b.lo) = s; };
    auto inside = [&](double s) {
        if (!(s == s)) s = b.lo + 1;  // NaN
        return int(std::lround(std::clamp(s, double(b.lo + 1), double(b.hi - 1))));
    };
    if (b.hi - b.lo > 1) {
        if (startAbove) {
            for (int s = inside(std::min(guess / 1.15, double(start - 1)));; s = std::max(1, s / 2)) {
                probe(s);
                if (b.lo > 0 || s <= 1) break;
            }
        } else {
            for (int s = inside(std::max(guess * 1.15, double(start + 1)));; s = std::min(cap, s * 2)) {
                probe(s);
                if (b.hi <= cap || s >= cap) break;
            }
        }
    }
    while (b.hi <= cap && b.hi - b.lo > 1 && double(b.hi) > double(b.lo) * (1.0 + tolerance))
        probe(inside(b.lo > 0 ? std::sqrt(double(b.lo) * double(b.hi)) : double(b.hi) / 2));
    return b;
}

}  // namespace wedge::render
