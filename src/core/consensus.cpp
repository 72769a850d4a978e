#include "consensus.hpp"

namespace tomomap {

bool agree(const Rigid2D& a, const Rigid2D& b, const ConsensusParams& params, const Eigen::Vector2d& pivot) {
  return (a.apply(pivot) - b.apply(pivot)).squaredNorm() <=
             params.translation_tolerance * params.translation_tolerance &&
         std::abs(wrapAngle(a.yaw - b.yaw)) <= params.yaw_tolerance;
}

Consensus findConsensus(const std::vector<Rigid2D>& estimates, const ConsensusParams& params,
                        const std::vector<double>& weights) {
  Consensus best;
  double best_weight = -1;
  for (size_t a = 0; a < estimates.size(); ++a) {
    std::vector<size_t> group;
    double weight = 0;
    for (size_t b = 0; b < estimates.size(); ++b) {
      if (agree(estimates[b], estimates[a], params)) {
        group.push_back(b);
        weight += weights.empty() ? 1.0 : weights[b];
      }
    }
    if (group.size() > best.supporters.size() || (group.size() == best.supporters.size() && weight > best_weight)) {
      best.supporters = std::move(group);
      best_weight = weight;
    }
  }
  if (best.supporters.empty()) return best;
  double s = 0, c = 0;
  for (size_t i : best.supporters) {
    best.mean.t += estimates[i].t;
    s += std::sin(estimates[i].yaw);
    c += std::cos(estimates[i].yaw);
  }
  best.mean.t /= static_cast<double>(best.supporters.size());
  best.mean.yaw = std::atan2(s, c);
  return best;
}

}  // namespace tomomap
