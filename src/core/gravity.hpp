#pragma once
// How far a map's z axis is from gravity. The method assumes gravity-aligned
// maps; map files from LiDAR odometry (KISS-ICP, FAST-LIO) sit in the first
// sensor or IMU frame and are tilted whenever that was.
#include <Eigen/Geometry>

#include "types.hpp"

namespace tomomap {

/// How many standard errors a tilt estimate must clear: its error, to be
/// levelled by (within the tolerance); its excess over the tolerance, to be
/// refused as tilted.
constexpr double kTiltSigmas = 3.0;

struct Tilt {
  bool measured = false;              ///< enough flat surfaces to tell; if not, the rest means nothing
  double angle = 0;                   ///< between the map's z axis and `up` [rad]
  Eigen::Vector3d up{0.0, 0.0, 1.0};  ///< the estimated up direction in the map frame (unit, z >= 0)
  /// The standard error of `angle` [rad]: the spread of the cue's normals
  /// about `up` over the square root of their count.
  double uncertainty = 0;
  /// What `up` was read from: floors (and ground, ceilings), or walls where
  /// there are too few floors.
  enum class Cue { floors, walls } cue = Cue::floors;
  size_t floor_patches = 0;  ///< flat patches facing up (floors, ceilings, ground)
  size_t wall_patches = 0;   ///< flat patches facing sideways (walls)

  /// Whether the estimate is good to level by: within `tolerance` at kTiltSigmas standard errors.
  bool levelable(double tolerance) const { return measured && kTiltSigmas * uncertainty <= tolerance; }
  /// Whether the map may lie within `tolerance`: its tilt is not beyond it by
  /// kTiltSigmas standard errors (or not measured).
  bool mayBeWithin(double tolerance) const { return !measured || angle - kTiltSigmas * uncertainty <= tolerance; }

  /// The rotation that makes the map level: it turns `up` onto z (the
  /// smallest such rotation: no yaw is added).
  Eigen::Quaterniond leveling() const { return Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ()); }
};

/// Beyond this lean the estimate can take walls for floors (a y-up map read
/// 16-48 degrees): such a map is refused, never levelled.
const double kMaxLevelable = radians(30.0);

/// Tilt from the flat surfaces of a map: floors and ceilings face up, walls
/// face sideways. The map is cut into cubes a few grid cells wide; each flat
/// cube gives a normal; `up` is the floors' mean normal, or the direction the
/// walls' normals avoid where there are too few floors; found from z in a few
/// rounds, then again in the frame levelled so far. On sloping ground it reads
/// the slope.
Tilt estimateTilt(const Points& map, double grid);

/// Rotates every point by `rotation` (about the origin).
Points rotatePoints(const Points& in, const Eigen::Quaterniond& rotation);

}  // namespace tomomap
