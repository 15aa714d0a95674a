// Plot: a small PNG line/scatter plotter with a built-in 5x7 bitmap font
// (no dependencies beyond Image). Used for the bench's frame-time and
// quality plots and the size sweep.
//
// Contract: renderPlot() never fails: empty series, NaN/inf values (skipped)
// and degenerate ranges are handled; log axes skip values <= 0. Text uses
// upper-case glyphs (lower-case letters are drawn as capitals) for
// characters outside the font, a box is drawn. Pure; thread-safe.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "runtime/engine/image.h"

namespace vista {

struct PlotSeries {
    std::string label;
    std::vector<double> x, y;
    glm::u8vec3 color{0, 0, 0};
    bool line = true;     // connect consecutive points
    bool points = false;  // draw a marker at each point
};

struct PlotSpec {
    std::string title, xLabel, yLabel;
    int width = 960, height = 540;
    bool logX = false, logY = false;
    bool yFromZero = true;  // linear y axis starts at 0 when all values are >= 0
    std::vector<PlotSeries> series;
};

Image renderPlot(const PlotSpec& spec);
// A colour from a fixed palette of distinguishable colours (index wraps).
glm::u8vec3 plotColor(size_t index);
// Draws `text` with the 5x7 font at (x, y) (top-left), scaled by `scale`.
void drawText(Image& img, int x, int y, const std::string& text, glm::u8vec3 color, int scale = 1);
int textWidth(const std::string& text, int scale = 1);

}  // namespace vista
