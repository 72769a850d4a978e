#pragma once
// The transform a fleet agreed for one pair of maps, as tomomapd keeps it and
// `tomomap status` reads it back: one type, one JSON form (transforms.json).
// The wire form lives in transport/estimate_wire.hpp.
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/matcher.hpp"
#include "core/types.hpp"

namespace tomomap {

/// An ordered pair of agents: target < source by id.
using PairKey = std::pair<std::string, std::string>;

/// "target<-source", as logged and shown.
inline std::string pairText(const PairKey& p) { return p.first + "<-" + p.second; }

/// Agents joined by arrows, "alpha -> bravo -> charlie" (a path in the
/// fleet's frame); with `closed`, back to the first (a loop), as logged and shown.
std::string chainText(const std::vector<std::string>& agents, bool closed = false);

/// Hex form of a map version, as logged and stored.
std::string versionText(uint64_t version);
/// The inverse; throws InputError for anything but 1-16 hex digits.
uint64_t parseVersion(const std::string& text);

struct AgreedTransform {
  std::string target, source;
  uint64_t target_version = 0, source_version = 0;  ///< the maps' versions it was computed for
  bool reliable = false;                            ///< false: computed, no reliable match (T is then meaningless)
  std::string reason;                               ///< why not, when not reliable
  /// p_target = T_target_source * p_source, between the maps as sliced:
  /// levelled where a map leaned (its up below), else as they are.
  Pose4 T_target_source;
  /// Each map's up direction in its own frame, as it was levelled by (z: sliced as it is).
  Eigen::Vector3d target_up = Eigen::Vector3d::UnitZ(), source_up = Eigen::Vector3d::UnitZ();
  /// The whole transform between the maps' own frames where the matcher gave
  /// one (the 6-DoF finish's); otherwise ownFrames() derives it from the above.
  std::optional<Eigen::Matrix4d> T_target_source_6dof;
  /// The search whose pose is the answer (candidates.hpp fromName).
  std::string answered_by = fromName(Candidate::From::features);
  /// How clearly the match singled the answer out (MatchResult::lead_sigma)
  /// [standard deviations]: the fleet's pose graph weighs the pair by it.
  double lead_sigma = 0;
  std::string computed_by;
  uint64_t computed_at_ms = 0;  ///< the computing agent's wall clock [ms since the epoch]
  double seconds = 0;           ///< matching time [s]

  PairKey pair() const { return {target, source}; }
  /// p_target = ownFrames() * p_source, in the maps' own frames (6-DoF).
  Eigen::Matrix4d ownFrames() const;
  /// Computed for exactly these versions of the two maps.
  bool isFor(uint64_t target_v, uint64_t source_v) const {
    return target_version == target_v && source_version == source_v;
  }
};

/// Whether a pair's quality is one a match gives: a lead that is a number
/// >= 0 (the pose graph weighs by it), from a search tomomap has. Checked on
/// every estimate received and every stored transform read.
bool plausibleQuality(const std::string& answered_by, double lead_sigma);

/// What a match says of a pair (reliable or why not, the transform, both
/// maps' ups, quality); the pair's ids, versions and who computed it when
/// are the caller's to set.
AgreedTransform agreedOf(const MatchResult& r, const MapFeatures& target, const MapFeatures& source);

/// A 4x4 matrix as four rows.
nlohmann::json matrixJson(const Eigen::Matrix4d& M);
/// A map's up direction as stored: [x, y, z].
nlohmann::json upJson(const Eigen::Vector3d& up);
/// The inverse; throws InputError naming `what` for anything but a unit
/// vector within kMaxLevelable of z (what a map may be levelled by).
Eigen::Vector3d upFromJson(const nlohmann::json& j, const std::string& what);

/// The inverse for a rigid transform; throws InputError (or a json exception) for anything else.
Eigen::Matrix4d matrixFromJson(const nlohmann::json& rows);
/// A 4-DoF transform as stored and printed: x, y, z [m], yaw [rad] and its 4x4 matrix.
nlohmann::json toJson(const Pose4& T);
nlohmann::json toJson(const AgreedTransform& t);
/// Reads one entry of transforms.json; throws InputError naming what is wrong.
AgreedTransform agreedFromJson(const nlohmann::json& j);

}  // namespace tomomap
