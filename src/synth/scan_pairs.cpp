#include "scan_pairs.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

namespace tomomap::synth {

ScanPair makeScanPair(const Points& scan, const ScanPairParams& params) {
  if (scan.size() < 2 * kMinPointsPerCrop)
    throw InputError("a scan of " + std::to_string(scan.size()) + " points is too small to cut into a pair (at least " +
                     std::to_string(2 * kMinPointsPerCrop) + ")");
  std::mt19937_64 rng(params.seed * 0x9E3779B97F4A7C15ull + 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  ScanPairInfo info;
  info.overlap = params.min_overlap + (params.max_overlap - params.min_overlap) * unit(rng);
  info.cut_yaw = 2 * kPi * unit(rng) - kPi;

  // Each point's place along the cut; the target keeps the first share c of
  // the points, the source the last c, so that the 2c - 1 in the middle are
  // `overlap` of each: (2c - 1) / c = overlap.
  const Eigen::Vector3f along(static_cast<float>(std::cos(info.cut_yaw)), static_cast<float>(std::sin(info.cut_yaw)),
                              0.0f);
  std::vector<float> u(scan.size());
  for (size_t i = 0; i < scan.size(); ++i) u[i] = scan[i].dot(along);
  std::vector<float> sorted = u;
  std::sort(sorted.begin(), sorted.end());
  const double c = 1.0 / (2.0 - info.overlap);
  const float target_end = sorted[static_cast<size_t>(c * static_cast<double>(sorted.size() - 1))];
  const float source_begin = sorted[static_cast<size_t>((1.0 - c) * static_cast<double>(sorted.size() - 1))];

  info.target_degraded = unit(rng) < 0.5;
  if (params.seed % 2 == 1) {
    info.thinning = std::uniform_int_distribution<int>(params.min_thinning, params.max_thinning)(rng);
  } else {
    info.noise = params.noise;
  }
  info.move = Pose4{params.move_xy * (2 * unit(rng) - 1), params.move_xy * (2 * unit(rng) - 1),
                    params.move_z * (2 * unit(rng) - 1), 2 * kPi * unit(rng) - kPi};

  std::normal_distribution<float> noise(0.0f, static_cast<float>(info.noise));
  std::uniform_int_distribution<int> keep(0, std::max(info.thinning, 1) - 1);
  auto crop = [&](bool first, bool degraded) {
    Points out;
    for (size_t i = 0; i < scan.size(); ++i) {
      if (first ? u[i] > target_end : u[i] < source_begin) continue;
      if (degraded && info.thinning > 1 && keep(rng) != 0) continue;
      Eigen::Vector3f p = scan[i];
      if (degraded && info.noise > 0) p += Eigen::Vector3f(noise(rng), noise(rng), noise(rng));
      out.push_back(p);
    }
    return out;
  };
  ScanPair pair;
  pair.target.points = crop(true, info.target_degraded);
  pair.source.points = transformPoints(crop(false, !info.target_degraded), info.move);
  if (pair.target.points.size() < kMinPointsPerCrop || pair.source.points.size() < kMinPointsPerCrop)
    throw SmallCrop("cutting this scan left a crop of " +
                    std::to_string(std::min(pair.target.points.size(), pair.source.points.size())) +
                    " points (at least " + std::to_string(kMinPointsPerCrop) + ")");
  // The scan's frame is the world: the target stays in it, the source is moved.
  pair.target.pose = Eigen::Matrix4d::Identity();
  pair.source.pose = info.move.matrix();
  pair.info = info;
  return pair;
}

std::string describe(const ScanPairInfo& info) {
  std::ostringstream o;
  o << "o" << std::lround(100 * info.overlap) << "-";
  if (info.thinning > 1)
    o << "thin" << info.thinning;
  else
    o << "noise" << std::lround(1000 * info.noise) << "mm";
  o << (info.target_degraded ? "-tgt" : "-src");
  return o.str();
}

}  // namespace tomomap::synth
