// Minimal raster plotting (no plotting library): a canvas with lines, markers and a built-in 5x7
// bitmap font, and line plots with linear or logarithmic axes, ticks and a legend, drawn into an
// Image3f of linear colours for writePng. Used by `wedge analyze` (the spectrum figure, Tables
// 1-2 and Fig. 6 of Wu et al. 2017) and `wedge raster` (the cache sweep, Fig. 8 of Vaidyanathan
// et al. 2012). svgPlot draws the same plots as SVG for `wedge experiment`'s HTML page.
#pragma once

#include <string>
#include <vector>

#include "core/image.h"

namespace wedge::io {

/// Display colour (sRGB components in [0, 1]) -> the linear value writePng expects.
Vec3f displayColor(float r, float g, float b);
/// A viridis-like ramp, t in [0, 1], as a linear colour.
Vec3f rampColor(float t);

class Canvas {
public:
    Canvas(int width, int height, const Vec3f& background);

    Image3f& image() { return m_image; }
    const Image3f& image() const { return m_image; }

    void setPixel(int x, int y, const Vec3f& c);
    void fillRect(int x0, int y0, int x1, int y1, const Vec3f& c);  // inclusive-exclusive
    /// A line of the given thickness (pixels); dash > 0 draws dash pixels on, dash off.
    void line(double x0, double y0, double x1, double y1, const Vec3f& c, int thickness = 1, int dash = 0);
    /// Marker: 0 square, 1 cross, 2 diamond; `size` is the half-size in pixels.
    void marker(double x, double y, const Vec3f& c, int kind, int size = 4);
    /// Text in the 5x7 font, scaled by `scale`, top-left at (x, y); lower case prints as upper.
    void text(int x, int y, const std::string& s, const Vec3f& c, int scale = 1);
    static int textWidth(const std::string& s, int scale = 1) { return int(s.size()) * 6 * scale; }
    static int textHeight(int scale = 1) { return 7 * scale; }

private:
    Image3f m_image;
};

struct PlotSeries {
    std::string label;
    std::vector<double> xs, ys;
    Vec3f color;
    bool lines = true;   // join the points
    int marker = -1;     // -1 none, else Canvas::marker kind
    int dash = 0;        // dashed line
};

struct LinePlot {
    std::string title, xLabel, yLabel;
    double xMin = 0, xMax = 1, yMin = 0, yMax = 1;
    bool logX = false, logY = false;  // log axes (positive values only)
    std::vector<double> xTicks;                 // empty: automatic
    std::vector<std::string> xTickLabels;       // optional, one per xTick
    std::vector<PlotSeries> series;
};

/// Renders the plot with its axes, ticks, labels and legend.
Image3f renderPlot(const LinePlot& plot, int width = 800, int height = 520);
/// The same plot as an SVG document (text, for inlining in HTML: `wedge experiment`'s page).
std::string svgPlot(const LinePlot& plot, int width = 640, int height = 420);
/// Places images side by side (top-aligned) on a white background with a gap.
Image3f besideEachOther(const std::vector<Image3f>& images, int gap = 16);

}  // namespace wedge::io
