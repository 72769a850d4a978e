#pragma once
// Log-log line plots: a cost against a size, one line per method, where a
// straight line's slope is the growth exponent.
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

/// Both axes logarithmic; the x values of the points are the x ticks.
cv::Mat drawLogLogPanel(const LinePanel& panel, cv::Size size = {760, 460});

/// The least-squares slope of log y against log x: the exponent of y ~ x^k.
double logLogSlope(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace tomomap::viz
