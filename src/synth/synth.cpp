#include "synth.hpp"

#include <atomic>
#include <random>

#include "core/gravity.hpp"
#include "core/voxel_filter.hpp"

namespace tomomap::synth {

NoiseModel noiseLevel(const std::string& name) {
  if (name == "none") return {};
  if (name == "low") return {0.02, 0.01, 0.01};
  if (name == "high") return {0.05, 0.025, 0.02};
  throw InputError("unknown noise level '" + name + "' (use none, low or high)");
}

std::vector<SynthMap> scanScene(const Scene& scene, const NoiseModel& noise, uint64_t seed,
                                const std::function<void(size_t, size_t)>& progress) {
  const SensorModel& sm = scene.sensor;
  // Beam directions in the sensor frame, shared by every scan.
  std::vector<Eigen::Vector3d> beams;
  for (int b = 0; b < sm.beams; ++b) {
    const double el = sm.elevation_min + (sm.elevation_max - sm.elevation_min) * b / std::max(1, sm.beams - 1);
    for (int a = 0; a < sm.azimuth_steps; ++a) {
      const double az = 2 * kPi * a / sm.azimuth_steps;
      beams.emplace_back(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    }
  }

  size_t total = 0;
  for (const auto& t : scene.trajectories) total += t.size();
  std::atomic<size_t> done{0};
  std::vector<SynthMap> maps;
  std::mt19937_64 frame_rng(seed * 31 + 5);
  for (size_t m = 0; m < scene.trajectories.size(); ++m) {
    const auto& traj = scene.trajectories[m];
    // The map frame starts at the robot's first pose, with an arbitrary heading.
    const Pose4& start = traj.front();
    const Pose4 P{start.x, start.y, start.z,
                  wrapAngle(start.yaw + std::uniform_real_distribution<double>(-kPi, kPi)(frame_rng))};
    const Pose4 world_to_map = P.inverse();

    std::vector<Points> per_scan(traj.size());
    std::vector<size_t> hits(traj.size(), 0);
#pragma omp parallel for schedule(dynamic)
    for (long long i = 0; i < static_cast<long long>(traj.size()); ++i) {
      std::mt19937_64 rng(seed * 1000003 + m * 7919 + static_cast<uint64_t>(i));
      std::normal_distribution<double> n01(0.0, 1.0);
      const Pose4& truth = traj[static_cast<size_t>(i)];
      // Where the robot believes it was when it took this reading.
      const Pose4 believed{truth.x + noise.pose_translation * n01(rng), truth.y + noise.pose_translation * n01(rng),
                           truth.z + noise.pose_translation * n01(rng), truth.yaw + noise.pose_yaw * n01(rng)};
      const Eigen::Vector3d origin(truth.x, truth.y, truth.z);
      const NearbySolids near = solidsNear(scene.world, origin, sm.max_range);
      const double c = std::cos(truth.yaw), s = std::sin(truth.yaw);
      Points& out = per_scan[static_cast<size_t>(i)];
      for (const auto& b : beams) {
        const Eigen::Vector3d dir(c * b.x() - s * b.y(), s * b.x() + c * b.y(), b.z());
        const double range = castRay(scene.world, near, origin, dir, sm.max_range);
        if (!std::isfinite(range)) continue;
        const double sigma = noise.range * std::max(1.0, (range / 3.0) * (range / 3.0));
        const Eigen::Vector3d local = b * (range + sigma * n01(rng));
        out.push_back(world_to_map.apply(believed.apply(local.cast<float>())));
      }
      hits[static_cast<size_t>(i)] = out.size();
      const size_t n = ++done;
      if (progress) {
#pragma omp critical(tomomap_synth_progress)
        progress(n, total);
      }
    }

    SynthMap map;
    map.pose = world_to_map.matrix();
    map.rays = traj.size() * beams.size();
    Points all;
    for (auto& scan : per_scan) {
      all.insert(all.end(), scan.begin(), scan.end());
      Points().swap(scan);
    }
    for (size_t h : hits) map.hits += h;
    map.points = voxelFilter(all, scene.map_resolution);
    maps.push_back(std::move(map));
  }
  return maps;
}

void roll(SynthMap& map, double angle) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()));
  map.points = rotatePoints(map.points, q);
  Eigen::Matrix4d R = Eigen::Matrix4d::Identity();
  R.topLeftCorner<3, 3>() = q.toRotationMatrix();
  map.pose = R * map.pose;
}

}  // namespace tomomap::synth
