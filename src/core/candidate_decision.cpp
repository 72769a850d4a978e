#include "candidate_decision.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "height_offsets.hpp"
#include "lead_sigma.hpp"
#include "text.hpp"

namespace tomomap {

double contradiction(const DensePose& p) {
  return static_cast<double>(p.contradicted) / static_cast<double>(std::max<size_t>(p.telling_inliers, 1));
}

bool consistent(const DensePose& p) { return contradiction(p) <= kBars.most_contradicted; }

bool holdsOver(const DensePose& p, int min_support) { return consistent(p) && p.support >= min_support; }

double DenseEvidence::lead() const { return best.score() <= 0 ? 0 : best.score() / std::max(next_score, 1.0); }

double DenseEvidence::leadSigma() const { return significance(best.score(), next_score); }

bool beyondChance(const DenseEvidence& d) { return d.found && d.leadSigma() >= kBars.significant; }

bool aheadBeyondChance(const DenseEvidence& d, double by) { return beyondChance(d) && d.lead() >= by; }

bool leads(const DenseEvidence& d, double by, const MatchParams& params) {
  return aheadBeyondChance(d, by) && holdsOver(d.best, params.min_support);
}

namespace {

/// Per slice: what a candidate lands there (telling cells, less those in
/// space the target saw empty as DensePose::score weighs them) and its
/// telling cells. One way, the source's cells on the target: judged both
/// ways (the climb's own score, slice pair by slice pair) the matrix
/// answered two crops wrong that this refuses (docs/results.md, "Four more
/// tries at the decision").
using SliceScores = std::map<int, std::pair<double, double>>;

SliceScores bySlice(const std::vector<SliceLanding>& slices) {
  SliceScores out;
  for (const SliceLanding& s : slices)
    if (s.telling > 0) out[s.slice] = {s.telling_on - kContradictionWeight * s.contradicted, s.telling};
  return out;
}

/// A candidate's place is judged on the occupancy pooled where the maps'
/// cells are too fine to read empty space (Candidate::pooled_slices).
SliceScores occupancyBySlice(const Candidate& c) {
  return bySlice(c.pooled_slices.empty() ? c.slices : c.pooled_slices);
}

double total(const SliceScores& s) {
  double sum = 0;
  for (const auto& [slice, v] : s) sum += v.first;
  return sum;
}

/// The pose answered for the place of candidate `at`: of the candidates at
/// that place, the one that lands the most on the maps' own cells
/// (Candidate::slices). The place is judged on occupancy pooled where the
/// maps' cells are finer than 0.1 m, to read empty space; a pooled cell
/// cannot tell poses a cell or two apart, the maps' own cells can: on the
/// held-out rooms at 0.05 m the median answer's error went 0.060 -> 0.050 m,
/// and on the RGB-D crops the 90th percentile 0.121 -> 0.033 m
/// (docs/results.md, "The pose within its place"). Where the cells are not
/// pooled, the candidate the occupancy's lead or the corroboration answers
/// lands the most of all already; the one the votes answer may not.
template <typename SamePlace>
size_t finestAt(const std::vector<Candidate>& candidates, size_t at, const SamePlace& samePlace) {
  const auto own = [&](size_t i) { return total(bySlice(candidates[i].slices)); };
  size_t best = at;
  double most = own(at);
  for (size_t i = 0; i < candidates.size(); ++i)
    if (samePlace(candidates[i], candidates[at]))
      if (const double o = own(i); o > most) best = i, most = o;
  return best;
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

/// Votes `a`'s lead over votes `b` (Candidate::feature_votes, by source
/// slice), over the source slices where either has one, by
/// signFlipLeadSigma: the counts are small and often the same from slice to
/// slice, where a t reads any lead over two slices as certain.
std::pair<double, int> votesLead(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<double> d;
  const size_t n = std::max(a.size(), b.size());
  for (size_t k = 0; k < n; ++k) {
    const int va = k < a.size() ? a[k] : 0;
    const int vb = k < b.size() ? b[k] : 0;
    if (va > 0 || vb > 0) d.push_back(va - vb);
  }
  return {signFlipLeadSigma(d), static_cast<int>(d.size())};
}

/// The decision's second step (decideOnCandidates), where the occupancy's
/// slices do not tell: `best`, the candidate that lands the most, answers
/// where a dense search of every pose ranks it first too (that search's own
/// best pose lies at its place, ahead of its next beyond chance) and one of
/// the features' slice-pair estimates agrees with it: evidence of another
/// kind, found on descriptors alone. A small map's occupancy often places a
/// right answer no more clearly than a copy of it a few cells along a wall;
/// the features, which do not slide, tell them apart. A search's best pose
/// within chance of its next ranks nothing: in a room with a copy of itself
/// about 2.7 m along (room-low-11 at g 0.05, the pooled search's best 1.04x
/// its next, 2.0 sigma) the features' estimates agreed with the copy.
/// The premise is a right answer and its copies alike: a pose the other
/// map's empty space contradicts (kBars.most_contradicted) is neither. On a
/// room whose right pose no search proposed (seed 208, high noise, g 0.1)
/// the best landed 24 % as many cells in that space as on its occupancy and
/// was corroborated 2.67 m off; the corroborated right answers of all four
/// suites landed at most 13 % (docs/results.md, "A corroborated pose the
/// empty space contradicts"). Answers on a lead beyond chance (the
/// occupancy's, the votes') are not held to it: right answers on streets
/// at 0.1 m land up to 37 %.
/// Whether it answered; `v` says why not.
template <typename SamePlace>
bool byCorroboration(CandidateVerdict& v, const std::vector<Candidate>& candidates, size_t best,
                     const std::vector<int>& agreeing, const std::vector<SearchLead>& searches,
                     const SamePlace& samePlace) {
  bool searched = false;
  const SearchLead* here = nullptr;  // of the searches whose best pose is at best's place, the clearest
  for (const Candidate& c : candidates) {
    if (!isDenseSearch(c.from)) continue;
    searched = true;
    if (c.rank != 0 || !samePlace(c, candidates[best])) continue;
    for (const SearchLead& s : searches)
      if (s.from == c.from && (!here || s.found.leadSigma() > here->found.leadSigma())) here = &s;
  }
  if (!searched) {
    v.reason += "; no dense search of the occupancy to corroborate it";
    return false;
  }
  if (!here) {
    v.reason += "; no dense search's best pose is at its place";
    return false;
  }
  if (!beyondChance(here->found)) {
    v.reason += "; " + std::string(fromName(here->from)) +
                "'s best pose is at its place but within chance of its next" +
                (here->judged_as_candidates ? " or a candidate elsewhere" : "") + " (" + fixed(here->found.lead(), 2) +
                "x, " + fixed(here->found.leadSigma(), 1) + " sigma)";
    return false;
  }
  if (agreeing[best] == 0) {
    v.reason += "; no slice-pair estimate of the features agrees with it";
    return false;
  }
  if (!consistent(candidates[best].landed)) {
    v.reason += "; it lands " + fixed(100 * contradiction(candidates[best].landed), 0) +
                " % as many telling cells in space the other map saw empty as on its occupancy (at most " +
                fixed(100 * kBars.most_contradicted, 0) + " %)";
    return false;
  }
  v.answer = static_cast<int>(best);
  v.on = CandidateVerdict::On::corroborated;
  v.reason.clear();
  return true;
}

/// The decision's third step (decideOnCandidates), where the occupancy does
/// not tell (a street's poses along its facades land alike): the candidate
/// the most slice-pair estimates of the features agree with (`agreeing`)
/// answers, where it leads the most agreed-with elsewhere beyond chance and
/// the occupancy does not tell against it (no candidate elsewhere lands
/// more, `landed`, beyond chance). Whether it answered; `v` says why not.
/// `bestElsewhere(at, better)`: the best by `better` not at `at`'s place, -1
/// where there is none.
template <typename SamePlace, typename BestElsewhere>
bool byVotes(CandidateVerdict& v, const std::vector<Candidate>& candidates, const std::vector<SliceScores>& scores,
             const std::vector<double>& landed, const std::vector<int>& agreeing, const SamePlace& samePlace,
             const BestElsewhere& bestElsewhere) {
  const auto agreed_more = [&](size_t a, size_t b) { return agreeing[a] > agreeing[b]; };
  size_t voted = 0;
  for (size_t i = 1; i < candidates.size(); ++i)
    if (agreed_more(i, voted)) voted = i;
  if (agreeing[voted] == 0) {
    v.reason += "; no slice-pair estimate of the features agrees with any candidate";
    return false;
  }
  // With no candidate elsewhere, nothing elsewhere has a vote.
  static const std::vector<int> kNoVotes;
  const int other = bestElsewhere(voted, agreed_more);
  const std::pair<double, int> by_votes = votesLead(
      candidates[voted].feature_votes, other < 0 ? kNoVotes : candidates[static_cast<size_t>(other)].feature_votes);
  v.reason += "; the candidate most slice pairs agree with leads " +
              std::string(other < 0 ? "no votes elsewhere (no candidate is)" : "the most agreed-with elsewhere") +
              " by " + fixed(by_votes.first, 1) + " sigma over " + std::to_string(by_votes.second) + " source slices";
  if (by_votes.first < kBars.significant) return false;
  for (size_t i = 0; i < candidates.size(); ++i)
    if (!samePlace(candidates[i], candidates[voted]) && landed[i] > landed[voted] &&
        occupancyLead(scores[i], scores[voted]).first >= kBars.significant) {
      v.reason += ", but a candidate elsewhere lands more, beyond chance";
      return false;
    }
  v.answer = static_cast<int>(voted);
  v.on = CandidateVerdict::On::feature_votes;
  v.lead_sigma = by_votes.first, v.slices = by_votes.second;
  v.reason.clear();
  return true;
}

/// The decision's last step (decideOnCandidates): a search on the maps' own
/// cells (at the grid, pooled) whose own best pose lies at
/// the place of `best`, the candidate that lands the most, clear of its
/// next, answers that pose (its candidate, climbed) where it finds it again
/// with the maps' roles swapped. The occupancy's slices may not tell a
/// room's right place from a copy of it a wall along (rooms at g 0.1:
/// 2.5-2.9 sigma), where the whole occupancy, searched both ways, does. The
/// pose found twice is the pose answered, not another at its place that
/// lands a little more (on a real RGB-D crop, sunrgbd-room-38 at g 0.1, one
/// climbed onto a single slice 0.64 m off). The wide search does not look
/// again: its second look answered 7 more RGB-D crops of the matrix right,
/// and 2 of the unseen seeds wrong, 8-10 cells off at g 0.05
/// (docs/results.md, "Four more tries at the decision"). A search's clear
/// best pose elsewhere tells against it: on a real RGB-D crop
/// (sunrgbd-room-once-wrong-200, g 0.05) the pooled search's best led 1.62x
/// and was found again, and was wrong; the grid's best lay elsewhere, 1.96x
/// ahead (docs/results.md, "Other tests for the decision, replayed"). Found
/// again is at the same place (SecondLook::same_place), with no further bar
/// on where the two looks put the source's origin: the suites were measured so.
void bySecondLook(CandidateVerdict& v, const std::vector<Candidate>& candidates, size_t at,
                  const std::vector<SearchLead>& searches, const MatchParams& params, const ConsensusParams& tolerance,
                  const Eigen::Vector2d& centre) {
  const Candidate& best = candidates[at];
  const auto here = [&](const SearchLead& s) {
    return onePlace(s.found.best.transform, s.found.best.offset, best.landed.transform, best.landed.offset, tolerance,
                    centre, s.pooling - 1);
  };
  for (const SearchLead& s : searches)
    if (aheadBeyondChance(s.found, kBars.dense_lead) && !here(s)) {
      v.reason += "; " + std::string(fromName(s.from)) + "'s best pose lies elsewhere, " + fixed(s.found.lead(), 2) +
                  "x ahead of its next";
      return;
    }
  for (const SearchLead& s : searches) {
    if (s.from == Candidate::From::search_wide || !leads(s.found, kBars.dense_lead, params) || !here(s)) continue;
    if (!s.look) {
      v.needs_look = s.from;
      return;
    }
    if (!s.look->found || !s.look->same_place) {
      v.reason += "; " + std::string(fromName(s.from)) + " with the maps' roles swapped found " +
                  (s.look->found ? "another place, " + fixed(s.look->apart, 2) + " m apart" : "no pose");
      continue;
    }
    // The pose found again is the search's own best, as its candidate
    // climbed: the pose vouched for is the pose answered.
    v.answer = static_cast<int>(at);
    for (size_t i = 0; i < candidates.size(); ++i)
      if (candidates[i].from == s.from && candidates[i].rank == 0) v.answer = static_cast<int>(i);
    v.on = CandidateVerdict::On::second_look;
    v.lead_sigma = s.found.leadSigma(), v.slices = s.found.best.support;
    v.reason.clear();
    return;
  }
}

/// "The same pose": the same place (onePlace) within one consensus
/// tolerance at the source raster's centre, the consensus yaw and half the
/// smear of heights.
struct SamePose {
  ConsensusParams tolerance;
  Eigen::Vector2d source_centre;
  bool operator()(const DensePose& a, const DensePose& b) const {
    return onePlace(a.transform, a.offset, b.transform, b.offset, tolerance, source_centre);
  }
};

/// `searches` weighed against `candidates` (weighedSearches). Why over every
/// pose proposed elsewhere and not only the few the search kept: which
/// coarse poses it keeps hangs on ties: on a sparse crop many
/// shifts reach a peak's count, and the one kept is a matter of how the
/// correlation rounds. On a LiDAR crop (unseen kitti-lidar-324 at g 0.2), a
/// rounding that dropped the one pose near the best (1.01x) left the best
/// 1.46x ahead of its own next but 1.09x of the features' candidate
/// elsewhere, and corroborated it 9.0 m off (docs/results.md, "A search's
/// lead over every candidate elsewhere").
std::vector<SearchLead> weighedAgainstCandidates(std::vector<SearchLead> searches,
                                                 const std::vector<Candidate>& candidates, const SamePose& samePose) {
  for (SearchLead& s : searches) {
    if (!s.judged_as_candidates || !s.found.found) continue;
    for (const Candidate& c : candidates)
      if (!samePose(c.landed, s.found.best)) s.found.next_score = std::max(s.found.next_score, c.landed.score());
  }
  return searches;
}

/// decideOnCandidates' place: which candidate, by which step, or why none.
template <typename SamePlace>
CandidateVerdict decidePlace(const std::vector<Candidate>& candidates, const MatchParams& params,
                             const ConsensusParams& tolerance, const Eigen::Vector2d& source_centre,
                             const std::vector<SearchLead>& searches, const SamePlace& samePlace) {
  CandidateVerdict v;
  v.compared_at = source_centre;
  if (candidates.empty()) {
    v.reason = "no candidate pose";
    return v;
  }
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

  size_t best = 0;
  for (size_t i = 1; i < candidates.size(); ++i)
    if (lands_more(i, best)) best = i;
  const int rival = bestElsewhere(best, lands_more);
  std::pair<double, int> lead{0.0, 0};
  if (rival >= 0) lead = occupancyLead(scores[best], scores[static_cast<size_t>(rival)]);
  if (lead.first >= kBars.significant) {
    v.answer = static_cast<int>(best);
    v.lead_sigma = lead.first, v.slices = lead.second;
    return v;
  }
  v.reason = rival < 0 ? "no candidate elsewhere to weigh the best against"
                       : "the candidate that lands the most leads the best elsewhere by " + fixed(lead.first, 1) +
                             " sigma over " + std::to_string(lead.second) + " slices (need " +
                             fixed(kBars.significant, 0) + ")";

  if (byCorroboration(v, candidates, best, agreeing, searches, samePlace)) {
    v.lead_sigma = lead.first, v.slices = lead.second;
    return v;
  }
  if (!byVotes(v, candidates, scores, landed, agreeing, samePlace, bestElsewhere))
    bySecondLook(v, candidates, best, searches, params, tolerance, source_centre);
  return v;
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
    case CandidateVerdict::On::second_look:
      return "second_look";
  }
  return "?";
}

CandidateVerdict decideOnCandidates(const DecisionEvidence& e, const MatchParams& params) {
  const std::vector<Candidate>& candidates = e.candidates;
  const Eigen::Vector2d& source_centre = e.source_centre;
  const ConsensusParams tolerance = consensusParams(params, e.grid);
  const SamePose samePose{tolerance, source_centre};
  const auto samePlace = [&](const Candidate& a, const Candidate& b) { return samePose(a.landed, b.landed); };
  CandidateVerdict v = decidePlace(candidates, params, tolerance, source_centre,
                                   weighedAgainstCandidates(e.searches, candidates, samePose), samePlace);
  // A second look answers the pose its search found twice, not the best at its place.
  if (v.answer >= 0 && v.on != CandidateVerdict::On::second_look)
    v.answer = static_cast<int>(finestAt(candidates, static_cast<size_t>(v.answer), samePlace));
  return v;
}

std::vector<SearchLead> weighedSearches(const DecisionEvidence& e, const MatchParams& params) {
  return weighedAgainstCandidates(e.searches, e.candidates, SamePose{consensusParams(params, e.grid), e.source_centre});
}

}  // namespace tomomap
