#pragma once
// How far a map's z axis is from gravity. The method assumes gravity-aligned
// maps; map files from LiDAR odometry (KISS-ICP, FAST-LIO) sit in the first
// sensor or IMU frame and are tilted whenever that was.
#include <Eigen/Geometry>
#include <optional>
#include <string>

#include "types.hpp"

namespace tomomap {

struct Tilt {
  bool measured = false;              ///< enough flat surfaces to tell; if not, the rest means nothing
  double angle = 0;                   ///< between the map's z axis and `up` [rad]
  Eigen::Vector3d up{0.0, 0.0, 1.0};  ///< the estimated up direction in the map frame (unit, z >= 0)
  /// How far `up` may be off [rad]: the farthest the same estimate reads on
  /// parts of the map that can check it (fairPart: its halves, a third and a
  /// tenth of its points) plus the cue's standard error; at least `angle`
  /// where most parts cannot check it (the lean is then not known better than
  /// it is). The cue's standard error alone where the parts were not measured.
  double uncertainty = 0;
  /// Whether the parts were measured (estimateTilt measures them only where a
  /// decision reads the uncertainty they give).
  bool checked = false;
  /// What `up` was read from: floors (and ground, ceilings), or walls where
  /// there are too few floors; or given by the user (an IMU's or the SLAM's
  /// own gravity), then exact.
  enum class Cue { floors, walls, given } cue = Cue::floors;
  size_t floor_patches = 0;  ///< flat patches facing up (floors, ceilings, ground)
  size_t wall_patches = 0;   ///< flat patches facing sideways (walls)
  /// Read beyond kClassCone, or found from there (the rounds from z finding
  /// nothing): its walls may pass for its floors, and its lines must tell.
  bool beyond_cone = false;
  /// Where beyond_cone: its lines (posts, trunks, door frames, corners), and
  /// how many of them stand within kClassCone of `up`.
  size_t lines = 0, standing_lines = 0;

  /// Whether `up` may be taken for the floors': within kMaxLevelable, and
  /// beyond kClassCone only where the map's lines stand along it.
  bool upTrusted() const;
  /// Whether the estimate is good to level by: `up` trusted, and measured
  /// better than the map leans (levelled by it, what is left leans less than
  /// the map did).
  bool levelable() const;
  /// Whether the map's lines say `up` is up: at least kMinLines of them, and
  /// most of them standing along it.
  bool linesStand() const;
  /// Whether the map may lie within `tolerance`: its tilt less its
  /// uncertainty not beyond it (or not measured).
  bool mayBeWithin(double tolerance) const { return !measured || angle - uncertainty <= tolerance; }

  /// The rotation that makes the map level (levelingOf its up).
  Eigen::Quaterniond leveling() const;
};

/// The rotation that makes a map whose up is `up` level: it turns `up` onto z
/// (the smallest such rotation: no yaw is added). p_levelled = R p_own.
Eigen::Quaterniond levelingOf(const Eigen::Vector3d& up);
/// The same as a 4x4 rigid transform (no translation).
Eigen::Matrix4d levelingMatrix(const Eigen::Vector3d& up);

/// A transform between two levelled maps (p_target_levelled = T
/// p_source_levelled) as the transform between their own frames, from each
/// map's up in its own frame (z for a map matched as it is):
/// R_target^-1 T R_source.
Eigen::Matrix4d betweenOwnFrames(const Eigen::Matrix4d& T, const Eigen::Vector3d& target_up,
                                 const Eigen::Vector3d& source_up);

/// A flat patch whose normal lies within this of up is a floor's (ground,
/// ceilings), within this of horizontal a wall's; the rest (stairs, clutter)
/// says nothing; a line within this of up stands. A map read leaning beyond
/// it may have had its walls taken for floors, as tightly as a leaning map's
/// floors are read; there its lines tell (Tilt::linesStand; measured:
/// docs/results.md, "Maps that lean 30-45 degrees, and maps on their side").
const double kClassCone = radians(30.0);
/// Fewer lines than this and they say nothing: a few posts' worth (a 3 m post
/// is 7 cubes at 0.4 m; the hall leaning or on its side held 41-97).
constexpr size_t kMinLines = 20;

/// Beyond this lean a map is never levelled by an estimate: its walls lie
/// nearer z than its floors.
const double kMaxLevelable = radians(45.0);

/// Whether `up` is one a map may be levelled by: a unit vector within
/// kMaxLevelable of z (what a peer may announce).
bool levelableUp(const Eigen::Vector3d& up);

/// Tilt from the flat surfaces of a map: floors and ceilings face up, walls
/// face sideways. The map is cut into cubes a few grid cells wide; each flat
/// cube gives a normal; `up` is the floors' mean normal, or the direction the
/// walls' normals avoid where there are too few floors; found from z in a few
/// rounds, then again in the frame levelled so far. On sloping ground it reads
/// the slope. Its uncertainty is measured on the map's parts (Tilt::uncertainty),
/// where it may matter: a map leaning no more than `matched_within`, where
/// given, is matched as it is whatever its uncertainty (MatchParams::max_tilt),
/// and its parts, most of the estimate's time, are not measured (Tilt::checked).
Tilt estimateTilt(const Points& map, double grid, std::optional<double> matched_within = std::nullopt);

/// A part of a map (a crop, a thinning) checks the whole's estimate where it
/// is read off the same cue and holds at least this share of the whole's
/// patches of that cue: a half holds about half of them, a tenth of the
/// points 0.5-0.8 of them on the real maps.
constexpr double kFairShare = 0.25;
bool fairPart(const Tilt& part, const Tilt& whole);

/// "10.0 +- 0.2 deg from gravity (read off its floors)", as logged and printed.
std::string leanText(const Tilt& t);

/// The tilt of a map whose up direction is known (`up` in the map's frame,
/// any length): exact, to be levelled by whatever it leans.
Tilt givenTilt(const Eigen::Vector3d& up);

/// Rotates every point by `rotation` (about the origin).
Points rotatePoints(const Points& in, const Eigen::Quaterniond& rotation);

}  // namespace tomomap
