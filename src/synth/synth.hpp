#pragma once
// Maps as a robot would build them: range scans along a trajectory, with occlusion,
// registered with noisy poses, expressed in the robot's own map frame.
#include <functional>

#include "scene.hpp"

namespace tomomap::synth {

/// The paper's simulation noise: per-reading pose perturbation and range noise.
struct NoiseModel {
  double pose_translation = 0;  ///< sigma of x, y, z per scan [m]
  double pose_yaw = 0;          ///< sigma of yaw per scan [rad]
  double range = 0;             ///< sigma of range up to 3 m [m]; grows with range^2 beyond, like a stereo depth camera
};

/// "none", "low" (0.02 m / 0.01 rad, range 0.01 m) or "high" (0.05 m / 0.025 rad, range 0.02 m).
NoiseModel noiseLevel(const std::string& name);

struct SynthMap {
  Points points;  ///< in the map frame, voxel-filtered at the scene's map resolution
  /// Ground truth in the convention of the shared datasets (demo-room): the
  /// world -> map matrix, so that T_target_source = pose_target * pose_source^-1.
  Eigen::Matrix4d pose;
  size_t rays = 0, hits = 0;
};

/// Scans the scene along every trajectory. Deterministic from `seed`; parallel over scans.
std::vector<SynthMap> scanScene(const Scene& scene, const NoiseModel& noise, uint64_t seed,
                                const std::function<void(size_t, size_t)>& progress = {});

/// Rolls a map's frame by `angle` about its x axis, points and ground truth
/// together: a map from LiDAR odometry whose first sensor frame leaned.
void roll(SynthMap& map, double angle);

}  // namespace tomomap::synth
