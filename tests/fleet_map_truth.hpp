#pragma once
// How far a fleet's map lies from the truth: its cells against the maps of a
// generated world (`tomomap synth`) merged by their true poses.
#include <unordered_set>

#include "core/fleet_map.hpp"
#include "core/lattice.hpp"
#include "core/voxel_filter.hpp"
#include "io/map_io.hpp"
#include "support.hpp"

namespace tomomap::test {

/// Map i's pose in map 0's frame, from the generator's poses in `world` (world to map: P_0 P_i^-1).
inline Eigen::Matrix4d truthOf(const std::string& world, int i) {
  return loadPoseFile(world + "/map_0-gtpose.txt") *
         loadPoseFile(world + "/map_" + std::to_string(i) + "-gtpose.txt").inverse();
}

/// Whether `p` lies in one of `cells` (lattice keys at `grid`) or in one of its 26 neighbours.
inline bool nearACell(const std::unordered_set<uint64_t>& cells, const Eigen::Vector3f& p, double grid) {
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz)
        if (cells.count(latticeKey(p + Eigen::Vector3i(dx, dy, dz).cast<float>() * static_cast<float>(grid), grid)))
          return true;
  return false;
}

/// The share of `merged`'s cells (in map 0's frame) within one cell (a
/// neighbour on the lattice of `grid`) of a cell of `world`'s first `maps`
/// maps merged by their true poses.
inline double shareNearTheTruth(const std::string& world, const Points& merged, int maps, double grid) {
  std::vector<PlacedMap> truth;
  for (int i = 0; i < maps; ++i)
    truth.push_back({"m" + std::to_string(i), voxelFilter(loadMap(world + "/map_" + std::to_string(i) + ".pcd"), grid),
                     truthOf(world, i)});
  std::unordered_set<uint64_t> cells;
  for (const auto& p : mergeMaps(truth, grid).points) cells.insert(latticeKey(p, grid));
  size_t near = 0;
  for (const auto& p : merged) near += nearACell(cells, p, grid);
  return merged.empty() ? 0.0 : static_cast<double>(near) / static_cast<double>(merged.size());
}

}  // namespace tomomap::test
