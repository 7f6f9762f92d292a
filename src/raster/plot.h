// A small line-plot renderer into an Image3f, for the cache-size sweep (the analogue of
// Vaidyanathan et al. 2012, Fig. 8): log-scaled axes, grid lines, anti-aliased polylines with
// markers, optional dashed horizontal reference lines, a legend, and labels drawn with a built-in
// 5x7 bitmap font (upper-case letters, digits and a little punctuation; lower case is drawn upper).
#pragma once

#include <string>
#include <vector>

#include "core/image.h"

namespace wedge::raster {

struct PlotSeries {
    std::string label;
    Vec3f colour;
    std::vector<double> x, y;
    bool dashed = false;  // dashed and without markers (e.g. an asymptote)
};

struct PlotSpec {
    std::string title, xLabel, yLabel;
    bool logX = true, logY = true;  // base 2 along x, base 10 along y
    std::vector<PlotSeries> series;
    int width = 760, height = 500;
};

/// Draws the plot; positive values only on log axes (others are skipped).
Image3f drawLinePlot(const PlotSpec& spec);

/// Draws `text` with its top-left corner at (x, y), each font pixel `scale` image pixels wide.
void drawText(Image3f& img, int x, int y, const std::string& text, int scale, const Vec3f& colour);
/// Width in image pixels of `text` drawn at `scale`.
int textWidth(const std::string& text, int scale);

}  // namespace wedge::raster
