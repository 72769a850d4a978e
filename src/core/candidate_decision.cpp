#include "candidate_decision.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "height_offsets.hpp"
#include "lead_sigma.hpp"
#include "text.hpp"

namespace tomomap {
namespace {

/// Per slice: what a candidate lands there (telling cells less twice those in
/// space the target saw empty) and its telling cells.
using SliceScores = std::map<int, std::pair<double, double>>;

SliceScores occupancyBySlice(const Candidate& c) {
  SliceScores out;
  for (const SliceLanding& s : c.pooled_slices.empty() ? c.slices : c.pooled_slices)
    if (s.telling > 0) out[s.slice] = {s.telling_on - 2.0 * s.contradicted, s.telling};
  return out;
}

double total(const SliceScores& s) {
  double sum = 0;
  for (const auto& [slice, v] : s) sum += v.first;
  return sum;
}

int votes(const Candidate& c) {
  int sum = 0;
  for (int v : c.feature_votes) sum += v;
  return sum;
}

/// `a`'s lead over `b` on the occupancy, slice by slice: each slice's
/// difference per telling cell (the larger of the two), so that every slice
/// weighs alike whatever its size. Slices with no telling cell on either are
/// left out; the rest are neighbours in sliceLeadSigma's series, as the
/// slices of a wall's height are.
std::pair<double, int> occupancyLead(const SliceScores& a, const SliceScores& b) {
  std::set<int> slices;
  for (const auto& [k, v] : a) slices.insert(k);
  for (const auto& [k, v] : b) slices.insert(k);
  const std::pair<double, double> none{0.0, 0.0};
  std::vector<double> d;
  for (int k : slices) {
    const auto& va = a.count(k) ? a.at(k) : none;
    const auto& vb = b.count(k) ? b.at(k) : none;
    d.push_back((va.first - vb.first) / std::max({va.second, vb.second, 1.0}));
  }
  return {sliceLeadSigma(d), static_cast<int>(d.size())};
}

/// `a`'s lead over `b` in slice-pair estimates agreeing, over the source
/// slices where either has one, by signFlipLeadSigma: the counts are small
/// and often the same from slice to slice, where a t reads any lead over
/// two slices as certain.
std::pair<double, int> votesLead(const Candidate& a, const Candidate& b) {
  std::vector<double> d;
  const size_t n = std::max(a.feature_votes.size(), b.feature_votes.size());
  for (size_t k = 0; k < n; ++k) {
    const int va = k < a.feature_votes.size() ? a.feature_votes[k] : 0;
    const int vb = k < b.feature_votes.size() ? b.feature_votes[k] : 0;
    if (va > 0 || vb > 0) d.push_back(va - vb);
  }
  return {signFlipLeadSigma(d), static_cast<int>(d.size())};
}

}  // namespace

const char* onName(CandidateVerdict::On on) {
  switch (on) {
    case CandidateVerdict::On::occupancy:
      return "occupancy";
    case CandidateVerdict::On::corroborated:
      return "corroborated";
    case CandidateVerdict::On::feature_votes:
      return "feature_votes";
  }
  return "?";
}

CandidateVerdict decideOnCandidates(const std::vector<Candidate>& candidates, const MatchParams& params, double grid,
                                    const Eigen::Vector2d& source_centre) {
  CandidateVerdict v;
  v.compared_at = source_centre;
  if (candidates.empty()) {
    v.reason = "no candidate pose";
    return v;
  }
  const ConsensusParams tolerance = consensusParams(params, grid);
  const auto samePlace = [&](const Candidate& a, const Candidate& b) {
    return onePlace(a.landed.transform, a.landed.offset, b.landed.transform, b.landed.offset, tolerance, source_centre);
  };
  std::vector<SliceScores> scores;
  std::vector<double> landed;  // each candidate's score, summed over its slices
  std::vector<int> agreeing;   // the slice-pair estimates that agree with it
  for (const Candidate& c : candidates) {
    scores.push_back(occupancyBySlice(c));
    landed.push_back(total(scores.back()));
    agreeing.push_back(votes(c));
  }
  // The best of those not at `at`'s place, by `better`; -1 if every one is there.
  const auto bestElsewhere = [&](size_t at, const auto& better) {
    int out = -1;
    for (size_t i = 0; i < candidates.size(); ++i)
      if (!samePlace(candidates[i], candidates[at]) && (out < 0 || better(i, static_cast<size_t>(out))))
        out = static_cast<int>(i);
    return out;
  };
  const auto lands_more = [&](size_t a, size_t b) { return landed[a] > landed[b]; };
  const auto agreed_more = [&](size_t a, size_t b) { return agreeing[a] > agreeing[b]; };

  size_t best = 0;
  for (size_t i = 1; i < candidates.size(); ++i)
    if (lands_more(i, best)) best = i;
  const int rival = bestElsewhere(best, lands_more);
  std::pair<double, int> lead{0.0, 0};
  if (rival >= 0) lead = occupancyLead(scores[best], scores[static_cast<size_t>(rival)]);
  if (lead.first >= kClearSigma) {
    v.answer = static_cast<int>(best);
    v.lead_sigma = lead.first, v.slices = lead.second;
    return v;
  }
  v.reason = rival < 0
                 ? "no candidate elsewhere to weigh the best against"
                 : "the candidate that lands the most leads the best elsewhere by " + fixed(lead.first, 1) +
                       " sigma over " + std::to_string(lead.second) + " slices (need " + fixed(kClearSigma, 0) + ")";

  // Corroboration: where the occupancy ranks one place first both among the
  // candidates and in a dense search of every pose (that search's own best
  // lies there), one of the features' slice-pair estimates agreeing with it
  // is evidence of another kind, found on descriptors alone. A small map's
  // occupancy often places a right answer no more clearly than a copy of it
  // a few cells along a wall; the features, which do not slide, tell them apart.
  const bool dense_best_here = std::any_of(candidates.begin(), candidates.end(), [&](const Candidate& c) {
    return isDenseSearch(c.from) && c.rank == 0 && samePlace(c, candidates[best]);
  });
  if (dense_best_here && agreeing[best] > 0) {
    v.answer = static_cast<int>(best);
    v.on = CandidateVerdict::On::corroborated;
    v.lead_sigma = lead.first, v.slices = lead.second;
    v.reason.clear();
    return v;
  }
  const bool searched =
      std::any_of(candidates.begin(), candidates.end(), [](const Candidate& c) { return isDenseSearch(c.from); });
  v.reason += !searched         ? "; no dense search of the occupancy to corroborate it"
              : dense_best_here ? "; no slice-pair estimate of the features agrees with it"
                                : "; no dense search's best pose is at its place";

  // The features' evidence, where the occupancy does not tell (a street's
  // poses along its facades land alike): answered only where the occupancy
  // does not tell against it.
  size_t voted = 0;
  for (size_t i = 1; i < candidates.size(); ++i)
    if (agreed_more(i, voted)) voted = i;
  if (agreeing[voted] == 0) return v;
  const int other = bestElsewhere(voted, agreed_more);
  if (other < 0) return v;
  const std::pair<double, int> by_votes = votesLead(candidates[voted], candidates[static_cast<size_t>(other)]);
  v.reason += "; the candidate most slice pairs agree with leads the most agreed-with elsewhere by " +
              fixed(by_votes.first, 1) + " sigma over " + std::to_string(by_votes.second) + " source slices";
  if (by_votes.first < kClearSigma) return v;
  for (size_t i = 0; i < candidates.size(); ++i)
    if (!samePlace(candidates[i], candidates[voted]) && lands_more(i, voted) &&
        occupancyLead(scores[i], scores[voted]).first >= kClearSigma) {
      v.reason += ", but a candidate elsewhere lands more, beyond chance";
      return v;
    }
  v.answer = static_cast<int>(voted);
  v.on = CandidateVerdict::On::feature_votes;
  v.lead_sigma = by_votes.first, v.slices = by_votes.second;
  v.reason.clear();
  return v;
}

}  // namespace tomomap
