#pragma once
// Line plots, one line per series: log-log (a cost against a size, where a
// straight line's slope is the growth exponent) or linear (a figure over time).
#include <string>
#include <vector>

#include "canvas.hpp"

namespace tomomap::viz {

struct LineSeries {
  std::string name;          ///< legend entry
  std::vector<double> x, y;  ///< points, by increasing x; values <= 0 are left out
};

struct LinePanel {
  std::string title;
  std::string x_label, y_label;  ///< with units
  std::vector<LineSeries> series;
};

enum class Axes {
  LogLog,  ///< both axes logarithmic; the x values of the points are the x ticks
  Linear,  ///< both axes linear from zero, 1-2-5 ticks
};

cv::Mat drawLinePanel(const LinePanel& panel, Axes axes, cv::Size size = {760, 460});

/// The least-squares slope of log y against log x: the exponent of y ~ x^k.
double logLogSlope(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace tomomap::viz
