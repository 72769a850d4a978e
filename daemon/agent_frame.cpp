// The fleet's frame as this agent sees it: rebuilt from the agreed transforms
// whenever they change (every agent holds the same ones, so every agent
// builds the same frame), and a pair that turns inconsistent said once.
#include "agent.hpp"
#include "core/text.hpp"

namespace tomomap::daemon {

void Agent::updateFrame() {
  std::vector<AgreedTransform> agreed;
  for (const auto& [key, t] : board_.results()) agreed.push_back(t);
  std::vector<std::string> agents = config_.peerIds();
  agents.push_back(config_.agent());
  // "Consistent" means what "agree" means to the matcher: its consensus limits.
  const CycleLimits limits{config_.match.consensus_translation_cells * config_.match.grid, config_.match.consensus_yaw};
  FleetFrame next = buildFleetFrame(agreed, agents, config_.frameReference(), limits);
  for (const auto& v : next.pairs) {
    const PairVerdict* before = frame_.verdict(v.pair);
    if (v.verdict != Consistency::Inconsistent || (before && before->verdict == Consistency::Inconsistent)) continue;
    log_.warning(pairText(v.pair) + " is inconsistent with the fleet's other transforms: the loop " +
                 chainText(v.cycle, /*closed=*/true) + " misses by " + fixed(v.cycle_translation, 2) + " m and " +
                 fixed(degrees(v.cycle_yaw), 1) + " deg; left out of the fleet's frame");
  }
  frame_ = std::move(next);
}

}  // namespace tomomap::daemon
