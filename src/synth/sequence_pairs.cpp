#include "sequence_pairs.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <unordered_set>

#include "core/gravity.hpp"
#include "core/lattice.hpp"
#include "core/voxel_filter.hpp"

namespace tomomap::synth {
namespace {

/// Fewer keyframes than this and there are no two windows to cut.
constexpr size_t kMinKeyframes = 10;
/// The cube that measures how much space two maps share [m]: coarse enough
/// that two scans of one wall from a metre apart fall in the same cubes.
constexpr double kOverlapCube = 1.0;

Points transformed(const Points& in, const Eigen::Matrix4d& T) {
  const Eigen::Matrix3f R = T.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f t = T.topRightCorner<3, 1>().cast<float>();
  Points out;
  out.reserve(in.size());
  for (const auto& p : in) out.push_back(R * p + t);
  return out;
}

std::unordered_set<uint64_t> cubesOf(const Points& world) {
  std::unordered_set<uint64_t> cubes;
  for (const auto& p : world) cubes.insert(latticeKey(p, kOverlapCube));
  return cubes;
}

/// Share of `a`'s cubes that `b` holds too.
double shareHeld(const std::unordered_set<uint64_t>& a, const std::unordered_set<uint64_t>& b) {
  if (a.empty()) return 0;
  size_t held = 0;
  for (uint64_t k : a) held += b.count(k);
  return static_cast<double>(held) / static_cast<double>(a.size());
}

/// The map frame of a robot whose first keyframe is T_world_first, as the
/// world -> map matrix: that keyframe's own frame (leaning as it did), or,
/// levelled, the frame at its x, y, z and yaw in the world turned by
/// `leveling` (up onto z).
Eigen::Matrix4d mapFrame(const Eigen::Matrix4d& T_world_first, const Eigen::Matrix4d& leveling, bool level) {
  if (!level) return T_world_first.inverse();
  return Pose4::fromMatrix(leveling * T_world_first).matrix().inverse() * leveling;
}

/// Angle of a map's z axis from `up` (world), for the world -> map matrix M.
double leanOf(const Eigen::Matrix4d& M, const Eigen::Vector3d& up) {
  const Eigen::Vector3d up_in_map = M.topLeftCorner<3, 3>() * up;
  return std::acos(std::clamp(up_in_map.normalized().z(), -1.0, 1.0));
}

}  // namespace

Points accumulate(const std::vector<PosedScan>& scans, size_t first, size_t last, const SequencePairParams& params) {
  Points world;
  const double near2 = params.min_range * params.min_range, far2 = params.max_range * params.max_range;
  for (size_t k = first; k <= last; ++k) {
    const Eigen::Matrix4f T = scans[k].T_world_body.cast<float>();
    for (const auto& p : scans[k].points) {
      const double r2 = p.squaredNorm();
      if (r2 < near2 || r2 > far2) continue;
      world.push_back(T.topLeftCorner<3, 3>() * p + T.topRightCorner<3, 1>());
    }
  }
  return voxelFilter(world, params.voxel);
}

Eigen::Vector3d sequenceUp(const std::vector<PosedScan>& scans, const SequencePairParams& params) {
  if (scans.empty()) throw InputError("the sequence has no keyframes");
  const Tilt tilt = estimateTilt(accumulate(scans, 0, scans.size() - 1, params), params.voxel);
  if (!tilt.measured) throw InputError("the sequence's flat surfaces do not tell its up direction");
  return tilt.up;
}

SequencePair makeSequencePair(const std::vector<PosedScan>& scans, const Eigen::Vector3d& up,
                              const SequencePairParams& params) {
  const size_t n = scans.size();
  if (n < kMinKeyframes)
    throw InputError("a sequence of " + std::to_string(n) +
                     " keyframes is too short to cut into two robots' maps (at least " + std::to_string(kMinKeyframes) +
                     ")");
  std::mt19937_64 rng(params.seed * 0x9E3779B97F4A7C15ull + 7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto draw = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };

  // Two windows of `w` keyframes sharing `shared` of them, placed at random
  // along the sequence; which robot walked first is drawn too.
  const auto w = std::clamp<size_t>(
      static_cast<size_t>(std::lround(draw(params.min_window, params.max_window) * static_cast<double>(n))), 2, n);
  const auto shared = std::min(
      w - 1, static_cast<size_t>(std::lround(draw(params.min_shared, params.max_shared) * static_cast<double>(w))));
  const size_t span = std::min(n, 2 * w - shared);
  const auto first = static_cast<size_t>(std::floor(unit(rng) * static_cast<double>(n - span + 1)));
  size_t a0 = first, a1 = first + w - 1, b0 = first + span - w, b1 = first + span - 1;
  if (unit(rng) < 0.5) {
    std::swap(a0, b0);
    std::swap(a1, b1);
  }
  SequencePairInfo info;
  info.target_first = a0;
  info.target_last = a1;
  info.source_first = b0;
  info.source_last = b1;
  info.level = params.level;
  info.move = Pose4{params.move_xy * (2 * unit(rng) - 1), params.move_xy * (2 * unit(rng) - 1),
                    params.move_z * (2 * unit(rng) - 1), 2 * kPi * unit(rng) - kPi};
  info.turn_deg = params.turn_deg;
  // Drawn after everything else, so that a turned pair is the same pair turned.
  const auto turn = [&] {
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    if (params.turn_deg == 0) return T;
    const double a = 2 * kPi * unit(rng);
    T.topLeftCorner<3, 3>() =
        Eigen::AngleAxisd(radians(params.turn_deg), Eigen::Vector3d(std::cos(a), std::sin(a), 0)).toRotationMatrix();
    return T;
  };
  const Eigen::Matrix4d target_turn = turn(), source_turn = turn();

  const Points target_world = accumulate(scans, a0, a1, params);
  const Points source_world = accumulate(scans, b0, b1, params);
  const auto target_cubes = cubesOf(target_world), source_cubes = cubesOf(source_world);
  info.target_overlap = shareHeld(target_cubes, source_cubes);
  info.source_overlap = shareHeld(source_cubes, target_cubes);

  Eigen::Matrix4d leveling = Eigen::Matrix4d::Identity();
  leveling.topLeftCorner<3, 3>() = Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  SequencePair pair;
  const bool level = params.level || params.turn_deg != 0;
  pair.target.pose = target_turn * mapFrame(scans[a0].T_world_body, leveling, level);
  pair.source.pose = info.move.matrix() * source_turn * mapFrame(scans[b0].T_world_body, leveling, level);
  info.target_lean = leanOf(pair.target.pose, up);
  info.source_lean = leanOf(pair.source.pose, up);
  pair.target.points = transformed(target_world, pair.target.pose);
  pair.source.points = transformed(source_world, pair.source.pose);
  if (pair.target.points.size() < kMinPointsPerCrop || pair.source.points.size() < kMinPointsPerCrop)
    throw SmallCrop("these windows left a map of " +
                    std::to_string(std::min(pair.target.points.size(), pair.source.points.size())) +
                    " points (at least " + std::to_string(kMinPointsPerCrop) + ")");
  pair.info = info;
  return pair;
}

std::string describe(const SequencePairInfo& info) {
  std::ostringstream o;
  o << "o" << std::lround(100 * info.overlap()) << "-kf" << info.target_first << "-" << info.target_last << "-"
    << info.source_first << "-" << info.source_last;
  if (info.turn_deg != 0)
    o << "-turned" << info.turn_deg;
  else
    o << (info.level ? "-level" : "-lean");
  return o.str();
}

}  // namespace tomomap::synth
