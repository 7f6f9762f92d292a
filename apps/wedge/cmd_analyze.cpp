// wedge analyze spectrum|coverage|table|penumbra: the flatland Fourier analysis of Wu et al. 2017,
// Secs. 3-5 (see docs/analysis.md). spectrum: the Fig. 4 light field and its FFT with the
// predicted wedge slopes; coverage: eqs. 14-15 for one filter and wedge, beside the closed forms
// (eqs. 16, 18) and their corrections; table: Tables 1-2 and Fig. 6 as CSV and PNG; penumbra:
// the renderer's MAAF filter across a penumbra for 1, 3, 5 and 7 components (Fig. 10 as bias
// and noise).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "analysis/coverage.h"
#include "analysis/flatland.h"
#include "analysis/penumbra.h"
#include "io/plot.h"
#include "analysis/tables.h"
#include "apps/wedge/commands.h"
#include "apps/wedge/common.h"
#include "core/error.h"
#include "filter/maaf_components.h"
#include "io/image_io.h"
#include "io/output_file.h"

namespace wedge::app {

namespace {

// --- spectrum ------------------------------------------------------------------------------

struct SpectrumArgs {
    analysis::FlatlandSetup setup;
    std::string occluders;
    std::string output;
    bool csv = false;
    long long seed = 1;
};

std::vector<double> parseList(const std::string& flag, const std::string& text) {
    std::vector<double> out;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        size_t used = 0;
        double v = 0;
        try {
            v = std::stod(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        while (used < item.size() && std::isspace((unsigned char)item[used])) ++used;
        if (item.empty() || used != item.size()) throw Error(flag, "expected comma-separated numbers, got '" + text + "'");
        out.push_back(v);
    }
    if (out.empty()) throw Error(flag, "expected at least one number");
    return out;
}

/// OUT.png -> OUT_slopes.csv
std::string slopesCsvPath(const std::string& png) {
    std::filesystem::path p(png);
    return (p.parent_path() / (p.stem().string() + "_slopes.csv")).string();
}

void runSpectrum(SpectrumArgs a) {
    a.setup.occluderDistances = parseList("--occluders", a.occluders);
    a.setup.seed = uint64_t(a.seed);
    analysis::validateSetup(a.setup);
    io::checkOutputPath(a.output, {".png"});

    analysis::FlatlandField field = analysis::sampleFlatland(a.setup);
    analysis::FlatlandSpectrum spec = analysis::flatlandSpectrum(field);
    io::writePng(a.output, analysis::flatlandFigure(field, spec, a.setup.lightSize));

    const double halfWidth = 3;                              // bins
    const double dcRadius = std::max(2.0, field.n / 64.0);  // all lines meet near the origin
    std::printf("flatland: L = %g (sigma_y = %g, Omega_y^max = 4/L = %g), d1 = %g, domain [-%g, %g]^2, %d x %d\n",
                a.setup.lightSize, a.setup.lightSize / 2, 4 / a.setup.lightSize, a.setup.receiverDistance,
                field.halfExtent, field.halfExtent, field.n, field.n);
    std::printf("spectrum bin = %g rad per unit; Omega_y^max = %.2f bins\n", spec.binWidth,
                4 / a.setup.lightSize / spec.binWidth);
    double sLo = 1e300, sHi = -1e300;
    for (size_t k = 0; k < field.slopes.size(); ++k) {
        double s = field.slopes[k];
        sLo = std::min(sLo, s);
        sHi = std::max(sHi, s);
        std::printf("occluder d2 = %g: slope s = d1/d2 - 1 = %.4f; energy within %g bins of Omega_y = s Omega_x: %.3f\n",
                    a.setup.occluderDistances[k], s, halfWidth, analysis::energyNearSlope(spec, s, halfWidth, dcRadius));
    }
    std::printf("energy inside the double wedge s in [%.4f, %.4f] (+- %g bins): %.3f\n", sLo, sHi, halfWidth,
                analysis::energyInWedge(spec, sLo, sHi, halfWidth, dcRadius));
    std::printf("(energy fractions exclude the %g bins around the zero frequency)\n", dcRadius);
    std::printf("wrote %s\n", a.output.c_str());

    if (a.csv) {
        const int bins = 360;
        std::vector<double> e = analysis::energyPerAngle(spec, bins, dcRadius);
        std::ostringstream csv;
        csv << "angle_deg,slope,energy_fraction,predicted\n";
        for (int b = 0; b < bins; ++b) {
            double lo = -90.0 + 180.0 * b / bins, hi = lo + 180.0 / bins, mid = 0.5 * (lo + hi);
            int predicted = 0;
            for (double s : field.slopes) {
                double deg = std::atan(s) * 180 / M_PI;
                if (deg > lo && deg <= hi) predicted = 1;
            }
            char line[128];
            std::snprintf(line, sizeof line, "%.2f,%.6g,%.8f,%d\n", mid, std::tan(mid * M_PI / 180), e[b], predicted);
            csv << line;
        }
        std::string path = slopesCsvPath(a.output);
        io::writeTextFile(path, csv.str());
        std::printf("wrote %s\n", path.c_str());
    }
}

// --- coverage ------------------------------------------------------------------------------

struct CoverageArgs {
    std::string filter, shape, domain = "plane", mu = "eq10", fsfSigma = "printed";
    int components = 0;  // 0: the default (1 for AAF / FSF, 5 for MAAF)
    double sMin = NAN, sMax = NAN, sigmaScale = 1;
    int grid = 0;
    bool json = false;
};

void runCoverage(const CoverageArgs& a) {
    using namespace analysis;
    FilterKind kind = parseFilterKind(a.filter);
    FilterShape shape = parseFilterShape(a.shape);
    int k = a.components != 0 ? a.components : (kind == FilterKind::Maaf ? 5 : 1);
    DoubleWedge w{1.0, a.sMin, a.sMax};
    validateWedge(w);
    GaussianConvention conv;
    conv.maafWeights = a.mu == "eq10";
    conv.fsfSigmaAsPrinted = a.fsfSigma == "printed";
    conv.sigmaScale = a.sigmaScale;
    CoverageDomain domain = a.domain == "plane" ? CoverageDomain::Plane : CoverageDomain::WedgeBox;
    FourierFilter f(kind, shape, k, w, conv);
    FilterMetrics m = measureFilter(f, domain);

    if (a.json) {
        nlohmann::json j = {{"filter", toString(kind)}, {"components", k},         {"smin", a.sMin},
                            {"smax", a.sMax},           {"shape", toString(shape)}, {"coverage", m.coverage},
                            {"accuracy", m.accuracy}};
        std::printf("%s\n", j.dump().c_str());
        return;
    }
    std::printf("filter %s, %d component%s, %s, s_min = %g, s_max = %g (Omega_y^max = 1; the results do not depend on it)\n",
                toString(kind).c_str(), k, k == 1 ? "" : "s", toString(shape).c_str(), a.sMin, a.sMax);
    if (shape == FilterShape::Gaussian)
        std::printf("Gaussians: peak-one, std = %g x box half-width%s%s; eq. 15 denominator over the %s\n", a.sigmaScale,
                    kind == FilterKind::Fsf ? (conv.fsfSigmaAsPrinted ? ", FSF std Omega (1/s_min - 1/s_max) (eq. 4 as printed)"
                                                                      : ", FSF std = parallelogram half-width")
                                            : "",
                    kind == FilterKind::Maaf ? (conv.maafWeights ? ", mu_p of eq. 10" : ", mu_p = 1") : "",
                    domain == CoverageDomain::Plane ? "whole plane" : "wedge's bounding box");
    std::printf("coverage (eq. 15) = %.6f\naccuracy (eq. 14) = %.6f\n", m.coverage, m.accuracy);
    std::printf("integrals: |W| over the wedge %.6g, |W| over the %s %.6g, (W-1)^2 over the wedge %.6g; wedge area %.6g "
                "(exact Omega^2 (1/s_min - 1/s_max) = %.6g)\n",
                m.inWedge, domain == CoverageDomain::Plane ? "plane" : "wedge box", m.total, m.squaredError, m.wedgeArea,
                wedgeArea(w));
    if (shape == FilterShape::Gaussian)
        std::printf("coverage with eq. 15's denominator over the %s instead: %.6f\n",
                    domain == CoverageDomain::Plane ? "wedge's bounding box |Omega_x| <= Omega/s_min, |Omega_y| <= Omega"
                                                    : "whole plane",
                    m.coverageIn(domain == CoverageDomain::Plane ? CoverageDomain::WedgeBox : CoverageDomain::Plane));
    if (a.grid > 0) {
        FilterMetrics g = measureOnGrid(f, a.grid);
        std::printf("midpoint grid %d x %d (whole plane): coverage %.6f, accuracy %.6f\n", a.grid, a.grid, g.coverage,
                    g.accuracy);
    }
    if (shape != FilterShape::Box) return;
    // Box filters: the closed forms of Sec. 5 beside the numeric value.
    if (kind == FilterKind::Aaf || (kind == FilterKind::Maaf && k == 1)) {
        double printed = aafBoxCoverageEq16(a.sMin, a.sMax), exact = aafBoxCoverageExact(a.sMin, a.sMax);
        std::printf("eq. 16 as printed, (s_min/4)(1 - s_min/s_max)  = %.6f   (uses AAF area 4 (Omega/s_min)^2)\n", printed);
        std::printf("true geometry,     (1/4)(1 - s_min/s_max)      = %.6f   (AAF area 4 Omega^2/s_min)\n", exact);
        std::printf("discrepancy: eq. 16 is off by the factor s_min = %g (printed - true = %+.6f)\n", a.sMin, printed - exact);
    }
    if (kind == FilterKind::Fsf)
        std::printf("eq. 16, gamma_FSF = 1/2: agrees (parallelogram area 2 Omega^2 (1/s_min - 1/s_max))\n");
    if (kind == FilterKind::Maaf) {
        int n = (k + 1) / 2;
        double printed = filter::maafBoxCoverageEq18(n, a.sMin, a.sMax, true);
        double corrected = filter::maafBoxCoverageEq18(n, a.sMin, a.sMax, false);
        std::printf("eq. 18 as printed (centre term 1/s_min^2)       = %.6f\n", printed);
        std::printf("eq. 18 corrected (centre term 1/s_min)          = %.6f   (numeric - corrected = %+.2e)\n", corrected,
                    m.coverage - corrected);
        std::printf("discrepancy: eqs. 17-18 take the centre box's area as 4 (Omega/K)^2 / s_min^2; eq. 8 gives "
                    "4 (Omega/K)^2 / s_min (printed - corrected = %+.6f)\n",
                    printed - corrected);
    }
}

// --- table ---------------------------------------------------------------------------------

struct TableArgs {
    int randomWedges = 50;
    long long seed = 1;
    std::string dir;
};

void runTable(const TableArgs& a) {
    std::error_code ec;
    if (!std::filesystem::is_directory(a.dir)) {
        std::filesystem::create_directories(a.dir, ec);
        if (ec) throw Error(a.dir, "cannot create the output directory: " + ec.message());
    }
    analysis::TableOptions opt;
    opt.randomWedges = a.randomWedges;
    opt.seed = uint64_t(a.seed);
    analysis::TableReport r = analysis::writeTables(a.dir, opt);
    std::fputs(r.summary.c_str(), stdout);
    std::printf("\nNotes: eq. 16 (AAF) and eq. 18 (MAAF) as printed take the centre box's area as 4 (Omega/s_min)^2 "
                "(times 1/K^2) instead of 4 Omega^2/s_min; with that corrected they equal the numeric coverage.\n"
                "Gaussian conventions (plane, wedgebox, mu_p): see docs/analysis.md.\n");
    for (const auto& f : r.files) std::printf("wrote %s\n", f.c_str());
}

// --- penumbra ------------------------------------------------------------------------------

struct PenumbraArgs {
    analysis::PenumbraSetup setup;
    std::string weights = "sampling", output, csv;
};

void runPenumbra(PenumbraArgs a) {
    using namespace analysis;
    a.setup.weights = filter::parseMaafWeights(a.weights, "--weights");
    validatePenumbra(a.setup);
    if (!a.output.empty()) io::checkOutputPath(a.output, {".png"});
    if (!a.csv.empty()) io::checkOutputPath(a.csv, {".csv"});
    const PenumbraSetup& s = a.setup;
    std::vector<PenumbraResponse> rs;
    for (int pairs = 1; pairs <= filter::kMaafMaxPairs; ++pairs) rs.push_back(penumbraResponse(pairs, s));

    const double width = 2 * s.slope * s.lightHalfLength;  // the penumbra's width
    std::printf("flatland penumbra: light y in [-%g, %g] (aspect %g), edge slope s = %g (penumbra width %g), filter "
                "wedge [%g, %g]; weights %s, spatial scale %g, window %s\n",
                s.lightHalfLength, s.lightHalfLength, s.lightAspect, s.slope, width,
                s.filterSMin > 0 ? s.filterSMin : s.slope, s.filterSMax > 0 ? s.filterSMax : s.slope, a.weights.c_str(),
                s.spatialScale, s.window > 0 ? std::to_string(s.window).c_str() : "unbounded");
    const bool stratified = s.spp > 0;
    if (stratified)
        std::printf("samples: %d per pixel of width %g (%.1f pixels across the penumbra), stratified along the light\n", s.spp,
                    s.pixelWidth, width / s.pixelWidth);
    else
        std::printf("samples: independent (a Poisson process in x, light points from the whole light)\n");
    std::printf("%-11s %10s %10s %12s %26s", "components", "RMS bias", "hardness", "variance", "beats K=1 below (samples");
    if (stratified) std::printf(" %12s %13s", "variance", "stratified /");
    std::printf("\n%-11s %10s %10s %12s %26s", "", "", "(>0 hard)", "(x K=1)", "per penumbra width)");
    if (stratified) std::printf(" %12s %13s", "rho Var", "independent");
    std::printf("\n");
    for (const auto& r : rs) {
        double rho = breakEvenDensity(r, rs[0]);
        char beats[64];
        if (r.components == 1) std::snprintf(beats, sizeof beats, "-");
        else if (std::isinf(rho)) std::snprintf(beats, sizeof beats, "always");
        else if (rho <= 0) std::snprintf(beats, sizeof beats, "never");
        else if (stratified) std::snprintf(beats, sizeof beats, "%.0f (%.2g rows)", rho * width, rho * s.pixelWidth / s.spp);
        else std::snprintf(beats, sizeof beats, "%.0f", rho * width);
        std::printf("%-11d %10.4f %+10.4f %12.3f %26s", r.components, r.rmsBias, r.hardness, r.variance / rs[0].variance, beats);
        if (stratified) std::printf(" %12.4g %13.3f", r.variance, r.variance / r.varianceIndependent);
        std::printf("\n");
    }
    std::printf("(mean squared error at a sample density rho = bias^2 + variance / rho; expectation and variance of "
                "the ratio estimator by quadrature, docs/analysis.md%s)\n",
                stratified ? "; with --spp, rho is spp / pixel width times the rows a 2D filter averages along the edge" : "");

    if (!a.csv.empty()) {
        std::ostringstream csv;
        csv << "x,truth";
        for (const auto& r : rs) csv << ",k" << r.components;
        csv << "\n";
        for (size_t t = 0; t < rs[0].x.size(); ++t) {
            csv << rs[0].x[t] << "," << rs[0].truth[t];
            for (const auto& r : rs) csv << "," << r.mean[t];
            csv << "\n";
        }
        io::writeTextFile(a.csv, csv.str());
        std::printf("wrote %s\n", a.csv.c_str());
    }
    if (!a.output.empty()) {
        io::LinePlot plot;
        plot.title = "Expected MAAF output across a penumbra";
        plot.xLabel = "x / penumbra half-width";
        plot.yLabel = "visibility";
        plot.xMin = -1.25;
        plot.xMax = 1.25;
        plot.yMin = -0.05;
        plot.yMax = 1.05;
        const double halfWidth = s.slope * s.lightHalfLength;
        io::PlotSeries truth{"exact", {}, {}, io::displayColor(0, 0, 0)};
        truth.dash = 6;
        for (size_t t = 0; t < rs[0].x.size(); ++t) {
            truth.xs.push_back(rs[0].x[t] / halfWidth);
            truth.ys.push_back(rs[0].truth[t]);
        }
        plot.series.push_back(truth);
        for (size_t i = 0; i < rs.size(); ++i) {
            io::PlotSeries ser{"K = " + std::to_string(rs[i].components) + (i == 0 ? " (AAF)" : ""), {}, {},
                               io::rampColor(float(i) / float(rs.size()))};
            for (size_t t = 0; t < rs[i].x.size(); ++t) {
                ser.xs.push_back(rs[i].x[t] / halfWidth);
                ser.ys.push_back(rs[i].mean[t]);
            }
            plot.series.push_back(ser);
        }
        io::writePng(a.output, io::renderPlot(plot));
        std::printf("wrote %s\n", a.output.c_str());
    }
}

}  // namespace

void registerAnalyze(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand("analyze", "Flatland Fourier analysis of the wedge spectrum and of AAF, FSF and MAAF");
    cmd->require_subcommand(1);

    auto sa = std::make_shared<SpectrumArgs>();
    CLI::App* sp = cmd->add_subcommand("spectrum", "Flatland soft-shadow light field f(x, y) and its 2D FFT (Fig. 4)");
    sp->add_option("--light-size", sa->setup.lightSize, "L: the light spans y in [-L, L], Gaussian with sigma = L/2")->required();
    sp->add_option("--receiver-distance", sa->setup.receiverDistance, "d1: distance from the light to the receiver")->required();
    sp->add_option("--occluders", sa->occluders, "Comma-separated distances d2 from the light, each in (0, d1)")->required();
    sp->add_option("--size", sa->setup.size, "Samples per axis (even, 16..4096)");
    sp->add_option("--extent", sa->setup.extent, "Half-size R of the (x, y) domain (default 2 L)");
    sp->add_option("--feature", sa->setup.feature, "Mean slat and gap width on the occluders (default L/8)");
    sp->add_option("--supersample", sa->setup.supersample, "Sub-samples per axis per grid point (1..16)");
    sp->add_option("--seed", sa->seed, "Seed of the occluders' slat patterns")->check(CLI::Range(0LL, 4294967295LL));
    sp->add_option("-o,--output", sa->output, "Output PNG: occlusion image beside the log spectrum")->required();
    sp->add_flag("--csv", sa->csv, "Also write OUT_slopes.csv: spectral energy per direction (slope)");
    sp->callback([sa] { runSpectrum(*sa); });

    auto ca = std::make_shared<CoverageArgs>();
    CLI::App* co = cmd->add_subcommand("coverage", "Coverage (eq. 15) and accuracy (eq. 14) of a filter on the double wedge");
    co->add_option("--filter", ca->filter, "aaf|fsf|maaf")->required()->check(CLI::IsMember({"aaf", "fsf", "maaf"}));
    co->add_option("--components", ca->components, "MAAF: number of filters K = 2N - 1 (odd; default 5); AAF/FSF: 1")
        ->check(CLI::Range(1, 100001));
    co->add_option("--smin", ca->sMin, "Smallest wedge slope, > 0")->required();
    co->add_option("--smax", ca->sMax, "Largest wedge slope, > smin")->required();
    co->add_option("--shape", ca->shape, "box|gaussian")->required()->check(CLI::IsMember({"box", "gaussian"}));
    co->add_flag("--json", ca->json, "Print {filter, components, smin, smax, shape, coverage, accuracy} as JSON");
    co->add_option("--domain", ca->domain, "Gaussians: eq. 15's denominator over the whole plane (default) or the wedge's bounding box")
        ->check(CLI::IsMember({"plane", "wedgebox"}));
    co->add_option("--mu", ca->mu, "Gaussian MAAF weights: eq10 (default) or one")->check(CLI::IsMember({"eq10", "one"}));
    co->add_option("--fsf-sigma", ca->fsfSigma, "Gaussian FSF std: printed (eq. 4, default) or half (the parallelogram's half-width)")
        ->check(CLI::IsMember({"printed", "half"}));
    co->add_option("--sigma-scale", ca->sigmaScale, "Gaussians: std = this x the box half-width (default 1)")
        ->check(numberIn(1e-3, 1e3));
    co->add_option("--grid", ca->grid, "Also evaluate on an N x N midpoint grid (cross-check)")->check(CLI::Range(2, 8192));
    co->callback([ca] { runCoverage(*ca); });

    auto ta = std::make_shared<TableArgs>();
    CLI::App* tb = cmd->add_subcommand("table", "Tables 1-2 and Fig. 6 as CSV and PNG, with the paper's values");
    tb->add_option("--random-wedges", ta->randomWedges, "Number of random wedges 0 < s_min < s_max < 10")
        ->check(CLI::Range(1, 100000));
    tb->add_option("--seed", ta->seed, "Seed of the random wedges")->check(CLI::Range(0LL, 4294967295LL));
    tb->add_option("-o,--output", ta->dir, "Output directory (created if missing)")->required();
    tb->callback([ta] { runTable(*ta); });

    auto pa = std::make_shared<PenumbraArgs>();
    CLI::App* pe = cmd->add_subcommand(
        "penumbra", "The renderer's MAAF filter across a flatland penumbra for 1, 3, 5, 7 components: bias, hardness, noise (Fig. 10)");
    pe->add_option("--light-half-length", pa->setup.lightHalfLength, "L: the light spans y in [-L, L] (default 0.5)");
    pe->add_option("--light-aspect", pa->setup.lightAspect, "Length / width of the 2D light, which sets sigma = sqrt(area)/2 (default 1)");
    pe->add_option("--slope", pa->setup.slope, "Slope s = d1/d2 - 1 of the occluder edge (default 0.6)");
    pe->add_option("--smin", pa->setup.filterSMin, "The filter's wedge, smallest slope (default: the edge's)");
    pe->add_option("--smax", pa->setup.filterSMax, "The filter's wedge, largest slope (default: the edge's)");
    pe->add_option("--weights", pa->weights, "Component weights mu_p: sampling (default), eq10 or unit")
        ->check(CLI::IsMember({"sampling", "eq10", "unit"}));
    pe->add_option("--spatial-scale", pa->setup.spatialScale, "Fourier std of the spatial Gaussians / eq. 8's half-width (default sqrt 6, the renderer's)");
    pe->add_option("--window", pa->setup.window, "Cut the filter at |x - x'| <= this (default 0: unbounded)");
    pe->add_option("--points", pa->setup.points, "Output positions across the penumbra (default 61)");
    pe->add_option("--spp", pa->setup.spp,
                   "Samples per pixel, stratified along the light as the renderer's Sobol points (default 0: independent samples)");
    pe->add_option("--pixel-width", pa->setup.pixelWidth, "The pixel's width in x, with --spp");
    pe->add_option("-o,--output", pa->output, "PNG plot of the expected edge profiles");
    pe->add_option("--csv", pa->csv, "CSV of the expected edge profiles");
    pe->callback([pa] { runPenumbra(*pa); });
}

}  // namespace wedge::app
