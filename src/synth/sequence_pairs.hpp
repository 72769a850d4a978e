#pragma once
// Two robots' maps cut from one real SLAM sequence, the way robots that
// walked parts of the same route would have built them: each robot's window
// of keyframes accumulated with the SLAM's own poses, each map in its own
// first keyframe's frame as the SLAM saves it (leaning as that keyframe did),
// or levelled; the source moved by a random 4-DoF transform. The expected
// answer comes from the poses (6-DoF for leaning maps), and carries the
// SLAM's own error.
#include <cstdint>
#include <string>
#include <vector>

#include "scan_pairs.hpp"

namespace tomomap::synth {

struct SequencePairParams {
  uint64_t seed = 1;
  /// Each robot's window, as a share of the sequence's keyframes, drawn per seed.
  double min_window = 0.3, max_window = 0.6;
  /// Share of each window's keyframes that the other window holds too, drawn
  /// per seed (windows that share none still overlap where the sensor saw
  /// the same place: the pair's overlap is measured on the maps).
  double min_shared = 0.0, max_shared = 0.9;
  /// Each scan's points kept between these ranges from the sensor [m]: the
  /// operator's body within the first, sky and far facades beyond the second,
  /// as SLAM maps are cropped.
  double min_range = 1.0, max_range = 40.0;
  double voxel = 0.05;  ///< the accumulated map's voxel filter [m], as SLAM saves its map
  /// Each map levelled (its z axis turned onto the sequence's up, only x, y,
  /// z and yaw of its first keyframe kept) instead of leaning as saved.
  bool level = false;
  /// Each map levelled, then turned this far [deg] about a horizontal axis
  /// drawn per map: a SLAM started on a slope or held tilted, leaning more
  /// than the sequence's own keyframes do (0: not turned).
  double turn_deg = 0;
  /// The source's move: x and y within +-move_xy, z within +-move_z [m], any yaw.
  double move_xy = 20, move_z = 2;
};

/// What one pair is, for its name and the record beside the maps.
struct SequencePairInfo {
  size_t target_first = 0, target_last = 0, source_first = 0, source_last = 0;  ///< keyframe windows (inclusive)
  /// Share of each map's space (1 m cubes) that the other map holds too.
  double target_overlap = 0, source_overlap = 0;
  double target_lean = 0, source_lean = 0;  ///< angle of each map's z axis from the sequence's up [rad]
  bool level = false;
  double turn_deg = 0;  ///< SequencePairParams::turn_deg
  Pose4 move;           ///< applied to the source after it was put in its own frame

  /// The pair's overlap: the smaller share (the harder side).
  double overlap() const { return std::min(target_overlap, source_overlap); }
};

struct SequencePair {
  SynthMap target, source;  ///< poses in synth's convention: T_target_source = pose_target * pose_source^-1
  SequencePairInfo info;
};

/// Keyframes [first, last] of `scans` accumulated in the world frame, each
/// scan cropped to the params' ranges, voxel-filtered at params.voxel: the
/// map a SLAM would save for them.
Points accumulate(const std::vector<PosedScan>& scans, size_t first, size_t last, const SequencePairParams& params);

/// The up direction of a sequence's world frame: the floors' and ground's
/// normal (estimateTilt) over every keyframe's points, a map larger than
/// either robot's. Throws InputError when its flat surfaces cannot tell.
Eigen::Vector3d sequenceUp(const std::vector<PosedScan>& scans, const SequencePairParams& params);

/// Cuts two robots' maps from `scans` (in keyframe order; `up` from
/// sequenceUp). Deterministic from params.seed. Throws InputError for a
/// sequence too short to cut, SmallCrop (scan_pairs.hpp) when this seed's
/// windows leave a map of too few points.
SequencePair makeSequencePair(const std::vector<PosedScan>& scans, const Eigen::Vector3d& up,
                              const SequencePairParams& params);

/// "o35-kf0-120-90-210-lean" style: what a reader needs to tell pairs of one sequence apart.
std::string describe(const SequencePairInfo& info);

}  // namespace tomomap::synth
