// The plotter (cmd/plot.h): series drawn, bad values survived.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <unistd.h>

#include "runtime/engine/image.h"
#include "runtime/engine/metrics.h"
#include "cmd/plot.h"

using namespace vista;

TEST(Plot, DrawsSeriesAndSurvivesBadValues) {
    PlotSpec s;
    s.title = "Frame time";
    s.xLabel = "frame";
    s.yLabel = "ms";
    PlotSeries a;
    a.label = "full";
    a.color = {200, 0, 0};
    for (int i = 0; i < 50; ++i) {
        a.x.push_back(i);
        a.y.push_back(10 + (i % 7));
    }
    a.y[10] = std::nan("");
    s.series.push_back(a);
    Image img = renderPlot(s);
    ASSERT_TRUE(img.valid());
    size_t red = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (img.at(x, y) == glm::u8vec4(200, 0, 0, 255)) ++red;
    EXPECT_GT(red, 200u);
    PlotSpec empty;
    empty.logX = empty.logY = true;
    EXPECT_TRUE(renderPlot(empty).valid());
}
