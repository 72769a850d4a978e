#pragma once
// Candidate poses: what every search proposes, each refined and scored the
// same way on the two maps' occupancy (docs/algorithm.md, "Candidates").
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "features.hpp"
#include "match_params.hpp"
#include "pose_lander.hpp"

namespace tomomap {

/// One pose a search proposed, refined on the occupancy and landed there.
struct Candidate {
  enum class From { features, feature_rival, search_at_grid, search_wide, search_pooled };
  From from = From::features;
  int rank = 0;               ///< its rank among its search's proposals (0: that search's best)
  int feature_support = 0;    ///< agreeing slice pairs behind it (from features only)
  Rigid2D proposed;           ///< as its search proposed it
  int proposed_offset = 0;    ///< [slices]
  DensePose proposed_landed;  ///< the proposal landed as it is
  /// Refined (uphill on small maps, by an ICP on the occupancy on larger
  /// ones, where it was refined; at the occupancy's height) and landed: the
  /// pose judged.
  DensePose landed;
  std::vector<SliceLanding> slices;  ///< `landed`, source slice by source slice
  /// `landed` on the occupancy pooled to twice the cell, slice by slice
  /// (pooled slices), for maps finer than DenseSearchParams::finest_empty_cell:
  /// the empty space their own cells do not read. Empty otherwise.
  std::vector<SliceLanding> pooled_slices;
  /// Slice-pair estimates of the features that agree with `landed` (within
  /// the consensus tolerances, at its height within half the smear), by
  /// source slice index; empty where the features gave none to count.
  std::vector<int> feature_votes;
  /// `landed` as the whole transform between the maps' own frames (as
  /// MatchResult::matrix() gives the answer's).
  Eigen::Matrix4d T_own_frames = Eigen::Matrix4d::Identity();
};

const char* fromName(Candidate::From from);
/// Whether `from` is a dense search of the occupancy (not the features).
bool isDenseSearch(Candidate::From from);
/// The inverse: the search a name names; empty for any other text.
std::optional<Candidate::From> fromName(const std::string& name);

/// How many of the features' slice-pair estimates agree with a pose (T,
/// offset), by source slice index.
using FeatureVotes = std::function<std::vector<int>(const Rigid2D&, int)>;

/// A proposal: a pose, its height offset, where it came from.
struct Proposal {
  Candidate::From from = Candidate::From::features;
  int rank = 0;
  int feature_support = 0;
  Rigid2D T;
  int offset = 0;
};

/// Every proposal landed on the maps' occupancy as the dense search lands its
/// poses (pose_lander.hpp); the kMostRefined best distinct places are
/// refined: uphill (nearby_poses.hpp) on maps small enough for a dense
/// search, by one ICP on the occupancy (dense_refine.hpp) on larger ones.
/// Then every one takes the occupancy's height within half the smear of its
/// own (PoseLander::heightOffset).
std::vector<Candidate> refineAndLand(const MapFeatures& target, const MapFeatures& source,
                                     const std::vector<Proposal>& proposals, const MatchParams& params,
                                     const FeatureVotes& votes = {});
/// refineAndLand with `land`, the lander of the maps' occupancy
/// (target.occupancy, source.occupancy) the caller has prepared already.
std::vector<Candidate> refineAndLand(const PoseLander& land, const MapFeatures& target, const MapFeatures& source,
                                     const std::vector<Proposal>& proposals, const MatchParams& params,
                                     const FeatureVotes& votes = {});

}  // namespace tomomap
