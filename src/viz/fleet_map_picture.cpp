#include "fleet_map_picture.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "canvas.hpp"

namespace tomomap::viz {

cv::Scalar robotColour(size_t i) { return colour::kSeries[i % colour::kSeries.size()]; }

uint32_t robotRgb(size_t i) {
  const cv::Scalar c = robotColour(i);  // B, G, R
  return (static_cast<uint32_t>(c[2]) << 16) | (static_cast<uint32_t>(c[1]) << 8) | static_cast<uint32_t>(c[0]);
}

std::vector<uint32_t> robotRgbs(size_t n) {
  std::vector<uint32_t> rgb;
  for (size_t r = 0; r < n; ++r) rgb.push_back(robotRgb(r));
  return rgb;
}

cv::Mat drawFleetMap(const FleetMap& map, double z_low, double z_high, const std::vector<std::string>& caption) {
  Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (const auto& p : map.points) {
    lo = lo.cwiseMin(p.head<2>().cast<double>());
    hi = hi.cwiseMax(p.head<2>().cast<double>());
  }
  if (map.points.empty()) lo = hi = Eigen::Vector2d::Zero();
  lo.array() -= map.grid / 2;  // the cells' corners, not their centres
  const double extent = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1.0});
  // About 1000 pixels across; a cell is drawn as a square of at least one pixel.
  const double px = extent / 1000.0;
  const int cell_px = std::max(1, static_cast<int>(std::ceil(map.grid / px)));  // cells touch: no seams
  const int w = static_cast<int>((hi.x() - lo.x()) / px) + cell_px,
            h = static_cast<int>((hi.y() - lo.y()) / px) + cell_px;
  cv::Mat plot(h, w, CV_8UC3, colour::kWhite);
  const auto cellAt = [&](const Eigen::Vector3f& p) {
    const int u = static_cast<int>((p.x() - lo.x()) / px), v = h - cell_px - static_cast<int>((p.y() - lo.y()) / px);
    return cv::Rect(u, v, cell_px, cell_px);
  };
  // The grey first, then the band over it, the first robot last (on top where maps overlap).
  for (const auto& p : map.points)
    if (p.z() < z_low || p.z() > z_high) cv::rectangle(plot, cellAt(p), colour::kLightGrey, cv::FILLED);
  for (size_t r = map.agents.size(); r-- > 0;)
    for (size_t i = 0; i < map.points.size(); ++i)
      if (map.robot[i] == r && map.points[i].z() >= z_low && map.points[i].z() <= z_high)
        cv::rectangle(plot, cellAt(map.points[i]), robotColour(r), cv::FILLED);
  std::vector<std::pair<std::string, cv::Scalar>> legend;
  for (size_t r = 0; r < map.agents.size(); ++r) legend.emplace_back(map.agents[r], robotColour(r));
  legend.emplace_back("outside the height band", colour::kLightGrey);
  return framePlanView(plot, lo, px, caption, legend);
}

}  // namespace tomomap::viz
