#pragma once
// Procedural scenes: a world, the range sensor that sees it, and one trajectory per map.
#include <cstdint>
#include <string>

#include "core/types.hpp"
#include "world.hpp"

namespace tomomap::synth {

enum class WorldType { Indoor, Outdoor, Room };

/// Parses "indoor" / "outdoor" / "room"; throws InputError otherwise.
WorldType parseWorldType(const std::string& name);
std::string toString(WorldType type);

/// A spinning multi-beam range sensor.
struct SensorModel {
  int beams = 32;               ///< vertical channels
  double elevation_min = -0.7;  ///< [rad]
  double elevation_max = 0.7;   ///< [rad]
  int azimuth_steps = 360;      ///< readings per revolution per beam
  double max_range = 10.0;      ///< [m]
};

struct Scene {
  World world;
  SensorModel sensor;
  std::vector<std::vector<Pose4>> trajectories;  ///< sensor poses in the world, one list per map
  double grid = 0.05;                            ///< grid size the scene is meant to be matched at [m]
  double map_resolution = 0.02;                  ///< voxel size the generated maps are stored at [m]
};

struct SceneParams {
  WorldType type = WorldType::Indoor;
  uint64_t seed = 1;
  int maps = 2;        ///< trajectories (maps) through the world, overlapping in sequence
  double scale = 1.0;  ///< stretches the world's length (outdoor street, indoor corridor)
  double tilt = 0.0;   ///< every map but the first is rolled this much about its x axis (see roll) [rad]
};

/// Indoor: a two-floor building, corridor with rooms on both sides, doors,
/// furniture. Outdoor: a street with facades of varied heights, trees, poles,
/// parked cars and uneven ground. Room: one furnished room with a
/// partition across half its depth, each map scanned from one side (partial
/// overlap, under 32 slices at g = 0.1). Deterministic from the seed.
Scene makeScene(const SceneParams& params);

}  // namespace tomomap::synth
