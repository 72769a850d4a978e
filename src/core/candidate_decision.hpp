#pragma once
// The one decision that answers a match: the best candidate answers when its
// lead over the best candidate elsewhere, slice by slice, is beyond chance
// (docs/algorithm.md, "One decision"). Its evidence record, the bars it
// holds that evidence to (the one place they are stated), and the measures
// of a landed pose it reads.
#include <optional>
#include <string>
#include <vector>

#include "candidates.hpp"
#include "dense_search.hpp"
#include "match_params.hpp"

namespace tomomap {

/// Every bar the decision uses, each with its unit and how it was derived:
/// the one place they are stated. (What the bars measure is defined where it
/// is computed: a pose's score in dense_search.hpp, the leads' tests in
/// lead_sigma.hpp, the smear of heights in height_offsets.hpp, the user's
/// settings in match_params.hpp.)
struct DecisionBars {
  /// A lead counts only this many standard deviations beyond chance: one-sided,
  /// 0.13 %. On the matrix's 316 pairs no lower bar answered fewer wrong, and
  /// the decision is not tuned below it (docs/results.md, "Candidates on the
  /// matrix"). On a real RGB-D room (sunrgbd-room-2 at g 0.1) the pooled
  /// search's best pose led 13 to 7 (1.3 sigma) and was 13.9 m off; right
  /// answers on rooms lead by tens of sigma.
  double significant = 3.0;  ///< [standard deviations]
  /// A corroborated pose that lands more than this share as many telling
  /// cells in space the other map saw empty as on its occupancy is not
  /// corroborated: the corroborated right answers of all four suites landed at
  /// most 0.13; a room whose right pose no search proposed (seed 208, high
  /// noise, g 0.1) was corroborated 2.67 m off at 0.24 (docs/results.md, "A
  /// corroborated pose the empty space contradicts").
  double most_contradicted = 0.2;  ///< [share of telling cells landed]
  /// A dense search's best pose answers on its second look only where it
  /// scores this many times its next pose, and a search's best pose that far
  /// ahead elsewhere tells against any such answer. Room pairs (synth -w
  /// room, seeds 1-10, every noise, g 0.1 and 0.05), ranked by telling cells
  /// alone: wrong best poses led by 1.00-1.33, right ones by 1.04-3.37; with
  /// empty space read (seeds 1-100, low and high noise, g 0.1; and pooled from
  /// g 0.05) wrong ones led by at most 1.14.
  double dense_lead = 1.4;  ///< [ratio of scores]
  /// Pooled occupancy is searched only where its cell stays this fine (maps
  /// at g 0.1 and finer): room pairs were measured up to there.
  double coarsest_pooled_cell = 0.2;  ///< [m]
};
inline constexpr DecisionBars kBars{};

/// A pose's telling cells in the other map's empty space, per one landed on its occupancy.
double contradiction(const DensePose& p);
/// Whether a pose contradicts no more than kBars.most_contradicted.
bool consistent(const DensePose& p);
/// Whether a pose is consistent over at least `min_support` slices.
bool holdsOver(const DensePose& p, int min_support);

/// What one dense search says of its own best pose: how far ahead of its next.
struct DenseEvidence {
  bool found = false;     ///< searched, and found at least one pose
  DensePose best;         ///< its best pose (found only)
  double next_score = 0;  ///< its next pose's score; 0 if it found one only

  /// The best pose's score over its next's; 0 where even the best contradicts more than it finds.
  double lead() const;
  /// The same lead in sigmas of chance (significance): how far beyond what
  /// two poses alike would score apart.
  double leadSigma() const;
};

/// Whether a search found a best pose ahead of its next beyond chance
/// (kBars.significant), by whatever ratio.
bool beyondChance(const DenseEvidence& d);
/// Whether a search found a best pose that leads its next by `by`, beyond
/// chance (kBars.significant).
bool aheadBeyondChance(const DenseEvidence& d, double by);
/// The same, its best pose holding over min_support slices (holdsOver).
bool leads(const DenseEvidence& d, double by, const MatchParams& params);

/// The search whose best pose would answer, asked again with the maps' roles
/// swapped (the target's cells landed on the source's raster): a second look
/// at the same occupancy, its best pose turned back to map the source onto
/// the target.
struct SecondLook {
  bool found = false;  ///< it found a pose
  /// That pose is the search's best (the same place at the source's centre, within the smear of heights).
  bool same_place = false;
  double apart = 0;  ///< where the two put the source's frame origin, apart [m]
};

/// What the decision over the candidates says.
struct CandidateVerdict {
  int answer = -1;  ///< index into the candidates; -1: no reliable match
  /// The evidence it answered on: the occupancy the candidate lands on; or,
  /// where that does not tell, the occupancy's best place corroborated by a
  /// dense search's best pose (ahead of its next beyond chance) and a feature
  /// estimate there; or the features'
  /// slice-pair estimates it agrees with; or, last, a dense search's own
  /// best pose at the occupancy's best place, clear of its next and found
  /// again by the same search with the maps' roles swapped.
  enum class On { occupancy, corroborated, feature_votes, second_look } on = On::occupancy;
  /// The answer's lead over the best candidate elsewhere; on a second look,
  /// its search's best pose's over its next [normal sigmas].
  double lead_sigma = 0;
  int slices = 0;      ///< the slices it was measured over
  std::string reason;  ///< why there is no answer
  /// Where two candidates' places were compared: the source raster's centre,
  /// in the source's frame [m].
  Eigen::Vector2d compared_at = Eigen::Vector2d::Zero();
  /// The search whose second look would decide (SearchLead::look): look,
  /// and ask again. Unset once the decision has what it needs.
  std::optional<Candidate::From> needs_look;
};

/// What one dense search says of its own best pose, for the decision's last
/// step: how far ahead of its next it is, and, where the decision asks for
/// it, what the same search with the maps' roles swapped found.
struct SearchLead {
  Candidate::From from = Candidate::From::search_at_grid;
  DenseEvidence found;  ///< its best pose, as it found it, and its next's score
  int pooling = 1;      ///< the maps' slices per slice it searched: its height is that coarse
  std::optional<SecondLook> look;
  /// It judged its poses on the occupancy the candidates are landed on (the
  /// wide search): what that changes, weighedSearches.
  bool judged_as_candidates = false;
};

const char* onName(CandidateVerdict::On on);

/// Everything the decision weighs: the one record it is a function of.
struct DecisionEvidence {
  /// Every pose the searches proposed, refined and landed (refineAndLand).
  std::vector<Candidate> candidates;
  /// What each dense search that ran says of its own best pose.
  std::vector<SearchLead> searches;
  double grid = 0;  ///< the maps' grid [m]
  /// The source raster's centre, in the source's frame [m]: where two
  /// candidates' places are compared.
  Eigen::Vector2d source_centre = Eigen::Vector2d::Zero();
};

/// The decision on `e`. Two candidates are at the same place within one
/// consensus tolerance at the source raster's centre, the consensus yaw and
/// half the smear of heights. The candidate that lands the most (telling
/// cells less twice the contradicted ones, slice by slice, on occupancy pooled
/// to DenseSearchParams::finest_empty_cell where the grid is finer) answers if
/// it leads the best candidate elsewhere by kBars.significant over the slices; else
/// it answers as well where a dense search's best pose lies at its place,
/// ahead of its next beyond chance (`searches`), and at least one of the
/// features' slice-pair estimates agrees with it; else
/// the one the most slice-pair estimates agree with answers if it leads the
/// most agreed-with elsewhere by kBars.significant, source slice by source slice,
/// and no candidate elsewhere lands kBars.significant more; else the best
/// pose of one of the searches on the maps' own cells (at the grid,
/// pooled) answers (its candidate) where it lies at the place of the
/// one that lands the most, leads its next by kBars.dense_lead beyond chance
/// over min_support slices, no search's best pose elsewhere leads its next
/// so, and that search's second look finds it again (asked for by
/// needs_look). At the place the first three answer, the pose answered is
/// the candidate there that lands the most on the maps' own cells, unpooled.
/// The searches are weighed as weighedSearches weighs them.
CandidateVerdict decideOnCandidates(const DecisionEvidence& e, const MatchParams& params);

/// e.searches as decideOnCandidates weighs them. A search's next is its own
/// next pose; for one judged_as_candidates, the best of that and every
/// candidate not at its best pose's place: the same measure on the same
/// occupancy, so its lead is over every pose proposed elsewhere (a lead
/// below 1 where one of them scores more). What a result reports as a
/// search's lead.
std::vector<SearchLead> weighedSearches(const DecisionEvidence& e, const MatchParams& params);

}  // namespace tomomap
