// Tables 1-2 and Fig. 6 of Wu et al. 2017 (Sec. 5), recomputed; see tables.h.
#include "analysis/tables.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>
#include <unistd.h>

#include "io/plot.h"
#include "core/error.h"
#include "filter/maaf_components.h"
#include "io/image_io.h"
#include "io/output_file.h"

namespace wedge::analysis {

using io::besideEachOther;
using io::Canvas;
using io::displayColor;
using io::LinePlot;
using io::PlotSeries;
using io::rampColor;
using io::renderPlot;

namespace {

struct Stats {
    double mean = 0, sem = 0;  // mean and its standard error
};

Stats stats(const std::vector<double>& v) {
    Stats s;
    if (v.empty()) return s;
    for (double x : v) s.mean += x;
    s.mean /= v.size();
    if (v.size() > 1) {
        double ss = 0;
        for (double x : v) ss += (x - s.mean) * (x - s.mean);
        s.sem = std::sqrt(ss / (v.size() - 1) / v.size());
    }
    return s;
}

std::string fmt(double v, int digits = 4) {
    if (!std::isfinite(v)) return "";
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

std::string sci(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2e", v);
    return buf;
}

/// Runs fn(i) for i in [0, n) in parallel; callers store results by index, so the output does not
/// depend on the scheduling.
template <class Fn>
void parallelIndex(int n, Fn&& fn) {
    tbb::parallel_for(0, n, [&](int i) { fn(i); });
}

const char* kFilterNames[5] = {"AAF", "FSF", "MAAF3", "MAAF5", "MAAF7"};

bool sameConvention(const GaussianConvention& a, const GaussianConvention& b) {
    return a.sigmaScale == b.sigmaScale && a.fsfSigmaAsPrinted == b.fsfSigmaAsPrinted && a.maafWeights == b.maafWeights;
}

/// {coverage, accuracy} of one filter under every setting; settings that differ only in the
/// coverage domain share one measurement (measureFilter computes both denominators).
template <class MakeFilter>
std::vector<std::pair<double, double>> measureSettings(const std::vector<GaussianSetting>& settings, MakeFilter&& make) {
    std::vector<std::pair<double, double>> out(settings.size());
    std::vector<FilterMetrics> done(settings.size());
    for (size_t s = 0; s < settings.size(); ++s) {
        size_t same = s;
        for (size_t t = 0; t < s; ++t)
            if (sameConvention(settings[t].convention, settings[s].convention)) {
                same = t;
                break;
            }
        done[s] = same == s ? measureFilter(make(settings[s].convention)) : done[same];
        out[s] = {done[s].coverageIn(settings[s].domain), done[s].accuracy};
    }
    return out;
}

FourierFilter table2Filter(int column, FilterShape shape, const DoubleWedge& w, const GaussianConvention& conv) {
    if (column == 0) return FourierFilter(FilterKind::Aaf, shape, 1, w, conv);
    if (column == 1) return FourierFilter(FilterKind::Fsf, shape, 1, w, conv);
    return FourierFilter(FilterKind::Maaf, shape, 2 * column - 1, w, conv);  // 3, 5, 7
}

}  // namespace

std::vector<DoubleWedge> randomWedges(int count, uint64_t seed, double sLimit) {
    std::vector<DoubleWedge> out;
    uint64_t state = seed;
    auto uniform = [&] {
        uint64_t z = (state += 0x9e3779b97f4a7c15ULL);  // splitmix64
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return ((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
    };
    while (int(out.size()) < count) {
        double a = sLimit * uniform(), b = sLimit * uniform();
        if (a > b) std::swap(a, b);
        if (!(a > 1e-6 * sLimit && b > a * (1 + 1e-9))) continue;  // keep the wedge non-degenerate
        out.push_back({1.0, a, b});
    }
    return out;
}

std::vector<GaussianSetting> gaussianSettings() {
    GaussianSetting plane{"plane", {}, CoverageDomain::Plane};
    GaussianSetting box{"wedgebox", {}, CoverageDomain::WedgeBox};
    GaussianSetting boxMu1{"wedgebox_mu1", {}, CoverageDomain::WedgeBox};
    boxMu1.convention.maafWeights = false;
    return {plane, box, boxMu1};
}

TableReport writeTables(const std::string& dir, const TableOptions& opt) {
    if (opt.randomWedges < 1 || opt.randomWedges > 100000) throw Error("--random-wedges", "expected 1..100000");
    if (!std::filesystem::is_directory(dir)) throw Error(dir, "output directory does not exist");
    namespace fs = std::filesystem;
    auto path = [&](const std::string& name) { return (fs::path(dir) / name).string(); };

    const std::vector<DoubleWedge> wedges = randomWedges(opt.randomWedges, opt.seed);
    const int nw = int(wedges.size());
    const auto settings = gaussianSettings();
    TableReport report;
    std::ostringstream sum;
    sum << "Random wedges: " << nw << ", (s_min, s_max) uniform over 0 < s_min < s_max < 10, seed " << opt.seed
        << "\n";

    // --- Table 1: box coverage -------------------------------------------------------------
    struct T1Row {
        std::string filter;
        int components;
        double paper;
        std::vector<double> numeric, printed, corrected;
    };
    std::vector<T1Row> t1;
    t1.push_back({"aaf", 1, PaperTable1::kAaf, {}, {}, {}});
    t1.push_back({"fsf", 1, PaperTable1::kFsf, {}, {}, {}});
    t1.push_back({"maaf", 1, NAN, {}, {}, {}});
    for (int i = 0; i < 6; ++i) t1.push_back({"maaf", PaperTable1::kMaafComponents[i], PaperTable1::kMaaf[i], {}, {}, {}});
    for (auto& r : t1) {
        r.numeric.assign(nw, 0);
        r.printed.assign(nw, 0);
        r.corrected.assign(nw, 0);
        parallelIndex(nw, [&](int i) {
            const DoubleWedge& w = wedges[i];
            FilterKind kind = parseFilterKind(r.filter);
            r.numeric[i] = measureFilter(FourierFilter(kind, FilterShape::Box, r.components, w)).coverage;
            if (kind == FilterKind::Aaf) {
                r.printed[i] = aafBoxCoverageEq16(w.sMin, w.sMax);
                r.corrected[i] = aafBoxCoverageExact(w.sMin, w.sMax);
            } else if (kind == FilterKind::Fsf) {
                r.printed[i] = r.corrected[i] = fsfBoxCoverageExact();
            } else {
                int n = (r.components + 1) / 2;
                r.printed[i] = filter::maafBoxCoverageEq18(n, w.sMin, w.sMax, true);
                r.corrected[i] = filter::maafBoxCoverageEq18(n, w.sMin, w.sMax, false);
            }
        });
    }
    {
        std::ostringstream csv;
        csv << "# Table 1 (box filters): coverage (eq. 15) averaged over " << nw << " random wedges, seed " << opt.seed
            << ".\n# closed_form_printed: eq. 16 (AAF) / eq. 18 (MAAF) as printed; closed_form_corrected: the true box"
               " areas (AAF 4 Omega^2/s_min; eq. 18 with 1/s_min for 1/s_min^2).\n";
        csv << "filter,components,paper,numeric_mean,numeric_sem,closed_form_printed_mean,closed_form_corrected_mean,"
               "max_abs_numeric_minus_corrected\n";
        sum << "\nTable 1 (boxes, coverage; mean +- standard error over the wedges)\n";
        sum << "  filter   K   paper   numeric          eq.16/18 printed  corrected   max|num-corr|\n";
        for (const auto& r : t1) {
            Stats n = stats(r.numeric), p = stats(r.printed), c = stats(r.corrected);
            double dev = 0;
            for (int i = 0; i < nw; ++i) dev = std::max(dev, std::abs(r.numeric[i] - r.corrected[i]));
            csv << r.filter << "," << r.components << "," << fmt(r.paper, 3) << "," << fmt(n.mean, 6) << ","
                << fmt(n.sem, 6) << "," << fmt(p.mean, 6) << "," << fmt(c.mean, 6) << "," << sci(dev) << "\n";
            char line[200];
            std::snprintf(line, sizeof line, "  %-5s %4d   %-6s  %.4f +- %.4f  %.4f            %.4f      %.1e\n",
                          r.filter.c_str(), r.components, std::isfinite(r.paper) ? fmt(r.paper, 3).c_str() : "-",
                          n.mean, n.sem, p.mean, c.mean, dev);
            sum << line;
        }
        io::writeTextFile(path("table1.csv"), csv.str());
        report.files.push_back(path("table1.csv"));

        LinePlot lp;
        lp.title = "TABLE 1: BOX COVERAGE VS MAAF COMPONENTS";
        lp.xLabel = "NUMBER OF MAAF COMPONENTS K (LOG); K=1 IS AAF";
        lp.yLabel = "COVERAGE";
        lp.logX = true;
        lp.xMin = 0.8;
        lp.xMax = 160;
        lp.yMin = 0;
        lp.yMax = 1.05;
        PlotSeries ours{"OURS, NUMERIC (= EQ. 18 CORRECTED)", {}, {}, displayColor(0.1f, 0.3f, 0.8f), true, 0};
        PlotSeries printed{"EQ. 16/18 AS PRINTED", {}, {}, displayColor(0.9f, 0.5f, 0.1f), true, 2, 6};
        PlotSeries paper{"PAPER TABLE 1", {}, {}, displayColor(0.8f, 0.1f, 0.1f), false, 1};
        PlotSeries fsf{"FSF: OURS = PAPER = 0.5", {0.8, 160}, {0.5, 0.5}, displayColor(0.4f, 0.4f, 0.4f), true, -1, 4};
        for (const auto& r : t1) {
            if (r.filter == "fsf" || (r.filter == "aaf")) continue;
            ours.xs.push_back(r.components);
            ours.ys.push_back(stats(r.numeric).mean);
            printed.xs.push_back(r.components);
            printed.ys.push_back(stats(r.printed).mean);
        }
        paper.xs.push_back(1);
        paper.ys.push_back(PaperTable1::kAaf);
        for (int i = 0; i < 6; ++i) {
            paper.xs.push_back(PaperTable1::kMaafComponents[i]);
            paper.ys.push_back(PaperTable1::kMaaf[i]);
        }
        lp.series = {ours, printed, paper, fsf};
        io::writePng(path("table1.png"), renderPlot(lp));
        report.files.push_back(path("table1.png"));
    }

    // --- Table 2: Gaussian coverage and accuracy --------------------------------------------
    // values[row][column][setting] = {coverage, accuracy}; row 0 is the average.
    const int ns = int(settings.size());
    std::vector<double> cov(4 * 5 * ns), acc(4 * 5 * ns);
    auto at = [&](int row, int col, int s) { return (row * 5 + col) * ns + s; };
    for (int col = 0; col < 5; ++col) {
        std::vector<std::vector<std::pair<double, double>>> perWedge(nw);
        parallelIndex(nw, [&](int i) {
            perWedge[i] = measureSettings(settings, [&](const GaussianConvention& conv) {
                return table2Filter(col, FilterShape::Gaussian, wedges[i], conv);
            });
        });
        for (int s = 0; s < ns; ++s) {
            std::vector<double> c(nw), a(nw);
            for (int i = 0; i < nw; ++i) std::tie(c[i], a[i]) = perWedge[i][s];
            cov[at(0, col, s)] = stats(c).mean;
            acc[at(0, col, s)] = stats(a).mean;
        }
        for (int row = 1; row < 4; ++row) {
            DoubleWedge w{1.0, PaperTable2::kShapes[row][0], PaperTable2::kShapes[row][1]};
            auto r = measureSettings(settings, [&](const GaussianConvention& conv) {
                return table2Filter(col, FilterShape::Gaussian, w, conv);
            });
            for (int s = 0; s < ns; ++s) std::tie(cov[at(row, col, s)], acc[at(row, col, s)]) = r[s];
        }
    }
    {
        std::ostringstream csv;
        csv << "# Table 2 (Gaussian filters): coverage (eq. 15) and accuracy (eq. 14). Rows 'average' are means over "
            << nw << " random wedges (seed " << opt.seed << ").\n"
            << "# plane: eqs. 2, 4, 9-10 as printed (peak-one Gaussians, eq. 10 weights), eq. 15 over the whole plane"
               " (our convention).\n# wedgebox: eq. 15's denominator over the wedge's bounding box only; wedgebox_mu1:"
               " that, and MAAF weights mu_p = 1.\n";
        csv << "shape,smin,smax,filter,components,metric,paper";
        for (const auto& s : settings) csv << "," << s.name;
        csv << "\n";
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 5; ++col)
                for (int metric = 0; metric < 2; ++metric) {
                    csv << (row == 0 ? "average" : "fixed") << ",";
                    csv << (row == 0 ? "" : fmt(PaperTable2::kShapes[row][0], 1)) << ","
                        << (row == 0 ? "" : fmt(PaperTable2::kShapes[row][1], 1)) << ",";
                    csv << (col == 0 ? "aaf" : col == 1 ? "fsf" : "maaf") << "," << (col < 2 ? 1 : 2 * col - 1) << ","
                        << (metric == 0 ? "coverage" : "accuracy") << ","
                        << fmt(metric == 0 ? PaperTable2::kCoverage[row][col] : PaperTable2::kAccuracy[row][col], 3);
                    for (int s = 0; s < ns; ++s) csv << "," << fmt(metric == 0 ? cov[at(row, col, s)] : acc[at(row, col, s)]);
                    csv << "\n";
                }
        io::writeTextFile(path("table2.csv"), csv.str());
        report.files.push_back(path("table2.csv"));

        sum << "\nTable 2 (Gaussians): paper | ours (plane) | ours (wedgebox) | ours (wedgebox, mu_p = 1)\n";
        for (int row = 0; row < 4; ++row) {
            char head[96];
            if (row == 0) std::snprintf(head, sizeof head, "  average over the random wedges");
            else std::snprintf(head, sizeof head, "  s_min %.1f, s_max %.1f", PaperTable2::kShapes[row][0], PaperTable2::kShapes[row][1]);
            sum << head << "\n";
            for (int metric = 0; metric < 2; ++metric) {
                sum << (metric == 0 ? "    coverage " : "    accuracy ");
                for (int col = 0; col < 5; ++col) {
                    char cell[120];
                    const double paper = metric == 0 ? PaperTable2::kCoverage[row][col] : PaperTable2::kAccuracy[row][col];
                    const auto& v = metric == 0 ? cov : acc;
                    std::snprintf(cell, sizeof cell, " %s %.3f|%.3f|%.3f|%.3f", kFilterNames[col], paper, v[at(row, col, 0)],
                                  v[at(row, col, 1)], v[at(row, col, 2)]);
                    sum << cell;
                }
                sum << "\n";
            }
        }

        std::vector<Image3f> panels;
        for (int metric = 0; metric < 2; ++metric) {
            LinePlot lp;
            lp.title = metric == 0 ? "TABLE 2: GAUSSIAN COVERAGE (AVERAGE)" : "TABLE 2: GAUSSIAN ACCURACY (AVERAGE)";
            lp.xLabel = "FILTER";
            lp.yLabel = metric == 0 ? "COVERAGE" : "ACCURACY";
            lp.xMin = -0.5;
            lp.xMax = 4.5;
            lp.yMin = 0;
            lp.yMax = metric == 0 ? 0.6 : 1.0;
            lp.xTicks = {0, 1, 2, 3, 4};
            lp.xTickLabels = {"AAF", "FSF", "MAAF 3", "MAAF 5", "MAAF 7"};
            const Vec3f colors[3] = {displayColor(0.1f, 0.3f, 0.8f), displayColor(0.1f, 0.6f, 0.3f), displayColor(0.6f, 0.2f, 0.7f)};
            const char* labels[3] = {"OURS: PLANE (EQS. 2,4,9,10)", "OURS: WEDGE BOX", "OURS: WEDGE BOX, MU=1"};
            for (int s = 0; s < ns; ++s) {
                PlotSeries ps{labels[s], {}, {}, colors[s], true, 0};
                for (int col = 0; col < 5; ++col) {
                    ps.xs.push_back(col);
                    ps.ys.push_back(metric == 0 ? cov[at(0, col, s)] : acc[at(0, col, s)]);
                }
                lp.series.push_back(ps);
            }
            PlotSeries paper{"PAPER TABLE 2", {}, {}, displayColor(0.8f, 0.1f, 0.1f), false, 1};
            for (int col = 0; col < 5; ++col) {
                paper.xs.push_back(col);
                paper.ys.push_back(metric == 0 ? PaperTable2::kCoverage[0][col] : PaperTable2::kAccuracy[0][col]);
            }
            lp.series.push_back(paper);
            panels.push_back(renderPlot(lp, 640, 480));
        }
        io::writePng(path("table2.png"), besideEachOther(panels));
        report.files.push_back(path("table2.png"));
    }

    // --- Fig. 6: coverage and accuracy against the number of components ---------------------
    {
        const auto& ks = opt.fig6Components;
        const int nk = int(ks.size());
        std::vector<double> boxCov(nk), boxPrinted(nk), gCov(nk * ns), gAcc(nk * ns);
        for (int k = 0; k < nk; ++k) {
            if (ks[k] < 1 || ks[k] % 2 == 0) throw Error("Fig. 6", "component counts must be odd");
            std::vector<double> bc(nw), bp(nw);
            parallelIndex(nw, [&](int i) {
                bc[i] = measureFilter(FourierFilter(FilterKind::Maaf, FilterShape::Box, ks[k], wedges[i])).coverage;
                bp[i] = filter::maafBoxCoverageEq18((ks[k] + 1) / 2, wedges[i].sMin, wedges[i].sMax, true);
            });
            boxCov[k] = stats(bc).mean;
            boxPrinted[k] = stats(bp).mean;
            std::vector<std::vector<std::pair<double, double>>> perWedge(nw);
            parallelIndex(nw, [&](int i) {
                perWedge[i] = measureSettings(settings, [&](const GaussianConvention& conv) {
                    return FourierFilter(FilterKind::Maaf, FilterShape::Gaussian, ks[k], wedges[i], conv);
                });
            });
            for (int s = 0; s < ns; ++s) {
                std::vector<double> c(nw), a(nw);
                for (int i = 0; i < nw; ++i) std::tie(c[i], a[i]) = perWedge[i][s];
                gCov[k * ns + s] = stats(c).mean;
                gAcc[k * ns + s] = stats(a).mean;
            }
        }
        auto paperBox = [](int k) {
            if (k == 1) return PaperTable1::kAaf;
            for (int i = 0; i < 6; ++i)
                if (PaperTable1::kMaafComponents[i] == k) return PaperTable1::kMaaf[i];
            return double(NAN);
        };
        auto paperGauss = [](int k, int metric) {
            int col = k == 1 ? 0 : (k >= 3 && k <= 7) ? (k + 1) / 2 : -1;
            if (col < 0) return double(NAN);
            return metric == 0 ? PaperTable2::kCoverage[0][col] : PaperTable2::kAccuracy[0][col];
        };
        std::ostringstream csv;
        csv << "# Fig. 6: MAAF coverage and accuracy against the number of components K (K = 1 is AAF), means over " << nw
            << " random wedges (seed " << opt.seed << ").\n# The paper's Fig. 6 prints no numbers; paper_* columns"
               " repeat its Tables 1 and 2 where they have this K.\n";
        csv << "components,box_coverage,box_coverage_eq18_printed";
        for (const auto& s : settings) csv << ",gauss_coverage_" << s.name << ",gauss_accuracy_" << s.name;
        csv << ",paper_box_coverage,paper_gauss_coverage,paper_gauss_accuracy\n";
        for (int k = 0; k < nk; ++k) {
            csv << ks[k] << "," << fmt(boxCov[k], 6) << "," << fmt(boxPrinted[k], 6);
            for (int s = 0; s < ns; ++s) csv << "," << fmt(gCov[k * ns + s], 6) << "," << fmt(gAcc[k * ns + s], 6);
            csv << "," << fmt(paperBox(ks[k]), 3) << "," << fmt(paperGauss(ks[k], 0), 3) << ","
                << fmt(paperGauss(ks[k], 1), 3) << "\n";
        }
        io::writeTextFile(path("fig6.csv"), csv.str());
        report.files.push_back(path("fig6.csv"));

        LinePlot lp;
        lp.title = "FIG. 6: MAAF COVERAGE AND ACCURACY VS COMPONENTS";
        lp.xLabel = "NUMBER OF MAAF COMPONENTS K (LOG); K=1 IS AAF";
        lp.yLabel = "COVERAGE / ACCURACY";
        lp.logX = true;
        lp.xMin = 0.8;
        lp.xMax = 160;
        lp.yMin = 0;
        lp.yMax = 1.05;
        PlotSeries bc{"BOX COVERAGE (NUMERIC)", {}, {}, displayColor(0.1f, 0.3f, 0.8f), true, 0};
        PlotSeries gc{"GAUSS COVERAGE (PLANE)", {}, {}, displayColor(0.1f, 0.6f, 0.3f), true, 0};
        PlotSeries ga{"GAUSS ACCURACY (PLANE)", {}, {}, displayColor(0.1f, 0.6f, 0.3f), true, 2, 6};
        PlotSeries gc1{"GAUSS COVERAGE (WEDGE BOX, MU=1)", {}, {}, displayColor(0.6f, 0.2f, 0.7f), true, 0};
        PlotSeries ga1{"GAUSS ACCURACY (WEDGE BOX, MU=1)", {}, {}, displayColor(0.6f, 0.2f, 0.7f), true, 2, 6};
        PlotSeries pb{"PAPER TABLE 1 (BOX COVERAGE)", {}, {}, displayColor(0.1f, 0.3f, 0.8f), false, 1};
        PlotSeries pc{"PAPER TABLE 2 (GAUSS COVERAGE)", {}, {}, displayColor(0.8f, 0.1f, 0.1f), false, 1};
        PlotSeries pa{"PAPER TABLE 2 (GAUSS ACCURACY)", {}, {}, displayColor(0.9f, 0.5f, 0.1f), false, 1};
        for (int k = 0; k < nk; ++k) {
            bc.xs.push_back(ks[k]);
            bc.ys.push_back(boxCov[k]);
            gc.xs.push_back(ks[k]);
            gc.ys.push_back(gCov[k * ns + 0]);
            ga.xs.push_back(ks[k]);
            ga.ys.push_back(gAcc[k * ns + 0]);
            gc1.xs.push_back(ks[k]);
            gc1.ys.push_back(gCov[k * ns + 2]);
            ga1.xs.push_back(ks[k]);
            ga1.ys.push_back(gAcc[k * ns + 2]);
        }
        for (int k : {1, 3, 5, 7, 25, 75, 125}) {
            pb.xs.push_back(k);
            pb.ys.push_back(paperBox(k));
        }
        for (int k : {1, 3, 5, 7}) {
            pc.xs.push_back(k);
            pc.ys.push_back(paperGauss(k, 0));
            pa.xs.push_back(k);
            pa.ys.push_back(paperGauss(k, 1));
        }
        lp.series = {bc, gc, ga, gc1, ga1, pb, pc, pa};
        io::writePng(path("fig6.png"), renderPlot(lp, 900, 600));
        report.files.push_back(path("fig6.png"));

        sum << "\nFig. 6 (means over the random wedges): K, box coverage, Gaussian coverage/accuracy (plane), "
               "(wedgebox, mu_p = 1)\n";
        for (int k = 0; k < nk; ++k) {
            char line[160];
            std::snprintf(line, sizeof line, "  K=%3d  box %.3f   gauss %.3f / %.3f   %.3f / %.3f\n", ks[k], boxCov[k],
                          gCov[k * ns], gAcc[k * ns], gCov[k * ns + 2], gAcc[k * ns + 2]);
            sum << line;
        }
    }
    report.summary = sum.str();
    return report;
}

}  // namespace wedge::analysis
