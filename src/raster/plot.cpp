// The sweep plot's renderer: log axes, anti-aliased segments and discs by distance coverage, and a
// built-in 5x7 bitmap font (see plot.h).
#include "raster/plot.h"

#include <cstdio>

namespace wedge::raster {

namespace {

/// 5x7 glyphs, one byte per row from the top, bit 4 the leftmost column.
struct Glyph {
    char c;
    uint8_t rows[7];
};
constexpr Glyph kFont[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'A', {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}}, {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
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
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}}, {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}}, {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}}, {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}}, {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
    {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}},
};

const Glyph* findGlyph(char c) {
    if (c >= 'a' && c <= 'z') c = char(c - 'a' + 'A');
    for (const Glyph& g : kFont)
        if (g.c == c) return &g;
    return nullptr;  // space and unknown characters draw nothing
}

void blend(Image3f& img, int x, int y, const Vec3f& c, float alpha) {
    if (x < 0 || y < 0 || x >= img.width() || y >= img.height() || alpha <= 0) return;
    alpha = std::min(alpha, 1.f);
    img(x, y) = img(x, y) * (1.f - alpha) + c * alpha;
}

/// Anti-aliased segment of the given width (coverage from the distance to the segment).
void drawSegment(Image3f& img, float x0, float y0, float x1, float y1, float width, const Vec3f& c) {
    float half = 0.5f * width;
    int bx0 = int(std::floor(std::min(x0, x1) - half - 1)), bx1 = int(std::ceil(std::max(x0, x1) + half + 1));
    int by0 = int(std::floor(std::min(y0, y1) - half - 1)), by1 = int(std::ceil(std::max(y0, y1) + half + 1));
    float dx = x1 - x0, dy = y1 - y0, len2 = dx * dx + dy * dy;
    for (int y = std::max(0, by0); y <= std::min(img.height() - 1, by1); ++y)
        for (int x = std::max(0, bx0); x <= std::min(img.width() - 1, bx1); ++x) {
            float px = x + 0.5f - x0, py = y + 0.5f - y0;
            float t = len2 > 0 ? std::clamp((px * dx + py * dy) / len2, 0.f, 1.f) : 0.f;
            float d = std::hypot(px - t * dx, py - t * dy);
            blend(img, x, y, c, half + 0.5f - d);
        }
}

void drawDisc(Image3f& img, float cx, float cy, float radius, const Vec3f& c) {
    for (int y = int(cy - radius - 1); y <= int(cy + radius + 1); ++y)
        for (int x = int(cx - radius - 1); x <= int(cx + radius + 1); ++x)
            blend(img, x, y, c, radius + 0.5f - std::hypot(x + 0.5f - cx, y + 0.5f - cy));
}

std::string compactNumber(double v) {
    char buf[32];
    if (v >= 1e6 && std::fmod(v, 1e6) == 0) std::snprintf(buf, sizeof buf, "%.0fM", v / 1e6);
    else if (v >= 1e6) std::snprintf(buf, sizeof buf, "%.1fM", v / 1e6);
    else if (v >= 1e4 && std::fmod(v, 1e3) == 0) std::snprintf(buf, sizeof buf, "%.0fK", v / 1e3);
    else std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
}

}  // namespace

int textWidth(const std::string& text, int scale) { return int(text.size()) * 6 * scale - scale; }

void drawText(Image3f& img, int x, int y, const std::string& text, int scale, const Vec3f& colour) {
    for (size_t i = 0; i < text.size(); ++i) {
        const Glyph* g = findGlyph(text[i]);
        if (!g) continue;
        int gx = x + int(i) * 6 * scale;
        for (int row = 0; row < 7; ++row)
            for (int col = 0; col < 5; ++col)
                if (g->rows[row] & (0x10 >> col))
                    for (int sy = 0; sy < scale; ++sy)
                        for (int sx = 0; sx < scale; ++sx) blend(img, gx + col * scale + sx, y + row * scale + sy, colour, 1.f);
    }
}

Image3f drawLinePlot(const PlotSpec& spec) {
    const Vec3f white(1.f), black(0.f), grid(0.85f), minorGrid(0.93f), text(0.1f);
    Image3f img(spec.width, spec.height, white);
    const int left = 96, right = 24, top = 56, bottom = 64;
    const int pw = spec.width - left - right, ph = spec.height - top - bottom;

    auto tx = [&](double v) { return spec.logX ? std::log2(v) : v; };
    auto ty = [&](double v) { return spec.logY ? std::log10(v) : v; };
    auto usable = [&](double x, double y) { return (!spec.logX || x > 0) && (!spec.logY || y > 0); };
    double xMin = kInf, xMax = -kInf, yMin = kInf, yMax = -kInf;
    for (const auto& s : spec.series)
        for (size_t i = 0; i < s.x.size(); ++i)
            if (usable(s.x[i], s.y[i])) {
                xMin = std::min(xMin, tx(s.x[i]));
                xMax = std::max(xMax, tx(s.x[i]));
                yMin = std::min(yMin, ty(s.y[i]));
                yMax = std::max(yMax, ty(s.y[i]));
            }
    if (!(xMin <= xMax)) xMin = 0, xMax = 1, yMin = 0, yMax = 1;
    if (xMax - xMin < 1e-9) xMin -= 1, xMax += 1;
    double xPad = 0.06 * (xMax - xMin);
    xMin -= xPad;
    xMax += xPad;
    if (spec.logY) {
        yMin = std::floor(yMin);
        yMax = std::ceil(yMax);
        if (yMax - yMin < 1) yMax = yMin + 1;
    } else {
        double pad = 0.06 * std::max(yMax - yMin, 1e-9);
        yMin -= pad;
        yMax += pad;
    }
    auto sx = [&](double v) { return float(left + (tx(v) - xMin) / (xMax - xMin) * pw); };
    auto sy = [&](double v) { return float(top + ph - (ty(v) - yMin) / (yMax - yMin) * ph); };

    // Grid lines and tick labels: x at the data's x values, y at decades (minor lines at 2 and 5).
    std::vector<double> xTicks;
    for (const auto& s : spec.series)
        for (double v : s.x)
            if (std::find(xTicks.begin(), xTicks.end(), v) == xTicks.end() && (!spec.logX || v > 0)) xTicks.push_back(v);
    for (double v : xTicks) {
        float x = sx(v);
        drawSegment(img, x, float(top), x, float(top + ph), 1.f, grid);
        std::string label = compactNumber(v);
        drawText(img, int(x) - textWidth(label, 2) / 2, top + ph + 10, label, 2, text);
    }
    if (spec.logY) {
        for (int d = int(yMin); d < int(yMax) + 1; ++d) {
            double v = std::pow(10.0, d);
            for (double m : {2.0, 5.0})
                if (d < int(yMax)) {
                    float y = sy(v * m);
                    drawSegment(img, float(left), y, float(left + pw), y, 1.f, minorGrid);
                }
            float y = sy(v);
            drawSegment(img, float(left), y, float(left + pw), y, 1.f, grid);
            std::string label = compactNumber(v);
            drawText(img, left - 8 - textWidth(label, 2), int(y) - 7, label, 2, text);
        }
    }
    drawSegment(img, float(left), float(top), float(left), float(top + ph), 1.5f, black);
    drawSegment(img, float(left), float(top + ph), float(left + pw), float(top + ph), 1.5f, black);

    for (const auto& s : spec.series) {
        float px = 0, py = 0;
        bool have = false;
        for (size_t i = 0; i < s.x.size(); ++i) {
            if (!usable(s.x[i], s.y[i])) continue;
            float x = sx(s.x[i]), y = sy(s.y[i]);
            if (have) {
                if (s.dashed) {
                    float len = std::hypot(x - px, y - py);
                    int dashes = std::max(1, int(len / 10.f));
                    for (int k = 0; k < dashes; k += 2)
                        drawSegment(img, px + (x - px) * k / dashes, py + (y - py) * k / dashes,
                                    px + (x - px) * (k + 1) / dashes, py + (y - py) * (k + 1) / dashes, 2.f, s.colour);
                } else {
                    drawSegment(img, px, py, x, y, 2.5f, s.colour);
                }
            }
            if (!s.dashed) drawDisc(img, x, y, 4.f, s.colour);
            px = x;
            py = y;
            have = true;
        }
    }

    // Legend in the top-right corner of the plot area.
    int ly = top + 12;
    for (const auto& s : spec.series) {
        int lw = textWidth(s.label, 2);
        int lx = left + pw - 16 - lw - 40;
        if (s.dashed) {
            for (int k = 0; k < 3; ++k) drawSegment(img, float(lx + 12 * k), float(ly + 7), float(lx + 12 * k + 6), float(ly + 7), 2.f, s.colour);
        } else {
            drawSegment(img, float(lx), float(ly + 7), float(lx + 30), float(ly + 7), 2.5f, s.colour);
        }
        if (!s.dashed) drawDisc(img, float(lx + 15), float(ly + 7), 4.f, s.colour);
        drawText(img, lx + 40, ly, s.label, 2, text);
        ly += 22;
    }

    drawText(img, (spec.width - textWidth(spec.title, 2)) / 2, 14, spec.title, 2, text);
    drawText(img, left + (pw - textWidth(spec.xLabel, 2)) / 2, spec.height - 26, spec.xLabel, 2, text);
    drawText(img, 8, top - 22, spec.yLabel, 2, text);
    return img;
}

}  // namespace wedge::raster
