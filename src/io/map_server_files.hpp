#pragma once
// A 2D occupancy grid as ROS's map_server (nav2_map_server, map_saver_cli)
// reads and writes it: a PGM image and a YAML file beside it.
#include <string>

#include "core/fleet_map.hpp"

namespace tomomap {

/// Writes STEM.pgm (trinary: 0 occupied, 254 free, 205 unknown; its top row
/// is the grid's highest y, as map_saver writes) and STEM.yaml (image,
/// mode, resolution, origin, negate, occupied_thresh, free_thresh). Throws
/// InputError if either cannot be written or the grid is empty.
void saveMapServerMap(const std::string& stem, const OccupancyGrid2D& grid);

}  // namespace tomomap
