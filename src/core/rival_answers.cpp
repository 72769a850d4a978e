#include "rival_answers.hpp"

#include <algorithm>

#include "verdict.hpp"

namespace tomomap {
namespace {

/// Answers landed, at most: the right pose of the full-size building at g 0.2
/// was among the five with most support where the features' winner was a copy.
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

std::optional<LandedChoice> chooseByLanding(const SlicePairTable& table, const MapFeatures& target,
                                            const MapFeatures& source, const MatchParams& params) {
  // Where the dense search would run: on a street at g 0.1 (not searchable)
  // the landings cost 90-160 MB and 0.2-0.3 s a match, for answers that were right.
  if (!denseSearchable(target.occupancy) || !denseSearchable(source.occupancy)) return std::nullopt;
  const std::vector<OffsetScore> answers = distinctAnswers(table, target, source, params);
  if (answers.size() < 2) return std::nullopt;

  std::vector<std::pair<Rigid2D, int>> poses;
  for (const OffsetScore& a : answers) poses.emplace_back(a.consensus.mean, a.offset);
  const std::vector<DensePose> landed = landPoses(target.occupancy, source.occupancy, poses);
  if (landed.size() != answers.size()) return std::nullopt;
  std::vector<size_t> order(answers.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return landed[a].score() > landed[b].score(); });
  const DensePose& best = landed[order[0]];
  if (!holdsOver(best, params.min_support) || significance(best.score(), landed[order[1]].score()) < kBars.significant)
    return std::nullopt;
  LandedChoice c{answers[order[0]]};
  for (size_t i = 1; i < order.size(); ++i)
    if (holdsOver(landed[order[i]], params.min_support) &&
        static_cast<int>(answers[order[i]].consensus.support()) > c.rival_support) {
      c.rival_support = static_cast<int>(answers[order[i]].consensus.support());
      c.rival_offset = answers[order[i]].offset;
    }
  return c;
}

}  // namespace tomomap
