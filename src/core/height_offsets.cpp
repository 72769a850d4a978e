#include "height_offsets.hpp"

#include <algorithm>
#include <map>

namespace tomomap {

ConsensusParams consensusParams(const MatchParams& params, double cell) {
  return {params.consensus_translation_cells * cell, params.consensus_yaw};
}

bool outranks(const OffsetScore& a, const OffsetScore& b) {
  if (a.consensus.support() != b.consensus.support()) return a.consensus.support() > b.consensus.support();
  return a.inlier_sum > b.inlier_sum;
}

std::vector<OffsetScore> scoreOffsets(const SlicePairTable& table, const MapFeatures& target, const MapFeatures& source,
                                      const MatchParams& params, int groups) {
  // Each (target, source) slice pair belongs to exactly one height offset.
  std::map<int, std::vector<size_t>> by_offset;
  for (size_t k = 0; k < table.estimates.size(); ++k)
    if (table.estimates[k].ok)
      by_offset[target.slices[k / table.ns].index - source.slices[k % table.ns].index].push_back(k);
  const ConsensusParams cp = consensusParams(params, params.grid);
  std::vector<OffsetScore> scores;
  for (auto& [offset, members] : by_offset) {
    for (int group = 0; group < groups && !members.empty(); ++group) {
      std::vector<Rigid2D> estimates;
      std::vector<double> weights;
      for (size_t k : members) {
        estimates.push_back(table.estimates[k].T);
        weights.push_back(table.estimates[k].inliers);
      }
      OffsetScore s{offset, findConsensus(estimates, cp, weights), 0};
      if (group > 0 && s.consensus.support() < 2) break;
      std::vector<bool> taken(members.size(), false);
      for (size_t& i : s.consensus.supporters) {
        taken[i] = true;
        i = members[i];  // from index into `estimates` to index into the table
        s.inlier_sum += table.estimates[i].inliers;
      }
      scores.push_back(std::move(s));
      std::vector<size_t> left;
      for (size_t i = 0; i < members.size(); ++i)
        if (!taken[i]) left.push_back(members[i]);
      members = std::move(left);
    }
  }
  return scores;
}

OffsetChoice pickOffset(const std::vector<OffsetScore>& scores, const MatchParams& params,
                        const Eigen::Vector2d& source_centre) {
  OffsetChoice c;
  if (scores.empty()) return c;
  c.best = &*std::max_element(scores.begin(), scores.end(),
                               [](const OffsetScore& x, const OffsetScore& y) { return outranks(y, x); });
  const ConsensusParams cp = consensusParams(params, params.grid);
  for (const auto& s : scores) {
    const int apart = std::abs(s.offset - c.best->offset);
    const bool other_answer =
        apart > kSmearSlices || (apart > 1 && !agree(s.consensus.mean, c.best->consensus.mean, cp, source_centre));
    if (other_answer && static_cast<int>(s.consensus.support()) > c.runner_up_support) {
      c.runner_up_support = static_cast<int>(s.consensus.support());
      c.runner_up_offset = s.offset;
    }
  }
  return c;
}

}  // namespace tomomap
