#pragma once
// Box plots like the paper's evaluation figures: one box per method within each
// group (noise level), whiskers at the 10th and 90th percentiles, every sample
// drawn as a dot, an optional dashed threshold line.
#include <map>

#include "canvas.hpp"

namespace tomomap::viz {

struct BoxPanel {
  std::string title;       ///< e.g. "translation error"
  std::string axis_label;  ///< value axis, with unit, e.g. "error [grid cells]"
  bool log = false;        ///< logarithmic value axis (errors span decades)
  double threshold = NAN;  ///< drawn dashed when finite
  std::string threshold_label;
  std::vector<std::string> groups;  ///< along the horizontal axis, in order
  std::vector<std::string> series;  ///< one box per series within a group (legend), in order
  /// values[{group, series}]: the samples; NaN samples are left out.
  std::map<std::pair<std::string, std::string>, std::vector<double>> values;
};

cv::Mat drawBoxPanel(const BoxPanel& panel, cv::Size size = {760, 460});

}  // namespace tomomap::viz
