#pragma once
// Consensus among per-slice-pair estimates at one height offset (docs/algorithm.md).
#include "rigid2d.hpp"

namespace tomomap {

struct ConsensusParams {
  double translation_tolerance = 0.25;   ///< [m]; the matcher sets 5 x grid
  double yaw_tolerance = radians(10.0);  ///< [rad]
};

/// Whether two estimates are within tolerance of each other (the same answer):
/// their yaws, and where they put `pivot`. Translations alone would part two
/// estimates whose yaws differ by a little, far from the origin.
bool agree(const Rigid2D& a, const Rigid2D& b, const ConsensusParams& params,
           const Eigen::Vector2d& pivot = Eigen::Vector2d::Zero());

struct Consensus {
  Rigid2D mean;                    ///< average of the supporters (yaw via mean sin/cos)
  std::vector<size_t> supporters;  ///< indices into the estimates; size() is the support
  size_t support() const { return supporters.size(); }
};

/// Takes every estimate as an anchor, counts the estimates within tolerance of
/// it, and averages the largest group. Ties go to the group with more weight
/// (e.g. inliers), then to the lower anchor index, so the result is deterministic.
/// `weights` may be empty (all 1).
Consensus findConsensus(const std::vector<Rigid2D>& estimates, const ConsensusParams& params,
                        const std::vector<double>& weights = {});

}  // namespace tomomap
