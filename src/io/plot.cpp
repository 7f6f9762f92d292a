// Raster plotting for the analysis figures: canvas primitives, a 5x7 bitmap font (the classic
// HD44780 character shapes) and line plots.
#include "io/plot.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "io/image_io.h"
#include "io/text_file.h"

namespace wedge::io {

namespace {

struct Glyph {
    char c;
    unsigned char rows[7];  // 5 bits per row, most significant bit on the left
};

// clang-format off
constexpr Glyph kFont[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'A', {0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11}}, {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
    {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}}, {'D', {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C}},
    {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}}, {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
    {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}}, {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
    {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}}, {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
    {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}}, {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
    {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}}, {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
    {'Q', {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}}, {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
    {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}}, {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}}, {'X', {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}},
    {'Y', {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04}}, {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}},
    {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}}, {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
    {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}}, {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}}, {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}}, {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}}, {'<', {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02}},
    {'>', {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08}}, {'|', {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'[', {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E}}, {']', {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E}},
    {'^', {0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00}}, {'*', {0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00}},
    {'\'', {0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00}},
};
// clang-format on

const Glyph* findGlyph(char c) {
    c = char(std::toupper((unsigned char)c));
    for (const auto& g : kFont)
        if (g.c == c) return &g;
    return nullptr;
}

std::string formatTick(double v) {
    char buf[32];
    if (std::abs(v) < 1e-12) return "0";
    if (std::abs(v) >= 1000 || std::abs(v - std::round(v)) < 1e-9) std::snprintf(buf, sizeof buf, "%.0f", v);
    else if (std::abs(v * 10 - std::round(v * 10)) < 1e-9) std::snprintf(buf, sizeof buf, "%.1f", v);
    else std::snprintf(buf, sizeof buf, "%.2f", v);
    return buf;
}

/// "Nice" ticks covering [lo, hi]: steps of 1, 2 or 5 times a power of ten.
std::vector<double> niceTicks(double lo, double hi, int target) {
    double span = hi - lo;
    if (!(span > 0)) return {lo};
    double raw = span / target, mag = std::pow(10.0, std::floor(std::log10(raw)));
    double step = mag;
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * mag >= raw) {
            step = m * mag;
            break;
        }
    std::vector<double> t;
    for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * span; v += step) t.push_back(v);
    return t;
}

}  // namespace

Vec3f displayColor(float r, float g, float b) { return {io::srgbDecode(r), io::srgbDecode(g), io::srgbDecode(b)}; }

Vec3f rampColor(float t) {
    static const float stops[5][3] = {{0.267f, 0.005f, 0.329f}, {0.231f, 0.322f, 0.545f}, {0.129f, 0.569f, 0.549f},
                                      {0.369f, 0.788f, 0.384f}, {0.993f, 0.906f, 0.144f}};
    t = std::clamp(std::isfinite(t) ? t : 0.f, 0.f, 1.f);
    float f = t * 4.f;
    int k = std::min(3, int(f));
    float a = f - k;
    return displayColor(stops[k][0] * (1 - a) + stops[k + 1][0] * a, stops[k][1] * (1 - a) + stops[k + 1][1] * a,
                        stops[k][2] * (1 - a) + stops[k + 1][2] * a);
}

Canvas::Canvas(int width, int height, const Vec3f& background) : m_image(width, height, background) {}

void Canvas::setPixel(int x, int y, const Vec3f& c) {
    if (x >= 0 && y >= 0 && x < m_image.width() && y < m_image.height()) m_image(x, y) = c;
}

void Canvas::fillRect(int x0, int y0, int x1, int y1, const Vec3f& c) {
    for (int y = std::max(0, y0); y < std::min(m_image.height(), y1); ++y)
        for (int x = std::max(0, x0); x < std::min(m_image.width(), x1); ++x) m_image(x, y) = c;
}

void Canvas::line(double x0, double y0, double x1, double y1, const Vec3f& c, int thickness, int dash) {
    double len = std::hypot(x1 - x0, y1 - y0);
    int steps = std::max(1, int(std::ceil(len * 2)));
    int lo = -(thickness - 1) / 2, hi = thickness / 2;
    for (int i = 0; i <= steps; ++i) {
        double t = double(i) / steps;
        if (dash > 0 && int(std::floor(t * len / dash)) % 2 == 1) continue;
        int px = int(std::lround(x0 + t * (x1 - x0))), py = int(std::lround(y0 + t * (y1 - y0)));
        for (int dy = lo; dy <= hi; ++dy)
            for (int dx = lo; dx <= hi; ++dx) setPixel(px + dx, py + dy, c);
    }
}

void Canvas::marker(double x, double y, const Vec3f& c, int kind, int size) {
    int cx = int(std::lround(x)), cy = int(std::lround(y));
    if (kind == 0) {
        fillRect(cx - size, cy - size, cx + size + 1, cy + size + 1, c);
    } else if (kind == 1) {
        line(cx - size, cy - size, cx + size, cy + size, c, 2);
        line(cx - size, cy + size, cx + size, cy - size, c, 2);
    } else {
        for (int dy = -size; dy <= size; ++dy)
            for (int dx = -size; dx <= size; ++dx)
                if (std::abs(dx) + std::abs(dy) <= size) setPixel(cx + dx, cy + dy, c);
    }
}

void Canvas::text(int x, int y, const std::string& s, const Vec3f& c, int scale) {
    for (size_t i = 0; i < s.size(); ++i) {
        const Glyph* g = findGlyph(s[i]);
        if (!g) continue;  // space and unknown characters: blank
        int gx = x + int(i) * 6 * scale;
        for (int r = 0; r < 7; ++r)
            for (int b = 0; b < 5; ++b)
                if (g->rows[r] & (0x10 >> b)) fillRect(gx + b * scale, y + r * scale, gx + (b + 1) * scale, y + (r + 1) * scale, c);
    }
}

namespace {

/// Where a LinePlot's frame sits in a width x height picture, how values map into it, and its
/// ticks with their labels: shared by the raster (renderPlot) and the SVG (svgPlot) drawings.
struct PlotGeometry {
    const LinePlot& plot;
    int width, height;
    // Log-axis labels as "%g" (0.005, 2e-05) instead of formatTick's two decimals, which print
    // small decades as 0.00; the raster plots keep formatTick's.
    bool gLabels = false;
    static constexpr int left = 70, right = 20, top = 34, bottom = 50;
    int pw = width - left - right, ph = height - top - bottom;

    double mapX(double x) const {
        double t = plot.logX ? (std::log(x) - std::log(plot.xMin)) / (std::log(plot.xMax) - std::log(plot.xMin))
                             : (x - plot.xMin) / (plot.xMax - plot.xMin);
        return left + t * pw;
    }
    double mapY(double y) const {
        double t = plot.logY ? (std::log(y) - std::log(plot.yMin)) / (std::log(plot.yMax) - std::log(plot.yMin))
                             : (y - plot.yMin) / (plot.yMax - plot.yMin);
        return top + ph - t * ph;
    }
    static std::vector<double> logTicks(double lo, double hi) {
        std::vector<double> t;
        for (double d = std::pow(10.0, std::floor(std::log10(lo))); d <= hi * 1.0001; d *= 10)
            for (double m : {1.0, 2.0, 5.0})
                if (m * d >= lo * 0.9999 && m * d <= hi * 1.0001) t.push_back(m * d);
        return t;
    }
    /// (value, label) of the x ticks and of the y ticks.
    std::vector<std::pair<double, std::string>> xTicks() const {
        std::vector<double> xt = plot.xTicks;
        if (xt.empty()) xt = plot.logX ? logTicks(plot.xMin, plot.xMax) : niceTicks(plot.xMin, plot.xMax, 8);
        std::vector<std::pair<double, std::string>> t;
        for (size_t i = 0; i < xt.size(); ++i)
            t.emplace_back(xt[i], i < plot.xTickLabels.size() ? plot.xTickLabels[i] : label(xt[i], plot.logX));
        return t;
    }
    std::vector<std::pair<double, std::string>> yTicks() const {
        std::vector<std::pair<double, std::string>> t;
        for (double v : plot.logY ? logTicks(plot.yMin, plot.yMax) : niceTicks(plot.yMin, plot.yMax, 6))
            t.emplace_back(v, label(v, plot.logY));
        return t;
    }
    std::string label(double v, bool logAxis) const {
        if (!gLabels || !logAxis) return formatTick(v);
        char buf[32];
        std::snprintf(buf, sizeof buf, "%g", v);
        return buf;
    }
};

/// A linear colour as the "#rrggbb" of its display value.
std::string svgColor(const Vec3f& c) {
    char buf[8];
    auto byte = [](float v) { return int(std::lround(255.f * std::clamp(srgbEncode(v), 0.f, 1.f))); };
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", byte(c.x), byte(c.y), byte(c.z));
    return buf;
}

}  // namespace

Image3f renderPlot(const LinePlot& plot, int width, int height) {
    const Vec3f white(1.f), black(0.f), grey = displayColor(0.85f, 0.85f, 0.85f);
    Canvas cv(width, height, white);
    const PlotGeometry g{plot, width, height};
    const int left = g.left, top = g.top, pw = g.pw, ph = g.ph;
    auto mapX = [&](double x) { return g.mapX(x); };
    auto mapY = [&](double y) { return g.mapY(y); };

    // Grid, ticks and tick labels.
    for (const auto& [v, label] : g.xTicks()) {
        double px = mapX(v);
        cv.line(px, top, px, top + ph, grey);
        cv.text(int(px) - Canvas::textWidth(label) / 2, top + ph + 8, label, black);
    }
    for (const auto& [v, label] : g.yTicks()) {
        double py = mapY(v);
        cv.line(left, py, left + pw, py, grey);
        cv.text(left - 8 - Canvas::textWidth(label), int(py) - 3, label, black);
    }
    cv.line(left, top, left, top + ph, black);
    cv.line(left, top + ph, left + pw, top + ph, black);
    cv.line(left, top, left + pw, top, black);
    cv.line(left + pw, top, left + pw, top + ph, black);

    cv.text((width - Canvas::textWidth(plot.title, 2)) / 2, 8, plot.title, black, 2);
    cv.text(left + (pw - Canvas::textWidth(plot.xLabel)) / 2, height - 18, plot.xLabel, black);
    cv.text(6, top - 14, plot.yLabel, black);

    // Data, clipped to the plot area.
    Canvas area(pw + 1, ph + 1, white);
    for (const auto& s : plot.series) {
        for (size_t i = 0; i < s.xs.size(); ++i) {
            double x = mapX(s.xs[i]) - left, y = mapY(s.ys[i]) - top;
            if (s.lines && i > 0) {
                double xp = mapX(s.xs[i - 1]) - left, yp = mapY(s.ys[i - 1]) - top;
                if (std::isfinite(x + y + xp + yp)) area.line(xp, yp, x, y, s.color, 2, s.dash);
            }
        }
        for (size_t i = 0; i < s.xs.size(); ++i)
            if (s.marker >= 0) area.marker(mapX(s.xs[i]) - left, mapY(s.ys[i]) - top, s.color, s.marker);
    }
    // Composite the area inside the frame (keeping grid lines where the area is background).
    for (int y = 1; y < ph; ++y)
        for (int x = 1; x < pw; ++x)
            if (!(area.image()(x, y) == white)) cv.setPixel(left + x, top + y, area.image()(x, y));

    // Legend, top-left inside the frame.
    int ly = top + 8, lx = left + 10;
    int lw = 0;
    for (const auto& s : plot.series) lw = std::max(lw, Canvas::textWidth(s.label));
    if (!plot.series.empty()) {
        cv.fillRect(lx - 4, ly - 4, lx + lw + 40, ly + int(plot.series.size()) * 14, white);
        for (const auto& s : plot.series) {
            if (s.lines) cv.line(lx, ly + 3, lx + 24, ly + 3, s.color, 2, s.dash ? 4 : 0);
            if (s.marker >= 0) cv.marker(lx + 12, ly + 3, s.color, s.marker, 3);
            cv.text(lx + 32, ly, s.label, black);
            ly += 14;
        }
    }
    return cv.image();
}

std::string svgPlot(const LinePlot& plot, int width, int height) {
    const PlotGeometry g{plot, width, height, true};
    std::string s;
    char buf[256];
    auto add = [&](const char* fmt, auto... args) {
        std::snprintf(buf, sizeof buf, fmt, args...);
        s += buf;
    };
    add("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
        "font-family=\"sans-serif\" font-size=\"11\">\n",
        width, height, width, height);
    add("<rect width=\"%d\" height=\"%d\" fill=\"#fff\"/>\n", width, height);
    for (const auto& [v, label] : g.xTicks()) {
        const double px = g.mapX(v);
        add("<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#ddd\"/>", px, g.top, px, g.top + g.ph);
        add("<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">", px, g.top + g.ph + 16);
        s += htmlEscape(label) + "</text>\n";
    }
    for (const auto& [v, label] : g.yTicks()) {
        const double py = g.mapY(v);
        add("<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#ddd\"/>", g.left, py, g.left + g.pw, py);
        add("<text x=\"%d\" y=\"%.1f\" text-anchor=\"end\">", g.left - 6, py + 4);
        s += htmlEscape(label) + "</text>\n";
    }
    add("<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"#000\"/>\n", g.left, g.top, g.pw,
        g.ph);
    add("<text x=\"%d\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">", width / 2);
    s += htmlEscape(plot.title) + "</text>\n";
    add("<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">", g.left + g.pw / 2, height - 10);
    s += htmlEscape(plot.xLabel) + "</text>\n";
    add("<text x=\"6\" y=\"%d\">", g.top - 8);
    s += htmlEscape(plot.yLabel) + "</text>\n";

    // Data, clipped to the frame; ids unique per plot so that several can share a page.
    static int plots = 0;
    const std::string clip = "wedge-plot-clip-" + std::to_string(plots++);
    add("<clipPath id=\"%s\"><rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\"/></clipPath>\n<g clip-path=\"url(#%s)\">\n",
        clip.c_str(), g.left, g.top, g.pw, g.ph, clip.c_str());
    for (const auto& ser : plot.series) {
        const std::string color = svgColor(ser.color);
        if (ser.lines && ser.xs.size() > 1) {
            s += "<polyline fill=\"none\" stroke=\"" + color + "\" stroke-width=\"2\"" +
                 (ser.dash ? " stroke-dasharray=\"" + std::to_string(ser.dash) + "\"" : "") + " points=\"";
            for (size_t i = 0; i < ser.xs.size(); ++i) add("%.1f,%.1f ", g.mapX(ser.xs[i]), g.mapY(ser.ys[i]));
            s += "\"/>\n";
        }
        if (ser.marker >= 0)
            for (size_t i = 0; i < ser.xs.size(); ++i)
                add("<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3.5\" fill=\"%s\"/>", g.mapX(ser.xs[i]), g.mapY(ser.ys[i]),
                    color.c_str());
        s += "\n";
    }
    s += "</g>\n";
    // Legend, top-right inside the frame.
    int ly = g.top + 14;
    for (const auto& ser : plot.series) {
        const int lx = g.left + g.pw - 110;
        add("<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"%s\" stroke-width=\"2\"/>", lx, ly - 4, lx + 24,
            ly - 4, svgColor(ser.color).c_str());
        add("<text x=\"%d\" y=\"%d\">", lx + 30, ly);
        s += htmlEscape(ser.label) + "</text>\n";
        ly += 15;
    }
    return s + "</svg>\n";
}

Image3f besideEachOther(const std::vector<Image3f>& images, int gap) {
    int w = 0, h = 0;
    for (const auto& im : images) {
        w += im.width() + gap;
        h = std::max(h, im.height());
    }
    w += gap;
    h += 2 * gap;
    Image3f out(w, h, Vec3f(1.f));
    int x0 = gap;
    for (const auto& im : images) {
        for (int y = 0; y < im.height(); ++y)
            for (int x = 0; x < im.width(); ++x) out(x0 + x, gap + y) = im(x, y);
        x0 += im.width() + gap;
    }
    return out;
}

}  // namespace wedge::io
