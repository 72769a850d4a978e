#pragma once
// The fleet's maps in one frame: every agent's pose in the reference agent's
// map, from all agreed pairs at once (a 4-DoF pose graph), after cycle checks
// have put aside the pairs that contradict the others. Every agent computes
// it from the same agreed transforms and gets the same frame.
#include <optional>
#include <string>
#include <vector>

#include "agreed_transform.hpp"
#include "tf_tree.hpp"

namespace tomomap {

/// How far a loop of transforms may miss closing and still count as
/// consistent: the matcher's own agreement limits (consensus_translation_cells
/// x grid, consensus_yaw_deg), so "consistent" means what "agree" means there.
struct CycleLimits {
  double translation = 0.25;  ///< [m]
  double yaw = 0.1745;        ///< [rad]
};

enum class Consistency {
  Consistent,    ///< closes every cycle it was checked in
  Inconsistent,  ///< contradicts the others: left out of the frame
  Unchecked,     ///< on no cycle (the only link between two parts of the graph)
};
const char* consistencyName(Consistency c);

struct PairVerdict {
  PairKey pair;
  Consistency verdict = Consistency::Unchecked;
  /// The loop that decided: target, the agents in between, source (empty when unchecked).
  std::vector<std::string> cycle;
  double cycle_translation = 0;  ///< how far the loop misses closing [m]
  double cycle_yaw = 0;          ///< [rad]
};

struct AgentPose {
  std::string agent;
  Pose4 T_reference_agent;  ///< p_reference = T_reference_agent * p_agent, between the maps as sliced (levelled)
  /// Its map's up in its own frame (z where it was sliced as it is).
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  /// How it is reached: the reference, the agents in between, the agent
  /// (the clearest links, by lead_sigma; the pose itself comes from every pair).
  std::vector<std::string> path;
};

struct FleetFrame {
  std::string reference;
  std::vector<AgentPose> poses;          ///< reachable agents, the reference first, then by id
  std::vector<std::string> unreachable;  ///< agents with no consistent path to the reference
  std::vector<PairVerdict> pairs;        ///< every reliable pair given, by key
  size_t optimised_pairs = 0;            ///< pairs in the pose graph
  bool converged = true;                 ///< the optimiser said so (false: the poses are its last iterate)

  const AgentPose* pose(const std::string& agent) const;
  /// `p`'s pose between the maps' own frames, the levellings undone:
  /// p_reference = T * p_agent (what tf and frame.json's T_reference_agent_6dof carry).
  Eigen::Matrix4d ownFramePose(const AgentPose& p) const;
  const PairVerdict* verdict(const PairKey& pair) const;
};

/// The frame of `agents` in `reference`'s map from the reliable pairs of
/// `agreed`. Cycle checks: each pair is compared with the shortest other
/// path between its two maps; while some loop misses closing by more than
/// `limits`, the pair on the most failing loops (then the least clear, lead_sigma) is
/// put aside. The rest are solved together (Ceres, Huber loss), starting from
/// the tree of the clearest links.
FleetFrame buildFleetFrame(const std::vector<AgreedTransform>& agreed, const std::vector<std::string>& agents,
                           const std::string& reference, const CycleLimits& limits);

/// The frame as a tree for ROS 2's tf: every placed agent a child of `root`
/// (T_root_agent), stamped `stamp_ms`; empty when `root` is not placed.
std::vector<TreeEdge> treeOf(const FleetFrame& frame, const std::string& root, uint64_t stamp_ms);

/// frame.json's form (docs/json.md).
nlohmann::json toJson(const FleetFrame& frame);

}  // namespace tomomap
