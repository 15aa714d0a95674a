#include "cmd/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace vista {

namespace {

struct Glyph {
    char c;
    uint8_t rows[7];
};

// 5x7 glyphs, one byte per row (bit 4 = leftmost column).
const Glyph kFont[] = {
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
    {'x', {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11}}, {' ', {0, 0, 0, 0, 0, 0, 0}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}},
    {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}}, {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
    {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}}, {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}}, {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}},
    {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}}, {'[', {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E}},
    {']', {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E}}, {'>', {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08}},
    {'<', {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02}}, {'*', {0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00}},
};

const uint8_t* glyphFor(char c) {
    if (c >= 'a' && c <= 'z' && c != 'x') c = char(c - 'a' + 'A');
    for (const auto& g : kFont)
        if (g.c == c) return g.rows;
    return nullptr;
}

void putPixel(Image& img, int x, int y, glm::u8vec3 c) {
    if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
    img.set(x, y, glm::u8vec4(c, 255));
}

void fillRect(Image& img, int x0, int y0, int x1, int y1, glm::u8vec3 c) {
    for (int y = std::max(0, y0); y <= std::min(img.height - 1, y1); ++y)
        for (int x = std::max(0, x0); x <= std::min(img.width - 1, x1); ++x) img.set(x, y, glm::u8vec4(c, 255));
}

void line(Image& img, int x0, int y0, int x1, int y1, glm::u8vec3 c, int thick = 1) {
    int dx = std::abs(x1 - x0), sx = x0 < x1 ? 1 : -1, dy = -std::abs(y1 - y0), sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    for (int guard = 0; guard < 100000; ++guard) {
        if (thick <= 1) putPixel(img, x0, y0, c);
        else fillRect(img, x0 - thick / 2, y0 - thick / 2, x0 + (thick - 1) / 2, y0 + (thick - 1) / 2, c);
        if (x0 == x1 && y0 == y1) break;
        int e2 = 2 * err;
        if (e2 >= dy) {
            err += dy;
            x0 += sx;
        }
        if (e2 <= dx) {
            err += dx;
            y0 += sy;
        }
    }
}

std::string fmtTick(double v) {
    char buf[32];
    if (v != 0 && (std::abs(v) >= 1e6 || std::abs(v) < 1e-3)) std::snprintf(buf, sizeof(buf), "%.0e", v);
    else std::snprintf(buf, sizeof(buf), "%g", v);
    return buf;
}

// "Nice" linear ticks covering [lo, hi].
std::vector<double> niceTicks(double lo, double hi, int target = 6) {
    double span = hi - lo;
    double raw = span / target, mag = std::pow(10.0, std::floor(std::log10(raw)));
    double step = mag;
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * mag >= raw) {
            step = m * mag;
            break;
        }
    std::vector<double> t;
    for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9 && t.size() < 50; v += step)
        t.push_back(std::abs(v) < step * 1e-9 ? 0.0 : v);
    return t;
}

struct Axis {
    double lo = 0, hi = 1;
    bool log = false;
    double map(double v) const {  // -> 0..1
        if (log) return (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
        return (v - lo) / (hi - lo);
    }
    bool ok(double v) const { return std::isfinite(v) && (!log || v > 0); }
    std::vector<double> ticks() const {
        if (!log) return niceTicks(lo, hi);
        std::vector<double> t;
        for (double e = std::floor(std::log10(lo)); e <= std::ceil(std::log10(hi)); e += 1) {
            for (double m : {1.0, 2.0, 5.0}) {
                double v = m * std::pow(10.0, e);
                if (v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) t.push_back(v);
            }
        }
        return t;
    }
};

Axis makeAxis(const std::vector<const std::vector<double>*>& data, bool log, bool fromZero) {
    Axis a;
    a.log = log;
    double lo = 1e300, hi = -1e300;
    for (const auto* v : data)
        for (double x : *v)
            if (a.ok(x)) {
                lo = std::min(lo, x);
                hi = std::max(hi, x);
            }
    if (lo > hi) {
        lo = log ? 1 : 0;
        hi = log ? 10 : 1;
    }
    if (!log && fromZero && lo >= 0) lo = 0;
    if (hi - lo <= 0) {
        if (log) {
            lo /= 2;
            hi *= 2;
        } else {
            double d = std::max(1.0, std::abs(hi) * 0.1);
            lo -= d;
            hi += d;
        }
    }
    if (log) {  // widen to decades' 1-2-5 marks
        lo = std::pow(10.0, std::floor(std::log10(lo) * 4) / 4);
        hi = std::pow(10.0, std::ceil(std::log10(hi) * 4) / 4);
    } else {
        auto t = niceTicks(lo, hi);
        double step = t.size() > 1 ? t[1] - t[0] : (hi - lo);
        lo = std::floor(lo / step + 1e-9) * step;
        hi = std::ceil(hi / step - 1e-9) * step;
        if (hi <= lo) hi = lo + step;
    }
    a.lo = lo;
    a.hi = hi;
    return a;
}

}  // namespace

int textWidth(const std::string& text, int scale) { return int(text.size()) * 6 * scale; }

void drawText(Image& img, int x, int y, const std::string& text, glm::u8vec3 color, int scale) {
    for (size_t i = 0; i < text.size(); ++i) {
        const uint8_t* g = glyphFor(text[i]);
        int ox = x + int(i) * 6 * scale;
        for (int r = 0; r < 7; ++r)
            for (int col = 0; col < 5; ++col) {
                bool on = g ? (g[r] >> (4 - col)) & 1 : (r == 0 || r == 6 || col == 0 || col == 4);
                if (on)
                    fillRect(img, ox + col * scale, y + r * scale, ox + col * scale + scale - 1,
                             y + r * scale + scale - 1, color);
            }
    }
}

glm::u8vec3 plotColor(size_t i) {
    static const glm::u8vec3 kPalette[] = {{31, 119, 180},  {214, 39, 40}, {44, 160, 44},   {255, 127, 14},
                                           {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127},
                                           {188, 189, 34},  {23, 190, 207}};
    return kPalette[i % (sizeof(kPalette) / sizeof(kPalette[0]))];
}

Image renderPlot(const PlotSpec& spec) {
    int W = std::max(200, spec.width), H = std::max(150, spec.height);
    Image img(W, H);
    fillRect(img, 0, 0, W - 1, H - 1, {255, 255, 255});
    size_t maxLabel = 0;
    for (const auto& s : spec.series) maxLabel = std::max(maxLabel, s.label.size());
    const int left = 78, top = 34, bottom = 48, right = 24 + std::min<int>(240, int(maxLabel) * 6 + 30);
    const int px0 = left, px1 = W - right, py0 = top, py1 = H - bottom;
    std::vector<const std::vector<double>*> xs, ys;
    for (const auto& s : spec.series) {
        xs.push_back(&s.x);
        ys.push_back(&s.y);
    }
    Axis ax = makeAxis(xs, spec.logX, false), ay = makeAxis(ys, spec.logY, spec.yFromZero);
    auto sx = [&](double v) { return px0 + int(std::lround(ax.map(v) * (px1 - px0))); };
    auto sy = [&](double v) { return py1 - int(std::lround(ay.map(v) * (py1 - py0))); };
    const glm::u8vec3 grid{225, 225, 225}, black{0, 0, 0};
    for (double t : ax.ticks()) {
        int x = sx(t);
        line(img, x, py0, x, py1, grid);
        std::string s = fmtTick(t);
        drawText(img, x - textWidth(s) / 2, py1 + 6, s, black);
    }
    for (double t : ay.ticks()) {
        int y = sy(t);
        line(img, px0, y, px1, y, grid);
        std::string s = fmtTick(t);
        drawText(img, px0 - 6 - textWidth(s), y - 3, s, black);
    }
    line(img, px0, py0, px0, py1, black);
    line(img, px0, py1, px1, py1, black);
    line(img, px1, py0, px1, py1, black);
    line(img, px0, py0, px1, py0, black);
    drawText(img, (W - textWidth(spec.title, 2)) / 2, 8, spec.title, black, 2);
    drawText(img, (px0 + px1 - textWidth(spec.xLabel)) / 2, H - 18, spec.xLabel, black);
    drawText(img, 4, py0 - 14, spec.yLabel, black);
    int ly = py0 + 6;
    for (const auto& s : spec.series) {
        fillRect(img, px1 + 10, ly + 1, px1 + 24, ly + 5, s.color);
        drawText(img, px1 + 30, ly, s.label, black);
        ly += 14;
        bool have = false;
        int lx = 0, lyy = 0;
        size_t n = std::min(s.x.size(), s.y.size());
        for (size_t i = 0; i < n; ++i) {
            if (!ax.ok(s.x[i]) || !ay.ok(s.y[i])) {
                have = false;
                continue;
            }
            int x = std::clamp(sx(s.x[i]), px0, px1), y = std::clamp(sy(s.y[i]), py0, py1);
            if (s.line && have) line(img, lx, lyy, x, y, s.color, 2);
            if (s.points) fillRect(img, x - 2, y - 2, x + 2, y + 2, s.color);
            lx = x;
            lyy = y;
            have = true;
        }
    }
    return img;
}

}  // namespace vista
