// Reproduction of Wu et al. 2017's Sec. 5 numbers: Table 1 (box coverage, eqs. 16-18, averaged
// over random wedges 0 < s_min < s_max < 10), Table 2 (Gaussian coverage and accuracy, eqs. 14-15,
// averaged and for three wedges) and Fig. 6 (both against the number of MAAF components), with the
// paper's printed values beside ours, written as CSV and PNG plots.
//
// Random wedges: (s_min, s_max) uniform over the triangle 0 < s_min < s_max < 10 (two uniform
// draws, sorted), from a seeded splitmix64 stream; the paper does not say how it drew its 50.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "analysis/coverage.h"

namespace wedge::analysis {

/// Table 1 of the paper: box coverage, averaged over its 50 random wedges.
struct PaperTable1 {
    static constexpr double kAaf = 0.097, kFsf = 0.5;
    static constexpr int kMaafComponents[6] = {3, 5, 7, 25, 75, 125};
    static constexpr double kMaaf[6] = {0.197, 0.275, 0.401, 0.677, 0.876, 0.943};
};

/// Table 2 of the paper: rows (average, then three wedges), columns AAF, FSF, MAAF 3, 5, 7.
struct PaperTable2 {
    static constexpr double kShapes[4][2] = {{0, 0}, {0.5, 0.8}, {1.5, 2.0}, {0.7, 2.2}};  // {0, 0}: average
    static constexpr double kCoverage[4][5] = {{0.088, 0.199, 0.173, 0.256, 0.316},
                                               {0.079, 0.168, 0.122, 0.174, 0.218},
                                               {0.047, 0.134, 0.090, 0.156, 0.210},
                                               {0.172, 0.216, 0.245, 0.315, 0.383}};
    static constexpr double kAccuracy[4][5] = {{0.662, 0.731, 0.748, 0.799, 0.827},
                                               {0.585, 0.826, 0.833, 0.903, 0.933},
                                               {0.639, 0.686, 0.761, 0.811, 0.842},
                                               {0.616, 0.742, 0.734, 0.793, 0.824}};
};

/// `count` wedges (s_min, s_max), uniform over 0 < s_min < s_max < sLimit, Omega_y^max = 1.
std::vector<DoubleWedge> randomWedges(int count, uint64_t seed, double sLimit = 10);

/// A named way of normalising the Gaussian filters and of integrating eq. 15's denominator.
struct GaussianSetting {
    std::string name;  // column name in the CSV files
    GaussianConvention convention;
    CoverageDomain domain = CoverageDomain::Plane;
};
/// "plane" (ours: eqs. 2, 4 and 9-10 as printed, eq. 15 over the whole plane), "wedgebox" (eq.
/// 15's denominator over the wedge's bounding box) and "wedgebox_mu1" (that, with mu_p = 1).
std::vector<GaussianSetting> gaussianSettings();

struct TableOptions {
    int randomWedges = 50;
    uint64_t seed = 1;
    std::vector<int> fig6Components = {1, 3, 5, 7, 9, 11, 13, 15, 19, 25, 35, 49, 75, 125};
};

struct TableReport {
    std::vector<std::string> files;  // written, in order
    std::string summary;             // human-readable, for stdout
};

/// Computes Tables 1 and 2 and Fig. 6 and writes table1.csv/png, table2.csv/png, fig6.csv/png
/// into `dir` (which must exist). Deterministic for a given seed.
TableReport writeTables(const std::string& dir, const TableOptions& options);

/// Writes text through a temporary file and a rename (no half-written outputs).


}  // namespace wedge::analysis
