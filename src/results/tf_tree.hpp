#pragma once
// The fleet's maps as one tree of frames, as ROS 2's tf wants them: every map
// but the root has exactly one parent, with no cycles, although the fleet
// agrees a transform for every pair it can.
#include <string>
#include <vector>

#include "agreed_transform.hpp"
#include "core/gravity.hpp"

namespace tomomap {

struct TreeEdge {
  std::string parent, child;  ///< agent ids
  Pose4 T_parent_child;       ///< p_parent = T_parent_child * p_child, between the maps as sliced (levelled)
  /// Each map's up in its own frame (AgreedTransform's target_up, source_up).
  Eigen::Vector3d parent_up = Eigen::Vector3d::UnitZ(), child_up = Eigen::Vector3d::UnitZ();
  uint64_t stamp_ms = 0;  ///< when the transform behind it was computed [ms since the epoch]

  /// p_parent = ownFrames() * p_child, between the maps' own frames (what tf carries).
  Eigen::Matrix4d ownFrames() const { return betweenOwnFrames(T_parent_child.matrix(), parent_up, child_up); }
};

/// The reliable transforms among `agreed` that tie the most maps to `root`,
/// each map through its most clearly singled-out link (a maximum spanning
/// tree by lead_sigma, grown from the root; ties go to the lower ids). Maps with no
/// reliable path to the root are left out. Parents come before children.
std::vector<TreeEdge> spanningTree(const std::vector<AgreedTransform>& agreed, const std::string& root);

}  // namespace tomomap
