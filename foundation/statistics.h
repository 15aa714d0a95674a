// Order statistics of measurements (frame times, ratios, motion per frame).
//
// percentile(): linear interpolation between the closest ranks of a sorted
// copy of v (p in [0, 1], clamped; p = 0.5 is the median, the mean of the two
// middle values for an even count). Non-finite values are ignored; NaN when
// none is left. Pure; thread-safe.
#pragma once
#include <vector>

namespace vista {

double percentile(std::vector<double> v, double p);
inline double median(std::vector<double> v) { return percentile(std::move(v), 0.5); }

}  // namespace vista
