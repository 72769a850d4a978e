#include "bit_raster.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace tomomap {

BitRaster::Stamp BitRaster::disk(double radius_cells) {
  const int r = static_cast<int>(std::floor(radius_cells));
  const cv::Mat shape = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  Stamp out;
  for (int v = 0; v < shape.rows; ++v)
    for (int u = 0; u < shape.cols; ++u)
      if (shape.at<uint8_t>(v, u)) out.emplace_back(u - r, v - r);
  return out;
}

}  // namespace tomomap
