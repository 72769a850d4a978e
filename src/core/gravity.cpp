#include "gravity.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <unordered_map>

namespace tomomap {
namespace {

/// A cube this many grid cells wide holds enough of a surface to fit its plane,
/// and is small enough that most cubes see one surface only.
constexpr double kPatchCells = 8.0;
constexpr double kMinPatchSide = 0.4;  ///< [m]: below, voxel noise tilts the patches
constexpr size_t kMinPatchPoints = 12;
/// Flat: the thinnest extent well below the other two (eigenvalues of the
/// patch's covariance), and the patch not a line.
constexpr double kFlatness = 0.05, kNotALine = 0.2;
/// A normal within this of up is a floor's, within this of horizontal a
/// wall's; the rest (stairs, clutter) says nothing.
const double kClassCone = radians(30.0);
constexpr int kRounds = 4;
/// Fewer flat patches than this and the tilt is not measured.
constexpr size_t kMinPatches = 20;
/// Estimates, each in the frame the previous ones levelled (see estimateTilt).
constexpr int kPasses = 3;
/// Points looked at, at most: the large surfaces show in a sample.
constexpr size_t kMaxPoints = 500000;

struct Patch {
  Eigen::Vector3d normal;
  double weight;
};

/// Every `stride`-th point of `map`, turned by `turn`, binned in cubes of `side`.
/// The points are read where they lie, not copied: a sample of a large map,
/// and its turned copy, would sit beside the voxel filter's buffers.
std::vector<Patch> flatPatches(const Points& map, size_t stride, const Eigen::Matrix3f& turn, double side) {
  struct Sums {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    size_t n = 0;
  };
  const auto key = [side](const Eigen::Vector3f& p) {
    const auto cell = [side](float v) {
      return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v / side)) & 0x1FFFFF);
    };
    return (cell(p.z()) << 42) | (cell(p.y()) << 21) | cell(p.x());
  };
  std::unordered_map<uint64_t, Sums> cubes;
  const bool turned = !turn.isIdentity(0.0f);
  for (size_t i = 0; i < map.size(); i += stride) {
    const Eigen::Vector3f p = turned ? Eigen::Vector3f(turn * map[i]) : map[i];
    Sums& s = cubes[key(p)];
    const Eigen::Vector3d q = p.cast<double>();
    s.sum += q;
    s.outer += q * q.transpose();
    ++s.n;
  }
  std::vector<Patch> patches;
  for (const auto& [k, s] : cubes) {
    if (s.n < kMinPatchPoints) continue;
    const double n = static_cast<double>(s.n);
    const Eigen::Vector3d mean = s.sum / n;
    const Eigen::Matrix3d cov = s.outer / n - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(cov);
    const Eigen::Vector3d l = eig.eigenvalues();  // ascending
    if (!(l(0) < kFlatness * l(1)) || !(l(1) > kNotALine * l(2))) continue;
    patches.push_back({eig.eigenvectors().col(0).normalized(), n});
  }
  return patches;
}

/// The up direction closest to the floor patches and farthest from the wall
/// patches, from z in a few rounds; empty if too few flat patches.
std::optional<Eigen::Vector3d> upOf(const std::vector<Patch>& patches, size_t& floors, size_t& walls) {
  const double floor_cos = std::cos(kClassCone), wall_cos = std::sin(kClassCone);
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  for (int round = 0; round < kRounds; ++round) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    floors = walls = 0;
    for (const auto& p : patches) {
      const double c = std::abs(p.normal.dot(up));
      if (c >= floor_cos) {
        m += p.weight * p.normal * p.normal.transpose();
        ++floors;
      } else if (c <= wall_cos) {
        m -= p.weight * p.normal * p.normal.transpose();
        ++walls;
      }
    }
    if (floors + walls < kMinPatches) return std::nullopt;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(m);
    up = eig.eigenvectors().col(2).normalized();
    if (up.z() < 0) up = -up;
  }
  return up;
}

}  // namespace

Tilt estimateTilt(const Points& map, double grid) {
  // Every k-th point: a few hundred thousand describe the large surfaces.
  const size_t stride = std::max<size_t>(1, map.size() / kMaxPoints);

  // The cubes are axis-aligned: a leaning floor cut at a cube's top and bottom
  // fits a little flatter than it is (a 10 deg lean read as 9.3). Measured
  // again in the frame levelled so far, the cut runs along the floor.
  Tilt t;
  Eigen::Quaterniond leveling = Eigen::Quaterniond::Identity();
  const double side = std::max(kMinPatchSide, kPatchCells * grid);
  for (int pass = 0; pass < kPasses; ++pass) {
    const Eigen::Matrix3f turn = leveling.toRotationMatrix().cast<float>();  // as rotatePoints turns
    const auto up = upOf(flatPatches(map, stride, turn, side), t.floor_patches, t.wall_patches);
    if (!up) return t;
    leveling = Eigen::Quaterniond::FromTwoVectors(*up, Eigen::Vector3d::UnitZ()) * leveling;
  }
  t.measured = true;
  t.up = (leveling.inverse() * Eigen::Vector3d::UnitZ()).normalized();
  t.angle = std::acos(std::clamp(t.up.z(), -1.0, 1.0));
  return t;
}

Points rotatePoints(const Points& in, const Eigen::Quaterniond& rotation) {
  const Eigen::Matrix3f r = rotation.toRotationMatrix().cast<float>();
  Points out;
  out.reserve(in.size());
  for (const auto& p : in) out.push_back(r * p);
  return out;
}

}  // namespace tomomap
