#include "rival_answers.hpp"

#include <algorithm>

namespace tomomap {
namespace {

/// Answers proposed, at most: the right pose of the full-size building at g
/// 0.2 was among the five with most support where the features' winner was a copy.
constexpr size_t kMostRivals = 8;
/// Consensus groups looked at per height offset.
constexpr int kGroupsPerOffset = 3;

}  // namespace

bool sameAnswer(const OffsetScore& a, const OffsetScore& b, const MatchParams& params, const Eigen::Vector2d& centre) {
  return std::abs(a.offset - b.offset) <= kSmearSlices &&
         agree(a.consensus.mean, b.consensus.mean, consensusParams(params, params.grid), centre);
}

std::vector<OffsetScore> distinctAnswers(const SlicePairTable& table, const MapFeatures& target,
                                         const MapFeatures& source, const MatchParams& params) {
  std::vector<OffsetScore> groups = scoreOffsets(table, target, source, params, kGroupsPerOffset);
  std::stable_sort(groups.begin(), groups.end(), outranks);
  std::vector<OffsetScore> answers;
  for (OffsetScore& g : groups) {
    if (answers.size() == kMostRivals) break;
    const bool seen = std::any_of(answers.begin(), answers.end(),
                                  [&](const OffsetScore& a) { return sameAnswer(a, g, params, source.centre()); });
    if (!seen) answers.push_back(std::move(g));
  }
  return answers;
}

}  // namespace tomomap
