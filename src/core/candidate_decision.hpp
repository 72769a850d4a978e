#pragma once
// One decision over the candidates, which answers a match (the verdict it
// replaced, verdict.hpp, is kept beside it for comparison): the best
// candidate answers when its lead over the best candidate elsewhere, slice
// by slice, is beyond chance (docs/algorithm.md, "One decision").
#include <optional>
#include <string>
#include <vector>

#include "candidates.hpp"
#include "verdict.hpp"

namespace tomomap {

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
  /// The answer finished in 6-DoF as the verdict's answer is (six_dof_finish.hpp),
  /// as the whole transform between the maps' own frames; unset where the
  /// finish did not run or did not hold.
  std::optional<Eigen::Matrix4d> finished;
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
};

const char* onName(CandidateVerdict::On on);

/// The decision over `candidates` (refineAndLand's, for maps of `grid` whose
/// source raster is centred at `source_centre`). Two candidates are at the same
/// place within one consensus tolerance at that centre, the consensus yaw and
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
/// pose of one of `searches` that answers alone in the verdict (at the
/// grid, pooled) answers (its candidate) where it lies at the place of the
/// one that lands the most, leads its next by kBars.dense_lead beyond chance
/// over min_support slices, no search's best pose elsewhere leads its next
/// so, and that search's second look finds it again (asked for by
/// needs_look). At the place the first three answer, the pose answered is
/// the candidate there that lands the most on the maps' own cells, unpooled.
CandidateVerdict decideOnCandidates(const std::vector<Candidate>& candidates, const MatchParams& params, double grid,
                                    const Eigen::Vector2d& source_centre, const std::vector<SearchLead>& searches);

}  // namespace tomomap
