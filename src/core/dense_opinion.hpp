#pragma once
// From what the features proposed to the answer: the dense searches of small
// maps (dense_search.hpp), every proposal made a candidate (candidates.hpp),
// and the one decision over them (candidate_decision.hpp).
#include <string>
#include <vector>

#include "candidate_decision.hpp"
#include "matcher.hpp"

namespace tomomap {

/// What the tomographic match (matcher.cpp) hands the decision beside the
/// features' own answer in MatchResult.
struct FeatureProposals {
  /// Why the features proposed nothing (too few descriptive slices, no slice
  /// pair estimated); empty when they did.
  std::string missing;
  /// Their distinct answers after the winner (rival_answers.hpp).
  std::vector<Proposal> rivals;
  /// Their slice-pair estimates that agree with a pose.
  FeatureVotes votes;
};

/// Settles `r` (matchFeatures' figures from the features, `f` what else they
/// proposed): the dense searches run where the maps are small enough (each
/// its own reach), every pose proposed (the features' answer and rivals, the
/// searches' best poses) is refined and landed as a candidate, and the
/// decision over them (decideOnCandidates) answers, asking for a search's
/// second look where that would decide. The pose answered is the candidate
/// judged. Small maps get the dense searches because few slices and a
/// 31-pixel ORB patch spanning most of the image leave the tomographic match
/// refusing or, with noisy walls, fooled by a half-turned room or by one
/// enclosure laid on a similar one, while the occupancy itself still tells
/// the right pose apart.
void settleMatch(MatchResult& r, const FeatureProposals& f, const MapFeatures& target, const MapFeatures& source,
                 const MatchParams& params);

}  // namespace tomomap
