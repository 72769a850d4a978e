#pragma once
// The fleet's map from above, each robot in its colour.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/fleet_map.hpp"

namespace tomomap::viz {

/// Robot `i`'s colour (BGR): the series colours in turn.
cv::Scalar robotColour(size_t i);
/// The same as 0xRRGGBB (a PCD's rgb field).
uint32_t robotRgb(size_t i);
/// robotRgb of robots 0 to n - 1.
std::vector<uint32_t> robotRgbs(size_t n);

/// Every cell of the map whose height lies in [z_low, z_high] (the obstacles
/// a robot of that height meets) in the colour of the robot that saw it
/// (where maps overlap, the first's), the rest of what the maps hold in light
/// grey; metre ticks, the caption above and a legend naming the robots.
cv::Mat drawFleetMap(const FleetMap& map, double z_low, double z_high, const std::vector<std::string>& caption);

}  // namespace tomomap::viz
